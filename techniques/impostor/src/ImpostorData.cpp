// ImpostorData: the "impostor" chunk (layout and meaning in ImpostorData.h).
#include "TreeLod/ImpostorData.h"

#include "TreeLod/ChunkCodec.h"
#include "TreeLod/Package.h"

#include <cmath>

namespace TreeLod
{
    namespace
    {
        constexpr std::uint32_t KNOWN_FLAGS = 0;

        std::string size(std::uint32_t w, std::uint32_t h) { return std::to_string(w) + "x" + std::to_string(h); }
    }

    Result<void> ImpostorData::validate(const std::string& label) const
    {
        const std::string name = chunkElement(IMPOSTOR_CHUNK, 0);
        if (!std::isfinite(halfWidth) || !std::isfinite(bottom) || !std::isfinite(top) || !(halfWidth > 0.0f) ||
            !(top > bottom) || !std::isfinite(top - bottom))
            return fail(label, name + ", quad",
                        "half width " + std::to_string(halfWidth) + ", y from " + std::to_string(bottom) + " to " +
                            std::to_string(top) + " (finite, width > 0 and top > bottom needed)");
        if (!(alphaCutoff > 0.0f && alphaCutoff <= 1.0f))
            return fail(label, name + ", quad", "alpha cutoff " + std::to_string(alphaCutoff) + " outside (0, 1]");
        for (const GpuTexture* tex : {&colour, &normal})
        {
            const bool isColour = tex == &colour;
            const std::string problem = gpuTextureProblem(
                *tex, {GpuTextureFormat::RGBA8, isColour ? GpuTextureFormat::DXT5 : GpuTextureFormat::DXT1});
            if (!problem.empty())
                return fail(label, name + (isColour ? ", colour texture '" : ", normal texture '") + tex->name + "'",
                            problem);
        }
        if (normal.width != colour.width || normal.height != colour.height || normal.mipCount != colour.mipCount)
            return fail(label, name + ", normal texture '" + normal.name + "'",
                        size(normal.width, normal.height) + " with " + std::to_string(normal.mipCount) +
                            " mip levels, the colour texture is " + size(colour.width, colour.height) + " with " +
                            std::to_string(colour.mipCount));
        return {};
    }

    std::vector<std::uint8_t> encodeImpostorChunk(const ImpostorData& data)
    {
        ByteWriter w;
        w.reserve(128 + data.colour.data.size() + data.normal.data.size());
        w.u32(KNOWN_FLAGS);
        w.fields(data.halfWidth, data.bottom, data.top, data.alphaCutoff);
        writeGpuTexture(w, data.colour);
        writeGpuTexture(w, data.normal);
        return w.take();
    }

    Result<ImpostorData> decodeImpostorChunk(const std::vector<std::uint8_t>& bytes, const std::string& label)
    {
        const std::string name = chunkElement(IMPOSTOR_CHUNK, 0);
        ByteReader r(bytes.data(), bytes.size(), label, name);
        ImpostorData data;
        readFlags(r, KNOWN_FLAGS);
        r.setElement(name + ", quad");
        r.fields(data.halfWidth, data.bottom, data.top, data.alphaCutoff);
        readGpuTexture(r, name + ", colour texture", data.colour);
        readGpuTexture(r, name + ", normal texture", data.normal);
        return finishDecode(r, label, name, std::move(data));
    }
}
