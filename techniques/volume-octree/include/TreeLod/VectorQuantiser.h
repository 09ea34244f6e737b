// VectorQuantiser: texture compression by vector quantisation for the volumetric octree tree
// (Linz et al. 2006, §4.1, after Beers et al. 1996): every 4x4 billboard texture is one training
// vector; the Generalized Lloyd Algorithm (GLA) finds a codebook of K codewords under the L2 norm
// and each billboard keeps the index of its nearest codeword.
//
//   - Colour (§4.1.2) is quantised in CIELab (D65 white, sRGB primaries): 16 texels x (L, a, b)
//     = 48 components; RGB space (48 sRGB components scaled to [0, 100]) is kept for comparison
//     (Fig. 5 b).
//   - Modified GLA (§4.1.2): after the last iteration every codeword is replaced by the training
//     vector nearest to it among those assigned to it (the paper's fix for GLA's averaging, which
//     darkens and loses contrast), then every vector is reassigned once. Deviation: once, after
//     convergence (the paper does not say when), as GLA's error falls monotonically only while
//     codewords are means.
//   - Alpha (§4.1.1) is quantised on its own: 16 grey values in [0, 255].
//   - Black-pixel heuristic (§4.1.1): a texel with no colour (alpha 0 in the input) would show
//     black wherever the separately quantised alpha gives it coverage; fillTransparentTexels gives
//     every such texel the colour of the billboard's brightest (largest L*) covered texel before
//     colour quantisation. Deviation: the paper patches the quantised texture, a codeword that many
//     billboards share and none can change alone.
//
// GLA: codewords start as K training vectors picked by a seeded deterministic draw among the
// distinct vectors; each iteration assigns every vector to its nearest codeword (ties: lowest
// index), moves every codeword to its cluster's mean (an empty cluster takes the vector farthest
// from its codeword, lowest index on ties), and stops when the mean squared error improves by less
// than `tolerance` (relative) or after maxIterations. K is clamped to the number of distinct
// training vectors. Deterministic for a seed and any thread count (assignment in parallel, sums in
// a fixed order).
#pragma once

#include "TreeLod/Progress.h"

#include <array>
#include <functional>
#include <cstdint>
#include <vector>

namespace TreeLod
{
    /// Texels of one billboard texture (4 x 4, row-major, top row first).
    constexpr int BILLBOARD_TEXELS = 16;

    /// One billboard texture: 16 texels of 8-bit sRGB colour and straight 8-bit alpha.
    struct BillboardTexture
    {
        std::array<std::array<std::uint8_t, 4>, BILLBOARD_TEXELS> texels{};
    };

    enum class QuantisationSpace
    {
        Rgb, ///< sRGB bytes scaled to [0, 100] (the paper's Fig. 5 b)
        Lab  ///< CIELab, D65 (Fig. 5 c, d)
    };

    struct GlaOptions
    {
        std::uint32_t codebookSize = 512; ///< K >= 1 (clamped to the distinct training vectors)
        int maxIterations = 40;           ///< >= 1
        double tolerance = 1e-4;          ///< relative improvement of the mean squared error
        bool nearestInput = true;         ///< the modified GLA: codewords are training vectors
        std::uint64_t seed = 1;
        /// > 0: train on an evenly strided subset of this many vectors (vector i * count / limit),
        /// then give every vector its nearest codeword; 0: train on all.
        std::size_t maxTrainingVectors = 0;
        /// Called after every GLA iteration with the share of maxIterations done; may be empty.
        std::function<void(float)> progress;
    };

    struct GlaResult
    {
        int dimension = 0;
        std::vector<float> codebook;             ///< K x dimension
        std::vector<std::uint32_t> assignment;   ///< per training vector, its codeword
        double meanSquaredError = 0.0;           ///< per vector (sum over components), final
        int iterations = 0;
        std::uint32_t codebookSize() const { return dimension ? std::uint32_t(codebook.size() / dimension) : 0; }
    };

    /// GLA over `count` vectors of `dimension` floats (row-major in `vectors`). count 0 gives an
    /// empty result. Throws std::invalid_argument on dimension < 1, a size mismatch, codebookSize
    /// 0, maxIterations < 1 or a non-finite component.
    GlaResult runGla(const std::vector<float>& vectors, int dimension, const GlaOptions& options);

    /// CIELab (D65) of an sRGB colour in [0, 1], and back (clamped to [0, 1]).
    std::array<float, 3> srgbToLab(float r, float g, float b);
    std::array<float, 3> labToSrgb(float l, float a, float b);

    /// The black-pixel heuristic above (in place).
    void fillTransparentTexels(BillboardTexture& texture);

    /// The 48 colour components of a billboard in `space`, and back to sRGB bytes (alpha left 255).
    std::array<float, 3 * BILLBOARD_TEXELS> colourVector(const BillboardTexture& texture, QuantisationSpace space);
    BillboardTexture colourFromVector(const float* vector, QuantisationSpace space);

    /// A quantised set of billboards: colour and alpha codebooks as 4x4 textures, per billboard
    /// the two indices.
    struct QuantisedBillboards
    {
        std::vector<BillboardTexture> colourCodebook; ///< alpha 255
        std::vector<BillboardTexture> alphaCodebook;  ///< grey in alpha; colour 0
        std::vector<std::uint32_t> colourIndex, alphaIndex; ///< per input billboard
        int colourIterations = 0, alphaIterations = 0;
    };

    struct BillboardQuantisationOptions
    {
        std::uint32_t colourCodebookSize = 512;
        std::uint32_t alphaCodebookSize = 512;
        QuantisationSpace space = QuantisationSpace::Lab;
        bool nearestInput = true; ///< the modified GLA
        int maxIterations = 40;
        std::uint64_t seed = 1;
        /// GlaOptions::maxTrainingVectors of both codebooks. Deviation from §4.1 (training on every
        /// billboard): a million billboards train in minutes, a strided 200,000 in seconds, and
        /// every billboard still gets its nearest codeword.
        std::size_t maxTrainingVectors = 200000;
    };

    /// Quantise `billboards` (§4.1): fillTransparentTexels on a copy of each, colour GLA in
    /// options.space, alpha GLA on the 16 alpha bytes. Deterministic.
    QuantisedBillboards quantiseBillboards(const std::vector<BillboardTexture>& billboards,
                                           const BillboardQuantisationOptions& options,
                                           const ProgressCallback& progress = {});

    /// Billboard i as the quantisation gives it back: colourCodebook[colourIndex[i]]'s colour with
    /// alphaCodebook[alphaIndex[i]]'s alpha.
    BillboardTexture dequantise(const QuantisedBillboards& q, std::size_t i);

    /// Peak signal-to-noise ratio (dB, peak 255) of `decoded` against `original` over every
    /// texel's R, G, B and A (A only: `alphaOnly`); +inf when equal. Both the same size.
    double billboardPsnr(const std::vector<BillboardTexture>& original, const std::vector<BillboardTexture>& decoded,
                         bool alphaOnly = false);
    /// Root mean squared error of the colour channels (R, G, B averaged, 0..255), over texels
    /// whose original alpha is > 0 (the paper's Fig. 5 "average RMS over the colour channels").
    double billboardColourRms(const std::vector<BillboardTexture>& original,
                              const std::vector<BillboardTexture>& decoded);
}
