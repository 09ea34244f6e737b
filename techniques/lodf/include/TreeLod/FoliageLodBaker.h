// FoliageLodBaker: builds LoDF's multiresolution foliage from a tree (Rebollo et al. 2006 §3,
// §3.1).
//
// 1. Independent groups (§3.1): the leaves of each leaf material are split into spatially
//    compact clusters of at most `clusterSize` leaves (recursive median split of the leaf
//    centres along the longest axis). A collapse never crosses clusters, and the sequence
//    runs until each cluster is one leaf, so the coarsest level has one leaf per cluster.
// 2. Leaf collapse (§3, after the Foliage Simplification Algorithm [15]): inside a cluster the
//    cheapest pair of active leaves is collapsed, greedily, until one leaf is left. Cost of
//    collapsing a and b (metres: the error of replacing two leaves by one):
//        cost = (|c_a - c_b| + s * (1 - |n_a . n_b|) + s * uvPenalty) * sqrt((A_a + A_b) / A_mean)
//    c centre, n normal, A the area the leaf stands for (sum of the original leaves it
//    replaces), s = sqrt(A_a + A_b) its size, uvPenalty 1 when the two leaves show different
//    parts of the texture (else 0), A_mean the mean original leaf area. Distance keeps the
//    crown's shape, orientation keeps its shading, the area factor makes leaves grow evenly.
// 3. The new leaf (eq. 3, no new vertices): each leaf has four corner vertices, one per corner
//    of its texture rectangle. Candidates: every corner from a or from b (16 choices, eq. 3),
//    and a quad whose corner r is a corner-r vertex of any original leaf of the cluster showing
//    the same leaf image, chosen near corner r of the ideal leaf (area A_a + A_b around the
//    pair's centre, the larger leaf's axes and aspect) and then improved corner by corner. The
//    one kept is the closest to covering A_a + A_b, centred on the pair, without folding. So the
//    crown's covered area is kept as leaves disappear, and the whole leaf image stays mapped on
//    the new quad. Deviation (techniques/lodf/README.md): eq. 3 takes the corners from a and b only; a few
//    collapses deep their vertices cannot reach the area the leaf stands for, and the crowns of
//    third-party trees thinned out at distance (ez-tree oak at 30 px: FLIP 0.102 against 0.069).
//    Crossed leaves (deviation, techniques/lodf/README.md): originals of one leaf image through one centre
//    (within 5 % of a leaf size) in different planes, as ez-tree's "double billboards" and needle
//    sprigs, are one crossed leaf. Two crossed leaves collapse part with part (each part of the
//    one with fewer parts with the most parallel free part of the other; cost: the largest of
//    those pairs'), one step per pair, the later parts centred on the first; only a cluster's
//    last steps merge the parts of its one remaining crossed leaf. Collapsed as flat leaves,
//    crossed leaves lost a quarter of their area by L/2 and their crossing by L/4.
//    Leaves in several planes (deviation, techniques/lodf/README.md): a leaf that is one mesh in several planes
//    (a folded leaf, a sprig in one piece) is one original per plane (its triangles grouped by
//    normal; planes under 10 % of its area joined to the most parallel other), so L counts
//    quads, and its planes collapse part with part as a crossed leaf's do, each later part
//    centred on its own pair. Collapsed as one flat quad, 2 % of a folded test crown's area
//    stayed folded at L/2.
// 4. Order (Fig. 8): Changed_group lists the collapses by cost band (`costBands` equal-count bands
//    of each collapse's running-maximum cost in its cluster), and inside a band cluster by cluster
//    (clusters in a fixed pseudo-random order, so no region of the crown simplifies first).
//    Deviation from a pure global cost order, stated in techniques/lodf/README.md: with it, any 1 % change
//    touches nearly every cluster and §4's partial upload saves nothing; with bands, a run of
//    consecutive changes touches few clusters, at the price of reordering collapses whose costs lie
//    in the same band.
// Deterministic: the same model and options give the same data, whatever the thread count.
#pragma once

#include "TreeLod/FoliageLodData.h"
#include "TreeLod/Progress.h"
#include "TreeLod/Result.h"
#include "TreeLod/TreeModel.h"

#include <cstdint>
#include <string>

namespace TreeLod
{
    class PackageWriter;

    struct FoliageLodOptions
    {
        std::uint32_t clusterSize = 64; ///< leaves per independent cluster (1 .. 4096)
        /// Bands of Changed_group (1..64); 0 = the paper's pure global cost order (every
        /// change then touches most clusters). 1 = cluster by cluster.
        std::uint32_t costBands = 4;
        /// Leaves in several planes collapse part with part (step 3): crossed quads through one
        /// centre, and the planes of a leaf that is one mesh (a folded leaf, a sprig in one
        /// piece), each plane then an original of its own. False: every leaf is one original and
        /// collapses into one flat quad, as the paper's (the baseline of techniques/lodf/README.md).
        bool crossedLeaves = true;
    };

    /// Build F^r for `model` (validated first). Errors name `label`. A tree without leaves
    /// gives empty data (no clusters).
    Result<FoliageLodData> buildFoliageLod(const TreeModel& model, const FoliageLodOptions& options = {},
                                           const std::string& label = "", const ProgressCallback& progress = {});

    /// The polygonal foliage of `model` with `leafCount` leaves: the leaves of that LoDF state
    /// as a TreeModel (same bark, vertices, materials), for the CPU renderer and for
    /// discrete-level baselines.
    TreeModel foliageLodModel(const TreeModel& model, const FoliageLodData& data, std::uint32_t leafCount);

    /// Add the "lodf" chunk of `model` to `writer`, and its "reference" chunk (whose vertices
    /// it indexes) unless the writer has it.
    Result<void> addFoliageLodChunk(PackageWriter& writer, const TreeModel& model, const std::string& label,
                                    const ProgressCallback& progress = {});
    Result<void> addFoliageLodChunk(PackageWriter& writer, const TreeModel& model, const FoliageLodOptions& options,
                                    const std::string& label, const ProgressCallback& progress = {});
}
