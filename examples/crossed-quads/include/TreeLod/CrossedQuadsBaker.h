// CrossedQuadsBaker: TreeModel -> CrossedQuadsData (CrossedQuadsData.h).
//
//   1. Frame, per azimuth: the model's vertices projected on the quad's right axis and on +Y
//      give the rectangle, plus CROSSED_QUADS_MARGIN_TEXELS texels on every side; texels are
//      square, `resolution` of them along the longer side.
//   2. Render the tree with the CPU ReferenceRenderer, orthographic along -n, under a white
//      ambient light alone (colour = albedo), transparent background (alpha = coverage).
//   3. Bleed the colour into uncovered texels (bleedValues), build the mip chain with the
//      coverage of level 0 kept (buildMipChain), optionally compress to DXT5.
// Deterministic for any thread count.
#pragma once

#include "TreeLod/CrossedQuadsData.h"
#include "TreeLod/PackageWriter.h"
#include "TreeLod/Progress.h"
#include "TreeLod/Result.h"
#include "TreeLod/TreeModel.h"

#include <cstdint>
#include <string>
#include <vector>

namespace TreeLod
{
    /// Empty texels around the tree on each side of each texture (room for bilinear filtering).
    constexpr std::uint32_t CROSSED_QUADS_MARGIN_TEXELS = 2;

    struct CrossedQuadsOptions
    {
        /// Azimuths of the quads, degrees in [0, 180) (a quad shows both sides): 1 to
        /// CROSSED_QUADS_MAX_QUADS of them, e.g. {0, 60, 120} for three.
        std::vector<float> azimuths = {0.0f, 90.0f};
        /// Texels along the longer side of each quad, a multiple of 4 in [16, 4096].
        std::uint32_t resolution = 256;
        int samplesPerPixel = 16; ///< per texel, a square in [1, 256]
        float alphaCutoff = 0.5f; ///< the quads' alpha test, in (0, 1]
        bool compress = true;     ///< DXT5 (libsquish); else RGBA8
    };

    /// Bake the quads. Errors name `label`: bad options, an invalid model, a model with no
    /// extent seen from some azimuth. Progress steps: "crossed-quads: render".
    Result<CrossedQuadsData> bakeCrossedQuads(const TreeModel& model, const CrossedQuadsOptions& options,
                                              const std::string& label, const ProgressCallback& progress = {});

    /// Package glue for `treelod bake` (BakeTechniques.h): adds the reference chunk when missing
    /// (the Forest takes the tree's bounds from it) and the crossed-quads chunk, default options.
    Result<void> addCrossedQuadsChunk(PackageWriter& writer, const TreeModel& model, const std::string& label,
                                      const ProgressCallback& progress = {});
    /// The same with `options`.
    Result<void> addCrossedQuadsChunk(PackageWriter& writer, const TreeModel& model,
                                      const CrossedQuadsOptions& options, const std::string& label,
                                      const ProgressCallback& progress = {});
}
