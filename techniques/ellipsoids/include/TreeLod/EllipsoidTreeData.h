// EllipsoidTreeData: the leaves of a tree as a hierarchy of ellipsoids, package chunk "ellipsoids",
// after the ellipsoids-and-lines paper (001), §3.1 (the hierarchy) and §5 (storage as a sequential
// point tree). The baker is EllipsoidTreeBaker.h. Lines (the branches, §3.2) are chunk
// "ellipsoid-lines" (EllipsoidLineData.h); the noise cube maps are shared by every tree
// (EllipsoidNoise.h), this chunk holds each level's noise parameters.
//
// ---- Meaning ----------------------------------------------------------------------------------
// One array of ellipsoids ordered by level, finest first (paper 001 §5): level 0 has one
// ellipsoid per leaf, each coarser level about a quarter as many (clustered by EM/GMM), the last
// one a single ellipsoid. A level is drawn whole (the paper's per-level error thresholds, §5/§6):
// ellipsoids [first, first + count). An ellipsoid is the set of points
//   centre + rotation * (scale * radii * u), |u| <= 1,
// where `scale` is its level's calibrated visible-area factor (§3.1) and radii are the semi-axes
// along the rotation's local x, y, z (largest first when baked; the smallest may be a floor of
// 2 % of the largest, a thin disc). Metres, the tree's own frame (+Y up).
// targetHeightPx (§6): the tree's height in screen pixels at which the level's mean ellipsoid is
// ELLIPSOID_TARGET_DIAMETER_PX pixels across; a renderer shows the level whose target is nearest
// above the tree's height on screen. imageError: the level's multi-scale RMSE (§4) against the
// leaves as the baker measured it (flat-colour coverage images, see EllipsoidTreeBaker.h).
// Noise (§3.1, Fig. 6; EllipsoidNoise.h): a level's ellipsoids drop the surface points whose
// alpha noise is below noiseThreshold (0: no holes), sampled at the lod of
// ellipsoidNoiseBaseLod(leafWeight) or the pixel footprint's if coarser, and blend their normal
// towards the normal noise by normalBlend (0: the ellipsoid's own normal). The level's scale
// includes the area compensation for the holes.
//
// ---- Chunk layout, formatVersion 2 (ELLIPSOID_TREE_CHUNK_FORMAT_VERSION) ------------------------
// Little-endian:
//   u32 flags (0; others are an error)
//   f32 x 3 boundsMin, f32 x 3 boundsMax   the box of the centres (finite, max >= min)
//   f32 radiusUnit                         metres (finite, > 0): the unit of the radii's log scale
//   u32 levelCount in [1, 32], then per level (28 bytes):
//     u32 first, u32 count (>= 1)          level 0 starts at 0, each level right after the previous,
//                                          the last ends at ellipsoidCount
//     f32 scale in (0, 16], f32 targetHeightPx (finite, > 0), f32 imageError in [0, 1]
//     f32 noiseThreshold in [0, 1), f32 normalBlend in [0, 1]
//   u32 ellipsoidCount, then per ellipsoid ELLIPSOID_RECORD_BYTES = 28 bytes:
//     u16 x 3 centre      boundsMin + (boundsMax - boundsMin) * q / 65535
//     u16 x 3 radii       radiusUnit * 2^(24 q / 65535 - 20)  (relative step 2^(24/65535), 0.025 %)
//     i16 x 4 rotation    unit quaternion x, y, z, w as q / 32767 (w >= 0); its length must be
//                         within 2 % of 1, the decoder normalises it
//     u8 x 4 colour       sRGB mean leaf colour R, G, B; A = ambient occlusion (255 = none)
//     f32 leafWeight      the leaves it stands for, sum of the fuzzy memberships (finite, >= 0)
//   (end of chunk: trailing bytes are an error)
#pragma once

#include "TreeLod/Result.h"

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace TreeLod
{
    constexpr const char* ELLIPSOID_TREE_CHUNK = "ellipsoids";
    constexpr std::uint32_t ELLIPSOID_TREE_CHUNK_FORMAT_VERSION = 2;
    constexpr std::size_t ELLIPSOID_RECORD_BYTES = 28;
    constexpr std::size_t ELLIPSOID_LEVEL_BYTES = 28;
    constexpr std::uint32_t ELLIPSOID_MAX_LEVELS = 32;
    /// Mean ellipsoid diameter in pixels a level is made for (paper 001 §6's default of 5).
    constexpr float ELLIPSOID_TARGET_DIAMETER_PX = 5.0f;
    /// The radii's log-scale range: radiusUnit * 2^[RADIUS_LOG2_MIN, RADIUS_LOG2_MIN + RADIUS_LOG2_SPAN].
    constexpr float ELLIPSOID_RADIUS_LOG2_MIN = -20.0f;
    constexpr float ELLIPSOID_RADIUS_LOG2_SPAN = 24.0f;

    struct Ellipsoid
    {
        glm::vec3 centre{0.0f};       ///< metres
        glm::quat rotation{1, 0, 0, 0}; ///< unit; local x, y, z are the axes of radii
        glm::vec3 radii{0.0f};        ///< semi-axes in metres, before the level's scale, > 0
        std::array<std::uint8_t, 4> colour{{0, 0, 0, 255}}; ///< sRGB RGB, A = AO
        float leafWeight = 0.0f;      ///< leaves it stands for (fuzzy), >= 0
    };

    struct EllipsoidLevel
    {
        std::uint32_t first = 0, count = 0; ///< into EllipsoidTreeData::ellipsoids
        float scale = 1.0f;                 ///< calibrated visible-area factor on every radius
        float targetHeightPx = 0.0f;        ///< tree height on screen this level is made for
        float imageError = 0.0f;            ///< multi-scale RMSE against the leaves when baked
        float noiseThreshold = 0.0f;        ///< alpha test on the noise (§3.1): 0 = no holes
        float normalBlend = 0.0f;           ///< towards the noise normal: 0 = the ellipsoid's
    };

    struct EllipsoidTreeData
    {
        glm::vec3 boundsMin{0.0f}, boundsMax{0.0f}; ///< the box of the centres (quantisation)
        float radiusUnit = 1.0f;                    ///< metres
        std::vector<EllipsoidLevel> levels;         ///< finest first
        std::vector<Ellipsoid> ellipsoids;          ///< by level

        /// Bytes of the encoded chunk.
        std::size_t encodedBytes() const;

        /// Everything the layout above requires, on the values as held (a decoded chunk passes
        /// exactly when its bytes are valid). Errors name `label` and the level or ellipsoid.
        Result<void> validate(const std::string& label) const;
    };

    /// The largest error quantisation makes: a centre coordinate (metres, per axis) and a radius
    /// (relative) of `data`.
    float ellipsoidCentreStep(const EllipsoidTreeData& data, int axis);
    constexpr float ELLIPSOID_RADIUS_RELATIVE_STEP = 2.6e-4f;

    /// Serialise in the layout above (quantising; values outside the box or log range clamp).
    /// Deterministic; does not validate (decode does).
    std::vector<std::uint8_t> encodeEllipsoidTreeChunk(const EllipsoidTreeData& data);

    /// Parse and validate(); errors name `label`, "chunk 'ellipsoids' level 0" and the element
    /// ("level 2", "ellipsoid 17").
    Result<EllipsoidTreeData> decodeEllipsoidTreeChunk(const std::vector<std::uint8_t>& bytes, const std::string& label);
}
