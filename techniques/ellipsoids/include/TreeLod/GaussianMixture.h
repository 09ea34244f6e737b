// GaussianMixture: Expectation-Maximization for a Gaussian mixture over weighted 3D points, the
// clustering step of the ellipsoids-and-lines paper (001), §3.1 / Alg. 1 (FindEMClusterWeights),
// after Dempster, Laird and Rubin, "Maximum likelihood from incomplete data via the EM algorithm"
// (1977).
//
// Input: points x_i with weights a_i > 0 (a leaf's area) and optional spreads S_i (a leaf's own
// covariance: the point stands for a small distribution, not a single position).
// E-step: log-domain responsibilities, r_ic = exp(log pi_c + log N(x_i | mu_c, C_c) - LSE_i), with
//   LSE_i the log-sum-exp over the point's candidate components.
// M-step: N_c = sum_i a_i r_ic, mu_c = sum_i a_i r_ic x_i / N_c,
//   C_c = sum_i a_i r_ic ((x_i - mu_c)(x_i - mu_c)^T + S_i) / N_c + covarianceFloor * I, pi_c = N_c / sum a.
// Stops when the weighted mean log-likelihood changes by at most `tolerance` (relative, at least
// absolute) or after maxIterations.
//
// Deviations from the textbook algorithm, and why:
//   - Truncated E-step: a point is only given to its `candidates` nearest components (by distance
//     to the means, a k-d tree); the rest get responsibility 0. Exact when K <= candidates; for
//     thousands of clusters it makes an iteration O(N log K) instead of O(N K) (the paper spends
//     0.9 s per leaf; we need a 24k-leaf tree in a minute). The candidates are searched every
//     candidateRefresh iterations (and after a re-seed); in between, EM runs on fixed candidate
//     sets, which still never lowers the likelihood.
//   - S_i in the covariance (see above) and a covariance floor: clusters of coplanar or colinear
//     leaves are normal in trees and must not make C_c singular.
//   - A component that holds (nearly) no weight, or sits on the same mean as an earlier one (all
//     starts at one point), is re-seeded at the worst-explained point: the one farthest from
//     every kept mean and every earlier re-seed of the round (farthest-point seeding, so that
//     re-seeds spread out), at most maxReseedRounds rounds.
// Deterministic for given inputs and any TBB thread count: the E-step is per point; the M-step
// is per component, each component's sums taken over its points in point order.
#pragma once

#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

namespace TreeLod
{
    struct GaussianMixtureOptions
    {
        std::uint32_t maxIterations = 100;
        double tolerance = 1e-5;           ///< on the weighted mean log-likelihood per point
        std::uint32_t candidates = 12;     ///< components considered per point (>= 1)
        /// Iterations between searches for each point's nearest components (>= 1; 1: every
        /// iteration). In between the points keep their candidates.
        std::uint32_t candidateRefresh = 1;
        double covarianceFloor = 1e-6;     ///< added to every covariance's diagonal, > 0 (units^2)
        double initialVariance = 1e-2;     ///< isotropic covariance of a start or re-seeded component
        std::uint32_t maxReseedRounds = 10;
    };

    struct GaussianMixtureInput
    {
        std::vector<glm::dvec3> points;
        std::vector<double> weights;       ///< per point, > 0; empty = all 1
        std::vector<glm::dmat3> spreads;   ///< per point; empty = none
    };

    struct GaussianMixtureResult
    {
        std::vector<glm::dvec3> means;
        std::vector<glm::dmat3> covariances;
        std::vector<double> mixing;        ///< pi_c, sum 1
        std::vector<double> mass;          ///< N_c: the weight each component holds
        /// Sparse responsibilities: point i's are entries [offsets[i], offsets[i + 1]) of
        /// `component` and `responsibility` (sum 1 per point, components ascending).
        std::vector<std::uint32_t> offsets;
        std::vector<std::uint32_t> component;
        std::vector<double> responsibility;
        double logLikelihood = 0.0;        ///< weighted mean over points
        std::uint32_t iterations = 0;
        std::uint32_t reseeds = 0;         ///< components re-seeded in all
        bool converged = false;
    };

    /// EM from `initialMeans` (one per component, K >= 1; the count of points must be >= 1).
    GaussianMixtureResult fitGaussianMixture(const GaussianMixtureInput& input,
                                             const std::vector<glm::dvec3>& initialMeans,
                                             const GaussianMixtureOptions& options = {});
}
