// The core descriptor of the one-quad impostor, runtime half: chunk "impostor" (ImpostorData.h).
#include "TreeLod/ImpostorData.h"
#include "TreeLod/TechniqueDescriptor.h"

#include <nlohmann/json.hpp>

#include <cstdio>

namespace TreeLod
{
    namespace
    {
        Result<ChunkSummary> inspect(const std::vector<std::uint8_t>& bytes, const std::string& label)
        {
            Result<ImpostorData> data = decodeImpostorChunk(bytes, label);
            if (!data)
                return data.error();
            const ImpostorData& d = data.value();
            char text[256];
            std::snprintf(text, sizeof(text),
                          "quad %.3f x %.3f m (y %.3f .. %.3f), colour and normal textures %ux%u %s, %u mip levels, "
                          "alpha cutoff %.2f, %llu bytes on the GPU",
                          2.0f * d.halfWidth, d.top - d.bottom, d.bottom, d.top, d.colour.width, d.colour.height,
                          isBlockCompressed(d.colour.format) ? "DXT5 / DXT1" : "RGBA8", d.colour.mipCount,
                          d.alphaCutoff, (unsigned long long)d.gpuBytes());
            ChunkSummary summary;
            summary.text = text;
            summary.json = nlohmann::json{{"halfWidth", d.halfWidth},
                                          {"bottom", d.bottom},
                                          {"top", d.top},
                                          {"alphaCutoff", d.alphaCutoff},
                                          {"texture", {d.colour.width, d.colour.height}},
                                          {"mipCount", d.colour.mipCount},
                                          {"compressed", isBlockCompressed(d.colour.format)},
                                          {"gpuBytes", d.gpuBytes()}}
                               .dump();
            return summary;
        }

        void fuzz(const std::vector<std::uint8_t>& bytes)
        {
            Result<ImpostorData> decoded = decodeImpostorChunk(bytes, "fuzz");
            if (!decoded)
                return;
            // What the Ogre side uploads: every mip of both textures.
            for (const GpuTexture* t : {&decoded->colour, &decoded->normal})
                for (std::uint32_t level = 0; level < t->mipCount; ++level)
                    if (t->mipOffset(level) + t->mipBytes(level) > t->data.size())
                        __builtin_trap();
        }

        const TechniqueRegistration registration(
            {IMPOSTOR_CHUNK, "one camera-facing quad with baked colour and normal textures, the speed floor",
             IMPOSTOR_CHUNK_FORMAT_VERSION, &inspect, &fuzz});
    }
}
