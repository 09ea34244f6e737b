// OctahedralImpostorBaker: the octahedral impostor (steps in OctahedralImpostorBaker.h, format
// in OctahedralImpostorData.h).
#include "TreeLod/OctahedralImpostorBaker.h"

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
        /// Rings of bleeding around the tree in each frame; farther texels get the frame's mean.
        constexpr int BLEED_RINGS = 8;

        Result<void> checkOptions(const OctahedralImpostorOptions& o, const std::string& label)
        {
            const int n = int(std::lround(std::sqrt(double(std::max(o.samplesPerPixel, 0)))));
            if (o.framesPerSide < 2 || o.framesPerSide > 32)
                return fail(label, "octahedral-impostor option framesPerSide",
                            std::to_string(o.framesPerSide) + " is outside [2, 32]");
            if (o.frameResolution < 8 || o.frameResolution > 1024 || o.frameResolution % 4 != 0)
                return fail(label, "octahedral-impostor option frameResolution",
                            std::to_string(o.frameResolution) + " is not a multiple of 4 in [8, 1024]");
            if (o.framesPerSide * o.frameResolution > GPU_TEXTURE_MAX_SIZE)
                return fail(label, "octahedral-impostor option frameResolution",
                            std::to_string(o.framesPerSide) + " frames of " + std::to_string(o.frameResolution) +
                                " texels make an atlas wider than " + std::to_string(GPU_TEXTURE_MAX_SIZE));
            if (o.samplesPerPixel < 1 || o.samplesPerPixel > 256 || n * n != o.samplesPerPixel)
                return fail(label, "octahedral-impostor option samplesPerPixel",
                            std::to_string(o.samplesPerPixel) + " is not a square in [1, 256]");
            if (o.aoRays < 0)
                return fail(label, "octahedral-impostor option aoRays", std::to_string(o.aoRays) + " is negative");
            if (!(o.alphaCutoff > 0.0f && o.alphaCutoff <= 1.0f))
                return fail(label, "octahedral-impostor option alphaCutoff",
                            std::to_string(o.alphaCutoff) + " is outside (0, 1]");
            return {};
        }

        /// Levels whose every frame halves exactly, down to frames of 4 texels.
        std::uint32_t frameAlignedMipCount(std::uint32_t frameTexels)
        {
            std::uint32_t count = 1;
            while (frameTexels % 2 == 0 && frameTexels / 2 >= 4)
            {
                frameTexels /= 2;
                ++count;
            }
            return count;
        }
    }

    Result<OctahedralImpostorData> bakeOctahedralImpostor(const TreeModel& model,
                                                          const OctahedralImpostorOptions& options,
                                                          const std::string& label, const ProgressCallback& progress)
    {
        if (Result<void> ok = checkOptions(options, label); !ok)
            return ok.error();
        if (Result<void> valid = model.validate(label); !valid)
            return valid.error();
        if (model.barkVertices.empty() && model.leafVertices.empty())
            return fail(label, "octahedral-impostor", "the model has no vertices: nothing to draw");

        // 1. The bounding cylinder of every vertex (not the stored bounds, which may be stale).
        float radius = 0.0f, bottom = std::numeric_limits<float>::max(), top = -std::numeric_limits<float>::max();
        for (const std::vector<Vertex>* vertices : {&model.barkVertices, &model.leafVertices})
            for (const Vertex& v : *vertices)
            {
                radius = std::max(radius, std::sqrt(v.position.x * v.position.x + v.position.z * v.position.z));
                bottom = std::min(bottom, v.position.y);
                top = std::max(top, v.position.y);
            }
        const float extent = std::max(2.0f * radius, top - bottom);
        if (!(extent > 0.0f) || !std::isfinite(extent))
            return fail(label, "octahedral-impostor", "the model has no extent (every vertex on one point)");
        // A flat or axis-thin tree still gets a cylinder with volume (a thousandth of its extent).
        radius = std::max(radius, 5e-4f * extent);
        if (top - bottom < 1e-3f * extent)
        {
            const float middle = 0.5f * (top + bottom);
            bottom = middle - 5e-4f * extent;
            top = middle + 5e-4f * extent;
        }

        OctahedralImpostorData data;
        data.framesPerSide = options.framesPerSide;
        data.radius = radius;
        data.bottom = bottom;
        data.top = top;
        data.alphaCutoff = options.alphaCutoff;

        AmbientOcclusion ao;
        if (options.aoRays > 0)
        {
            AoOptions aoOptions;
            aoOptions.raysPerPoint = options.aoRays;
            ao = computeAmbientOcclusion(model, aoOptions, [&](const std::string&, float f) {
                report(progress, "octahedral impostor: ambient occlusion", f);
            });
        }

        // 2. The frames, rendered one by one (each render is parallel over its tiles).
        const std::uint32_t n = options.framesPerSide, f = options.frameResolution, size = n * f;
        const glm::vec3 centre(0.0f, 0.5f * (bottom + top), 0.0f);
        const float depthRadius = octahedralDepthRadius(radius, bottom, top), pad = 0.1f * depthRadius;
        std::vector<glm::vec3> albedo(std::size_t(size) * size);
        std::vector<glm::vec4> normalAo(albedo.size());
        std::vector<float> coverage(albedo.size());
        report(progress, "octahedral impostor: views", 0.0f);
        try
        {
            ReferenceRenderer renderer(model);
            RenderOptions render = albedoRenderOptions(int(f), int(f), options.samplesPerPixel);
            for (std::uint32_t j = 0; j < n; ++j)
                for (std::uint32_t i = 0; i < n; ++i)
                {
                    const glm::vec3 towards = octahedralFrameDirection(i, j, n);
                    const OctahedralFrameAxes axes = octahedralFrameAxes(towards);
                    CameraSpec camera;
                    camera.orthographic = true;
                    camera.target = centre;
                    camera.position = centre + (depthRadius + pad) * towards;
                    camera.up = axes.up;
                    camera.orthoHeight = octahedralFrameSide(towards, radius, bottom, top, f);
                    camera.nearClip = 0.5f * pad;
                    camera.farClip = 2.0f * depthRadius + 1.5f * pad;
                    render.ambientOcclusion = nullptr;
                    const RenderImages plain = renderer.render(camera, render);
                    RenderImages occluded;
                    if (options.aoRays > 0)
                    {
                        render.ambientOcclusion = &ao;
                        occluded = renderer.render(camera, render);
                    }
                    // Depth: metres in front of the frame's plane through the centre, normalised.
                    ImpostorView view = impostorView(plain, options.aoRays > 0 ? &occluded : nullptr, axes.right,
                                                     axes.up, [&](std::size_t t) {
                                                         const float d = depthRadius + pad - plain.depth[t];
                                                         return std::clamp(0.5f + 0.5f * d / depthRadius, 0.0f, 1.0f);
                                                     });
                    bleedImpostorView(view, BLEED_RINGS, 0.5f);
                    for (std::uint32_t y = 0; y < f; ++y)
                    {
                        const std::size_t from = std::size_t(y) * f, to = std::size_t(j * f + y) * size + i * f;
                        std::copy_n(view.albedo.begin() + from, f, albedo.begin() + to);
                        std::copy_n(view.normalAo.begin() + from, f, normalAo.begin() + to);
                        std::copy_n(view.coverage.begin() + from, f, coverage.begin() + to);
                    }
                    report(progress, "octahedral impostor: views", float(j * n + i + 1) / float(n * n));
                }
        }
        catch (const std::exception& e)
        {
            return fail(label, "octahedral-impostor", std::string("rendering failed: ") + e.what());
        }

        // 3. The atlas textures, mips aligned to the frames.
        report(progress, "octahedral impostor: textures", 0.0f);
        const std::uint32_t mipCount = frameAlignedMipCount(f);
        const TextureImage colourImage =
            albedoTexture("octahedral impostor colour", int(size), int(size), albedo, coverage);
        MipChainOptions mips;
        mips.preserveAlphaCoverage = true;
        mips.alphaCutoff = options.alphaCutoff;
        data.colour = buildMipChain(colourImage, mips);
        data.colour.mipCount = mipCount;
        data.colour.data.resize(gpuTextureBytes(data.colour.format, size, size, mipCount));
        data.normal = impostorNormalTexture("octahedral impostor normal", size, size, std::move(normalAo),
                                            std::move(coverage), mipCount);
        report(progress, "octahedral impostor: textures", 0.5f);

        // 4. Block compression.
        if (options.compress)
        {
            data.colour = compressTexture(data.colour, GpuTextureFormat::DXT5);
            data.normal = compressTexture(data.normal, GpuTextureFormat::DXT5);
        }
        report(progress, "octahedral impostor: textures", 1.0f);
        if (Result<void> valid = data.validate(label); !valid)
            return valid.error();
        return data;
    }

    Result<void> addOctahedralImpostorChunk(PackageWriter& writer, const TreeModel& model,
                                            const OctahedralImpostorOptions& options, const std::string& label,
                                            const ProgressCallback& progress)
    {
        return addBakedChunk(writer, model, label, progress, OCTAHEDRAL_IMPOSTOR_CHUNK,
                             OCTAHEDRAL_IMPOSTOR_CHUNK_FORMAT_VERSION, encodeOctahedralImpostorChunk,
                             [&]() { return bakeOctahedralImpostor(model, options, label, progress); });
    }
}
