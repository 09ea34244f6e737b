// GaussianMixture: EM for a Gaussian mixture (the algorithm and its deviations in GaussianMixture.h).
#include "TreeLod/GaussianMixture.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <tuple>
#include <utility>

namespace TreeLod
{
    namespace
    {
        constexpr double LOG_2PI = 1.8378770664093454835606594728112;
        constexpr std::uint32_t LEAF_SIZE = 8;

        /// A static k-d tree over the component means, for the truncated E-step: the `k` nearest
        /// means of a point, ties by index, so the set does not depend on the traversal. A subtree
        /// is skipped when the distance from the query to its cell (Arya and Mount's incremental
        /// distance: the per-axis offsets to the cells on the way down) exceeds the k-th nearest
        /// so far; the points are stored in leaf order.
        class KdTree
        {
        public:
            explicit KdTree(const std::vector<glm::dvec3>& points) : mOrder(points.size())
            {
                std::iota(mOrder.begin(), mOrder.end(), 0u);
                mNodes.reserve(2 * points.size() / LEAF_SIZE + 2);
                build(points, 0, std::uint32_t(points.size()));
                mSorted.reserve(points.size());
                for (std::uint32_t i : mOrder)
                    mSorted.push_back(points[i]);
            }

            /// The k nearest (squared distance, index), ascending, into `out` (resized to k).
            void nearest(const glm::dvec3& q, std::uint32_t k, std::vector<std::pair<double, std::uint32_t>>& out) const
            {
                out.clear();
                visit(0, q, k, glm::dvec3(0.0), out);
            }

        private:
            struct Node
            {
                std::uint32_t lo = 0, hi = 0;
                std::int32_t left = -1, right = -1; ///< -1: a leaf holding mOrder[lo, hi)
                int axis = 0;
                double split = 0.0;
            };

            std::int32_t build(const std::vector<glm::dvec3>& points, std::uint32_t lo, std::uint32_t hi)
            {
                const std::int32_t id = std::int32_t(mNodes.size());
                mNodes.push_back(Node{lo, hi});
                if (hi - lo <= LEAF_SIZE)
                    return id;
                glm::dvec3 mn(std::numeric_limits<double>::max()), mx(-std::numeric_limits<double>::max());
                for (std::uint32_t i = lo; i < hi; ++i)
                {
                    mn = glm::min(mn, points[mOrder[i]]);
                    mx = glm::max(mx, points[mOrder[i]]);
                }
                const glm::dvec3 extent = mx - mn;
                const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
                const std::uint32_t mid = (lo + hi) / 2;
                std::nth_element(mOrder.begin() + lo, mOrder.begin() + mid, mOrder.begin() + hi,
                                 [&](std::uint32_t a, std::uint32_t b) {
                                     return std::make_pair(points[a][axis], a) < std::make_pair(points[b][axis], b);
                                 });
                // The median's coordinate, read before the children's builds reorder their ranges.
                const double split = points[mOrder[mid]][axis];
                const std::int32_t left = build(points, lo, mid);
                const std::int32_t right = build(points, mid, hi);
                mNodes[std::size_t(id)].left = left;
                mNodes[std::size_t(id)].right = right;
                mNodes[std::size_t(id)].axis = axis;
                mNodes[std::size_t(id)].split = split;
                return id;
            }

            /// `offset`: per axis, the distance from `q` to node `id`'s cell (0 where q is inside it).
            void visit(std::int32_t id, const glm::dvec3& q, std::uint32_t k, const glm::dvec3& offset,
                       std::vector<std::pair<double, std::uint32_t>>& out) const
            {
                const Node& n = mNodes[std::size_t(id)];
                if (n.left < 0)
                {
                    for (std::uint32_t i = n.lo; i < n.hi; ++i)
                    {
                        const glm::dvec3 d = mSorted[i] - q;
                        const std::pair<double, std::uint32_t> c(glm::dot(d, d), mOrder[i]);
                        if (out.size() < k)
                            out.push_back(c);
                        else if (c < out.back())
                            out.back() = c;
                        else
                            continue;
                        for (std::size_t m = out.size() - 1; m > 0 && c < out[m - 1]; --m)
                            std::swap(out[m], out[m - 1]);
                    }
                    return;
                }
                // The left cell's coordinates on the axis are <= split, the right one's >= split.
                const double diff = q[n.axis] - n.split;
                visit(diff < 0.0 ? n.left : n.right, q, k, offset, out);
                glm::dvec3 farOffset = offset;
                farOffset[n.axis] = diff;
                // A lower bound of every distance computed in the far cell (rounding is monotone);
                // shrunk by 1e-9 so that no contraction of the arithmetic can lift it above one.
                const double farDistance = glm::dot(farOffset, farOffset) * (1.0 - 1e-9);
                if (out.size() < k || farDistance <= out.back().first)
                    visit(diff < 0.0 ? n.right : n.left, q, k, farOffset, out);
            }

