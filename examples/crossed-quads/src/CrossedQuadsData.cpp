// CrossedQuadsData: the "crossed-quads" chunk (layout and meaning in CrossedQuadsData.h).
#include "TreeLod/CrossedQuadsData.h"

#include "TreeLod/ChunkCodec.h"
#include "TreeLod/Package.h"

#include <cmath>

namespace TreeLod
{
    namespace
    {
        constexpr std::uint32_t KNOWN_FLAGS = 0;
        /// The quad records (their textures follow them); the count limits serve decode and validate.
        constexpr ArrayLayout QUADS{5 * 4, 1, 1, CROSSED_QUADS_MAX_QUADS, "quads"};

        /// A quad record's fields, one list for the encoder and the decoder.
        constexpr auto quadFields = [](auto& s, auto& q) { s.fields(q.azimuth, q.left, q.right, q.bottom, q.top); };

        std::string quadElement(std::size_t i) { return chunkElement(CROSSED_QUADS_CHUNK, 0) + ", quad " + std::to_string(i); }
    }

    glm::vec3 CrossedQuad::rightAxis() const
    {
        const float a = glm::radians(azimuth);
        return glm::vec3(std::cos(a), 0.0f, -std::sin(a));
    }

    glm::vec3 CrossedQuad::facing() const
    {
        const float a = glm::radians(azimuth);
        return glm::vec3(std::sin(a), 0.0f, std::cos(a));
    }

    std::uint64_t CrossedQuadsData::textureBytes() const
    {
        std::uint64_t bytes = 0;
        for (const CrossedQuad& q : quads)
            bytes += q.colour.data.size();
        return bytes;
    }

    Result<void> CrossedQuadsData::validate(const std::string& label) const
    {
        const std::string name = chunkElement(CROSSED_QUADS_CHUNK, 0);
        if (std::string problem = QUADS.countProblem(quads.size()); !problem.empty())
            return fail(label, name, problem);
        if (!(alphaCutoff > 0.0f && alphaCutoff <= 1.0f))
            return fail(label, name, "alpha cutoff " + std::to_string(alphaCutoff) + " outside (0, 1]");
        for (std::size_t i = 0; i < quads.size(); ++i)
        {
            const CrossedQuad& q = quads[i];
            if (!(q.azimuth >= 0.0f && q.azimuth < 360.0f))
                return fail(label, quadElement(i), "azimuth " + std::to_string(q.azimuth) + " outside [0, 360)");
            const bool finite = std::isfinite(q.left) && std::isfinite(q.right) && std::isfinite(q.bottom) &&
                                std::isfinite(q.top) && std::isfinite(q.right - q.left) && std::isfinite(q.top - q.bottom);
            if (!finite || !(q.right > q.left) || !(q.top > q.bottom))
                return fail(label, quadElement(i),
                            "s from " + std::to_string(q.left) + " to " + std::to_string(q.right) + ", y from " +
                                std::to_string(q.bottom) + " to " + std::to_string(q.top) +
                                " (finite, right > left and top > bottom needed)");
            const std::string problem = gpuTextureProblem(q.colour, {GpuTextureFormat::RGBA8, GpuTextureFormat::DXT5});
            if (!problem.empty())
                return fail(label, quadElement(i) + ", texture '" + q.colour.name + "'", problem);
        }
        return {};
    }

    std::vector<std::uint8_t> encodeCrossedQuadsChunk(const CrossedQuadsData& data)
    {
        ByteWriter w;
        w.reserve(64 + data.quads.size() * (QUADS.recordBytes + 64) + data.textureBytes());
        w.u32(KNOWN_FLAGS);
        w.f32(data.alphaCutoff);
        writeArray(w, data.quads, QUADS, quadFields);
        for (const CrossedQuad& q : data.quads)
            writeGpuTexture(w, q.colour);
        return w.take();
    }

    Result<CrossedQuadsData> decodeCrossedQuadsChunk(const std::vector<std::uint8_t>& bytes, const std::string& label)
    {
        const std::string name = chunkElement(CROSSED_QUADS_CHUNK, 0);
        ByteReader r(bytes.data(), bytes.size(), label, name);
        CrossedQuadsData data;
        readFlags(r, KNOWN_FLAGS);
        data.alphaCutoff = r.f32();
        // The count is checked against the bytes left and QUADS' limits before anything is allocated.
        readArray(r, data.quads, QUADS, quadFields);
        for (std::size_t i = 0; i < data.quads.size() && r.ok(); ++i)
            readGpuTexture(r, quadElement(i) + ", texture", data.quads[i].colour);
        return finishDecode(r, label, name, std::move(data));
    }
}
