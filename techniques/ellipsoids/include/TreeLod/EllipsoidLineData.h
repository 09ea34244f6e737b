// EllipsoidLineData: the branches of a tree as a hierarchy of lines, package chunk "ellipsoid-lines",
// after the ellipsoids-and-lines paper (001), §3.2 (the line hierarchy), §5 (storage as a sequential
// point tree) and §6 (one default line width per level). The baker is EllipsoidLineBaker.h; the
// leaves are the "ellipsoids" chunk (EllipsoidTreeData.h).
//
// ---- Meaning ----------------------------------------------------------------------------------
// One array of lines ordered by level, finest first (paper 001 §5): level 0 has a line per segment
// of the tree's skeleton, each coarser level about a quarter as many (agglomerative merges, §3.2),
// the last one a single line. A level is drawn whole: lines [first, first + count), in no particular
// order; no parent links are stored (they matter only while merging). A line is the capsule
// (sphere-swept segment) of the points within `radius` of the segment start..end: a tube with round
// ends, so lines meeting at a joint close it, and a line of zero length is a sphere. Under an
// orthographic view it covers exactly the 2D stadium of the projected segment widened by radius (the
// baker's image error draws it so); a renderer may draw a camera-facing quad with round caps.
// Metres, the tree's own frame (+Y up).
//   colour: index into the palette, the sRGB mean bark colour of the bark the line stands for.
//   ambientOcclusion: 255 = none (the baker does not compute it yet: always 255).
//   heightMetres: the tree height the level targets refer to, the height of the model's whole box
//     (bark and leaves, TreeModel::boundsMax.y - boundsMin.y; its diagonal when that is 0) — the
//     height a renderer measures on screen, as EllipsoidTree does.
//   targetHeightPx (§6): the tree's height in screen pixels at which the level's mean line width is
//     ELLIPSOID_LINE_TARGET_WIDTH_PX (1 px, the paper's default). The mean width is length-weighted,
//     W = sum(2 r_i L_i) / sum(L_i) over the level's lines (a line's share of the drawn outline is its
//     length; the plain mean of 2 r_i when every line has length 0), so targetHeightPx =
//     heightMetres / W * 1 px, or the previous level's target when that is smaller (targets never
//     grow towards coarser levels). The trunk's lines are then a few pixels wide, the twigs' under one,
//     as §6 intends.
//     A renderer draws the level whose target is nearest above the tree's height on screen. The
//     paper's per-primitive error value (the inverse of the target resolution in pixels per metre)
//     is heightMetres / targetHeightPx = W metres.
//   imageError: the level's multi-scale RMSE (§4) against the bark as the baker measured it
//     (flat-colour coverage images, see EllipsoidLineBaker.h).
//
// ---- Chunk layout, formatVersion 1 (ELLIPSOID_LINES_CHUNK_FORMAT_VERSION) ---------------------
// Little-endian:
//   u32 flags (0; others are an error)
//   f32 x 3 boundsMin, f32 x 3 boundsMax   the box of the line ends (finite, max >= min)
//   f32 radiusUnit                         metres (finite, > 0): the unit of the radii's log scale
//   f32 heightMetres                       (finite, > 0)
//   u32 paletteCount in [1, 256], then per entry u8 x 4: sRGB R, G, B, and A = 255 (others are an
//                                          error; an RGBA8 texel as it is, A kept for later use)
//   u32 levelCount in [1, 32], then per level ELLIPSOID_LINE_LEVEL_BYTES = 16 bytes:
//     u32 first, u32 count (>= 1)          level 0 starts at 0, each level right after the previous,
//                                          the last ends at lineCount
//     f32 targetHeightPx (finite, > 0), f32 imageError in [0, 1]
//   u32 lineCount, then per line ELLIPSOID_LINE_RECORD_BYTES = 16 bytes:
//     u16 x 3 start      boundsMin + (boundsMax - boundsMin) * q / 65535
//     u16 x 3 end        the same
//     u16 radius         radiusUnit * 2^(24 q / 65535 - 20)  (relative step 2^(24/65535), 0.025 %)
//     u8 colour          palette index (< paletteCount)
//     u8 ambientOcclusion  255 = none
//   (end of chunk: trailing bytes are an error)
// The paper stores a line in 48 bytes; the merge weights (§3.2) are a bake-time device and not stored.
#pragma once

