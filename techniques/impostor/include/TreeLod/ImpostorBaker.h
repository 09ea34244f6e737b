// ImpostorBaker: TreeModel -> ImpostorData (ImpostorData.h), the one-quad impostor.
//
//   1. Frame: the quad spans the model's bounds seen from +Z (x symmetric about the trunk
//      axis, since the quad turns about it), plus a margin of IMPOSTOR_MARGIN_TEXELS texels on
//      every side; texels are square, `resolution` of them along the longer side.
//   2. Render the tree with the CPU ReferenceRenderer, orthographic along -Z, transparent
//      background (straight alpha = coverage), samplesPerPixel samples per texel: once lit by
//      a white ambient light alone (albedo), and where asked (aoRays > 0) once more with
//      per-vertex ambient occlusion (albedo x AO, so AO = the ratio). The shading normals come
//      with the first render.
//   3. Bleed colour, normal and AO into the uncovered texels (bleedValues), then mip chains:
//      colour with the coverage of level 0 kept (buildMipChain), normal and AO weighted by
//      coverage.
//   4. Optionally compress (compressTexture): colour DXT5, normal + AO DXT1. 256 texels: 87 KB +
//      44 KB instead of 2 x 230 KB of RGBA8.
// Every size is relative to the model's bounds, so a 0.5 m and a 500 m tree give the same
// textures. Deterministic for any thread count.
#pragma once

#include "TreeLod/ImpostorData.h"
#include "TreeLod/PackageWriter.h"
#include "TreeLod/Progress.h"
#include "TreeLod/Result.h"
#include "TreeLod/TreeModel.h"

#include <cstdint>
#include <string>

namespace TreeLod
{
    /// Empty texels around the tree on each side of the textures (room for bilinear filtering).
    constexpr std::uint32_t IMPOSTOR_MARGIN_TEXELS = 2;

    struct ImpostorOptions
    {
        /// Texels along the longer side of the quad, a multiple of 4 in [16, 4096]; the other
        /// side gets what the tree's aspect asks for (a multiple of 4, at least 4 + 2 margins).
        std::uint32_t resolution = 256;
        int samplesPerPixel = 16;  ///< per texel, a square in [1, 256] (coverage in 1/n steps)
        /// Per vertex (AmbientOcclusion.h); 0 = no AO (B = 1), the default: the polygonal tree
        /// the impostor stands for draws its leaves without AO, and baked AO made trees 9-16 %
        /// darker than it (techniques/impostor/README.md, "Ambient occlusion").
        int aoRays = 0;
        float alphaCutoff = 0.5f;  ///< the quad's alpha test, in (0, 1]
        /// DXT5 colour, DXT1 normal (libsquish); else RGBA8, the default: at the 8 px where budgeted
        /// auto draws this level DXT cost 0.0068 FLIP on average over the corpus, more than a
        /// format may (docs/measurements.md "Texture formats"), and the RGBA8 pair stays small
        /// (at most 700 KB at 256 texels). Compressed or not, llvmpipe samples RGBA8 (decoded at load).
        bool compress = false;
    };

    /// Bake the impostor. Errors name `label`: an invalid model or options, and a model with
    /// no extent (no vertices, or all of them on one point). A model that the view from +Z
    /// does not see (e.g. only leaves edge-on) gives a valid, fully transparent impostor.
    /// Progress steps: "impostor: ambient occlusion", "impostor: render", "impostor: textures".
    Result<ImpostorData> bakeImpostor(const TreeModel& model, const ImpostorOptions& options, const std::string& label,
                                      const ProgressCallback& progress = {});

    /// Package glue for `treelod bake` (BakeTechniques): adds the reference chunk when missing
    /// (the Forest takes the tree's bounds from it) and the impostor chunk, default options.
    Result<void> addImpostorChunk(PackageWriter& writer, const TreeModel& model, const std::string& label,
                                  const ProgressCallback& progress = {});
    /// The same with `options`.
    Result<void> addImpostorChunk(PackageWriter& writer, const TreeModel& model, const ImpostorOptions& options,
                                  const std::string& label, const ProgressCallback& progress = {});
}
