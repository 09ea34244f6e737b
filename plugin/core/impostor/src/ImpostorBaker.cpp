// ImpostorBaker: the one-quad impostor (steps in ImpostorBaker.h, format in ImpostorData.h).
#include "TreeLod/ImpostorBaker.h"

#include "TreeLod/AmbientOcclusion.h"
#include "TreeLod/Image.h"
#include "TreeLod/Package.h"
#include "TreeLod/ReferenceRenderer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace TreeLod
{
    namespace
    {
        /// Rings of bleeding around the tree; farther texels get the tree's mean.
        constexpr int BLEED_RINGS = 8;

        std::uint32_t roundUp4(std::uint32_t v) { return (v + 3) / 4 * 4; }

        /// Source texels [first, last) under destination texel d of a halving (an odd source's
        /// last texel goes to the last destination texel, as GpuTexture's mip sizes floor).
        std::pair<std::uint32_t, std::uint32_t> halvingRange(std::uint32_t d, std::uint32_t dstSize,
                                                             std::uint32_t srcSize)
        {
            if (srcSize == 1)
                return {0u, 1u};
            return {2 * d, d + 1 == dstSize ? srcSize : 2 * d + 2};
        }

        /// The normal texture (ImpostorData.h): level 0 from `normalAo` (x, y, ao per texel),
        /// each further level the coverage-weighted mean of its children (the plain mean where
        /// none is covered), the normal renormalised.
        GpuTexture normalMipChain(std::uint32_t width, std::uint32_t height, std::vector<glm::vec3> normalAo,
                                  std::vector<float> coverage)
        {
            GpuTexture tex;
            tex.name = "impostor normal";
            tex.format = GpuTextureFormat::RGBA8;
            tex.width = width;
            tex.height = height;
            tex.mipCount = fullMipCount(width, height);
            tex.data.resize(gpuTextureBytes(tex.format, width, height, tex.mipCount));
            auto unpack = [](const glm::vec3& v) {
                return glm::vec3(v.x, v.y, std::sqrt(std::max(0.0f, 1.0f - v.x * v.x - v.y * v.y)));
            };
            for (std::uint32_t mip = 0; mip < tex.mipCount; ++mip)
            {
                const std::uint32_t w = tex.mipWidth(mip), h = tex.mipHeight(mip);
                if (mip > 0)
                {
                    const std::uint32_t sw = tex.mipWidth(mip - 1), sh = tex.mipHeight(mip - 1);
                    std::vector<glm::vec3> next(std::size_t(w) * h);
                    std::vector<float> nextCoverage(next.size());
                    for (std::uint32_t y = 0; y < h; ++y)
                        for (std::uint32_t x = 0; x < w; ++x)
                        {
                            const auto [y0, y1] = halvingRange(y, h, sh);
                            const auto [x0, x1] = halvingRange(x, w, sw);
                            glm::vec3 weightedN(0.0f), plainN(0.0f);
                            float weightedAo = 0.0f, plainAo = 0.0f, cov = 0.0f;
                            int n = 0;
                            for (std::uint32_t yy = y0; yy < y1; ++yy)
                                for (std::uint32_t xx = x0; xx < x1; ++xx)
                                {
                                    const std::size_t i = std::size_t(yy) * sw + xx;
                                    const glm::vec3 normal = unpack(normalAo[i]);
                                    weightedN += coverage[i] * normal;
                                    weightedAo += coverage[i] * normalAo[i].z;
                                    plainN += normal;
                                    plainAo += normalAo[i].z;
                                    cov += coverage[i];
                                    ++n;
                                }
                            glm::vec3 normal = cov > 0.0f ? weightedN : plainN;
                            normal = glm::length(normal) > 1e-6f ? glm::normalize(normal) : glm::vec3(0, 0, 1);
                            const std::size_t o = std::size_t(y) * w + x;
                            next[o] = glm::vec3(normal.x, normal.y, cov > 0.0f ? weightedAo / cov : plainAo / float(n));
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
                    out[4 * i + 3] = 255;
                }
            }
            return tex;
        }

        Result<void> checkOptions(const ImpostorOptions& o, const std::string& label)
        {
            const int n = int(std::lround(std::sqrt(double(std::max(o.samplesPerPixel, 0)))));
            if (o.resolution < 16 || o.resolution > 4096 || o.resolution % 4 != 0)
                return fail(label, "impostor option resolution",
                            std::to_string(o.resolution) + " is not a multiple of 4 in [16, 4096]");
            if (o.samplesPerPixel < 1 || o.samplesPerPixel > 256 || n * n != o.samplesPerPixel)
                return fail(label, "impostor option samplesPerPixel",
                            std::to_string(o.samplesPerPixel) + " is not a square in [1, 256]");
            if (o.aoRays < 0)
                return fail(label, "impostor option aoRays", std::to_string(o.aoRays) + " is negative");
            if (!(o.alphaCutoff > 0.0f && o.alphaCutoff <= 1.0f))
                return fail(label, "impostor option alphaCutoff",
                            std::to_string(o.alphaCutoff) + " is outside (0, 1]");
            return {};
        }
    }

    Result<ImpostorData> bakeImpostor(const TreeModel& model, const ImpostorOptions& options, const std::string& label,
                                      const ProgressCallback& progress)
    {
        if (Result<void> ok = checkOptions(options, label); !ok)
            return ok.error();
        if (Result<void> valid = model.validate(label); !valid)
            return valid.error();

        // 1. Frame: the bounds of every vertex (not the stored bounds, which may be stale).
        glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
        for (const std::vector<Vertex>* vertices : {&model.barkVertices, &model.leafVertices})
            for (const Vertex& v : *vertices)
            {
                lo = glm::min(lo, v.position);
                hi = glm::max(hi, v.position);
            }
        if (model.barkVertices.empty() && model.leafVertices.empty())
            return fail(label, "impostor", "the model has no vertices: nothing to draw");
        const float halfExtentX = std::max(std::abs(lo.x), std::abs(hi.x));
        const float extent = std::max(2.0f * halfExtentX, hi.y - lo.y);
        if (!(extent > 0.0f) || !std::isfinite(extent))
            return fail(label, "impostor",
                        "the model has no extent seen from +Z (every vertex at x = 0 and one height): no quad to draw");
        const std::uint32_t margin = IMPOSTOR_MARGIN_TEXELS;
        const float texel = extent / float(options.resolution - 2 * margin);
        // A small tolerance, so that the longer side is `resolution` texels whatever the rounding.
        auto texels = [&](float metres) {
            const float n = std::ceil(metres / texel - 1e-3f);
            return std::min(options.resolution, roundUp4(std::uint32_t(std::max(n, 0.0f)) + 2 * margin));
        };
        const std::uint32_t W = texels(2.0f * halfExtentX), H = texels(hi.y - lo.y);
        ImpostorData data;
        data.alphaCutoff = options.alphaCutoff;
        data.halfWidth = 0.5f * float(W) * texel;
        const float centreY = 0.5f * (lo.y + hi.y);
        data.bottom = centreY - 0.5f * float(H) * texel;
        data.top = centreY + 0.5f * float(H) * texel;

        // 2. Render, orthographic along -Z: white ambient light only, so colour = albedo (x AO).
        const float depth = hi.z - lo.z, pad = 0.1f * extent + 0.1f * depth;
        const CameraSpec camera = sideViewCamera(glm::vec3(0.0f, centreY, 0.0f), glm::vec3(0.0f, 0.0f, 1.0f), lo.z,
                                                 hi.z, data.top - data.bottom, pad);
        RenderOptions render = albedoRenderOptions(int(W), int(H), options.samplesPerPixel);

        AmbientOcclusion ao;
        if (options.aoRays > 0)
        {
            AoOptions aoOptions;
            aoOptions.raysPerPoint = options.aoRays;
            ao = computeAmbientOcclusion(model, aoOptions, [&](const std::string&, float f) {
                report(progress, "impostor: ambient occlusion", f);
            });
        }
        report(progress, "impostor: render", 0.0f);
        RenderImages plain, occluded;
        try
        {
            ReferenceRenderer renderer(model);
            plain = renderer.render(camera, render);
            report(progress, "impostor: render", 0.5f);
            if (options.aoRays > 0)
            {
                render.ambientOcclusion = &ao;
                occluded = renderer.render(camera, render);
            }
        }
        catch (const std::exception& e)
        {
            return fail(label, "impostor", std::string("rendering failed: ") + e.what());
        }
        report(progress, "impostor: render", 1.0f);

        // 3. Per texel: linear albedo, normal (x, y) and AO; then bleed into uncovered texels.
        report(progress, "impostor: textures", 0.0f);
        const std::size_t count = std::size_t(W) * H;
        std::vector<glm::vec3> albedo(count, glm::vec3(0.0f)), normalAo(count, glm::vec3(0.0f, 0.0f, 1.0f));
        std::vector<std::uint8_t> covered(count, 0);
        for (std::size_t i = 0; i < count; ++i)
        {
            if (!(plain.alpha[i] > 0.0f))
                continue;
            covered[i] = 1;
            const glm::vec4& c = plain.colour.pixels[i];
            albedo[i] = glm::vec3(srgbToLinear(c.r), srgbToLinear(c.g), srgbToLinear(c.b));
            float aoValue = 1.0f;
            if (options.aoRays > 0)
            {
                const glm::vec4& d = occluded.colour.pixels[i];
                const float withAo = srgbToLinear(d.r) + srgbToLinear(d.g) + srgbToLinear(d.b);
                const float without = albedo[i].r + albedo[i].g + albedo[i].b;
                aoValue = without > 1e-6f ? std::clamp(withAo / without, 0.0f, 1.0f) : 1.0f;
            }
            // The view is along -Z, so the quad frame is the model's: x right, y up, z to the viewer.
            normalAo[i] = glm::vec3(plain.normal[i].x, plain.normal[i].y, aoValue);
        }
        bleedValues(albedo, covered, int(W), int(H), BLEED_RINGS, glm::vec3(0.2f));
        bleedValues(normalAo, covered, int(W), int(H), BLEED_RINGS, glm::vec3(0.0f, 0.0f, 1.0f));

        const TextureImage colourImage = albedoTexture("impostor colour", int(W), int(H), albedo, plain.alpha);
        MipChainOptions mips;
        mips.preserveAlphaCoverage = true;
        mips.alphaCutoff = options.alphaCutoff;
        data.colour = buildMipChain(colourImage, mips);
        data.normal = normalMipChain(W, H, std::move(normalAo), std::move(plain.alpha));
        report(progress, "impostor: textures", 0.5f);

        // 4. Block compression.
        if (options.compress)
        {
            data.colour = compressTexture(data.colour, GpuTextureFormat::DXT5);
            data.normal = compressTexture(data.normal, GpuTextureFormat::DXT1);
        }
        report(progress, "impostor: textures", 1.0f);
        if (Result<void> valid = data.validate(label); !valid)
            return valid.error();
        return data;
    }

    Result<void> addImpostorChunk(PackageWriter& writer, const TreeModel& model, const std::string& label,
                                  const ProgressCallback& progress)
    {
        return addImpostorChunk(writer, model, ImpostorOptions{}, label, progress);
    }

    Result<void> addImpostorChunk(PackageWriter& writer, const TreeModel& model, const ImpostorOptions& options,
                                  const std::string& label, const ProgressCallback& progress)
    {
        if (!writer.hasChunk(REFERENCE_CHUNK, 0))
        {
            Result<void> added = addReferenceChunk(writer, model, label, progress);
            if (!added)
                return added;
        }
        Result<ImpostorData> data = bakeImpostor(model, options, label, progress);
        if (!data)
            return data.error();
        Result<void> added =
            writer.addChunk(IMPOSTOR_CHUNK, 0, IMPOSTOR_CHUNK_FORMAT_VERSION, encodeImpostorChunk(data.value()));
        if (!added)
            return fail(label, added.error().element, added.error().reason);
        return {};
    }
}
