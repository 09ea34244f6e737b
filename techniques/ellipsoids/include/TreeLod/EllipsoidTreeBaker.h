// EllipsoidTreeBaker: TreeModel -> EllipsoidTreeData (EllipsoidTreeData.h): the leaf half of
// the ellipsoids-and-lines paper (001), §3.1 and Alg. 1, with §4's image error and §6's
// per-level target size and the noise's calibration. Branches (the lines of §3.2) are
// EllipsoidLineBaker.h; ambient occlusion is addEllipsoidAmbientOcclusion below.
//
//   1. Leaves -> one ellipsoid each (§3.1): the mean and covariance of points spread uniformly
//      over the leaf's triangles, PCA (eigenvectors = axes, semi-axis = 2 sqrt(eigenvalue)); the
//      smallest semi-axes are floored at 2 % of the largest, so a flat leaf is a thin disc.
//   2. Levels (Alg. 1): K = floor(|L| / clustersDivisor), then / clustersDivisor per level while
//      K >= 1. Per level, `tries` runs of EM/GMM (GaussianMixture.h) over the leaf centres (one
//      run where K > triedClusters, see below), weighted by leaf area, from random starts in the box of the
//      centres; each component's
//      ellipsoid is the weighted PCA of its leaves' points with the fuzzy memberships w_ij as
//      weights (Fig. 5): covariance = sum_i w_ij a_i (S_i + (c_i - m_j)(c_i - m_j)^T) / sum_i w_ij a_i,
//      so a cluster covers its leaves' extent, not only the spread of their centres. Ellipsoids
//      whose surface area is under minAreaShare of the level's largest are dropped. Each try is
//      rendered and scored by image error against the leaves; the best is kept.
//   3. Calibration (§3.1, as [CP10]): each level's scale factor is the one of 0.6, 0.8, ... 1.4
//      (the grid extended by 0.2 while the best is at an end, within [0.2, 3]; then +-0.1 around
//      the best) with the least image error.
//   4. Image error (§4): multi-scale RMSE (ImageMetrics.h), mean over 4 orthographic views (three
//      around at 15 degrees elevation, one from above) of viewResolution^2 pixels, 2x2 samples,
//      the leaves rendered by the CPU ReferenceRenderer in one flat colour (their textures' alpha
//      kept, colour dropped), the ellipsoids ray cast in the same colour as the renderer draws
//      them (renderEllipsoids), so the error measures coverage only.
//   4b. Noise (§3.1, Fig. 6; EllipsoidNoise.h), with `noise`: per level, the alpha threshold
//      t of 0, 0.25, 0.4, 0.5, 0.6 and the area compensation on the calibrated scale (1 to 1.7;
//      1 for t = 0) with the least coverage error, then the normal blend of 0 to 0.7 with the
//      least error in shaded views (white surfaces under the default sun and sky), the holes, the
//      far side through them and the noise's lod (at the footprint of the level's target size) as
//      the renderer draws them; the level's imageError is then this error.
//   5. Target size (§6): targetHeightPx = the tree's height in pixels at which the level's mean
//      ellipsoid (the diameter of the disc with its mean projected area) is
//      ELLIPSOID_TARGET_DIAMETER_PX pixels across.
//
// Deviations from the paper, and why:
//   - The "uniform sampling" of a leaf is done in closed form: the exact mean and covariance of a
//     uniform distribution over its triangles (the limit of infinitely many samples): no sampling
//     noise, no seed needed, and O(triangles).
//   - The EM input carries each leaf's covariance and is truncated to the 12 nearest components
//     per point, searched every 8 iterations (GaussianMixture.h): the paper needs 0.9 s per leaf,
//     a 20k-leaf tree must bake in seconds here.
//   - One EM run instead of t on levels of more than triedClusters (12) clusters (Alg. 1 runs t
//     on every level):
//     there the runs' image errors differ little and the best of 4 did not pay for its time
//     (techniques/ellipsoids/README.md); the tries stay where the clusters are few.
//   - Every level clusters the leaves (as Alg. 1), but a last level of one ellipsoid is added when
//     the division stops above one (fewer than clustersDivisor^2 leaves, e.g. 2 or 3 leaves).
//   - Leaves of zero area are left out (they cannot be seen).
//   - The image error compares flat-colour coverage images instead of shaded ones (the leaves'
//     colours are the ellipsoids' means); only the normal blend is chosen on shaded images.
//   - The noise's mip level l_j is the paper's, but its footprint limit is taken once per
//     ellipsoid at its centre, not per fragment from fwidth: the CPU twin and the GPU then agree
//     exactly, and the ray caster has no derivatives of its own to take.
//   - Where the alpha test opens a hole in the near side, the far side is tested and drawn (the
//     paper does not say): a hole in a closed surface shows its inside.
// Every length is relative to the leaves' bounding box (a 0.5 m and a 500 m tree give the same
// result up to rounding). Deterministic for a seed and any TBB thread count.
#pragma once

#include "TreeLod/EllipsoidTreeData.h"
#include "TreeLod/Image.h"
#include "TreeLod/PackageWriter.h"
#include "TreeLod/Progress.h"
#include "TreeLod/ReferenceRenderer.h"
#include "TreeLod/Result.h"
#include "TreeLod/TreeModel.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <string>

