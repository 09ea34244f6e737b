// BillboardClustering: the leaf clustering of García et al. 2007 §4.1, k-means-like on leaf planes
// with an error bound, in the spirit of [BCF*05] (Behrendt et al., "Realistic real-time rendering
// of landscapes using billboard clouds", 2005) and [GSSK05] (García et al., "Leaf cluster impostors
// for tree rendering with parallax", 2005). Private to the baker (BillboardCloudBaker.cpp).
//
// A cluster is a plane (unit normal n, offset d: n.p = d) and a centroid g. The plane error of a
// leaf to a cluster is the largest distance of its vertices to the plane (planes are unoriented:
// a leaf and its flipped copy fit equally). Each iteration
//   1. assigns every leaf to the cluster of least cost
//          e + spatialWeight |centre - g| + orientationWeight length (1 - |n_leaf . n|)
//      among the clusters whose plane error e is within the bound; a leaf that no plane holds
//      within the bound goes to the plane of least error (it counts in the reported maximum);
//   2. re-seeds empty clusters with the worst-fitting leaves (their own plane and centre);
//   3. refits every plane by area-weighted least squares: the smallest eigenvector of the
//      covariance of its leaves' vertices (weight = leaf area / vertex count) minus
//      orientationWeight x the leaves' normal scatter (sum of area length^2 n_leaf n_leaf^T),
//      and every centroid (area-weighted mean of the leaf centres);
// until no assignment changes or after maxIterations. Seeds: farthest-point sampling of the leaf
// centres, starting from the leaf farthest from their mean. (length = the leaf's diameter.)
//
// Deviations from a plain plane k-means (techniques/billboard-cloud/README.md), both measured on generated oaks against the
// reference renderer (BillboardCloudBakerTest):
//   - the spatial term: plane error alone lets one plane collect leaves from both sides of the
//     crown wherever it cuts through it, which gives billboards as large as the tree with sparse
//     hash grids and low-res images (memory grows with billboard area); the term keeps each
//     cluster a compact patch, as the billboards of Fig. 1;
//   - the orientation term: a leaf seen edge-on from its billboard is drawn as a sliver, so
//     the cloud lost a quarter of the foliage's coverage from oblique views (coverage ratio 0.75
//     at 20k leaves); grouping leaves that face their plane brings it to 0.95.
//
// The assignment visits only the clusters that can win: a cluster's cost is at least
// spatialWeight x the distance to its centroid, so the centroids are put in a grid and a leaf
// looks at the cells around it, nearest shells first, its previous cluster before them, until no
// cell is within its best cost (the same choice as a scan of every cluster, which spatialWeight 0
// still does).
//
// Deterministic for any thread count: per-leaf work in parallel, reductions per cluster in leaf
// order, ties to the lower index.
#pragma once

#include "TreeLod/TreeModel.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

namespace TreeLod
{
    struct LeafClusteringOptions
    {
        std::uint32_t clusterCount = 1; ///< >= 1, at most the leaf count
        float errorBound = 0.0f;        ///< metres: largest plane error a leaf should have
        float spatialWeight = 0.5f;     ///< metres of plane error per metre from the centroid
        /// Leaf lengths of cost for a leaf perpendicular to the plane (x (1 - |n_leaf . n|)), and
        /// the weight of the leaves' normal scatter in the refit.
        float orientationWeight = 4.0f;
        std::uint32_t maxIterations = 20;
    };

    struct LeafClustering
    {
        std::vector<glm::vec3> normal;                   ///< per cluster, unit (sign arbitrary)
        std::vector<float> offset;                       ///< per cluster: plane dot(normal, p) = offset, world metres
        std::vector<glm::vec3> centroid;                 ///< per cluster, world
        std::vector<float> error;                        ///< per leaf: plane error to its cluster's final plane
        std::vector<std::vector<std::uint32_t>> members; ///< per cluster, increasing leaf index
    };

    /// Cluster all leaves of `model` (validated, at least one leaf).
    LeafClustering clusterLeaves(const TreeModel& model, const LeafClusteringOptions& options);

    /// The area of the clustering's billboards: per cluster, the rectangle on its plane, along the
    /// 2D principal axes of its leaves' vertices, that bounds them (the baker's quads, before
    /// padding to whole hash cells). Hash and low-res texels grow with it.
    double billboardArea(const TreeModel& model, const LeafClustering& clustering);

    /// `model` with every leaf flattened onto its cluster's plane (each vertex moved along the
    /// plane normal; normals, UVs and materials kept). That is what a cloud shows of its leaves:
    /// a leaf's Leaves Texture tile is its orthographic projection onto the billboard (García et
    /// al. 2007 §3), so from a view where the billboard is seen edge-on the leaf is a sliver.
    TreeModel flattenedOntoClusters(const TreeModel& model, const LeafClustering& clustering);

    /// Judges clusterings by image error, not by plane fit alone: the flattened leaves
    /// (flattenedOntoClusters) against the leaves in place, both ray traced (ReferenceRenderer,
    /// bark included) from views around and above the tree; FLIP (mean) over the square around the
    /// tree in each view (TreeViews.h), averaged over the views and sizes. The reference views are traced
    /// once, here.
    class ClusteringJudge
    {
    public:
        struct Options
        {
            /// (azimuth, elevation) in degrees: around the tree, obliquely, and from above.
            std::vector<glm::vec2> views{{0.0f, 10.0f}, {120.0f, 10.0f}, {240.0f, 10.0f}, {60.0f, 45.0f}, {30.0f, 80.0f}};
            /// Image sizes in pixels (the bounding sphere fills the view). 160: where the planes show;
            /// adding 40 (the silhouette far away) changed the corpus study by noise only.
            std::vector<int> sizes{160};
            int supersample = 2;  ///< per axis
        };

        /// `model` (with at least one leaf, inside the box [lo, hi]) must outlive the judge.
        ClusteringJudge(const TreeModel& model, const glm::vec3& lo, const glm::vec3& hi, const Options& options);
        ~ClusteringJudge();
        ClusteringJudge(const ClusteringJudge&) = delete;
        ClusteringJudge& operator=(const ClusteringJudge&) = delete;

        /// Mean FLIP of the clustering's flattened leaves over the views and sizes; in [0, 1].
        double error(const LeafClustering& clustering) const;

    private:
        struct View;
        const TreeModel& mModel;
        Options mOptions;
        std::vector<View> mViews;
    };
}
