// The core descriptor of the ellipsoid tree's lines, runtime half: chunk "ellipsoid-lines"
// (EllipsoidLineData.h).
#include "TreeLod/EllipsoidLineData.h"
#include "TreeLod/TechniqueDescriptor.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>

namespace TreeLod
{
    namespace
    {
        Result<ChunkSummary> inspect(const std::vector<std::uint8_t>& bytes, const std::string& label)
        {
            Result<EllipsoidLineData> data = decodeEllipsoidLineChunk(bytes, label);
            if (!data)
                return data.error();
            const EllipsoidLineData& d = data.value();
            std::string counts;
            nlohmann::json levelsJson = nlohmann::json::array();
            for (const EllipsoidLineLevel& l : d.levels)
            {
                char one[96];
                std::snprintf(one, sizeof(one), "%s%u (%.0f px, error %.4f)", counts.empty() ? "" : ", ", l.count,
                              l.targetHeightPx, l.imageError);
                counts += one;
                levelsJson.push_back({{"first", l.first},
                                      {"count", l.count},
                                      {"targetHeightPx", l.targetHeightPx},
                                      {"imageError", l.imageError}});
            }
            char text[192];
            std::snprintf(text, sizeof(text),
                          "%zu lines in %zu levels, %zu colours, %zu bytes (%zu per line): ", d.lines.size(),
                          d.levels.size(), d.palette.size(), d.encodedBytes(), ELLIPSOID_LINE_RECORD_BYTES);
            ChunkSummary summary;
            summary.text = text + counts;
            summary.json = nlohmann::json{{"lines", d.lines.size()},
                                          {"bytes", d.encodedBytes()},
                                          {"bytesPerLine", ELLIPSOID_LINE_RECORD_BYTES},
                                          {"colours", d.palette.size()},
                                          {"heightMetres", d.heightMetres},
                                          {"levels", levelsJson}}
                               .dump();
            return summary;
        }

        void fuzz(const std::vector<std::uint8_t>& bytes)
        {
            Result<EllipsoidLineData> decoded = decodeEllipsoidLineChunk(bytes, "fuzz");
            if (!decoded)
                return;
            // What a renderer reads: each level's range, each line's radius and palette colour.
            for (const EllipsoidLineLevel& l : decoded->levels)
                for (std::uint32_t i = l.first; i < l.first + l.count; ++i)
                {
                    if (i >= decoded->lines.size())
                        __builtin_trap();
                    const EllipsoidLine& line = decoded->lines[i];
                    if (!(line.radius > 0.0f) || !std::isfinite(line.radius) ||
                        line.colour >= decoded->palette.size() ||
                        !std::isfinite(line.start.x + line.start.y + line.start.z + line.end.x + line.end.y +
                                       line.end.z))
                        __builtin_trap();
                }
        }

        const TechniqueRegistration registration(
            {ELLIPSOID_LINES_CHUNK,
             "the branches as lines from the skeleton, merged by image error (straighten, combine), one level per "
             "quarter of the lines",
             ELLIPSOID_LINES_CHUNK_FORMAT_VERSION, &inspect, &fuzz});
    }
}
