// ImpostorViews: the impostor bakers' shared view texels and normal mip chain (ImpostorViews.h).
#include "TreeLod/ImpostorViews.h"

#include <algorithm>
#include <cmath>

namespace TreeLod
{
    namespace
    {
        /// Source texels [first, last) under destination texel d of a halving (an odd source's
        /// last texel goes to the last destination texel, as GpuTexture's mip sizes floor).
        std::pair<std::uint32_t, std::uint32_t> halvingRange(std::uint32_t d, std::uint32_t dstSize,
                                                             std::uint32_t srcSize)
        {
            if (srcSize == 1)
                return {0u, 1u};
            return {2 * d, d + 1 == dstSize ? srcSize : 2 * d + 2};
        }
    }

    void bleedImpostorView(ImpostorView& view, int rings, float fourthFallback)
    {
        std::vector<std::uint8_t> covered(view.coverage.size());
        for (std::size_t i = 0; i < covered.size(); ++i)
            covered[i] = view.coverage[i] > 0.0f ? 1 : 0;
        std::vector<glm::vec3> normalAo(view.normalAo.size()), fourth(view.normalAo.size());
        for (std::size_t i = 0; i < normalAo.size(); ++i)
        {
            normalAo[i] = glm::vec3(view.normalAo[i]);
            fourth[i] = glm::vec3(view.normalAo[i].w, 0.0f, 0.0f);
        }
        bleedValues(view.albedo, covered, view.width, view.height, rings, glm::vec3(0.2f));
        bleedValues(normalAo, covered, view.width, view.height, rings, glm::vec3(0.0f, 0.0f, 1.0f));
        bleedValues(fourth, covered, view.width, view.height, rings, glm::vec3(fourthFallback, 0.0f, 0.0f));
        for (std::size_t i = 0; i < normalAo.size(); ++i)
            view.normalAo[i] = glm::vec4(normalAo[i], fourth[i].x);
    }

    GpuTexture impostorNormalTexture(const std::string& name, std::uint32_t width, std::uint32_t height,
                                     std::vector<glm::vec4> normalAo, std::vector<float> coverage,
                                     std::uint32_t mipCount)
    {
        GpuTexture tex;
        tex.name = name;
        tex.format = GpuTextureFormat::RGBA8;
        tex.width = width;
        tex.height = height;
        tex.mipCount = mipCount == 0 ? fullMipCount(width, height) : std::min(mipCount, fullMipCount(width, height));
        tex.data.resize(gpuTextureBytes(tex.format, width, height, tex.mipCount));
        auto unpack = [](const glm::vec4& v) {
            return glm::vec3(v.x, v.y, std::sqrt(std::max(0.0f, 1.0f - v.x * v.x - v.y * v.y)));
        };
        for (std::uint32_t mip = 0; mip < tex.mipCount; ++mip)
        {
            const std::uint32_t w = tex.mipWidth(mip), h = tex.mipHeight(mip);
            if (mip > 0)
            {
                const std::uint32_t sw = tex.mipWidth(mip - 1), sh = tex.mipHeight(mip - 1);
                std::vector<glm::vec4> next(std::size_t(w) * h);
                std::vector<float> nextCoverage(next.size());
                for (std::uint32_t y = 0; y < h; ++y)
                    for (std::uint32_t x = 0; x < w; ++x)
                    {
                        const auto [y0, y1] = halvingRange(y, h, sh);
                        const auto [x0, x1] = halvingRange(x, w, sw);
                        glm::vec3 weightedN(0.0f), plainN(0.0f);
                        glm::vec2 weightedRest(0.0f), plainRest(0.0f); // AO, fourth
                        float cov = 0.0f;
                        int n = 0;
                        for (std::uint32_t yy = y0; yy < y1; ++yy)
                            for (std::uint32_t xx = x0; xx < x1; ++xx)
                            {
                                const std::size_t i = std::size_t(yy) * sw + xx;
                                const glm::vec3 normal = unpack(normalAo[i]);
                                const glm::vec2 rest(normalAo[i].z, normalAo[i].w);
                                weightedN += coverage[i] * normal;
                                weightedRest += coverage[i] * rest;
                                plainN += normal;
                                plainRest += rest;
                                cov += coverage[i];
                                ++n;
                            }
                        glm::vec3 normal = cov > 0.0f ? weightedN : plainN;
                        normal = glm::length(normal) > 1e-6f ? glm::normalize(normal) : glm::vec3(0, 0, 1);
                        const glm::vec2 rest = cov > 0.0f ? weightedRest / cov : plainRest / float(n);
                        const std::size_t o = std::size_t(y) * w + x;
                        next[o] = glm::vec4(normal.x, normal.y, rest.x, rest.y);
                        nextCoverage[o] = cov / float(n);
                    }
                normalAo = std::move(next);
                coverage = std::move(nextCoverage);
            }
            std::uint8_t* out = tex.data.data() + tex.mipOffset(mip);
            for (std::size_t i = 0; i < normalAo.size(); ++i)
            {
                out[4 * i + 0] = unitToByte(normalAo[i].x * 0.5f + 0.5f);
                out[4 * i + 1] = unitToByte(normalAo[i].y * 0.5f + 0.5f);
                out[4 * i + 2] = unitToByte(normalAo[i].z);
                out[4 * i + 3] = unitToByte(normalAo[i].w);
            }
        }
        return tex;
    }
}
