// BillboardClustering: leaf clustering into planes for the billboard clouds of García et al. 2007
// §4.1 (contract and deviations in BillboardClustering.h).
#include "BillboardClustering.h"

#include "TreeLod/ImageMetrics.h"
#include "TreeLod/ReferenceRenderer.h"
#include "TreeLod/TreeViews.h"

#include <Eigen/Dense>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace TreeLod
{
    namespace
    {
        constexpr float INF = std::numeric_limits<float>::infinity();
        constexpr std::uint32_t NONE = std::numeric_limits<std::uint32_t>::max();

        struct LeafData
        {
            glm::vec3 centre{0.0f}; ///< relative to the reference point
            glm::vec3 normal{0.0f, 1.0f, 0.0f};
            float weight = 1.0f; ///< area (least-squares weight)
            float radius = 0.0f; ///< largest vertex distance from the centre
            std::uint32_t first = 0, count = 0;
        };

        /// Largest distance of leaf `leaf`'s vertices to the plane (n, d); stops early, returning a
        /// lower bound above `limit`, once that bound passes it.
        float planeError(const LeafData& leaf, const std::vector<glm::vec3>& vertices, const glm::vec3& n, float d,
                         float limit)
        {
            float e = 0.0f;
            for (std::uint32_t v = leaf.first; v < leaf.first + leaf.count; ++v)
            {
                e = std::max(e, std::abs(glm::dot(n, vertices[v]) - d));
                if (e > limit)
                    return e;
            }
            return e;
        }

        /// The centroids in a grid of cubic cells over the leaf centres' box (centroids are means
        /// of leaf centres: inside it). visit() walks the cells in shells of growing Chebyshev
        /// radius around a point's cell and hands over the centroids of each cell whose distance
        /// from the point passes `keep` (a lower bound, kept below the true distance by a margin
        /// for rounding), until no cell of the next shell can.
        class CentroidGrid
        {
        public:
            CentroidGrid(const std::vector<glm::vec3>& centroids, const glm::vec3& lo, const glm::vec3& hi)
            {
                const glm::vec3 extent = glm::max(hi - lo, glm::vec3(1e-6f));
                const float pad = 1e-3f * std::max({extent.x, extent.y, extent.z});
                mLo = lo - pad;
                const glm::vec3 size = extent + 2.0f * pad;
                // About two centroids per cell.
                const double volume = double(size.x) * size.y * size.z;
                mCell = float(std::cbrt(volume / std::max(0.5 * double(centroids.size()), 1.0)));
                mCell = std::max(mCell, 1.001f * std::max({size.x, size.y, size.z}) / 256.0f);
                for (int a = 0; a < 3; ++a)
                    mCells[a] = std::clamp(int(std::ceil(size[a] / mCell)), 1, 256);
                mStart.assign(std::size_t(mCells[0]) * mCells[1] * mCells[2] + 1, 0);
                std::vector<std::uint32_t> cellOf(centroids.size());
                for (std::size_t k = 0; k < centroids.size(); ++k)
                {
                    const glm::ivec3 c = cellCoords(centroids[k]);
                    cellOf[k] = std::uint32_t(index(c.x, c.y, c.z));
                    ++mStart[cellOf[k] + 1];
                }
                for (std::size_t c = 1; c < mStart.size(); ++c)
                    mStart[c] += mStart[c - 1];
                mItems.resize(centroids.size());
                std::vector<std::uint32_t> next(mStart.begin(), mStart.end() - 1);
                for (std::size_t k = 0; k < centroids.size(); ++k)
                    mItems[next[cellOf[k]]++] = std::uint32_t(k);
            }

            template <typename Keep, typename Visit>
            void visit(const glm::vec3& p, const Keep& keep, const Visit& visitItem) const
            {
                const glm::ivec3 centre = cellCoords(p);
                const int maxRadius = std::max({mCells[0], mCells[1], mCells[2]});
                for (int r = 0; r < maxRadius; ++r)
                {
                    if (r > 1 && !keep(float(r - 1) * mCell * 0.999f))
                        return;
                    for (int dz = -r; dz <= r; ++dz)
                        for (int dy = -r; dy <= r; ++dy)
                        {
                            const bool face = dz == -r || dz == r || dy == -r || dy == r;
                            for (int dx = -r; dx <= r; dx += face || r == 0 ? 1 : 2 * r)
                                visitCell(p, centre + glm::ivec3(dx, dy, dz), keep, visitItem);
                        }
                }
            }

        private:
            glm::ivec3 cellCoords(const glm::vec3& p) const
            {
                glm::ivec3 c;
                for (int a = 0; a < 3; ++a)
                    c[a] = std::clamp(int(std::floor((p[a] - mLo[a]) / mCell)), 0, mCells[a] - 1);
                return c;
            }

            std::size_t index(int x, int y, int z) const
            {
                return (std::size_t(z) * mCells[1] + std::size_t(y)) * mCells[0] + std::size_t(x);
            }

            template <typename Keep, typename Visit>
            void visitCell(const glm::vec3& p, const glm::ivec3& c, const Keep& keep, const Visit& visitItem) const
            {
                if (c.x < 0 || c.y < 0 || c.z < 0 || c.x >= mCells[0] || c.y >= mCells[1] || c.z >= mCells[2])
                    return;
                const std::size_t id = index(c.x, c.y, c.z);
                if (mStart[id] == mStart[id + 1])
                    return;
                const glm::vec3 lo = mLo + glm::vec3(c) * mCell, hi = lo + mCell;
                const glm::vec3 out = glm::max(glm::max(lo - p, p - hi), glm::vec3(0.0f));
                if (!keep(glm::length(out) * 0.999f))
                    return;
                for (std::uint32_t m = mStart[id]; m < mStart[id + 1]; ++m)
                    visitItem(mItems[m]);
            }

            glm::vec3 mLo{0.0f};
            float mCell = 1.0f;
            int mCells[3] = {1, 1, 1};
            std::vector<std::uint32_t> mStart, mItems;
        };

        glm::vec3 canonicalSign(const glm::vec3& n)
        {
            const glm::vec3 a = glm::abs(n);
            const float big = a.x >= a.y && a.x >= a.z ? n.x : a.y >= a.z ? n.y : n.z;
            return big < 0.0f ? -n : n;
        }
    }

    LeafClustering clusterLeaves(const TreeModel& model, const LeafClusteringOptions& options)
    {
        LeafClustering out;
        const std::uint32_t L = std::uint32_t(model.leaves.size());
        if (L == 0)
            return out;
        const std::uint32_t C = std::clamp<std::uint32_t>(options.clusterCount, 1, L);
        const float bound = std::max(options.errorBound, 0.0f);
        const float w = std::max(options.spatialWeight, 0.0f);
        const float wn = std::max(options.orientationWeight, 0.0f);

        // Positions relative to the mean leaf centre (float precision for trees far from 0).
        glm::dvec3 sum(0.0);
        for (const Leaf& leaf : model.leaves)
            sum += glm::dvec3(leaf.centre);
        const glm::vec3 ref = glm::vec3(sum / double(L));
        std::vector<glm::vec3> vertices(model.leafVertices.size());
        for (std::size_t v = 0; v < vertices.size(); ++v)
            vertices[v] = model.leafVertices[v].position - ref;
        double areaSum = 0.0;
        for (const Leaf& leaf : model.leaves)
            areaSum += leaf.area;
        const float fallbackWeight = areaSum > 0.0 ? float(areaSum / L) * 1e-3f : 1.0f;
        std::vector<LeafData> leaves(L);
        for (std::uint32_t i = 0; i < L; ++i)
        {
            const Leaf& src = model.leaves[i];
            LeafData& leaf = leaves[i];
            leaf.centre = src.centre - ref;
            leaf.normal = glm::length(src.normal) > 0.0f ? glm::normalize(src.normal) : glm::vec3(0, 1, 0);
            leaf.weight = src.area > 0.0f ? src.area : fallbackWeight;
            leaf.first = src.firstVertex;
            leaf.count = src.vertexCount;
            for (std::uint32_t v = leaf.first; v < leaf.first + leaf.count; ++v)
                leaf.radius = std::max(leaf.radius, glm::length(vertices[v] - leaf.centre));
        }

        glm::vec3 centreLo(INF), centreHi(-INF);
        for (const LeafData& leaf : leaves)
        {
            centreLo = glm::min(centreLo, leaf.centre);
            centreHi = glm::max(centreHi, leaf.centre);
        }

        // Seeds: farthest-point sampling of the centres.
        std::vector<float> minDist(L, INF);
        std::vector<std::uint32_t> seeds;
        seeds.reserve(C);
        std::uint32_t pick = 0;
        for (std::uint32_t i = 1; i < L; ++i)
            if (glm::length(leaves[i].centre) > glm::length(leaves[pick].centre))
                pick = i;
        for (std::uint32_t s = 0; s < C; ++s)
        {
            seeds.push_back(pick);
            minDist[pick] = -1.0f; // chosen
            const glm::vec3 c = leaves[pick].centre;
            tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, L, 1024),
                              [&](const tbb::blocked_range<std::uint32_t>& r) {
                                  for (std::uint32_t i = r.begin(); i < r.end(); ++i)
                                      if (minDist[i] >= 0.0f)
                                          minDist[i] = std::min(minDist[i], glm::length(leaves[i].centre - c));
                              });
            if (s + 1 == C)
                break;
            float best = -1.0f;
            for (std::uint32_t i = 0; i < L; ++i)
                if (minDist[i] > best)
                {
                    best = minDist[i];
                    pick = i;
                }
        }
        std::vector<glm::vec3> normal(C), centroid(C);
        std::vector<float> offset(C);
        for (std::uint32_t k = 0; k < C; ++k)
        {
            const LeafData& leaf = leaves[seeds[k]];
            normal[k] = leaf.normal;
            offset[k] = glm::dot(leaf.normal, leaf.centre);
            centroid[k] = leaf.centre;
        }

        std::vector<std::uint32_t> assign(L, NONE), next(L, NONE);
        std::vector<float> error(L, 0.0f);
        std::vector<std::vector<std::uint32_t>> members(C);

        auto refit = [&]() {
            for (auto& m : members)
                m.clear();
            for (std::uint32_t i = 0; i < L; ++i)
                members[assign[i]].push_back(i);
            tbb::parallel_for(std::uint32_t(0), C, [&](std::uint32_t k) {
                const std::vector<std::uint32_t>& m = members[k];
                if (m.empty())
                    return;
                double wsum = 0.0, leafWeight = 0.0;
                glm::dvec3 mean(0.0), g(0.0);
                for (std::uint32_t i : m)
                {
                    const LeafData& leaf = leaves[i];
                    const double wv = double(leaf.weight) / std::max<std::uint32_t>(leaf.count, 1);
                    for (std::uint32_t v = leaf.first; v < leaf.first + leaf.count; ++v)
                        mean += wv * glm::dvec3(vertices[v]);
                    wsum += wv * leaf.count;
                    g += double(leaf.weight) * glm::dvec3(leaf.centre);
                    leafWeight += leaf.weight;
                }
                if (!(wsum > 0.0) || !(leafWeight > 0.0))
                    return;
                mean /= wsum;
                centroid[k] = glm::vec3(g / leafWeight);
                Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
                for (std::uint32_t i : m)
                {
                    const LeafData& leaf = leaves[i];
                    const double wv = double(leaf.weight) / std::max<std::uint32_t>(leaf.count, 1);
                    for (std::uint32_t v = leaf.first; v < leaf.first + leaf.count; ++v)
                    {
                        const glm::dvec3 d = glm::dvec3(vertices[v]) - mean;
                        const Eigen::Vector3d e(d.x, d.y, d.z);
                        cov += wv * e * e.transpose();
                    }
                }
                if (wn > 0.0f)
                {
                    // Orientation: minus the weighted leaf-normal scatter, scaled like the vertex
                    // spread of a leaf (weight x (2 radius)^2).
                    for (std::uint32_t i : m)
                    {
                        const LeafData& leaf = leaves[i];
                        const Eigen::Vector3d nl(leaf.normal.x, leaf.normal.y, leaf.normal.z);
                        const double l2 = 4.0 * double(leaf.radius) * leaf.radius;
                        cov -= double(wn) * double(leaf.weight) * l2 * nl * nl.transpose();
                    }
                }
                Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(cov);
                if (solver.info() != Eigen::Success)
                    return;
                const Eigen::Vector3d e = solver.eigenvectors().col(0);
                glm::vec3 n(float(e.x()), float(e.y()), float(e.z()));
                if (!(glm::length(n) > 0.5f) || !std::isfinite(n.x + n.y + n.z))
                    return; // keep the previous plane
                n = canonicalSign(glm::normalize(n));
                normal[k] = n;
                offset[k] = float(glm::dot(glm::dvec3(n), mean));
            });
        };

        const std::uint32_t maxPasses = std::max<std::uint32_t>(options.maxIterations, 1);
        std::uint32_t passes = 0;
        while (passes < maxPasses)
        {
            ++passes;
            // 1. Assignment (per leaf, in parallel): the cluster of least cost, ties to the lower
            // index. Its cost is at least spatialWeight x the distance to its centroid, so with
            // spatialWeight > 0 only the centroids in grid cells within bestCost / spatialWeight
            // of the leaf can win; the cells are visited in shells around the leaf's cell, its
            // previous cluster first (the same choice as a scan of every cluster).
            const CentroidGrid grid(centroid, centreLo, centreHi);
            tbb::parallel_for(
                tbb::blocked_range<std::uint32_t>(0, L, 64), [&](const tbb::blocked_range<std::uint32_t>& r) {
                    for (std::uint32_t i = r.begin(); i < r.end(); ++i)
                    {
                        const LeafData& leaf = leaves[i];
                        float bestCost = INF, bestErr = 0.0f, fallbackErr = INF;
                        std::uint32_t best = NONE, fallback = NONE;
                        const auto consider = [&](std::uint32_t k) {
                            const float spatial =
                                w * glm::length(leaf.centre - centroid[k]) +
                                wn * 2.0f * leaf.radius * (1.0f - std::abs(glm::dot(leaf.normal, normal[k])));
                            if (best != NONE && (spatial > bestCost || (spatial == bestCost && k > best)))
                                return;
                            const float lower = std::abs(glm::dot(normal[k], leaf.centre) - offset[k]) - leaf.radius;
                            if (lower > bound && (best != NONE || lower > fallbackErr))
                                return;
                            const float limit =
                                best != NONE ? std::min(bound, bestCost - spatial) : std::max(bound, fallbackErr);
                            const float e = planeError(leaf, vertices, normal[k], offset[k], limit);
                            if (e <= bound)
                            {
                                const float cost = e + spatial;
                                if (best == NONE || cost < bestCost || (cost == bestCost && k < best))
                                {
                                    bestCost = cost;
                                    bestErr = e;
                                    best = k;
                                }
                            }
                            else if (e < fallbackErr || (e == fallbackErr && k < fallback))
                            {
                                fallbackErr = e;
                                fallback = k;
                            }
                        };
                        if (w > 0.0f)
                        {
                            if (assign[i] != NONE)
                                consider(assign[i]);
                            grid.visit(leaf.centre, [&](float distance) { return best == NONE || w * distance <= bestCost; },
                                       [&](std::uint32_t k) {
                                           if (k != assign[i])
                                               consider(k);
                                       });
                        }
                        else
                            for (std::uint32_t k = 0; k < C; ++k)
                                consider(k);
                        next[i] = best != NONE ? best : fallback;
                        error[i] = best != NONE ? bestErr : fallbackErr;
                    }
                });
            const bool changed = next != assign;
            assign.swap(next);
            if (!changed)
                break;

            // 2. Empty clusters take the worst-fitting leaves (of clusters that keep a leaf).
            std::vector<std::uint32_t> count(C, 0);
            for (std::uint32_t i = 0; i < L; ++i)
                ++count[assign[i]];
            std::vector<std::uint32_t> empty;
            for (std::uint32_t k = 0; k < C; ++k)
                if (count[k] == 0)
                    empty.push_back(k);
            if (!empty.empty())
            {
                std::vector<std::uint32_t> order(L);
                std::iota(order.begin(), order.end(), 0u);
                std::stable_sort(order.begin(), order.end(),
                                 [&](std::uint32_t a, std::uint32_t b) { return error[a] > error[b]; });
                std::size_t o = 0;
                for (std::uint32_t k : empty)
                {
                    while (o < L && count[assign[order[o]]] <= 1)
                        ++o;
                    if (o == L)
                        break;
                    const std::uint32_t i = order[o++];
                    --count[assign[i]];
                    assign[i] = k;
                    count[k] = 1;
                    error[i] = 0.0f;
                }
            }

            // 3. Refit planes and centroids.
            refit();
        }
        // The first pass always changes the assignment (from none), so the last refit above saw
        // the final assignment: members and planes are current.

        // Final plane errors.
        tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, L, 256),
                          [&](const tbb::blocked_range<std::uint32_t>& r) {
                              for (std::uint32_t i = r.begin(); i < r.end(); ++i)
                                  error[i] = planeError(leaves[i], vertices, normal[assign[i]], offset[assign[i]], INF);
                          });

        out.normal = normal;
        out.offset.resize(C);
        out.centroid.resize(C);
        for (std::uint32_t k = 0; k < C; ++k)
        {
            out.offset[k] = offset[k] + glm::dot(normal[k], ref);
            out.centroid[k] = centroid[k] + ref;
        }
        out.error = std::move(error);
        out.members = std::move(members);
        return out;
    }

    double billboardArea(const TreeModel& model, const LeafClustering& clustering)
    {
        std::vector<double> area(clustering.members.size(), 0.0);
        tbb::parallel_for(std::size_t(0), clustering.members.size(), [&](std::size_t k) {
            const glm::dvec3 n(clustering.normal[k]);
            const glm::dvec3 a = glm::normalize(glm::cross(n, std::abs(n.y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0)));
            const glm::dvec3 b = glm::cross(n, a);
            std::vector<glm::dvec2> points;
            glm::dvec2 mean(0.0);
            for (std::uint32_t i : clustering.members[k])
            {
                const Leaf& leaf = model.leaves[i];
                for (std::uint32_t v = leaf.firstVertex; v < leaf.firstVertex + leaf.vertexCount; ++v)
                {
                    const glm::dvec3 p(model.leafVertices[v].position - clustering.centroid[k]);
                    points.emplace_back(glm::dot(p, a), glm::dot(p, b));
                    mean += points.back();
                }
            }
            if (points.empty())
                return;
            mean /= double(points.size());
            double sxx = 0.0, sxy = 0.0, syy = 0.0;
            for (const glm::dvec2& p : points)
            {
                const glm::dvec2 d = p - mean;
                sxx += d.x * d.x;
                sxy += d.x * d.y;
                syy += d.y * d.y;
            }
            const double angle = 0.5 * std::atan2(2.0 * sxy, sxx - syy);
            const glm::dvec2 u(std::cos(angle), std::sin(angle)), w(-u.y, u.x);
            glm::dvec2 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
            for (const glm::dvec2& p : points)
            {
                const glm::dvec2 q(glm::dot(p, u), glm::dot(p, w));
                lo = glm::min(lo, q);
                hi = glm::max(hi, q);
            }
            area[k] = (hi.x - lo.x) * (hi.y - lo.y);
        });
        double sum = 0.0;
        for (double x : area)
            sum += x;
        return sum;
    }

    TreeModel flattenedOntoClusters(const TreeModel& model, const LeafClustering& clustering)
    {
        TreeModel flat = model;
        for (std::size_t k = 0; k < clustering.members.size(); ++k)
        {
            const glm::vec3 n = clustering.normal[k];
            const float d = clustering.offset[k];
            for (std::uint32_t i : clustering.members[k])
            {
                const Leaf& leaf = model.leaves[i];
                for (std::uint32_t v = leaf.firstVertex; v < leaf.firstVertex + leaf.vertexCount; ++v)
                {
                    glm::vec3& p = flat.leafVertices[v].position;
                    p -= (glm::dot(n, p) - d) * n;
                }
            }
        }
        return flat;
    }

    struct ClusteringJudge::View
    {
        CameraSpec camera;
        int size = 0;
        Image reference;
        Extent extent;
    };

    ClusteringJudge::ClusteringJudge(const TreeModel& model, const glm::vec3& lo, const glm::vec3& hi,
                                     const Options& options)
        : mModel(model), mOptions(options)
    {
        const ReferenceRenderer renderer(model);
        for (int size : options.sizes)
            for (const glm::vec2& v : options.views)
            {
                View view;
                view.camera = CameraSpec::framing(lo, hi, v.x, v.y);
                view.size = size;
                view.reference = traceReference(renderer, view.camera, size, options.supersample);
                view.extent = treeExtent(view.reference);
                mViews.push_back(std::move(view));
            }
    }

    ClusteringJudge::~ClusteringJudge() = default;

    double ClusteringJudge::error(const LeafClustering& clustering) const
    {
        const TreeModel flat = flattenedOntoClusters(mModel, clustering);
        const ReferenceRenderer renderer(flat);
        double sum = 0.0;
        for (const View& view : mViews)
        {
            const Image test = traceReference(renderer, view.camera, view.size, mOptions.supersample);
            const Crop crop = cropAround(unite(view.extent, treeExtent(test)), test.width, test.height);
            const Result<FlipResult> f = flip(cropImage(view.reference, crop), cropImage(test, crop));
            sum += f ? f->mean : 1.0;
        }
        return mViews.empty() ? 0.0 : sum / double(mViews.size());
    }
}