            std::vector<std::uint32_t> mOrder;
            std::vector<glm::dvec3> mSorted; ///< the points in mOrder's order
            std::vector<Node> mNodes;
        };

        struct Component
        {
            glm::dmat3 precision{1.0};
            double logNorm = 0.0; ///< log pi - 0.5 (log det C + 3 log 2 pi)
        };

        /// The sparse responsibilities' entries grouped by component (a counting sort), each
        /// group in point order, with each entry's point.
        struct EntriesByComponent
        {
            std::vector<std::uint32_t> start;   ///< K + 1
            std::vector<std::uint32_t> entries; ///< indices into component / responsibility
            std::vector<std::uint32_t> point;   ///< per grouped entry, its point

            EntriesByComponent(const std::vector<std::uint32_t>& offsets, const std::vector<std::uint32_t>& component,
                               std::size_t k)
                : start(k + 1, 0), entries(component.size()), point(component.size())
            {
                for (std::uint32_t j : component)
                    ++start[j + 1];
                for (std::size_t j = 0; j < k; ++j)
                    start[j + 1] += start[j];
                std::vector<std::uint32_t> next(start.begin(), start.end() - 1);
                for (std::size_t i = 0; i + 1 < offsets.size(); ++i)
                    for (std::uint32_t e = offsets[i]; e < offsets[i + 1]; ++e)
                    {
                        const std::uint32_t m = next[component[e]]++;
                        entries[m] = e;
                        point[m] = std::uint32_t(i);
                    }
            }
        };
    }

