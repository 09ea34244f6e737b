// CrossedQuadsBaker: the crossed quads (steps in CrossedQuadsBaker.h, format in CrossedQuadsData.h).
#include "TreeLod/CrossedQuadsBaker.h"

#include "TreeLod/Image.h"
#include "TreeLod/Package.h"
#include "TreeLod/ReferenceRenderer.h"

#include <glm/gtc/constants.hpp>

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

        Result<void> checkOptions(const CrossedQuadsOptions& o, const std::string& label)
        {
            const int n = int(std::lround(std::sqrt(double(std::max(o.samplesPerPixel, 0)))));
            if (o.azimuths.empty() || o.azimuths.size() > CROSSED_QUADS_MAX_QUADS)
                return fail(label, "crossed-quads option azimuths",
                            std::to_string(o.azimuths.size()) + " azimuths (1.." +
                                std::to_string(CROSSED_QUADS_MAX_QUADS) + " needed)");
            for (float a : o.azimuths)
                if (!(a >= 0.0f && a < 180.0f))
                    return fail(label, "crossed-quads option azimuths", std::to_string(a) + " is outside [0, 180)");
            if (o.resolution < 16 || o.resolution > 4096 || o.resolution % 4 != 0)
                return fail(label, "crossed-quads option resolution",
                            std::to_string(o.resolution) + " is not a multiple of 4 in [16, 4096]");
            if (o.samplesPerPixel < 1 || o.samplesPerPixel > 256 || n * n != o.samplesPerPixel)
                return fail(label, "crossed-quads option samplesPerPixel",
                            std::to_string(o.samplesPerPixel) + " is not a square in [1, 256]");
            if (!(o.alphaCutoff > 0.0f && o.alphaCutoff <= 1.0f))
                return fail(label, "crossed-quads option alphaCutoff",
                            std::to_string(o.alphaCutoff) + " is outside (0, 1]");
            return {};
        }
    }

    Result<CrossedQuadsData> bakeCrossedQuads(const TreeModel& model, const CrossedQuadsOptions& options,
                                              const std::string& label, const ProgressCallback& progress)
    {
        if (Result<void> ok = checkOptions(options, label); !ok)
            return ok.error();
        if (Result<void> valid = model.validate(label); !valid)
            return valid.error();
        if (model.barkVertices.empty() && model.leafVertices.empty())
            return fail(label, "crossed-quads", "the model has no vertices: nothing to draw");

        CrossedQuadsData data;
        data.alphaCutoff = options.alphaCutoff;
        report(progress, "crossed-quads: render", 0.0f);
        try
        {
            ReferenceRenderer renderer(model);
            for (std::size_t i = 0; i < options.azimuths.size(); ++i)
            {
                // 1. Frame: the vertices in the quad's frame (r, y, n); CrossedQuadsData.h.
                const float a = glm::radians(options.azimuths[i]);
                const glm::vec3 r(std::cos(a), 0.0f, -std::sin(a)), n(std::sin(a), 0.0f, std::cos(a));
                glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
                for (const std::vector<Vertex>* vertices : {&model.barkVertices, &model.leafVertices})
                    for (const Vertex& v : *vertices)
                    {
                        const glm::vec3 p(glm::dot(v.position, r), v.position.y, glm::dot(v.position, n));
                        lo = glm::min(lo, p);
                        hi = glm::max(hi, p);
                    }
                const float extent = std::max(hi.x - lo.x, hi.y - lo.y);
                if (!(extent > 0.0f) || !std::isfinite(extent))
                    return fail(label, "crossed-quads",
                                "the model has no extent seen from azimuth " + std::to_string(options.azimuths[i]));
                const std::uint32_t margin = CROSSED_QUADS_MARGIN_TEXELS;
                const float texel = extent / float(options.resolution - 2 * margin);
                auto texels = [&](float metres) {
                    const float count = std::ceil(metres / texel - 1e-3f);
                    return std::min(options.resolution, roundUp4(std::uint32_t(std::max(count, 0.0f)) + 2 * margin));
                };
                const std::uint32_t W = texels(hi.x - lo.x), H = texels(hi.y - lo.y);
                const glm::vec2 centre = 0.5f * (glm::vec2(lo) + glm::vec2(hi));
                CrossedQuad quad;
                quad.azimuth = options.azimuths[i];
                quad.left = centre.x - 0.5f * float(W) * texel;
                quad.right = centre.x + 0.5f * float(W) * texel;
                quad.bottom = centre.y - 0.5f * float(H) * texel;
                quad.top = centre.y + 0.5f * float(H) * texel;

                // 2. Render along -n, white ambient light only: colour = albedo.
                const float depth = hi.z - lo.z, pad = 0.1f * extent + 0.1f * depth;
                const glm::vec3 middle = centre.x * r + glm::vec3(0.0f, centre.y, 0.0f);
                const CameraSpec camera = sideViewCamera(middle, n, lo.z, hi.z, quad.top - quad.bottom, pad);
                const RenderOptions render = albedoRenderOptions(int(W), int(H), options.samplesPerPixel);
                const RenderImages images = renderer.render(camera, render);

                // 3. Bleed in linear light, then the mip chain (coverage kept) and compression.
                const std::size_t count = std::size_t(W) * H;
                std::vector<glm::vec3> albedo(count, glm::vec3(0.0f));
                std::vector<std::uint8_t> covered(count, 0);
                for (std::size_t t = 0; t < count; ++t)
                    if (images.alpha[t] > 0.0f)
                    {
                        covered[t] = 1;
                        const glm::vec4& c = images.colour.pixels[t];
                        albedo[t] = glm::vec3(srgbToLinear(c.r), srgbToLinear(c.g), srgbToLinear(c.b));
                    }
                bleedValues(albedo, covered, int(W), int(H), BLEED_RINGS, glm::vec3(0.2f));
                const TextureImage image =
                    albedoTexture("crossed-quads " + std::to_string(i), int(W), int(H), albedo, images.alpha);
                MipChainOptions mips;
                mips.preserveAlphaCoverage = true;
                mips.alphaCutoff = options.alphaCutoff;
                quad.colour = buildMipChain(image, mips);
                if (options.compress)
                    quad.colour = compressTexture(quad.colour, GpuTextureFormat::DXT5);
                data.quads.push_back(std::move(quad));
                report(progress, "crossed-quads: render", float(i + 1) / float(options.azimuths.size()));
            }
        }
        catch (const std::exception& e)
        {
            return fail(label, "crossed-quads", std::string("rendering failed: ") + e.what());
        }
        if (Result<void> valid = data.validate(label); !valid)
            return valid.error();
        return data;
    }

    Result<void> addCrossedQuadsChunk(PackageWriter& writer, const TreeModel& model, const std::string& label,
                                      const ProgressCallback& progress)
    {
        return addCrossedQuadsChunk(writer, model, CrossedQuadsOptions{}, label, progress);
    }

    Result<void> addCrossedQuadsChunk(PackageWriter& writer, const TreeModel& model,
                                      const CrossedQuadsOptions& options, const std::string& label,
                                      const ProgressCallback& progress)
    {
        return addBakedChunk(writer, model, label, progress, CROSSED_QUADS_CHUNK, CROSSED_QUADS_CHUNK_FORMAT_VERSION,
                             encodeCrossedQuadsChunk, [&]() { return bakeCrossedQuads(model, options, label, progress); });
    }
}
