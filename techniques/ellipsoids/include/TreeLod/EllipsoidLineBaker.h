// EllipsoidLineBaker: TreeModel -> EllipsoidLineData (EllipsoidLineData.h): the branch half of the
// ellipsoids-and-lines paper (001), §3.2, with §4's image error and §6's per-level target size.
// The leaves are EllipsoidTreeBaker.h; the "ellipsoids" bake writes both chunks.
//
//   1. Skeleton: the model's own, else one extracted from the bark (SkeletonExtraction.h). No bark,
//      or only degenerate triangles (degenerateTriangle): no lines (an empty result, not an error).
//   2. Lines (§3.2): one per parent -> child segment of the skeleton, radius the mean of its two
//      nodes' radii (the frustum's mean radius: the side-view area of the tube between them), at
//      least MIN_RADIUS (1e-5) of the bark box's diagonal D. A node on its parent (within 1e-7 D) is
//      merged into it; a node with neither parent nor children (a skeleton of one node) is a line of
//      zero length, a sphere. A line is a capsule (EllipsoidLineData.h). Weights (Fig. 7): the
//      capsule's volume, pi r^2 (L + 4 r / 3). Colour: the mean bark colour (base colour times the
//      mean of its texture) of the bark triangles nearest the line's end node.
//   3. Merges (§3.2), until one line is left: straighten replaces a line and its only child by one
//      line from the first's start to the second's end; combine replaces two lines of the same parent
//      line (or two lines of no parent) by their weighted mean (ends, radius, colour). Each step draws
//      `candidates` mergeable pairs uniformly at random (seeded) and applies the one whose simplified
//      model has the least image error (4.), the merged line taking the sum of the weights. Eight
//      draws by default: on the generated oak the first merged level errs 0.024 with them, 0.058 with
//      one draw (a random merge order) and 0.023 with 32 at 2.6 times the time.
//   4. Image error (§4): multi-scale RMSE, mean over 4 orthographic views (three around at 15 degrees
//      elevation, one from above) of viewResolution^2 pixels with 2 x 2 samples, of coverage images:
//      the bark in one flat colour, rendered by the CPU ReferenceRenderer once, against the lines.
//   5. Levels: level 0 is every line of 2.; then the state when the count falls to
//      floor(n / linesDivisor^k), k = 1, 2, ..., while that is >= 1, and to one line last. Each
//      level's imageError is measured as in 4. with the lines ray-traced as capsule meshes
//      (ellipsoidLineLevelMesh); its targetHeightPx follows §6 (EllipsoidLineData.h: the height at
//      which the level's length-weighted mean line width is 1 px).
//
// Deviations from the paper, and why:
//   - The merge search does not render: each view keeps per-sample counts of the lines covering it
//     and the block sums of the difference image at every scale of the multi-scale RMSE, and a
//     candidate is scored by rasterising only the lines it removes and adds (analytically: under an
//     orthographic view a capsule covers the 2D stadium of its projected segment) over the screen
//     rectangle they cover, updating the affected block sums of every band. This is the same metric
//     as a full render of the capsules at the same samples (on the generated oak it is within 2 % of
//     the ray-traced capsule meshes' error at every level), at a cost proportional to the changed
//     area: the paper's 0.3 s per branch (and a full render per candidate) would take minutes for the
//     thousands of segments of a tree; here the 1580 merges of the generated oak take 0.3 s (2 cores).
//   - Merges that change no sample (lines thinner than a sample) score alike; among those the least
//     weighted displacement wins (sum over the two lines of weight times the mean distance of their
//     ends from the merged line), then the first drawn.
//   - Straighten needs the first line's only child: a joint with several children stays until they
//     are combined (so a mergeable pair exists until one line is left). Combine moves the starts of
//     the merged lines' children to the merged line's end, which keeps the lines connected.
//   - The image error compares flat-colour coverage images instead of shaded ones, as the ellipsoid
//     baker does: shading is the renderer's. Colours are averaged with the weights, per material
//     (not per texel); ambient occlusion is not computed (255). No crop operation (the paper did not
//     use it either).
// Every length is relative to the bark's bounding box: a tree scaled by a power of two gives the same
// lines scaled; another factor rounds the input differently, which can change which of two nearly
// equal candidates wins a merge (a 0.5 m and a 500 m oak: the same level counts and level 0, level
// errors within a few per cent). Deterministic for a seed and any TBB thread count.
#pragma once

#include "TreeLod/EllipsoidLineData.h"
#include "TreeLod/PackageWriter.h"
#include "TreeLod/Progress.h"
#include "TreeLod/Result.h"
#include "TreeLod/TreeModel.h"

#include <cstdint>
#include <string>
#include <vector>

namespace TreeLod
{
    struct EllipsoidLineOptions
    {
        std::uint32_t candidates = 8;   ///< mergeable pairs drawn per merge, 1 to 64
        std::uint64_t seed = 1;         ///< of the draws
        std::uint32_t linesDivisor = 4; ///< 2 to 64: each level has 1 / this of the previous' lines
        int viewResolution = 128;       ///< pixels a side of each error view, a power of two, 16 to 1024
    };

    /// The lines of level `level` of `data` as opaque, double-sided bark of one white material:
    /// capsules of 64 triangles (8 sides, widened so that their mean width is the capsule's). What the
    /// baker ray-traces for a level's error; tests measure coverage with it. Empty for a bad level.
    TreeModel ellipsoidLineLevelMesh(const EllipsoidLineData& data, std::size_t level);

    /// `model`'s bark alone, every material white and untextured (double-sidedness kept): the
    /// reference the baker measures against.
    TreeModel flatColourBark(const TreeModel& model);

    /// Bake the line hierarchy. Errors name `label`: invalid options or model, a skeleton with a
    /// non-finite node, more than ELLIPSOID_LINE_MAX_LEVELS levels. No bark, or only degenerate
    /// triangles: empty data (no levels, no lines). `weights`, when given, receives each line's merge
    /// weight (m^3, by data.lines), for tests and tools: every level's weights sum to the same total.
    /// Progress steps: "lines: skeleton", "lines: merging", "lines: level N of M".
    Result<EllipsoidLineData> bakeEllipsoidLines(const TreeModel& model, const EllipsoidLineOptions& options,
                                                 const std::string& label, const ProgressCallback& progress = {},
                                                 std::vector<double>* weights = nullptr);

    /// Package glue: adds the reference chunk when missing and the "ellipsoid-lines" chunk when the
    /// model has bark (nothing else when it has none). Used by the "ellipsoids" and "ellipsoid-lines"
    /// bake techniques.
    Result<void> addEllipsoidLineChunk(PackageWriter& writer, const TreeModel& model,
                                       const EllipsoidLineOptions& options, const std::string& label,
                                       const ProgressCallback& progress = {});
}
