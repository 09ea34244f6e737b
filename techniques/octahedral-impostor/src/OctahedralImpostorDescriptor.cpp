// The core descriptor of the octahedral impostor, runtime half: chunk "octahedral-impostor"
// (OctahedralImpostorData.h).
#include "TreeLod/OctahedralImpostorData.h"
#include "TreeLod/TechniqueDescriptor.h"

#include <nlohmann/json.hpp>

#include <cstdio>

namespace TreeLod
{
    namespace
    {
        Result<ChunkSummary> inspect(const std::vector<std::uint8_t>& bytes, const std::string& label)
        {
            Result<OctahedralImpostorData> data = decodeOctahedralImpostorChunk(bytes, label);
            if (!data)
                return data.error();
            const OctahedralImpostorData& d = data.value();
            char text[320];
            std::snprintf(text, sizeof(text),
                          "%u x %u views of %u texels (atlas %ux%u %s, %u mip levels), cylinder radius %.3f m, "
                          "y %.3f .. %.3f, alpha cutoff %.2f, %llu bytes on the GPU",
                          d.framesPerSide, d.framesPerSide, d.frameTexels(), d.colour.width, d.colour.height,
                          isBlockCompressed(d.colour.format) ? "DXT5" : "RGBA8", d.colour.mipCount, d.radius,
                          d.bottom, d.top, d.alphaCutoff, (unsigned long long)d.gpuBytes());
            ChunkSummary summary;
            summary.text = text;
            summary.json = nlohmann::json{{"framesPerSide", d.framesPerSide},
                                          {"frameTexels", d.frameTexels()},
                                          {"radius", d.radius},
                                          {"bottom", d.bottom},
                                          {"top", d.top},
                                          {"alphaCutoff", d.alphaCutoff},
                                          {"mipCount", d.colour.mipCount},
                                          {"compressed", isBlockCompressed(d.colour.format)},
                                          {"gpuBytes", d.gpuBytes()}}
                               .dump();
            return summary;
        }

        void fuzz(const std::vector<std::uint8_t>& bytes)
        {
            Result<OctahedralImpostorData> decoded = decodeOctahedralImpostorChunk(bytes, "fuzz");
            if (!decoded)
                return;
            // What the Ogre side uploads: every mip of both textures.
            for (const GpuTexture* t : {&decoded->colour, &decoded->normal})
                for (std::uint32_t level = 0; level < t->mipCount; ++level)
                    if (t->mipOffset(level) + t->mipBytes(level) > t->data.size())
                        __builtin_trap();
        }

        const TechniqueRegistration registration(
            {OCTAHEDRAL_IMPOSTOR_CHUNK,
             "many baked views over the upper hemisphere, the three nearest blended on one quad",
             OCTAHEDRAL_IMPOSTOR_CHUNK_FORMAT_VERSION, &inspect, &fuzz});
    }
}
