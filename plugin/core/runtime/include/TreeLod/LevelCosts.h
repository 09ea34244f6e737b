// LevelCosts: what each level of a tree costs to draw on the running machine, measured by a
// short calibration (LevelCalibration.h: instanced draws of each level at a few screen heights,
// timed by read-back) and cached in a file per renderer string, so that a calibration made on
// another renderer is never reused. Nothing here assumes a cost from triangle counts.
//
// File (JSON, written atomically): {"renderer": "...", "version": 1, "assets": {"<asset key>":
// [{"technique": "<technique>", "level": 1200, "lowRes": false, "heightsPx": [16, 64, 256],
// "msPerTree": [0.012, 0.020, 0.151]}, ...]}, "textureSampling": {"compressedMs": 9.1,
// "decodedMs": 5.0}} (textureSampling optional: a file without it is measured again for it). The asset key (assetCostKey) hashes the chunks the
// levels draw from, so a rebaked tree is calibrated again.
#pragma once

#include "TreeLod/Result.h"

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace TreeLod
{
    class PackageReader;

    /// One level's cost: milliseconds per tree against the tree's height on screen.
    struct LevelCost
    {
        std::string technique;
        std::uint32_t techniqueLevel = 0;
        bool lowRes = false;
        std::vector<float> heightsPx; ///< strictly increasing, > 0
        std::vector<float> msPerTree; ///< one per height, finite, >= 0
        /// Cost at `heightPx`: log(ms) linear in log(height) between the measured heights (fragment
        /// work grows with the area, vertex work does not); below the first height the first value;
        /// above the last, the last segment's slope (at least 0) extrapolated. 0 without values.
        float msAt(float heightPx) const;
    };

    /// The renderer's time for the same draw sampling a block-compressed texture and the same
    /// texture decoded to RGBA8 (LevelCalibration.h measureTextureSampling), empty frame subtracted.
    struct TextureSamplingCost
    {
        /// Compressed sampling slower than decoded by more than this fraction decodes at load.
        static constexpr double DECODE_MARGIN = 0.1;
        double compressedMs = 0.0; ///< finite, >= 0
        double decodedMs = 0.0;    ///< finite, >= 0
        /// Whether this renderer should get block-compressed textures decoded to RGBA8 at load:
        /// compressedMs > (1 + DECODE_MARGIN) decodedMs. A GPU's texture unit decodes blocks at no
        /// cost and reads a quarter of the bytes; a software rasteriser (llvmpipe) decodes per fetch.
        bool decodeAtLoad() const { return compressedMs > (1.0 + DECODE_MARGIN) * decodedMs; }
    };

    struct CostCalibration
    {
        static constexpr int VERSION = 1;
        std::string renderer; ///< the render system's renderer string (GL_RENDERER)
        std::map<std::string, std::vector<LevelCost>> assets; ///< by assetCostKey
        bool hasTextureSampling = false; ///< whether textureSampling was measured
        TextureSamplingCost textureSampling;

        /// The levels of `assetKey`, or null.
        const std::vector<LevelCost>* find(const std::string& assetKey) const;
    };

    /// The index in `levels` of (technique, techniqueLevel, lowRes), or -1.
    int findLevelCost(const std::vector<LevelCost>& levels, const std::string& technique, std::uint32_t techniqueLevel,
                      bool lowRes);

    /// "<directory>/calibration-<16 hex of FNV-1a 64 of the renderer string>.json".
    std::string costCalibrationPath(const std::string& directory, const std::string& renderer);

    /// Read a calibration; an error naming the file and the reason when it cannot be parsed or a value
    /// is invalid, and when it was made on another renderer than `renderer`.
    Result<CostCalibration> readCostCalibration(const std::string& path, const std::string& renderer);
    /// Write atomically; error naming the file.
    Result<void> writeCostCalibration(const std::string& path, const CostCalibration& calibration);

    /// The calibration key of a package: FNV-1a 64 (16 hex) of the table entries (technique,
    /// level, format version, CRC-32) of its chunks named in `chunks` (those the calibrated levels
    /// draw from), so that adding another technique's chunk to the package keeps its costs.
    std::string assetCostKey(const PackageReader& package, const std::vector<std::string>& chunks);
}