namespace TreeLod
{
    struct EllipsoidTreeOptions
    {
        std::uint32_t tries = 4;           ///< EM runs per level of at most triedClusters clusters, 1 to 16 (the paper's t)
        std::uint32_t triedClusters = 12;  ///< >= 1: larger levels get one EM run
        std::uint64_t seed = 1;            ///< of the EM starts
        std::uint32_t clustersDivisor = 4; ///< 2 to 64: each level has 1 / this of the previous' target
        float minAreaShare = 0.01f;        ///< in [0, 0.5]: smaller ellipsoids (surface area) dropped
        int viewResolution = 128;          ///< pixels a side of each error view, 16 to 1024
        /// Rays per point of the ellipsoids' ambient occlusion (§5), 0 to 1024; 0: none (the
        /// polygonal reference's leaves have none, techniques/ellipsoids/README.md "Ambient occlusion").
        std::uint32_t aoRays = 0;
        /// Calibrate each level's noise (§3.1, Fig. 6; EllipsoidNoise.h); false: none (every
        /// level's threshold and blend 0).
        bool noise = true;
    };

    /// The moments of leaf `leaf`'s triangles as a uniform area distribution (metres).
    struct LeafShape
    {
        glm::dvec3 mean{0.0};
        glm::dmat3 covariance{0.0};
        double area = 0.0;
    };
    LeafShape leafShape(const TreeModel& model, std::size_t leaf);

    /// The ellipsoid of a distribution (PCA): semi-axes 2 sqrt(eigenvalue), largest first along the
    /// rotation's local x, the others at least `minAxisShare` of the largest (and > 0 always).
    Ellipsoid ellipsoidFromCovariance(const glm::dvec3& mean, const glm::dmat3& covariance, float minAxisShare = 0.02f);

    /// Approximate surface area of an ellipsoid with semi-axes `radii` (Knud Thomsen's formula,
    /// within about 1 %).
    double ellipsoidSurfaceArea(const glm::dvec3& radii);

    /// The ellipsoids of level `level` of `data` (scaled by the level's scale times `extraScale`) as
    /// opaque, double-sided bark of one white material: icospheres of 80 triangles with the
    /// sphere's surface area, for the CPU reference renderer (tests measure coverage with it).
    TreeModel ellipsoidLevelMesh(const EllipsoidTreeData& data, std::size_t level, float extraScale = 1.0f);

    /// The noise an ellipsoid level is drawn with (EllipsoidLevel, EllipsoidNoise.h).
    struct EllipsoidNoiseSetting
    {
        float threshold = 0.0f;   ///< alpha test: 0 = no holes
        float normalBlend = 0.0f; ///< 0 = the ellipsoid's own normal
        /// Size of a pixel (metres) at the ellipsoids for the footprint's lod; 0: the clusters'
        /// own lod only.
        float pixelSize = 0.0f;
    };

    /// The radius the noise's footprint lod uses: the geometric mean of the two largest semi-axes.
    float ellipsoidNoiseRadius(const glm::vec3& scaledRadii);

    /// `ellipsoids` (radii times `scale`) ray cast as TreeLodEllipsoid.frag draws them, in white:
    /// the nearest surface point of any ellipsoid that passes the noise's alpha test (the near
    /// side, else the far side seen through the hole), lit with RenderOptions::lighting (ambient +
    /// sun * max(0, n.l), the normal blended with the noise and facing the camera), supersampled
    /// and written as ReferenceRenderer's colour image (sRGB, background opaque). Orthographic or
    /// perspective; deterministic; single-threaded (callers parallelise over views).
    Image renderEllipsoids(const std::vector<Ellipsoid>& ellipsoids, float scale, const EllipsoidNoiseSetting& noise,
                           const CameraSpec& camera, const RenderOptions& options);

    /// `model`'s leaves alone, every material white (base colour and texture colour; the
    /// textures' alpha and the alpha cutoffs kept): the reference the baker measures against.
    TreeModel flatColourLeaves(const TreeModel& model);

    /// Bake the ellipsoid hierarchy. Errors name `label`: invalid options or model, a model without
    /// leaves of nonzero area, or leaves with no extent. Progress steps: "ellipsoids: leaves",
    /// "ellipsoids: level N of M".
    Result<EllipsoidTreeData> bakeEllipsoidTree(const TreeModel& model, const EllipsoidTreeOptions& options,
                                                const std::string& label, const ProgressCallback& progress = {});

    /// Ambient occlusion (paper 001 §5) into every ellipsoid's colour alpha (255 = unoccluded):
    /// the mean, over points on its surface outside the other ellipsoids of its level, of the
    /// cosine-weighted visibility (AmbientOcclusion.h, `rays` rays a point) past the level's
    /// ellipsoids and `model`'s bark. Deterministic for a seed and any thread count.
    void addEllipsoidAmbientOcclusion(EllipsoidTreeData& data, const TreeModel& model, std::uint32_t rays,
                                      std::uint64_t seed, const ProgressCallback& progress = {});

    /// Package glue for `treelod bake` (BakeTechniques): adds the reference chunk when missing and
    /// the "ellipsoids" chunk.
    Result<void> addEllipsoidTreeChunk(PackageWriter& writer, const TreeModel& model,
                                       const EllipsoidTreeOptions& options, const std::string& label,
                                       const ProgressCallback& progress = {});
}
