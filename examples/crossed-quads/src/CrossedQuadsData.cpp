// CrossedQuadsData: the "crossed-quads" chunk (layout and meaning in CrossedQuadsData.h).
#include "TreeLod/CrossedQuadsData.h"

#include "TreeLod/ByteReader.h"
#include "TreeLod/ByteWriter.h"
#include "TreeLod/Package.h"

#include <cmath>

namespace TreeLod
{
    namespace
    {
        constexpr std::uint32_t KNOWN_FLAGS = 0;
        constexpr std::size_t QUAD_RECORD_BYTES = 5 * 4;

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
        if (quads.empty() || quads.size() > CROSSED_QUADS_MAX_QUADS)
            return fail(label, name, std::to_string(quads.size()) + " quads (1.." +
                                         std::to_string(CROSSED_QUADS_MAX_QUADS) + " needed)");
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
        w.reserve(64 + data.quads.size() * (QUAD_RECORD_BYTES + 64) + data.textureBytes());
        w.u32(KNOWN_FLAGS);
        w.f32(data.alphaCutoff);
        w.u32(std::uint32_t(data.quads.size()));
        for (const CrossedQuad& q : data.quads)
        {
            w.f32(q.azimuth);
            w.f32(q.left);
            w.f32(q.right);
            w.f32(q.bottom);
            w.f32(q.top);
        }
        for (const CrossedQuad& q : data.quads)
            writeGpuTexture(w, q.colour);
        return w.take();
    }

    Result<CrossedQuadsData> decodeCrossedQuadsChunk(const std::vector<std::uint8_t>& bytes, const std::string& label)
    {
        const std::string name = chunkElement(CROSSED_QUADS_CHUNK, 0);
        ByteReader r(bytes.data(), bytes.size(), label, name);
        CrossedQuadsData data;
        const std::uint32_t flags = r.u32();
        if (r.ok() && (flags & ~KNOWN_FLAGS) != 0)
            r.failHere("unknown flags " + std::to_string(flags));
        data.alphaCutoff = r.f32();
        // count() checks the records fit in the bytes left before anything is allocated.
        const std::uint32_t count = r.count(QUAD_RECORD_BYTES);
        if (r.ok() && (count < 1 || count > CROSSED_QUADS_MAX_QUADS))
            r.failHere(std::to_string(count) + " quads (1.." + std::to_string(CROSSED_QUADS_MAX_QUADS) + " needed)");
        if (!r.ok())
            return r.error();
        data.quads.resize(count);
        for (std::uint32_t i = 0; i < count; ++i)
        {
            r.setElement(quadElement(i));
            CrossedQuad& q = data.quads[i];
            q.azimuth = r.f32();
            q.left = r.f32();
            q.right = r.f32();
            q.bottom = r.f32();
            q.top = r.f32();
        }
        for (std::uint32_t i = 0; i < count && r.ok(); ++i)
            if (!readGpuTexture(r, quadElement(i) + ", texture", data.quads[i].colour))
                break;
        return finishDecode(r, label, name, std::move(data));
    }
}