    GaussianMixtureResult fitGaussianMixture(const GaussianMixtureInput& input,
                                             const std::vector<glm::dvec3>& initialMeans,
                                             const GaussianMixtureOptions& options)
    {
        const std::size_t n = input.points.size();
        const std::size_t k = initialMeans.size();
        const double floor = std::max(options.covarianceFloor, 1e-300);
        const glm::dmat3 startCovariance = glm::dmat3(std::max(options.initialVariance, 0.0) + floor);
        const std::uint32_t c = std::uint32_t(std::min<std::size_t>(std::max(options.candidates, 1u), k));

        GaussianMixtureResult out;
        out.means = initialMeans;
        out.covariances.assign(k, startCovariance);
        out.mixing.assign(k, k ? 1.0 / double(k) : 0.0);
        out.mass.assign(k, 0.0);
        out.offsets.resize(n + 1);
        for (std::size_t i = 0; i <= n; ++i)
            out.offsets[i] = std::uint32_t(i * c);
        out.component.assign(n * c, 0);
        out.responsibility.assign(n * c, 0.0);
        if (n == 0 || k == 0)
            return out;

        std::vector<double> weights(n, 1.0);
        if (input.weights.size() == n)
            for (std::size_t i = 0; i < n; ++i)
                weights[i] = std::isfinite(input.weights[i]) && input.weights[i] > 0.0 ? input.weights[i] : 0.0;
        const double totalWeight = std::accumulate(weights.begin(), weights.end(), 0.0);
        const double emptyMass = 1e-3 * totalWeight / double(n);
        const bool hasSpreads = input.spreads.size() == n;

        std::vector<double> pointLogLikelihood(n, 0.0);
        std::vector<Component> components(k);
        double previous = 0.0;
        bool reseededLast = false;
        std::uint32_t reseedRounds = 0;

        for (std::uint32_t it = 0; it < std::max(options.maxIterations, 1u); ++it)
        {
            // Per component: precision and normalisation (C is symmetric positive definite: floor > 0).
            for (std::size_t j = 0; j < k; ++j)
            {
                const double det = glm::determinant(out.covariances[j]);
                components[j].precision = glm::inverse(out.covariances[j]);
                components[j].logNorm =
                    std::log(std::max(out.mixing[j], 1e-300)) - 0.5 * (std::log(std::max(det, 1e-300)) + 3.0 * LOG_2PI);
            }

            // E-step, per point (parallel; each point writes only its own entries).
            // The nearest components: on the first iteration, after a re-seed and every
            // candidateRefresh iterations; otherwise the points keep the previous ones.
            const bool search = c < k && (it == 0 || reseededLast || it % std::max(options.candidateRefresh, 1u) == 0);
            const KdTree tree(search ? out.means : std::vector<glm::dvec3>{});
            tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 256), [&](const tbb::blocked_range<std::size_t>& range) {
                std::vector<std::pair<double, std::uint32_t>> near;
                std::vector<double> logP(c);
                for (std::size_t i = range.begin(); i != range.end(); ++i)
                {
                    const glm::dvec3& x = input.points[i];
                    std::uint32_t* comp = out.component.data() + out.offsets[i];
                    if (c == k)
                        std::iota(comp, comp + c, 0u);
                    else if (search)
                    {
                        tree.nearest(x, c, near);
                        for (std::uint32_t m = 0; m < c; ++m)
                            comp[m] = near[m].second;
                        std::sort(comp, comp + c);
                    }
                    for (std::uint32_t m = 0; m < c; ++m)
                    {
                        const glm::dvec3 d = x - out.means[comp[m]];
                        logP[m] = components[comp[m]].logNorm - 0.5 * glm::dot(d, components[comp[m]].precision * d);
                    }
                    // LSE = top + log sum exp(logP - top); r = exp(logP - top) / that sum.
                    double top = -std::numeric_limits<double>::infinity();
                    for (std::uint32_t m = 0; m < c; ++m)
                        top = std::max(top, logP[m]);
                    double* r = out.responsibility.data() + out.offsets[i];
                    double sum = 0.0;
                    if (std::isfinite(top))
                        for (std::uint32_t m = 0; m < c; ++m)
                            sum += (r[m] = std::exp(logP[m] - top));
                    const double lse = std::isfinite(top) ? top + std::log(sum) : top;
                    if (std::isfinite(lse))
                        for (std::uint32_t m = 0; m < c; ++m)
                            r[m] /= sum;
                    else // unreachable with finite inputs; keep the point whole on its nearest candidate
                        for (std::uint32_t m = 0; m < c; ++m)
                            r[m] = m == 0 ? 1.0 : 0.0;
                    pointLogLikelihood[i] = std::isfinite(lse) ? lse : -1e300;
                }
            });
            double logLikelihood = 0.0; // serial, in point order
            for (std::size_t i = 0; i < n; ++i)
                logLikelihood += weights[i] * pointLogLikelihood[i];
            logLikelihood /= std::max(totalWeight, 1e-300);
            out.logLikelihood = logLikelihood;
            out.iterations = it + 1;
            if (it > 0 && !reseededLast &&
                std::abs(logLikelihood - previous) <= options.tolerance * std::max(1.0, std::abs(logLikelihood)))
            {
                out.converged = true;
                break;
            }
            previous = logLikelihood;
            if (it + 1 >= options.maxIterations)
                break; // the responsibilities stay those of the parameters returned