#include "TreeLod/Result.h"

#include <glm/glm.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace TreeLod
{
    constexpr const char* ELLIPSOID_LINES_CHUNK = "ellipsoid-lines";
    constexpr std::uint32_t ELLIPSOID_LINES_CHUNK_FORMAT_VERSION = 1;
    constexpr std::size_t ELLIPSOID_LINE_RECORD_BYTES = 16;
    constexpr std::size_t ELLIPSOID_LINE_LEVEL_BYTES = 16;
    constexpr std::uint32_t ELLIPSOID_LINE_MAX_LEVELS = 32;
    constexpr std::uint32_t ELLIPSOID_LINE_MAX_PALETTE = 256;
    /// Mean line width in pixels a level is made for (paper 001 §6's default of 1).
    constexpr float ELLIPSOID_LINE_TARGET_WIDTH_PX = 1.0f;
    /// The radii's log-scale range: radiusUnit * 2^[RADIUS_LOG2_MIN, RADIUS_LOG2_MIN + RADIUS_LOG2_SPAN].
    constexpr float ELLIPSOID_LINE_RADIUS_LOG2_MIN = -20.0f;
    constexpr float ELLIPSOID_LINE_RADIUS_LOG2_SPAN = 24.0f;
    /// The largest relative error of a quantised radius (half a step of the log scale).
    constexpr float ELLIPSOID_LINE_RADIUS_RELATIVE_STEP = 2.6e-4f;

    struct EllipsoidLine
    {
        glm::vec3 start{0.0f}, end{0.0f};    ///< metres
        float radius = 0.0f;                 ///< metres, > 0
        std::uint8_t colour = 0;             ///< palette index
        std::uint8_t ambientOcclusion = 255; ///< 255 = none
    };

    struct EllipsoidLineLevel
    {
        std::uint32_t first = 0, count = 0; ///< into EllipsoidLineData::lines
        float targetHeightPx = 0.0f;        ///< tree height on screen this level is made for
        float imageError = 0.0f;            ///< multi-scale RMSE against the bark when baked
    };

    struct EllipsoidLineData
    {
        glm::vec3 boundsMin{0.0f}, boundsMax{0.0f};       ///< the box of the line ends (quantisation)
        float radiusUnit = 1.0f;                          ///< metres
        float heightMetres = 1.0f;                        ///< what targetHeightPx is a height of
        std::vector<std::array<std::uint8_t, 4>> palette; ///< sRGB RGB, A = 255
        std::vector<EllipsoidLineLevel> levels;           ///< finest first
        std::vector<EllipsoidLine> lines;                 ///< by level

        /// Bytes of the encoded chunk.
        std::size_t encodedBytes() const;

        /// Everything the layout above requires, on the values as held (a decoded chunk passes
        /// exactly when its bytes are valid). Errors name `label` and the level, palette entry or line.
        Result<void> validate(const std::string& label) const;
    };

    /// The largest error quantisation makes in a line end's coordinate `axis` (metres).
    float ellipsoidLineEndStep(const EllipsoidLineData& data, int axis);

    /// Serialise in the layout above (quantising; values outside the box or log range clamp).
    /// Deterministic; does not validate (decode does).
    std::vector<std::uint8_t> encodeEllipsoidLineChunk(const EllipsoidLineData& data);

    /// Parse and validate(); errors name `label`, "chunk 'ellipsoid-lines' level 0" and the element
    /// ("level 2", "palette entry 1", "line 17").
    Result<EllipsoidLineData> decodeEllipsoidLineChunk(const std::vector<std::uint8_t>& bytes,
                                                       const std::string& label);
}
