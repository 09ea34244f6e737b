// The core descriptor of the ellipsoid tree, runtime half: chunk "ellipsoids" (EllipsoidTreeData.h).
#include "TreeLod/EllipsoidTreeData.h"
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
            Result<EllipsoidTreeData> data = decodeEllipsoidTreeChunk(bytes, label);
            if (!data)
                return data.error();
            const EllipsoidTreeData& d = data.value();
            std::string counts, levels;
            nlohmann::json levelsJson = nlohmann::json::array();
            for (const EllipsoidLevel& l : d.levels)
            {
                char one[128];
                std::snprintf(one, sizeof(one), "%s%u (x%.2f, %.0f px, error %.4f, noise %.2f/%.2f)",
                              counts.empty() ? "" : ", ", l.count, l.scale, l.targetHeightPx, l.imageError,
                              l.noiseThreshold, l.normalBlend);
                counts += one;
                levelsJson.push_back({{"first", l.first},
                                      {"count", l.count},
                                      {"scale", l.scale},
                                      {"targetHeightPx", l.targetHeightPx},
                                      {"imageError", l.imageError},
                                      {"noiseThreshold", l.noiseThreshold},
                                      {"normalBlend", l.normalBlend}});
            }
            char text[160];
            std::snprintf(text, sizeof(text), "%zu ellipsoids in %zu levels, %zu bytes (%zu per ellipsoid): ",
                          d.ellipsoids.size(), d.levels.size(), d.encodedBytes(), ELLIPSOID_RECORD_BYTES);
            ChunkSummary summary;
            summary.text = text + counts;
            summary.json = nlohmann::json{{"ellipsoids", d.ellipsoids.size()},
                                          {"bytes", d.encodedBytes()},
                                          {"bytesPerEllipsoid", ELLIPSOID_RECORD_BYTES},
                                          {"levels", levelsJson}}
                               .dump();
            return summary;
        }

        void fuzz(const std::vector<std::uint8_t>& bytes)
        {
            Result<EllipsoidTreeData> decoded = decodeEllipsoidTreeChunk(bytes, "fuzz");
            if (!decoded)
                return;
            // What a renderer reads: each level's range, each ellipsoid's axes scaled by its level.
            for (const EllipsoidLevel& l : decoded->levels)
                for (std::uint32_t i = l.first; i < l.first + l.count; ++i)
                {
                    if (i >= decoded->ellipsoids.size())
                        __builtin_trap();
                    const glm::vec3 r = l.scale * decoded->ellipsoids[i].radii;
                    if (!(r.x > 0.0f && r.y > 0.0f && r.z > 0.0f) || !std::isfinite(r.x + r.y + r.z))
                        __builtin_trap();
                }
        }

        const TechniqueRegistration registration(
            {ELLIPSOID_TREE_CHUNK,
             "the leaves as a hierarchy of EM/GMM-clustered ellipsoids, one level per quarter of the primitives",
             ELLIPSOID_TREE_CHUNK_FORMAT_VERSION, &inspect, &fuzz});
    }
}
