// ImpostorBaker: the one-quad impostor (steps in ImpostorBaker.h, format in ImpostorData.h).
#include "TreeLod/ImpostorBaker.h"

#include "TreeLod/AmbientOcclusion.h"
#include "TreeLod/Image.h"
#include "TreeLod/ImpostorViews.h"
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

        // 3. Per texel: linear albedo, normal (x, y) and AO; then bleed into uncovered texels. The
        // view is along -Z, so the quad frame is the model's: x right, y up, z to the viewer.
        report(progress, "impostor: textures", 0.0f);
        ImpostorView view = impostorView(plain, options.aoRays > 0 ? &occluded : nullptr, glm::vec3(1, 0, 0),
                                         glm::vec3(0, 1, 0), [](std::size_t) { return 1.0f; });
        bleedImpostorView(view, BLEED_RINGS, 1.0f);

        const TextureImage colourImage = albedoTexture("impostor colour", int(W), int(H), view.albedo, view.coverage);
        MipChainOptions mips;
        mips.preserveAlphaCoverage = true;
        mips.alphaCutoff = options.alphaCutoff;
        data.colour = buildMipChain(colourImage, mips);
        data.normal = impostorNormalTexture("impostor normal", W, H, std::move(view.normalAo), std::move(view.coverage));
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
        return addBakedChunk(writer, model, label, progress, IMPOSTOR_CHUNK, IMPOSTOR_CHUNK_FORMAT_VERSION,
                             encodeImpostorChunk, [&]() { return bakeImpostor(model, options, label, progress); });
    }
}
