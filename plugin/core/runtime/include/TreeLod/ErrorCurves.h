// ErrorCurves: package chunk "error-curves", the image error of every Forest level of one tree
// against the tree's height on screen, measured at bake time by the Ogre side (which renders the
// levels). Here: the data, its layout and its checks. TechniqueDescriptor.cpp registers the
// chunk's descriptor together with "reference", so every program linking TreeLodRuntime knows it.
//
// ---- Meaning ----------------------------------------------------------------------------
// For each height in heightsPx (the tree's height on screen, pixels), each level is
// rendered from `views` directions and compared with the reference (the polygonal tree,
// supersampled referenceSamples times per pixel): flip is the mean FLIP over the views (the
// measurer averages those a camera near the ground sees), flipMax the worst view's (all views),
// rmse the mean multi-scale RMSE (ImageMetrics.h) over the same views as flip. A view's FLIP is
// the mean over the tree's own pixels (tree in the reference or in the level), its RMSE over a
// square crop around the tree.
// switchFlip (version 2) is what a hard switch between two levels shows: for each pair of levels
// and height, the mean over the same views as flip of the FLIP between the two levels' images,
// over the pixels that are tree in either.
// resourceBytes (version 3) is what the levels hold on the GPU: each texture (with its mips),
// vertex buffer and index buffer the measured levels draw from, once, and per level the indices
// of those it draws from. Levels of one technique share resources (one vertex buffer, one atlas),
// so a plan's bytes are those of the union of its levels' resources (gpuBytes). The Forest's
// instance buffers (per drawn tree, per camera) are not a level's and are not counted.
// A level is named as ForestLevel names it: (technique, techniqueLevel, lowRes).
//
// ---- Chunk layout, level 0, formatVersion 3 (ERROR_CURVES_FORMAT_VERSION) -----------------
// Little-endian; H = heightCount, n = levelCount:
//   u32 heightCount H (1..64), u32 levelCount n (1..256), u32 views (>= 1), u32 referenceSamples (>= 1)
//   f32 heightsPx[H]
//   n levels:
//       u32 nameLength (1..32), char technique[nameLength] (printable ASCII, no terminator)
//       u32 techniqueLevel, u32 flags (bit 0: lowRes; others are an error)
//       f32 flip[H], f32 flipMax[H], f32 rmse[H]
//   u32 switchPairs (0: not measured, or n (n - 1) / 2)
//   switchPairs pairs (a, b), a < b, in the order (0, 1), (0, 2), ..., (0, n - 1), (1, 2), ...:
//       f32 switchFlip[H]
//   u32 resourceCount R (0: not measured; at most ERROR_CURVES_MAX_RESOURCES)
//   where R > 0: u64 resourceBytes[R], then n levels: u32 k (0..R), u32 resources[k] (< R, increasing)
//   (end of chunk: trailing bytes are an error)
// Version 2 ends after the pairs (resourceBytes empty); version 1 after the levels (switchFlip
// empty too). Both still decode.
#pragma once

