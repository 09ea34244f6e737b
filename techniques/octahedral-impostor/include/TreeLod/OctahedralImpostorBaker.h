// OctahedralImpostorBaker: TreeModel -> OctahedralImpostorData (OctahedralImpostorData.h).
//
//   1. The bounding cylinder about the trunk axis (local y): radius, bottom, top of every vertex.
//   2. Per frame (i, j) of the N x N hemi-octahedral grid: render the tree with the CPU
//      ReferenceRenderer, orthographic along -octahedralFrameDirection(i, j, N), framing the
//      cylinder's projection (octahedralFrameSide), transparent background, samplesPerPixel
//      samples per texel: once with a white ambient light alone (albedo, normal, depth), once
//      more with per-vertex ambient occlusion (AO = the ratio), as the quad impostor
//      (ImpostorViews.h). Bleed every value into the frame's uncovered texels.
//   3. The atlas: colour with coverage-preserving mips (buildMipChain), normal + AO + depth
//      weighted by coverage (impostorNormalTexture); mips aligned to the frames, down to frames
//      of 4 texels, so no level mixes two views.
//   4. Compress (unless compress is false): DXT5 both (the normal's alpha holds depth).
// Every size is relative to the model's bounds (a 0.5 m and a 500 m tree give the same
// textures). Deterministic for any thread count.
#pragma once

#include "TreeLod/OctahedralImpostorData.h"
#include "TreeLod/PackageWriter.h"
#include "TreeLod/Progress.h"
#include "TreeLod/Result.h"
#include "TreeLod/TreeModel.h"

#include <cstdint>
#include <string>

namespace TreeLod
{
    struct OctahedralImpostorOptions
    {
        std::uint32_t framesPerSide = 8;   ///< N in [2, 32]: N^2 views over the upper hemisphere
        /// Texels a side of one frame, a multiple of 4 in [8, 1024]; the atlas (N times that) at
        /// most GPU_TEXTURE_MAX_SIZE. 64 (with 8 views and compress): the least error per byte at
        /// the heights budgeted auto draws the level (docs/measurements.md "Texture formats").
        std::uint32_t frameResolution = 64;
        int samplesPerPixel = 9;  ///< per texel, a square in [1, 256]
        int aoRays = 0;           ///< per vertex (AmbientOcclusion.h); 0 = no AO, as ImpostorOptions
        float alphaCutoff = 0.5f; ///< the quad's alpha test, in (0, 1]
        /// DXT5 colour and normal (the default: a quarter of RGBA8's bytes); else RGBA8. A renderer
        /// that samples blocks slower (llvmpipe) gets them decoded at load (TreeAssetManager.h).
        bool compress = true;
    };

    /// Bake the octahedral impostor. Errors name `label`: invalid options or model, and a model
    /// with no extent. Progress steps: "octahedral impostor: ambient occlusion",
    /// "octahedral impostor: views", "octahedral impostor: textures".
    Result<OctahedralImpostorData> bakeOctahedralImpostor(const TreeModel& model,
                                                          const OctahedralImpostorOptions& options,
                                                          const std::string& label,
                                                          const ProgressCallback& progress = {});

    /// Package glue for `treelod bake` (BakeTechniques): adds the reference chunk when missing
    /// and the octahedral-impostor chunk.
    Result<void> addOctahedralImpostorChunk(PackageWriter& writer, const TreeModel& model,
                                            const OctahedralImpostorOptions& options, const std::string& label,
                                            const ProgressCallback& progress = {});
}
