// The core descriptor of the crossed quads, runtime half: chunk "crossed-quads"
// (CrossedQuadsData.h): `treelod info` and the package fuzzer find it here.
#include "TreeLod/CrossedQuadsData.h"
#include "TreeLod/TechniqueDescriptor.h"

#include <nlohmann/json.hpp>

#include <cstdio>

namespace TreeLod
{
    namespace
    {
        Result<ChunkSummary> inspect(const std::vector<std::uint8_t>& bytes, const std::string& label)
        {
            Result<CrossedQuadsData> data = decodeCrossedQuadsChunk(bytes, label);
            if (!data)
                return data.error();
            const CrossedQuadsData& d = data.value();
            const CrossedQuad& first = d.quads.front();
            std::string azimuths;
            nlohmann::json quads = nlohmann::json::array();
            for (const CrossedQuad& q : d.quads)
            {
                char a[32];
                std::snprintf(a, sizeof(a), "%s%.0f", azimuths.empty() ? "" : ", ", q.azimuth);
                azimuths += a;
                quads.push_back({{"azimuth", q.azimuth},
                                 {"left", q.left},
                                 {"right", q.right},
                                 {"bottom", q.bottom},
                                 {"top", q.top},
                                 {"texture", {q.colour.width, q.colour.height}},
                                 {"mipCount", q.colour.mipCount}});
            }
            char text[256];
            std::snprintf(text, sizeof(text),
                          "%zu quads at azimuths %s degrees, %.3f m tall, textures %ux%u %s (first quad), "
                          "alpha cutoff %.2f, %llu texture bytes",
                          d.quads.size(), azimuths.c_str(), first.top - first.bottom, first.colour.width,
                          first.colour.height, isBlockCompressed(first.colour.format) ? "DXT5" : "RGBA8",
                          d.alphaCutoff, (unsigned long long)d.textureBytes());
            ChunkSummary summary;
            summary.text = text;
            summary.json = nlohmann::json{{"quadCount", d.quads.size()},
                                          {"alphaCutoff", d.alphaCutoff},
                                          {"compressed", isBlockCompressed(first.colour.format)},
                                          {"textureBytes", d.textureBytes()},
                                          {"quads", quads}}
                               .dump();
            return summary;
        }

        void fuzz(const std::vector<std::uint8_t>& bytes)
        {
            Result<CrossedQuadsData> decoded = decodeCrossedQuadsChunk(bytes, "fuzz");
            if (!decoded)
                return;
            // What the Ogre side reads: a quad's rectangle and every mip of its texture.
            if (decoded->quads.empty() || decoded->quads.size() > CROSSED_QUADS_MAX_QUADS)
                __builtin_trap();
            for (const CrossedQuad& q : decoded->quads)
            {
                if (!(q.right > q.left && q.top > q.bottom))
                    __builtin_trap();
                for (std::uint32_t level = 0; level < q.colour.mipCount; ++level)
                    if (q.colour.mipOffset(level) + q.colour.mipBytes(level) > q.colour.data.size())
                        __builtin_trap();
            }
        }

        const TechniqueRegistration registration(
            {CROSSED_QUADS_CHUNK, "two or three textured vertical quads crossing on the trunk axis (an example)",
             CROSSED_QUADS_CHUNK_FORMAT_VERSION, &inspect, &fuzz});
    }
}
