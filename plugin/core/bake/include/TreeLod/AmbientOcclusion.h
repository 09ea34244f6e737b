// AmbientOcclusion: per-vertex ambient occlusion of a TreeModel by ray casting (Embree).
//
// García et al. 2007 §5.2 ("Multi-layered indirect texturing for tree rendering") and the
// ellipsoids-and-lines paper §5 ("a level of detail method for trees based on ellipsoids and
// lines") both add a precomputed AO term, per vertex of the original polygonal tree, to the ambient
// light; the latter computes it "by path tracing random directions in the surface normal hemisphere
// until the ray leaves the model". This file casts exactly those rays:
//   ao(p) = fraction of cosine-weighted directions around n(p) whose ray, started at p offset
//           along n by epsilon, hits nothing within maxDistance.
// Cosine-weighted sampling makes the plain fraction the cosine-weighted visibility, the
// quantity a Lambert ambient term needs. Bark occludes from both sides; leaves occlude where
// their texture passes the alpha test (the same test as ReferenceRenderer).
//
// Leaves are thin and lit from both sides (LightingSpec), so a leaf corner casts half its rays
// into each hemisphere (around +n and -n) and stores the mean of the two visibilities.
//
// Deterministic: the directions of point i depend only on (seed, i): a stratified low-discrepancy
// set (Fibonacci lattice over the cosine-weighted disc) with a per-point random rotation and
// shift from a hash of (seed, i). No shared RNG, so results do not depend on thread count.
// Epsilons are relative to the model's bounding-box diagonal, so a 0.5 m and a 500 m tree get
// the same values.
#pragma once

#include "TreeLod/Progress.h"
#include "TreeLod/TreeModel.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

namespace TreeLod
{
    struct AoOptions
    {
        int raysPerPoint = 64;  ///< >= 1; leaves split them between both hemispheres
        float maxDistance = 0.0f; ///< metres a ray may travel; <= 0: 0.5 * bounding-box diagonal
        std::uint32_t seed = 1;
    };

    /// AO of a whole TreeModel, 1 = unoccluded, 0 = fully occluded.
    struct AmbientOcclusion
    {
        std::vector<float> barkVertex; ///< one per TreeModel::barkVertices
        std::vector<float> leafVertex; ///< one per TreeModel::leafVertices (leaf corners)
    };

    /// A point at which to measure AO against a model (e.g. a point on a LoD primitive).
    struct AoPoint
    {
        glm::vec3 position{0.0f};
        glm::vec3 normal{0.0f, 1.0f, 0.0f}; ///< need not be unit; zero or not finite: +Y, two-sided
        bool twoSided = false;              ///< true: mean of both hemispheres (as for leaves)
    };

    /// AO at every bark vertex (around its normal; vertices whose normal is zero or not finite
    /// use the mean face normal of their triangles) and every leaf vertex (two-sided). Vertices
    /// used by no triangle and non-finite positions get 1. Calls `progress` ("ambient occlusion", 0..1) from the calling
    /// thread. Precondition: model.validate() succeeds (out-of-range indices are skipped).
    AmbientOcclusion computeAmbientOcclusion(const TreeModel& model, const AoOptions& options = {},
                                             const ProgressCallback& progress = {});

    /// AO at arbitrary points against `model`: one value in [0, 1] per point, same rules and
    /// epsilons as computeAmbientOcclusion (point i is seeded by (seed, i)).
    std::vector<float> computeAmbientOcclusionAt(const TreeModel& model, const std::vector<AoPoint>& points,
                                                 const AoOptions& options = {},
                                                 const ProgressCallback& progress = {});
}
