// SkeletonExtraction: level sets of the geodesic distance over the bark's edge graph (steps and
// references in SkeletonExtraction.h).
#include "TreeLod/SkeletonExtraction.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <numeric>
#include <queue>
#include <unordered_map>
#include <utility>

namespace TreeLod
{
    namespace
    {
        /// Relative to the bark box's diagonal D (SkeletonExtraction.h).
        constexpr double WELD_TOLERANCE = 1e-6;
        constexpr double ATTACH_TOLERANCE = 0.01;
        constexpr double MIN_BAND = 0.005;
        constexpr double BAND_RADIUS_FACTOR = 2.0;

        bool finite(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

        struct UnionFind
        {
            std::vector<std::uint32_t> parent;
            explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
            std::uint32_t find(std::uint32_t v)
            {
                while (parent[v] != v)
                    v = parent[v] = parent[parent[v]];
                return v;
            }
            /// The smaller index becomes the root: results do not depend on the order of unions.
            void unite(std::uint32_t a, std::uint32_t b)
            {
                a = find(a);
                b = find(b);
                if (a != b)
                    parent[std::max(a, b)] = std::min(a, b);
            }
        };

        /// Cells of a sparse uniform grid, keyed by packed integer coordinates.
        std::uint64_t cellKey(std::int64_t x, std::int64_t y, std::int64_t z)
        {
            const std::uint64_t mask = (1ull << 21) - 1;
            return (std::uint64_t(x) & mask) | ((std::uint64_t(y) & mask) << 21) | ((std::uint64_t(z) & mask) << 42);
        }

        double segmentDistance(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b, double* along = nullptr)
        {
            const glm::dvec3 ab = b - a;
            const double ll = glm::dot(ab, ab);
            const double t = ll > 0.0 ? std::clamp(glm::dot(p - a, ab) / ll, 0.0, 1.0) : 0.0;
            if (along)
                *along = t;
            return glm::length(p - (a + t * ab));
        }

        /// The welded bark: positions, its triangles that are not degenerate, the edge graph.
        struct BarkGraph
        {
            std::vector<glm::dvec3> positions;
            std::vector<std::uint32_t> offsets; ///< CSR: neighbours of v are [offsets[v], offsets[v + 1])
            std::vector<std::uint32_t> neighbours;
            std::vector<double> lengths;
            std::vector<std::uint8_t> used;       ///< in a kept triangle
            std::vector<std::int32_t> loop;       ///< boundary loop id (smallest vertex on it), -1 = none
            std::vector<std::uint32_t> component; ///< smallest vertex of its component
            std::vector<double> componentArea;    ///< by component id
            glm::dvec3 lo{0.0}, hi{0.0};
            double diagonal = 0.0;
        };

        BarkGraph buildGraph(const TreeModel& model)
        {
            BarkGraph g;
            const std::size_t vertexCount = model.barkVertices.size();
            auto usable = [&](std::uint32_t i)
            { return i < vertexCount && finite(glm::dvec3(model.barkVertices[i].position)); };
            g.lo = glm::dvec3(std::numeric_limits<double>::max());
            g.hi = glm::dvec3(-std::numeric_limits<double>::max());
            bool any = false;
            for (std::uint32_t i : model.barkIndices)
                if (usable(i))
                {
                    const glm::dvec3 p(model.barkVertices[i].position);
                    g.lo = glm::min(g.lo, p);
                    g.hi = glm::max(g.hi, p);
                    any = true;
                }
            if (!any)
                return g;
            g.diagonal = glm::length(g.hi - g.lo);
            if (!(g.diagonal > 0.0) || !std::isfinite(g.diagonal))
            {
                g.diagonal = 0.0;
                return g;
            }

            // 1. Weld, in the order of first use (deterministic ids).
            const double eps = WELD_TOLERANCE * g.diagonal;
            std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> cells;
            std::vector<std::int64_t> welded(vertexCount, -1);
            auto weld = [&](std::uint32_t i) -> std::uint32_t
            {
                if (welded[i] >= 0)
                    return std::uint32_t(welded[i]);
                const glm::dvec3 p(model.barkVertices[i].position);
                const glm::dvec3 c = glm::floor((p - g.lo) / eps);
                const std::int64_t cx = std::int64_t(c.x), cy = std::int64_t(c.y), cz = std::int64_t(c.z);
                std::int64_t found = -1;
                for (std::int64_t dz = -1; dz <= 1 && found < 0; ++dz)
                    for (std::int64_t dy = -1; dy <= 1 && found < 0; ++dy)
                        for (std::int64_t dx = -1; dx <= 1 && found < 0; ++dx)
                        {
                            const auto it = cells.find(cellKey(cx + dx, cy + dy, cz + dz));
                            if (it == cells.end())
                                continue;
                            for (std::uint32_t w : it->second)
                                if (glm::length(g.positions[w] - p) <= eps)
                                {
                                    found = w;
                                    break;
                                }
                        }
                if (found < 0)
                {
                    found = std::int64_t(g.positions.size());
                    g.positions.push_back(p);
                    cells[cellKey(cx, cy, cz)].push_back(std::uint32_t(found));
                }
                welded[i] = found;
                return std::uint32_t(found);
            };

            std::vector<std::array<std::uint32_t, 3>> triangles;
            std::vector<double> areas;
            for (std::size_t t = 0; t + 2 < model.barkIndices.size(); t += 3)
            {
                const std::uint32_t i0 = model.barkIndices[t], i1 = model.barkIndices[t + 1],
                                    i2 = model.barkIndices[t + 2];
                if (!usable(i0) || !usable(i1) || !usable(i2))
                    continue;
                const std::array<std::uint32_t, 3> w = {weld(i0), weld(i1), weld(i2)};
                if (w[0] == w[1] || w[1] == w[2] || w[0] == w[2])
                    continue;
                if (degenerateTriangle(g.positions[w[0]], g.positions[w[1]], g.positions[w[2]]))
                    continue;
                const double area = 0.5 * glm::length(glm::cross(g.positions[w[1]] - g.positions[w[0]],
                                                                 g.positions[w[2]] - g.positions[w[0]]));
                triangles.push_back(w);
                areas.push_back(area);
            }
            const std::size_t n = g.positions.size();
            g.used.assign(n, 0);

            // 2. Edges (with the number of triangles on each: 1 = boundary), CSR adjacency.
            std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
            edges.reserve(triangles.size() * 3);
            for (const auto& w : triangles)
                for (int k = 0; k < 3; ++k)
                {
                    g.used[w[k]] = 1;
                    edges.emplace_back(std::min(w[k], w[(k + 1) % 3]), std::max(w[k], w[(k + 1) % 3]));
                }
            std::sort(edges.begin(), edges.end());
            std::vector<std::pair<std::uint32_t, std::uint32_t>> unique;
            std::vector<std::uint32_t> uses;
            for (const auto& e : edges)
            {
                if (!unique.empty() && unique.back() == e)
                    ++uses.back();
                else
                {
                    unique.push_back(e);
                    uses.push_back(1);
                }
            }
            g.offsets.assign(n + 1, 0);
            for (const auto& e : unique)
            {
                ++g.offsets[e.first + 1];
                ++g.offsets[e.second + 1];
            }
            for (std::size_t v = 0; v < n; ++v)
                g.offsets[v + 1] += g.offsets[v];
            g.neighbours.resize(g.offsets[n]);
            g.lengths.resize(g.offsets[n]);
            std::vector<std::uint32_t> fill(g.offsets.begin(), g.offsets.end() - 1);
            for (const auto& e : unique)
            {
                const double l = glm::length(g.positions[e.first] - g.positions[e.second]);
                g.neighbours[fill[e.first]] = e.second;
                g.lengths[fill[e.first]++] = l;
                g.neighbours[fill[e.second]] = e.first;
                g.lengths[fill[e.second]++] = l;
            }

            UnionFind components(n), loops(n);
            for (std::size_t e = 0; e < unique.size(); ++e)
            {
                components.unite(unique[e].first, unique[e].second);
                if (uses[e] == 1)
                    loops.unite(unique[e].first, unique[e].second);
            }
            std::vector<std::uint8_t> onBoundary(n, 0);
            for (std::size_t e = 0; e < unique.size(); ++e)
                if (uses[e] == 1)
                    onBoundary[unique[e].first] = onBoundary[unique[e].second] = 1;
            g.loop.assign(n, -1);
            g.component.resize(n);
            for (std::uint32_t v = 0; v < n; ++v)
            {
                g.component[v] = components.find(v);
                if (onBoundary[v])
                    g.loop[v] = std::int32_t(loops.find(v));
            }
            g.componentArea.assign(n, 0.0);
            for (std::size_t t = 0; t < triangles.size(); ++t)
                g.componentArea[g.component[triangles[t][0]]] += areas[t];
            return g;
        }

        /// The capsules of the skeleton built so far, for step 3's attachment: a sparse grid whose
        /// cells list each capsule whose box, grown by the tolerance, overlaps them.
        class CapsuleGrid
        {
        public:
            CapsuleGrid(const glm::dvec3& origin, double tolerance)
                : mOrigin(origin), mTolerance(tolerance), mCell(2.0 * tolerance)
            {
            }

            void add(const glm::dvec3& a, const glm::dvec3& b, double radius, std::int32_t nodeA, std::int32_t nodeB)
            {
                const std::uint32_t id = std::uint32_t(mCapsules.size());
                mCapsules.push_back({a, b, radius, nodeA, nodeB});
                const double grow = radius + mTolerance;
                const glm::dvec3 lo = glm::floor((glm::min(a, b) - grow - mOrigin) / mCell);
                const glm::dvec3 hi = glm::floor((glm::max(a, b) + grow - mOrigin) / mCell);
                for (double z = lo.z; z <= hi.z; ++z)
                    for (double y = lo.y; y <= hi.y; ++y)
                        for (double x = lo.x; x <= hi.x; ++x)
                            mCells[cellKey(std::int64_t(x), std::int64_t(y), std::int64_t(z))].push_back(id);
            }

            /// The capsule whose surface is nearest `p` within the tolerance: its gap (negative
            /// inside) and the node of its nearer end; false when none is that near.
            bool nearest(const glm::dvec3& p, double& gap, std::int32_t& node) const
            {
                const glm::dvec3 c = glm::floor((p - mOrigin) / mCell);
                const auto it = mCells.find(cellKey(std::int64_t(c.x), std::int64_t(c.y), std::int64_t(c.z)));
                if (it == mCells.end())
                    return false;
                bool found = false;
                for (std::uint32_t id : it->second)
                {
                    const Capsule& k = mCapsules[id];
                    double t = 0.0;
                    const double g = segmentDistance(p, k.a, k.b, &t) - k.radius;
                    if (g <= mTolerance && (!found || g < gap))
                    {
                        found = true;
                        gap = g;
                        node = t <= 0.5 ? k.nodeA : k.nodeB;
                    }
                }
                return found;
            }

        private:
            struct Capsule
            {
                glm::dvec3 a, b;
                double radius;
                std::int32_t nodeA, nodeB;
            };
            glm::dvec3 mOrigin;
            double mTolerance, mCell;
            std::vector<Capsule> mCapsules;
            std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> mCells;
        };

        /// Mean distance of `points` from the line through `centre` along `direction` (from `centre`
        /// itself when the direction is zero).
        double axisRadius(const std::vector<glm::dvec3>& positions, const std::vector<std::uint32_t>& points,
                          const glm::dvec3& centre, const glm::dvec3& direction)
        {
            if (points.empty())
                return 0.0;
            const double length = glm::length(direction);
            const glm::dvec3 axis = length > 0.0 ? direction / length : glm::dvec3(0.0);
            double sum = 0.0;
            for (std::uint32_t v : points)
            {
                const glm::dvec3 d = positions[v] - centre;
                sum += glm::length(d - glm::dot(d, axis) * axis);
            }
            return sum / double(points.size());
        }

        glm::dvec3 centroid(const std::vector<glm::dvec3>& positions, const std::vector<std::uint32_t>& points)
        {
            glm::dvec3 sum(0.0);
            for (std::uint32_t v : points)
                sum += positions[v];
            return points.empty() ? sum : sum / double(points.size());
        }
    }