            // M-step, per component in parallel; each component's sums run over its entries in
            // point order, as a serial pass over the points would add them (the same bits for any
            // thread count).
            const EntriesByComponent byComponent(out.offsets, out.component, k);
            tbb::parallel_for(tbb::blocked_range<std::size_t>(0, k, 64), [&](const tbb::blocked_range<std::size_t>& range) {
                for (std::size_t j = range.begin(); j != range.end(); ++j)
                {
                    double mass = 0.0;
                    glm::dvec3 sum(0.0);
                    for (std::uint32_t m = byComponent.start[j]; m < byComponent.start[j + 1]; ++m)
                    {
                        const std::uint32_t e = byComponent.entries[m];
                        const double w = weights[byComponent.point[m]] * out.responsibility[e];
                        mass += w;
                        sum += w * input.points[byComponent.point[m]];
                    }
                    out.mass[j] = mass;
                    if (mass > 0.0)
                        out.means[j] = sum / mass;
                    glm::dmat3 scatter(0.0);
                    for (std::uint32_t m = byComponent.start[j]; m < byComponent.start[j + 1]; ++m)
                    {
                        const std::uint32_t e = byComponent.entries[m], i = byComponent.point[m];
                        const double w = weights[i] * out.responsibility[e];
                        const glm::dvec3 d = input.points[i] - out.means[j];
                        scatter += w * glm::outerProduct(d, d);
                        if (hasSpreads)
                            scatter += w * input.spreads[i];
                    }
                    if (mass > 0.0)
                        out.covariances[j] = scatter / mass + glm::dmat3(floor);
                    out.mixing[j] = mass / std::max(totalWeight, 1e-300);
                }
            });

            // Re-seed empty components and ones on an earlier component's mean.
            reseededLast = false;
            if (reseedRounds >= options.maxReseedRounds)
                continue;
            std::vector<std::uint8_t> reseed(k, 0);
            for (std::size_t j = 0; j < k; ++j)
                reseed[j] = out.mass[j] < emptyMass;
            {
                const double cell = 1e-3 * std::sqrt(floor);
                using Key = std::tuple<long long, long long, long long, std::uint32_t>;
                std::vector<Key> keys(k);
                for (std::size_t j = 0; j < k; ++j)
                    keys[j] = Key(std::llround(out.means[j].x / cell), std::llround(out.means[j].y / cell),
                                  std::llround(out.means[j].z / cell), std::uint32_t(j));
                std::sort(keys.begin(), keys.end());
                for (std::size_t m = 1; m < k; ++m)
                    if (std::get<0>(keys[m]) == std::get<0>(keys[m - 1]) && std::get<1>(keys[m]) == std::get<1>(keys[m - 1]) &&
                        std::get<2>(keys[m]) == std::get<2>(keys[m - 1]))
                        reseed[std::get<3>(keys[m])] = 1; // the later index of each run of equal means
            }
            if (std::find(reseed.begin(), reseed.end(), 1) == reseed.end())
                continue;
            // Each at the point farthest from every kept mean and every earlier re-seed (the
            // worst explained), so that several re-seeds spread out instead of piling up.
            std::vector<glm::dvec3> kept;
            for (std::size_t j = 0; j < k; ++j)
                if (!reseed[j])
                    kept.push_back(out.means[j]);
            std::vector<double> distance(n, std::numeric_limits<double>::max());
            if (!kept.empty())
            {
                const KdTree keptTree(kept);
                tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024), [&](const tbb::blocked_range<std::size_t>& range) {
                    std::vector<std::pair<double, std::uint32_t>> near;
                    for (std::size_t i = range.begin(); i != range.end(); ++i)
                    {
                        keptTree.nearest(input.points[i], 1, near);
                        distance[i] = near[0].first;
                    }
                });
            }
            for (std::size_t j = 0; j < k; ++j)
            {
                if (!reseed[j])
                    continue;
                std::size_t far = n;
                for (std::size_t i = 0; i < n; ++i)
                    if (weights[i] > 0.0 && (far == n || distance[i] > distance[far]))
                        far = i;
                if (far == n)
                    break;
                const glm::dvec3 p = input.points[far];
                out.means[j] = p;
                out.covariances[j] = startCovariance;
                out.mixing[j] = 1.0 / double(k);
                ++out.reseeds;
                for (std::size_t i = 0; i < n; ++i)
                    distance[i] = std::min(distance[i], glm::dot(input.points[i] - p, input.points[i] - p));
            }
            const double mixingSum = std::accumulate(out.mixing.begin(), out.mixing.end(), 0.0);
            for (double& p : out.mixing)
                p /= mixingSum;
            reseededLast = true;
            ++reseedRounds;
        }

        // The mass behind the returned responsibilities.
        std::fill(out.mass.begin(), out.mass.end(), 0.0);
        for (std::size_t i = 0; i < n; ++i)
            for (std::uint32_t e = out.offsets[i]; e < out.offsets[i + 1]; ++e)
                out.mass[out.component[e]] += weights[i] * out.responsibility[e];
        return out;
    }
}
