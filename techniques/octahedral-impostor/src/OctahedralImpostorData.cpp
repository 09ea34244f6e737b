// OctahedralImpostorData: the "octahedral-impostor" chunk and its view mapping (layout and
// meaning in OctahedralImpostorData.h).
#include "TreeLod/OctahedralImpostorData.h"

#include "TreeLod/ChunkCodec.h"
#include "TreeLod/Package.h"

#include <algorithm>
#include <cmath>

namespace TreeLod
{
    namespace
    {
        constexpr std::uint32_t KNOWN_FLAGS = 0;

        std::string size(std::uint32_t w, std::uint32_t h) { return std::to_string(w) + "x" + std::to_string(h); }

        /// What is wrong with `tex` as a texture of the atlas, "" when nothing.
        std::string textureProblem(const GpuTexture& tex, std::uint32_t frames)
        {
            if (std::string problem = gpuTextureProblem(tex, {GpuTextureFormat::RGBA8, GpuTextureFormat::DXT5});
                !problem.empty())
                return problem;
            if (tex.width != tex.height)
                return "size " + size(tex.width, tex.height) + " (a square needed)";
            const std::uint32_t f = tex.width / frames;
            if (tex.width % frames != 0 || f % 4 != 0 || f < 8)
                return "size " + size(tex.width, tex.height) + " is not " + std::to_string(frames) +
                       " frames a side of a multiple of 4 texels, at least 8";
            if (f % (1u << (tex.mipCount - 1)) != 0 || (f >> (tex.mipCount - 1)) < 4)
                return std::to_string(tex.mipCount) + " mip levels for frames of " + std::to_string(f) +
                       " texels (each level halves every frame exactly, down to 4 texels at least)";
            return {};
        }
    }

    glm::vec2 hemiOctahedralEncode(const glm::vec3& direction)
    {
        const glm::vec3 d(direction.x, std::max(direction.y, 0.0f), direction.z);
        const float l1 = std::abs(d.x) + d.y + std::abs(d.z);
        if (!(l1 > 0.0f))
            return glm::vec2(0.0f); // straight down: the view from above
        const float x = d.x / l1, z = d.z / l1;
        return glm::vec2(x + z, x - z);
    }

    glm::vec3 hemiOctahedralDecode(const glm::vec2& point)
    {
        const glm::vec2 p = glm::clamp(point, glm::vec2(-1.0f), glm::vec2(1.0f));
        const float x = 0.5f * (p.x + p.y), z = 0.5f * (p.x - p.y);
        return glm::normalize(glm::vec3(x, std::max(1.0f - std::abs(x) - std::abs(z), 0.0f), z));
    }

    glm::vec3 octahedralFrameDirection(std::uint32_t i, std::uint32_t j, std::uint32_t framesPerSide)
    {
        const float last = float(framesPerSide - 1);
        return hemiOctahedralDecode(glm::vec2(2.0f * float(i) / last - 1.0f, 2.0f * float(j) / last - 1.0f));
    }

    OctahedralFrameAxes octahedralFrameAxes(const glm::vec3& towards)
    {
        const glm::vec3 r = glm::cross(glm::vec3(0.0f, 1.0f, 0.0f), towards);
        const float length = glm::length(r);
        OctahedralFrameAxes axes;
        axes.right = length > 1e-6f ? r / length : glm::vec3(1.0f, 0.0f, 0.0f);
        axes.up = glm::cross(towards, axes.right);
        return axes;
    }

    float octahedralHalfHeight(const glm::vec3& towards, float radius, float bottom, float top)
    {
        const glm::vec3 up = octahedralFrameAxes(towards).up;
        return 0.5f * (top - bottom) * std::abs(up.y) + radius * std::sqrt(up.x * up.x + up.z * up.z);
    }

    float octahedralFrameSide(const glm::vec3& towards, float radius, float bottom, float top,
                              std::uint32_t frameTexels)
    {
        const float content = std::max(2.0f * radius, 2.0f * octahedralHalfHeight(towards, radius, bottom, top));
        return content * float(frameTexels) / float(frameTexels - 2 * OCTAHEDRAL_MARGIN_TEXELS);
    }

    float octahedralDepthRadius(float radius, float bottom, float top)
    {
        const float h = 0.5f * (top - bottom);
        return std::sqrt(radius * radius + h * h);
    }

    Result<void> OctahedralImpostorData::validate(const std::string& label) const
    {
        const std::string name = chunkElement(OCTAHEDRAL_IMPOSTOR_CHUNK, 0);
        if (framesPerSide < 2 || framesPerSide > 32)
            return fail(label, name + ", frames", std::to_string(framesPerSide) + " frames a side (2 to 32 needed)");
        if (!std::isfinite(radius) || !std::isfinite(bottom) || !std::isfinite(top) || !(radius > 0.0f) ||
            !(top > bottom) || !std::isfinite(top - bottom))
            return fail(label, name + ", cylinder",
                        "radius " + std::to_string(radius) + ", y from " + std::to_string(bottom) + " to " +
                            std::to_string(top) + " (finite, radius > 0 and top > bottom needed)");
        if (!(alphaCutoff > 0.0f && alphaCutoff <= 1.0f))
            return fail(label, name + ", cylinder", "alpha cutoff " + std::to_string(alphaCutoff) + " outside (0, 1]");
        for (const GpuTexture* tex : {&colour, &normal})
        {
            const bool isColour = tex == &colour;
            const std::string problem = textureProblem(*tex, framesPerSide);
            if (!problem.empty())
                return fail(label, name + (isColour ? ", colour texture '" : ", normal texture '") + tex->name + "'",
                            problem);
        }
        if (normal.width != colour.width || normal.mipCount != colour.mipCount)
            return fail(label, name + ", normal texture '" + normal.name + "'",
                        size(normal.width, normal.height) + " with " + std::to_string(normal.mipCount) +
                            " mip levels, the colour texture is " + size(colour.width, colour.height) + " with " +
                            std::to_string(colour.mipCount));
        return {};
    }

    std::vector<std::uint8_t> encodeOctahedralImpostorChunk(const OctahedralImpostorData& data)
    {
        ByteWriter w;
        w.reserve(128 + data.colour.data.size() + data.normal.data.size());
        w.u32(KNOWN_FLAGS);
        w.fields(data.framesPerSide, data.radius, data.bottom, data.top, data.alphaCutoff);
        writeGpuTexture(w, data.colour);
        writeGpuTexture(w, data.normal);
        return w.take();
    }

    Result<OctahedralImpostorData> decodeOctahedralImpostorChunk(const std::vector<std::uint8_t>& bytes,
                                                                 const std::string& label)
    {
        const std::string name = chunkElement(OCTAHEDRAL_IMPOSTOR_CHUNK, 0);
        ByteReader r(bytes.data(), bytes.size(), label, name);
        OctahedralImpostorData data;
        readFlags(r, KNOWN_FLAGS);
        r.setElement(name + ", frames");
        data.framesPerSide = r.u32();
        r.setElement(name + ", cylinder");
        r.fields(data.radius, data.bottom, data.top, data.alphaCutoff);
        readGpuTexture(r, name + ", colour texture", data.colour);
        readGpuTexture(r, name + ", normal texture", data.normal);
        return finishDecode(r, label, name, std::move(data));
    }
}