    bool degenerateTriangle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c)
    {
        const double area = 0.5 * glm::length(glm::cross(b - a, c - a));
        const double edge = std::max({glm::dot(b - a, b - a), glm::dot(c - b, c - b), glm::dot(a - c, a - c)});
        return !(area > 1e-6 * edge) || !std::isfinite(area) || !std::isfinite(edge);
    }

    std::vector<SkeletonNode> barkSkeleton(const TreeModel& model)
    {
        return model.skeleton.empty() ? extractSkeleton(model) : model.skeleton;
    }

    std::vector<SkeletonNode> extractSkeleton(const TreeModel& model)
    {
        const BarkGraph g = buildGraph(model);
        std::vector<SkeletonNode> nodes;
        if (g.diagonal <= 0.0)
            return nodes;
        const std::size_t n = g.positions.size();

        // Components: vertices, lowest vertex (least y, then least index).
        std::unordered_map<std::uint32_t, std::vector<std::uint32_t>> members;
        std::vector<std::uint32_t> order; // component ids by first vertex
        for (std::uint32_t v = 0; v < n; ++v)
            if (g.used[v])
            {
                auto& list = members[g.component[v]];
                if (list.empty())
                    order.push_back(g.component[v]);
                list.push_back(v);
            }
        if (order.empty())
            return nodes;
        auto lowest = [&](std::uint32_t component)
        {
            const std::vector<std::uint32_t>& list = members.at(component);
            std::uint32_t best = list.front();
            for (std::uint32_t v : list)
                if (g.positions[v].y < g.positions[best].y)
                    best = v;
            return best;
        };
        std::uint32_t trunk = order.front();
        for (std::uint32_t c : order)
            if (g.positions[lowest(c)].y < g.positions[lowest(trunk)].y)
                trunk = c;
        std::stable_sort(order.begin(), order.end(),
                         [&](std::uint32_t a, std::uint32_t b)
                         {
                             if ((a == trunk) != (b == trunk))
                                 return a == trunk;
                             return g.componentArea[a] > g.componentArea[b];
                         });

        const double D = g.diagonal;
        CapsuleGrid grid(g.lo, ATTACH_TOLERANCE * D);
        std::vector<double> dist(n, std::numeric_limits<double>::infinity());
        std::vector<std::int64_t> pred(n, -1);
        std::vector<std::int64_t> band(n, 0);
        UnionFind pieces(n);

        for (std::uint32_t c : order)
        {
            const std::vector<std::uint32_t>& list = members.at(c);

            // 3. The root and where the component hangs.
            std::uint32_t root = lowest(c);
            std::int32_t attach = -1;
            if (c != trunk)
            {
                double best = 0.0;
                for (std::uint32_t v : list)
                {
                    double gap = 0.0;
                    std::int32_t node = -1;
                    if (grid.nearest(g.positions[v], gap, node) && (attach < 0 || gap < best))
                    {
                        best = gap;
                        root = v;
                        attach = node;
                    }
                }
            }
            std::vector<std::uint32_t> sources;
            if (g.loop[root] >= 0)
            {
                for (std::uint32_t v : list)
                    if (g.loop[v] == g.loop[root])
                        sources.push_back(v);
            }
            else
                sources.push_back(root);

            // 4. Geodesic distance and bands.
            using Item = std::pair<double, std::uint32_t>;
            std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
            for (std::uint32_t s : sources)
            {
                dist[s] = 0.0;
                queue.push({0.0, s});
            }
            while (!queue.empty())
            {
                const auto [d, v] = queue.top();
                queue.pop();
                if (d > dist[v])
                    continue;
                for (std::uint32_t e = g.offsets[v]; e < g.offsets[v + 1]; ++e)
                {
                    const std::uint32_t u = g.neighbours[e];
                    const double du = d + g.lengths[e];
                    if (du < dist[u] || (du == dist[u] && pred[u] >= 0 && v < pred[u]))
                    {
                        if (du < dist[u])
                            queue.push({du, u});
                        dist[u] = du;
                        pred[u] = v;
                    }
                }
            }
            const glm::dvec3 base = centroid(g.positions, sources);
            double baseRadius = 0.0;
            for (std::uint32_t s : sources)
                baseRadius += glm::length(g.positions[s] - base);
            baseRadius /= double(sources.size());
            const double width = std::max(BAND_RADIUS_FACTOR * baseRadius, MIN_BAND * D);
            for (std::uint32_t v : list)
                band[v] = dist[v] > 0.0 ? 1 + std::int64_t(std::floor(dist[v] / width)) : 0;

            // 5. Pieces of the bands, in (band, smallest vertex) order: parents come first.
            for (std::uint32_t v : list)
                for (std::uint32_t e = g.offsets[v]; e < g.offsets[v + 1]; ++e)
                    if (band[g.neighbours[e]] == band[v])
                        pieces.unite(v, g.neighbours[e]);
            std::unordered_map<std::uint32_t, std::uint32_t> pieceIndex; // root vertex -> piece
            struct Piece
            {
                std::int64_t band = 0;
                std::vector<std::uint32_t> vertices;
                std::int64_t parent = -1; ///< piece, -1 for the first
                std::uint32_t entry = 0;
                bool entered = false;
                std::vector<std::uint32_t> children;
                glm::dvec3 centre{0.0};
            };
            std::vector<Piece> found;
            for (std::uint32_t v : list) // ascending: a piece's first vertex is its smallest
            {
                const std::uint32_t r = pieces.find(v);
                auto it = pieceIndex.find(r);
                if (it == pieceIndex.end())
                {
                    it = pieceIndex.emplace(r, std::uint32_t(found.size())).first;
                    found.emplace_back();
                    found.back().band = band[v];
                }
                found[it->second].vertices.push_back(v);
            }
            std::vector<std::uint32_t> sorted(found.size());
            std::iota(sorted.begin(), sorted.end(), 0u);
            std::stable_sort(sorted.begin(), sorted.end(),
                             [&](std::uint32_t a, std::uint32_t b) { return found[a].band < found[b].band; });
            std::vector<std::uint32_t> rank(found.size());
            for (std::uint32_t k = 0; k < sorted.size(); ++k)
                rank[sorted[k]] = k;
            for (Piece& p : found)
            {
                const std::uint32_t self = rank[pieceIndex.at(pieces.find(p.vertices.front()))];
                for (std::uint32_t v : p.vertices)
                {
                    if (pred[v] < 0)
                        continue;
                    const std::uint32_t from = rank[pieceIndex.at(pieces.find(std::uint32_t(pred[v])))];
                    if (from == self)
                        continue;
                    if (!p.entered || dist[v] < dist[p.entry] || (dist[v] == dist[p.entry] && v < p.entry))
                    {
                        p.entered = true;
                        p.entry = v;
                        p.parent = from;
                    }
                }
                p.centre = centroid(g.positions, p.vertices);
            }
            std::vector<Piece> ordered;
            ordered.reserve(found.size());
            for (std::uint32_t k : sorted)
                ordered.push_back(std::move(found[k]));
            for (std::uint32_t k = 0; k < ordered.size(); ++k)
                if (ordered[k].parent >= 0)
                    ordered[std::size_t(ordered[k].parent)].children.push_back(k);

            const std::int32_t first = std::int32_t(nodes.size());
            for (std::uint32_t k = 0; k < ordered.size(); ++k)
            {
                const Piece& p = ordered[k];
                glm::dvec3 direction(0.0);
                if (p.parent >= 0)
                    direction = p.centre - ordered[std::size_t(p.parent)].centre;
                else if (!p.children.empty())
                    direction = ordered[p.children.front()].centre - p.centre;
                SkeletonNode node;
                node.position = glm::vec3(p.centre);
                node.radius = float(axisRadius(g.positions, p.vertices, p.centre, direction));
                node.parent = p.parent >= 0 ? first + std::int32_t(p.parent) : attach;
                nodes.push_back(node);
            }
            // 6. Tips.
            for (std::uint32_t k = 0; k < ordered.size(); ++k)
            {
                const Piece& p = ordered[k];
                if (!p.children.empty())
                    continue;
                double far = 0.0;
                for (std::uint32_t v : p.vertices)
                    far = std::max(far, dist[v]);
                std::vector<std::uint32_t> end;
                for (std::uint32_t v : p.vertices)
                    if (dist[v] >= far - 0.25 * width)
                        end.push_back(v);
                const glm::dvec3 tip = centroid(g.positions, end);
                if (!(glm::length(tip - p.centre) > 0.25 * width))
                    continue;
                SkeletonNode node;
                node.position = glm::vec3(tip);
                node.radius = float(axisRadius(g.positions, end, tip, tip - p.centre));
                node.parent = first + std::int32_t(k);
                nodes.push_back(node);
            }
            // The capsules of this component, for the ones placed after it.
            for (std::size_t i = std::size_t(first); i < nodes.size(); ++i)
            {
                const SkeletonNode& node = nodes[i];
                if (node.parent < 0)
                    grid.add(glm::dvec3(node.position), glm::dvec3(node.position), node.radius, std::int32_t(i),
                             std::int32_t(i));
                else
                {
                    const SkeletonNode& parent = nodes[std::size_t(node.parent)];
                    grid.add(glm::dvec3(parent.position), glm::dvec3(node.position),
                             0.5 * double(parent.radius + node.radius), node.parent, std::int32_t(i));
                }
            }
        }
        return nodes;
    }
}