#include "TreeLod/Result.h"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace TreeLod
{
    struct TechniqueDescriptor;

    constexpr const char* ERROR_CURVES_CHUNK = "error-curves";
    constexpr std::uint32_t ERROR_CURVES_FORMAT_VERSION = 3;
    /// The oldest version decodeErrorCurves reads (its curves have no switchFlip).
    constexpr std::uint32_t ERROR_CURVES_OLDEST_FORMAT_VERSION = 1;
    constexpr std::size_t ERROR_CURVES_MAX_HEIGHTS = 64;
    constexpr std::size_t ERROR_CURVES_MAX_LEVELS = 256;
    constexpr std::size_t ERROR_CURVES_MAX_RESOURCES = 4096;
    constexpr float ERROR_CURVES_MIN_HEIGHT_PX = 1.0f;
    constexpr float ERROR_CURVES_MAX_HEIGHT_PX = 16384.0f;
    /// ErrorCurves::switchFlipAt of curves without switchFlip (version 1): below every FLIP.
    constexpr float SWITCH_FLIP_UNKNOWN = -1.0f;

    /// One Forest level's curve: image error against the tree's height on screen.
    struct ErrorCurveLevel
    {
        std::string technique;            ///< registered technique name ("mesh", ...), 1..32 printable ASCII
        std::uint32_t techniqueLevel = 0; ///< the technique's own level (as ForestLevel::techniqueLevel)
        bool lowRes = false;              ///< as ForestLevel::lowRes
        std::vector<float> flip;          ///< mean FLIP over the (side) views, one per height, in [0, 1]
        std::vector<float> flipMax;       ///< worst view's FLIP, one per height, in [0, 1], >= flip
        std::vector<float> rmse;          ///< mean multi-scale RMSE over the views, one per height, in [0, 1]
        /// Indices into ErrorCurves::resourceBytes of what the level draws from, increasing; empty
        /// when the bytes were not measured (version 2 and older).
        std::vector<std::uint32_t> resources;
    };

    struct ErrorCurves
    {
        std::vector<float> heightsPx;        ///< strictly increasing, finite, in [1, 16384]; 1..64 entries
        std::uint32_t views = 0;             ///< views averaged per height (>= 1)
        std::uint32_t referenceSamples = 0;  ///< reference supersampling per pixel (>= 1)
        std::vector<ErrorCurveLevel> levels; ///< 1..256 levels; (technique, techniqueLevel, lowRes) unique
        /// FLIP between two levels' images, one vector of one value per height (in [0, 1]) per pair
        /// of levels (a, b), a < b, at switchPair(a, b); empty when not measured (version 1).
        std::vector<std::vector<float>> switchFlip;
        /// GPU bytes of each resource the levels draw from (textures with mips, vertex and index
        /// buffers), each once; empty when not measured (version 2 and older).
        std::vector<std::uint64_t> resourceBytes;

        /// The index of the level (technique, techniqueLevel, lowRes), or -1.
        int find(const std::string& technique, std::uint32_t techniqueLevel, bool lowRes) const;

        /// FLIP of `level` at `heightPx`: linear interpolation in log2(height) between the two nearest
        /// heights, clamped to the first/last value outside the measured range. Non-finite or <= 0
        /// heights give the first value. 0 when `level` is out of range or has no values; on
        /// validated curves the result is in [0, 1].
        float flipAt(std::size_t level, float heightPx) const;
        /// The worst view's FLIP (flipMax) of `level` at `heightPx`, interpolated as flipAt.
        float flipMaxAt(std::size_t level, float heightPx) const;

        /// Whether switchFlip holds every pair of levels (one level: no pair, nothing unknown).
        bool hasSwitchFlip() const { return switchFlip.size() == switchPairs(levels.size()); }
        /// FLIP between levels `a` and `b` at `heightPx` (either order), interpolated as flipAt; 0
        /// when a == b. SWITCH_FLIP_UNKNOWN when the curves have no switchFlip or a level is out
        /// of range.
        float switchFlipAt(std::size_t a, std::size_t b, float heightPx) const;
        /// Whether the levels' GPU bytes were measured.
        bool hasGpuBytes() const { return !resourceBytes.empty(); }
        /// GPU bytes of the union of the resources of `levelIndices` (out of range: skipped); 0
        /// without measured bytes.
        std::uint64_t gpuBytes(const std::vector<std::size_t>& levelIndices) const;
        /// Keep the levels whose flag in `keep` (one per level) is set, their switchFlip with them.
        void keepLevels(const std::vector<bool>& keep);
        /// The number of pairs of `levelCount` levels, and the index of pair (a, b), a < b.
        static std::size_t switchPairs(std::size_t levelCount)
        {
            return levelCount < 2 ? 0 : levelCount * (levelCount - 1) / 2;
        }
        std::size_t switchPair(std::size_t a, std::size_t b) const
        {
            return a * (2 * levels.size() - a - 1) / 2 + (b - a - 1);
        }
    };

    /// Serialise in the layout above, version ERROR_CURVES_FORMAT_VERSION. Deterministic; does not
    /// validate (decode does, and the measurer should call validateErrorCurves before writing).
    std::vector<std::uint8_t> encodeErrorCurves(const ErrorCurves& curves);

    /// Strict: every count, size and value checked; errors name `label`, the element
    /// ("error-curves level 3 '<technique>' 1200", "error-curves heights[2]") and the reason.
    /// `formatVersion`: the chunk's (PackageReader's ChunkInfo, TreeAsset::getChunkFormatVersion),
    /// ERROR_CURVES_OLDEST_FORMAT_VERSION..ERROR_CURVES_FORMAT_VERSION; others are an error.
    Result<ErrorCurves> decodeErrorCurves(const std::vector<std::uint8_t>& bytes, const std::string& label,
                                          std::uint32_t formatVersion = ERROR_CURVES_FORMAT_VERSION);

    /// The same checks on a value (decode calls it; the measurer calls it before writing): counts
    /// within the limits, every curve one value per height, values finite and in range, heights
    /// strictly increasing, flipMax >= flip - 1e-6, names valid, levels unique, switchFlip empty
    /// or one curve per pair, resources within the table and increasing (every level's empty
    /// without a table).
    Result<void> validateErrorCurves(const ErrorCurves& curves, const std::string& label);

    /// The chunk's descriptor (inspect, fuzz); TechniqueDescriptor.cpp registers it.
    TechniqueDescriptor errorCurvesDescriptor();
}
