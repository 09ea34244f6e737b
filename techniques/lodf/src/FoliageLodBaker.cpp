#include "TreeLod/FoliageLodBaker.h"

#include "TreeLod/FoliageLodState.h"
#include "TreeLod/Package.h"
#include "TreeLod/PackageWriter.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>

namespace TreeLod
{
    namespace
    {
        /// A leaf while collapsing: original or created, by its four corner vertices.
        struct Node
        {
            std::array<std::uint32_t, 4> corner{}; ///< vertices at texture corners (0,0) (1,0) (1,1) (0,1)
            glm::vec3 centre{0.0f};
            glm::vec3 normal{0.0f, 1.0f, 0.0f};
            float area = 0.0f;       ///< area it stands for: the sum over the original leaves it replaces
            glm::vec2 uvMin{0.0f}, uvMax{0.0f};
            std::uint32_t imageSource = 0; ///< an original (node id) whose leaf image it shows
        };

        /// An original of LoDF: a leaf, or, with FoliageLodOptions::crossedLeaves, one plane of a
        /// leaf that is one mesh in several planes (planeParts).
        struct Unit
        {
            std::uint32_t leaf = 0;                ///< model leaf index
            std::uint32_t firstIndex = 0, indexCount = 0; ///< its triangles, in the unit index pool
            Node node;
        };

        struct Collapse
        {
            std::uint32_t a = 0, b = 0; ///< cluster-local node ids (originals 0..n-1, created n..)
            float cost = 0.0f;          ///< running maximum in the cluster (monotone)
        };

        struct ClusterBuild
        {
            std::uint32_t material = 0;
            std::vector<std::uint32_t> leaves; ///< unit indices, the cluster's originals
            std::vector<Node> nodes;           ///< originals then created
            std::vector<Collapse> collapses;
        };

        float quadArea(const TreeModel& m, const std::array<std::uint32_t, 4>& q)
        {
            const glm::vec3& p0 = m.leafVertices[q[0]].position;
            const glm::vec3& p1 = m.leafVertices[q[1]].position;
            const glm::vec3& p2 = m.leafVertices[q[2]].position;
            const glm::vec3& p3 = m.leafVertices[q[3]].position;
            return 0.5f * glm::length(glm::cross(p2 - p0, p3 - p1));
        }

        /// Corners of `node` (normal and UV rectangle set): the four of `vertices` nearest the
        /// corners of their UV extent, or, without one, of their extent in the node's plane.
        void setCorners(const TreeModel& m, const std::vector<std::uint32_t>& vertices, Node& node)
        {
            const glm::vec2 uvExtent = node.uvMax - node.uvMin;
            const bool useUv = uvExtent.x > 1e-6f && uvExtent.y > 1e-6f;
            glm::vec3 axisU(1.0f, 0.0f, 0.0f);
            if (!useUv)
            {
                axisU = glm::cross(node.normal, std::abs(node.normal.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0));
                axisU = glm::normalize(axisU);
            }
            const glm::vec3 axisV = glm::cross(node.normal, axisU);
            std::vector<glm::vec2> t(vertices.size());
            glm::vec2 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
            for (std::size_t k = 0; k < vertices.size(); ++k)
            {
                const Vertex& v = m.leafVertices[vertices[k]];
                t[k] = useUv ? v.uv : glm::vec2(glm::dot(v.position, axisU), glm::dot(v.position, axisV));
                lo = glm::min(lo, t[k]);
                hi = glm::max(hi, t[k]);
            }
            const glm::vec2 extent = glm::max(hi - lo, glm::vec2(1e-12f));
            static const glm::vec2 CORNERS[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
            for (int r = 0; r < 4; ++r)
            {
                float best = std::numeric_limits<float>::max();
                for (std::size_t k = 0; k < vertices.size(); ++k)
                {
                    glm::vec2 d = (t[k] - lo) / extent - CORNERS[r];
                    float e = glm::dot(d, d);
                    if (e < best)
                    {
                        best = e;
                        node.corner[r] = vertices[k];
                    }
                }
            }
        }

        /// Crossed leaves: two originals of one leaf image are parts of one crossed leaf when their
        /// centres lie within CROSSED_CENTRE leaf sizes of each other and their planes differ
        /// (|n_a . n_b| < CROSSED_PARALLEL), as ez-tree's "double billboards" and needle sprigs.
        /// A leaf's triangles lie in one plane while |n_a . n_b| >= CROSSED_PARALLEL.
        constexpr float CROSSED_CENTRE = 0.05f, CROSSED_PARALLEL = 0.9f;
        /// A plane of a leaf under this share of its area joins the most parallel larger one.
        constexpr float PART_AREA = 0.1f;

        struct PlanePart
        {
            Node node;
            std::vector<std::uint32_t> indices; ///< its triangles (leaf vertex ids)
        };

        /// Leaf `i`, one mesh in several planes (TreeModel::leafPlanes), as one quad per plane,
        /// each on its own vertices nearest the corners of their UV extent. Empty for a flat leaf.
        std::vector<PlanePart> planeParts(const TreeModel& m, std::size_t i)
        {
            std::vector<std::vector<std::uint32_t>> planes = m.leafPlanes(i, CROSSED_PARALLEL, PART_AREA);
            if (planes.size() < 2)
                return {};
            std::vector<PlanePart> parts(planes.size());
            for (std::size_t p = 0; p < planes.size(); ++p)
            {
                Node& part = parts[p].node;
                glm::vec3 normalSum(0.0f), weighted(0.0f);
                std::vector<std::uint32_t> vertices;
                part.uvMin = glm::vec2(std::numeric_limits<float>::max());
                part.uvMax = -part.uvMin;
                for (std::size_t t = 0; t + 3 <= planes[p].size(); t += 3)
                {
                    const glm::vec3 a = m.leafVertices[planes[p][t]].position, b = m.leafVertices[planes[p][t + 1]].position,
                                    c = m.leafVertices[planes[p][t + 2]].position;
                    const glm::vec3 n = glm::cross(b - a, c - a);
                    normalSum += glm::dot(n, normalSum) < 0.0f ? -n : n; // length-weighted = area-weighted
                    weighted += 0.5f * glm::length(n) * (a + b + c) / 3.0f;
                    part.area += 0.5f * glm::length(n);
                }
                for (std::uint32_t v : planes[p])
                    if (std::find(vertices.begin(), vertices.end(), v) == vertices.end())
                    {
                        vertices.push_back(v);
                        part.uvMin = glm::min(part.uvMin, m.leafVertices[v].uv);
                        part.uvMax = glm::max(part.uvMax, m.leafVertices[v].uv);
                    }
                part.centre = part.area > 0.0f ? weighted / part.area : m.leafVertices[vertices[0]].position;
                part.normal = glm::length(normalSum) > 0.0f ? glm::normalize(normalSum) : m.leaves[i].normal;
                setCorners(m, vertices, part);
                parts[p].indices = std::move(planes[p]);
            }
            return parts;
        }

        /// Leaf `i` as a node: the four vertices nearest its texture rectangle's corners (or, for a
        /// leaf without a UV extent, nearest the corners of its extent in its own plane).
        Node originalNode(const TreeModel& m, std::size_t i)
        {
            const Leaf& leaf = m.leaves[i];
            Node node;
            node.centre = leaf.centre;
            node.normal = leaf.normal;
            node.uvMin = leaf.uvMin;
            node.uvMax = leaf.uvMax;
            std::vector<std::uint32_t> vertices(leaf.vertexCount);
            std::iota(vertices.begin(), vertices.end(), leaf.firstVertex);
            setCorners(m, vertices, node);
            float q = quadArea(m, node.corner);
            node.area = q > 1e-12f ? q : leaf.area;
            return node;
        }

        bool sameImage(const Node& a, const Node& b)
        {
            return glm::length(a.uvMin - b.uvMin) + glm::length(a.uvMax - b.uvMax) < 1e-4f;
        }

        float collapseCost(const Node& a, const Node& b, float meanArea)
        {
            const float area = a.area + b.area;
            const float size = std::sqrt(area);
            const float orient = 1.0f - std::abs(glm::dot(a.normal, b.normal));
            const float uv = sameImage(a, b) ? 0.0f : 1.0f;
            return (glm::length(a.centre - b.centre) + size * (orient + uv)) * std::sqrt(area / meanArea);
        }

        /// Weight of the corners' distance from the ideal leaf's corners (per corner, in leaf sizes)
        /// against quadScore when the corners are chosen among the cluster's vertices.
        constexpr float SHAPE_WEIGHT = 0.5f;

        /// The score of quad `q` as the leaf standing for `target` m^2 around `centre`: relative
        /// area miss + centre offset in leaf sizes + 4 when folded. Lower is better.
        float quadScore(const TreeModel& m, const std::array<std::uint32_t, 4>& q, float target,
                        const glm::vec3& centre)
        {
            const glm::vec3 p0 = m.leafVertices[q[0]].position, p1 = m.leafVertices[q[1]].position;
            const glm::vec3 p2 = m.leafVertices[q[2]].position, p3 = m.leafVertices[q[3]].position;
            const glm::vec3 n1 = glm::cross(p1 - p0, p2 - p0), n2 = glm::cross(p2 - p0, p3 - p0);
            const bool folded = glm::dot(n1, n2) <= 0.0f;
            return std::abs(quadArea(m, q) - target) / std::max(target, 1e-30f) +
                   glm::length(0.25f * (p0 + p1 + p2 + p3) - centre) / std::sqrt(std::max(target, 1e-30f)) +
                   (folded ? 4.0f : 0.0f);
        }

        /// eq. 1 and 3: the leaf that replaces a and b, on four existing vertices. Candidates: the
        /// 16 ways of taking each texture corner from a or from b (the paper's), and the quad whose
        /// corner r is, for each r, the corner-r vertex of an original leaf a and b replace nearest
        /// to corner r of the ideal leaf (the area A_a + A_b around the pair's centre, in the
        /// larger leaf's frame and aspect). Deviation (techniques/lodf/README.md): the paper's two leaves alone
        /// cannot reach that area a few collapses deep, and coarse levels thinned out.
        Node collapseLeaves(const TreeModel& m, const Node& a, const Node& b, const std::vector<Node>& nodes,
                            std::uint32_t originalCount, const glm::vec3* centreOf = nullptr)
        {
            const float target = a.area + b.area;
            const glm::vec3 centre =
                centreOf ? *centreOf : (a.centre * a.area + b.centre * b.area) / std::max(target, 1e-30f);
            float bestScore = std::numeric_limits<float>::max();
            Node out;
            out.corner = a.corner; // kept if every score is NaN (extreme coordinates)
            for (int mask = 0; mask < 16; ++mask)
            {
                std::array<std::uint32_t, 4> q;
                for (int r = 0; r < 4; ++r)
                    q[r] = (mask >> r) & 1 ? b.corner[r] : a.corner[r];
                const float score = quadScore(m, q, target, centre);
                if (score < bestScore)
                {
                    bestScore = score;
                    out.corner = q;
                }
            }
            // The ideal leaf: the larger leaf's texture axes (u: corner 0 -> 1, v: corner 0 -> 3) in
            // the plane of the mean normal, its aspect, area `target`.
            const Node& big = a.area >= b.area ? a : b;
            const auto pos = [&](std::uint32_t v) { return m.leafVertices[v].position; };
            glm::vec3 n = a.normal * a.area + (glm::dot(a.normal, b.normal) < 0.0f ? -b.normal : b.normal) * b.area;
            n = glm::length(n) > 1e-12f ? glm::normalize(n) : big.normal;
            const glm::vec3 eu = pos(big.corner[1]) - pos(big.corner[0]) + pos(big.corner[2]) - pos(big.corner[3]);
            const glm::vec3 ev = pos(big.corner[3]) - pos(big.corner[0]) + pos(big.corner[2]) - pos(big.corner[1]);
            glm::vec3 u = eu - n * glm::dot(eu, n);
            u = glm::length(u) > 1e-12f ? glm::normalize(u) : glm::vec3(0.0f);
            glm::vec3 v = ev - n * glm::dot(ev, n) - u * glm::dot(ev, u);
            if (glm::length(u) > 0.0f && glm::length(v) > 1e-12f)
            {
                const float aspect = std::clamp(glm::length(eu) / std::max(glm::length(ev), 1e-30f), 0.05f, 20.0f);
                const float hu = 0.5f * std::sqrt(target * aspect), hv = 0.5f * std::sqrt(target / aspect);
                u *= hu;
                v = glm::normalize(v) * hv;
                const glm::vec3 ideal[4] = {centre - u - v, centre + u - v, centre + u + v, centre - u + v};
                const Node& image = nodes[big.imageSource];
                std::array<std::uint32_t, 4> q = out.corner;
                for (int r = 0; r < 4; ++r)
                {
                    float nearest = std::numeric_limits<float>::max();
                    for (std::uint32_t source = 0; source < originalCount; ++source)
                        {
                            const Node& o = nodes[source];
                            if (!sameImage(o, image))
                                continue;
                            const float d = glm::length(pos(o.corner[r]) - ideal[r]);
                            if (d < nearest)
                            {
                                nearest = d;
                                q[r] = o.corner[r];
                            }
                        }
                }
                // Then each corner in turn moves to the candidate that scores best (two passes),
                // scored also by its distance from the ideal corners so the quad keeps the leaf's
                // shape and the image is not sheared.
                const auto shaped = [&](const std::array<std::uint32_t, 4>& t) {
                    float off = 0.0f;
                    for (int r = 0; r < 4; ++r)
                        off += glm::length(pos(t[r]) - ideal[r]);
                    return quadScore(m, t, target, centre) + SHAPE_WEIGHT * off / std::sqrt(std::max(target, 1e-30f));
                };
                float score = shaped(q);
                for (int pass = 0; pass < 2; ++pass)
                    for (int r = 0; r < 4; ++r)
                        for (std::uint32_t source = 0; source < originalCount; ++source)
                        {
                            const Node& o = nodes[source];
                            if (!sameImage(o, image) || o.corner[r] == q[r])
                                continue;
                            std::array<std::uint32_t, 4> t = q;
                            t[r] = o.corner[r];
                            if (const float st = shaped(t); st < score)
                            {
                                score = st;
                                q = t;
                            }
                        }
                if (quadScore(m, q, target, centre) < bestScore)
                    out.corner = q;
            }
            const glm::vec3 p0 = pos(out.corner[0]), p1 = pos(out.corner[1]), p2 = pos(out.corner[2]),
                            p3 = pos(out.corner[3]);
            out.centre = 0.25f * (p0 + p1 + p2 + p3);
            const glm::vec3 quadNormal = glm::cross(p2 - p0, p3 - p1);
            if (glm::length(quadNormal) > 1e-12f)
                out.normal = glm::normalize(glm::dot(quadNormal, n) < 0.0f ? -quadNormal : quadNormal);
            else
                out.normal = n;
            out.area = target;
            out.uvMin = sameImage(a, b) ? a.uvMin : glm::min(a.uvMin, b.uvMin);
            out.uvMax = sameImage(a, b) ? a.uvMax : glm::max(a.uvMax, b.uvMax);
            out.imageSource = a.imageSource;
            return out;
        }

        /// The cluster's originals grouped into leaves of several planes: the planes of one mesh
        /// (`leafOf`: the same model leaf) and crossed leaves (a plain leaf is a group of one;
        /// without `crossed`, every original), each group in increasing node order, groups by
        /// their first node.
        std::vector<std::vector<std::uint32_t>> crossedGroups(const std::vector<Node>& nodes,
                                                              const std::vector<std::uint32_t>& leafOf, bool crossed)
        {
            const std::uint32_t n = std::uint32_t(leafOf.size());
            std::vector<std::uint32_t> group(n);
            std::iota(group.begin(), group.end(), 0u);
            for (std::uint32_t i = 0; i < n && crossed; ++i)
                for (std::uint32_t j = i + 1; j < n; ++j)
                {
                    const Node& a = nodes[i];
                    const Node& b = nodes[j];
                    const bool oneMesh = leafOf[i] == leafOf[j];
                    if (group[j] != j ||
                        (!oneMesh && (!sameImage(a, b) || std::abs(glm::dot(a.normal, b.normal)) >= CROSSED_PARALLEL ||
                                      !(glm::length(a.centre - b.centre) <
                                        CROSSED_CENTRE * std::sqrt(std::min(a.area, b.area))))))
                        continue;
                    group[j] = group[i];
                }
            std::vector<std::vector<std::uint32_t>> groups;
            std::vector<std::uint32_t> index(n, 0);
            for (std::uint32_t i = 0; i < n; ++i)
            {
                if (group[i] == i)
                {
                    index[i] = std::uint32_t(groups.size());
                    groups.emplace_back();
                }
                groups[index[group[i]]].push_back(i);
            }
            return groups;
        }

        /// The parts of `u` and `v` collapsed with each other: each part of the one with fewer
        /// parts (u on a tie) with the most parallel free part of the other, in order.
        std::vector<std::pair<std::uint32_t, std::uint32_t>> matchParts(const std::vector<Node>& nodes,
                                                                        const std::vector<std::uint32_t>& u,
                                                                        const std::vector<std::uint32_t>& v)
        {
            const bool swap = v.size() < u.size();
            const std::vector<std::uint32_t>& few = swap ? v : u;
            const std::vector<std::uint32_t>& many = swap ? u : v;
            std::vector<char> used(many.size(), 0);
            std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
            for (std::uint32_t a : few)
            {
                std::size_t best = 0;
                float bestDot = -1.0f;
                for (std::size_t k = 0; k < many.size(); ++k)
                    if (!used[k])
                    {
                        const float d = std::abs(glm::dot(nodes[a].normal, nodes[many[k]].normal));
                        if (d > bestDot)
                        {
                            bestDot = d;
                            best = k;
                        }
                    }
                used[best] = 1;
                pairs.push_back(swap ? std::make_pair(many[best], a) : std::make_pair(a, many[best]));
            }
            return pairs;
        }

        /// The cost of collapsing two crossed leaves: the largest of their part pairs' (a plain
        /// leaf's is collapseCost).
        float groupCost(const std::vector<Node>& nodes, const std::vector<std::uint32_t>& u,
                        const std::vector<std::uint32_t>& v, float meanArea)
        {
            if (u.size() == 1 && v.size() == 1)
                return collapseCost(nodes[u[0]], nodes[v[0]], meanArea);
            float cost = 0.0f;
            for (const auto& [a, b] : matchParts(nodes, u, v))
                cost = std::max(cost, collapseCost(nodes[a], nodes[b], meanArea));
            return cost;
        }

        /// §3 / FSA: collapse the cheapest pair until one leaf is left. Crossed leaves collapse as
        /// one, part with part (matchParts), so they stay crossed; only the cluster's last
        /// collapses merge the parts of its one remaining crossed leaf. The planes of a leaf that
        /// is one mesh (units of one model leaf) are such parts too, each later one centred where
        /// its own pair lies rather than on the first. Row minima make it O(n^2) per cluster in
        /// practice.
        void simplifyCluster(const TreeModel& m, const std::vector<Unit>& units, ClusterBuild& cluster,
                             float meanArea, bool crossed)
        {
            const std::uint32_t n = std::uint32_t(cluster.leaves.size());
            std::vector<std::uint32_t> leafOf(n);
            for (std::uint32_t i = 0; i < n; ++i)
            {
                cluster.nodes.push_back(units[cluster.leaves[i]].node);
                cluster.nodes.back().imageSource = i;
                leafOf[i] = units[cluster.leaves[i]].leaf;
            }
            if (n < 2)
                return;
            float running = 0.0f;
            auto collapse = [&](std::uint32_t a, std::uint32_t b, float cost, const glm::vec3* centre = nullptr) {
                Node merged = collapseLeaves(m, cluster.nodes[a], cluster.nodes[b], cluster.nodes, n, centre);
                cluster.nodes.push_back(std::move(merged));
                running = std::max(running, cost);
                cluster.collapses.push_back({a, b, running});
                return std::uint32_t(cluster.nodes.size() - 1);
            };
            // slot -> the parts (node ids) of a crossed or plain leaf; a collapse puts the new leaf
            // in the slot of `a` and frees `b`'s.
            std::vector<std::vector<std::uint32_t>> slot = crossedGroups(cluster.nodes, leafOf, crossed);
            const std::uint32_t S = std::uint32_t(slot.size());
            // A slot whose parts all come from one mesh: its later parts keep their own centres.
            std::vector<char> oneMesh(S, 0);
            for (std::uint32_t k = 0; k < S; ++k)
                oneMesh[k] = slot[k].size() > 1 && std::all_of(slot[k].begin(), slot[k].end(), [&](std::uint32_t p) {
                                 return leafOf[p] == leafOf[slot[k][0]];
                             });
            std::vector<char> alive(S, 1);
            std::vector<float> cost(std::size_t(S) * S, 0.0f);
            auto at = [&](std::uint32_t i, std::uint32_t j) -> float& { return cost[std::size_t(i) * S + j]; };
            for (std::uint32_t i = 0; i < S; ++i)
                for (std::uint32_t j = i + 1; j < S; ++j)
                    at(i, j) = at(j, i) = groupCost(cluster.nodes, slot[i], slot[j], meanArea);
            std::vector<std::uint32_t> best(S);
            auto refreshRow = [&](std::uint32_t i) {
                float v = std::numeric_limits<float>::max();
                std::uint32_t b = i;
                for (std::uint32_t j = 0; j < S; ++j)
                    if (j != i && alive[j] && at(i, j) < v)
                    {
                        v = at(i, j);
                        b = j;
                    }
                best[i] = b;
            };
            for (std::uint32_t i = 0; i < S; ++i)
                refreshRow(i);
            for (std::uint32_t step = 1; step < S; ++step)
            {
                std::uint32_t bi = S, bj = S;
                float bv = std::numeric_limits<float>::max();
                for (std::uint32_t i = 0; i < S; ++i)
                    if (alive[i] && best[i] != i && at(i, best[i]) < bv)
                    {
                        bv = at(i, best[i]);
                        bi = i;
                        bj = best[i];
                    }
                if (bi == S)
                {
                    // Every cost NaN or infinite (finite but extreme coordinates): collapse the
                    // first two live leaves, the structure stays valid.
                    bi = std::uint32_t(std::find(alive.begin(), alive.end(), 1) - alive.begin());
                    bj = std::uint32_t(std::find(alive.begin() + bi + 1, alive.end(), 1) - alive.begin());
                    bv = std::numeric_limits<float>::max();
                }
                if (bi > bj)
                    std::swap(bi, bj);
                // Matched parts collapse (one step each); the larger leaf's unmatched parts stay.
                const auto pairs = matchParts(cluster.nodes, slot[bi], slot[bj]);
                // Later parts are centred where the first one came to lie, so the leaf stays crossed.
                std::vector<std::uint32_t> parts;
                const bool ownCentres = oneMesh[bi] || oneMesh[bj];
                for (const auto& [a, b] : pairs)
                {
                    const glm::vec3 first = parts.empty() ? glm::vec3(0.0f) : cluster.nodes[parts[0]].centre;
                    parts.push_back(collapse(a, b, bv, parts.empty() || ownCentres ? nullptr : &first));
                }
                for (const std::vector<std::uint32_t>* side : {&slot[bi], &slot[bj]})
                    for (std::uint32_t p : *side)
                        if (std::none_of(pairs.begin(), pairs.end(),
                                         [&](const auto& q) { return q.first == p || q.second == p; }))
                            parts.push_back(p);
                slot[bi] = std::move(parts);
                oneMesh[bi] = char(ownCentres);
                slot[bj].clear();
                alive[bj] = 0;
                for (std::uint32_t k = 0; k < S; ++k)
                    if (alive[k] && k != bi)
                        at(bi, k) = at(k, bi) = groupCost(cluster.nodes, slot[bi], slot[k], meanArea);
                refreshRow(bi);
                for (std::uint32_t k = 0; k < S; ++k)
                {
                    if (!alive[k] || k == bi)
                        continue;
                    if (best[k] == bi || best[k] == bj)
                        refreshRow(k);
                    else if (at(k, bi) < at(k, best[k]))
                        best[k] = bi;
                }
            }
            // The last crossed leaf's parts, cheapest pair first, down to one leaf.
            std::vector<std::uint32_t>& last = slot[std::uint32_t(std::find(alive.begin(), alive.end(), 1) - alive.begin())];
            while (last.size() > 1)
            {
                std::size_t bi = 0, bj = 1;
                float bv = std::numeric_limits<float>::max();
                for (std::size_t i = 0; i < last.size(); ++i)
                    for (std::size_t j = i + 1; j < last.size(); ++j)
                        if (const float c = collapseCost(cluster.nodes[last[i]], cluster.nodes[last[j]], meanArea); c < bv)
                        {
                            bv = c;
                            bi = i;
                            bj = j;
                        }
                last[bi] = collapse(last[bi], last[bj], bv);
                last.erase(last.begin() + std::ptrdiff_t(bj));
            }
        }

        /// §3.1: spatially compact clusters of at most `size` leaves (median splits).
        void splitClusters(const std::vector<Unit>& units, std::vector<std::uint32_t> leaves, std::uint32_t size,
                           std::uint32_t material, std::vector<ClusterBuild>& out)
        {
            if (leaves.size() <= size)
            {
                ClusterBuild c;
                c.material = material;
                c.leaves = std::move(leaves);
                out.push_back(std::move(c));
                return;
            }
            glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
            for (std::uint32_t i : leaves)
            {
                lo = glm::min(lo, units[i].node.centre);
                hi = glm::max(hi, units[i].node.centre);
            }
            const glm::vec3 e = hi - lo;
            const int axis = e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
            // Split at a multiple of `size` near the middle so clusters stay full.
            const std::size_t blocks = (leaves.size() + size - 1) / size;
            const std::size_t half = (blocks / 2) * size;
            std::nth_element(leaves.begin(), leaves.begin() + std::ptrdiff_t(half), leaves.end(),
                             [&](std::uint32_t a, std::uint32_t b) {
                                 float ca = units[a].node.centre[axis], cb = units[b].node.centre[axis];
                                 return ca < cb || (ca == cb && a < b);
                             });
            std::vector<std::uint32_t> right(leaves.begin() + std::ptrdiff_t(half), leaves.end());
            leaves.resize(half);
            splitClusters(units, std::move(leaves), size, material, out);
            splitClusters(units, std::move(right), size, material, out);
        }

        std::uint64_t mix64(std::uint64_t x)
        {
            x += 0x9e3779b97f4a7c15ull;
            x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
            x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
            return x ^ (x >> 31);
        }
    }

    Result<FoliageLodData> buildFoliageLod(const TreeModel& model, const FoliageLodOptions& options,
                                           const std::string& label, const ProgressCallback& progress)
    {
        if (options.clusterSize < 1 || options.clusterSize > 4096)
            return fail(label, "lodf option clusterSize", std::to_string(options.clusterSize) + " is not in 1..4096");
        if (options.costBands > 64)
            return fail(label, "lodf option costBands", std::to_string(options.costBands) + " is not in 0..64");
        Result<void> valid = model.validate(label);
        if (!valid)
            return valid.error();
        // The originals: leaves, and with crossedLeaves each plane of a leaf in several planes.
        std::vector<Unit> units;
        std::vector<std::uint32_t> unitIndices;
        units.reserve(model.leaves.size());
        for (std::uint32_t i = 0; i < model.leaves.size(); ++i)
        {
            const Leaf& leaf = model.leaves[i];
            std::vector<PlanePart> parts;
            if (options.crossedLeaves)
                parts = planeParts(model, i);
            if (parts.empty())
            {
                Unit u{i, std::uint32_t(unitIndices.size()), leaf.indexCount, originalNode(model, i)};
                unitIndices.insert(unitIndices.end(), model.leafIndices.begin() + leaf.firstIndex,
                                   model.leafIndices.begin() + leaf.firstIndex + leaf.indexCount);
                units.push_back(std::move(u));
            }
            for (PlanePart& part : parts)
            {
                units.push_back({i, std::uint32_t(unitIndices.size()), std::uint32_t(part.indices.size()), part.node});
                unitIndices.insert(unitIndices.end(), part.indices.begin(), part.indices.end());
            }
        }
        const std::uint32_t L = std::uint32_t(units.size());
        FoliageLodData data;
        data.originalLeafCount = L;
        data.leafVertexCount = std::uint32_t(model.leafVertices.size());
        if (L == 0)
            return data;

        // §3.1: independent groups, per material, then in spatial order.
        std::vector<std::vector<std::uint32_t>> byMaterial(model.materials.size());
        for (std::uint32_t i = 0; i < L; ++i)
            byMaterial[model.leaves[units[i].leaf].material].push_back(i);
        std::vector<ClusterBuild> clusters;
        for (std::uint32_t mat = 0; mat < byMaterial.size(); ++mat)
            if (!byMaterial[mat].empty())
                splitClusters(units, std::move(byMaterial[mat]), options.clusterSize, mat, clusters);

        double areaSum = 0.0;
        for (const Unit& u : units)
            areaSum += u.node.area;
        const float meanArea = float(std::max(areaSum / L, 1e-20));

        // §3 / FSA, cluster by cluster in parallel (each cluster's result depends on it alone).
        std::atomic<std::size_t> done{0};
        const std::size_t batch = 256;
        for (std::size_t first = 0; first < clusters.size(); first += batch)
        {
            const std::size_t last = std::min(clusters.size(), first + batch);
            tbb::parallel_for(first, last, [&](std::size_t c) { simplifyCluster(model, units, clusters[c], meanArea, options.crossedLeaves);
            });
            done = last;
            report(progress, "lodf collapse", float(done) / float(clusters.size()));
        }

        // Fig. 8: Changed_group by cost band, then cluster (pseudo-random order), then step.
        struct Order
        {
            std::uint32_t band, rank, cluster, step;
        };
        std::vector<float> costs;
        for (const ClusterBuild& c : clusters)
            for (const Collapse& k : c.collapses)
                costs.push_back(k.cost);
        std::sort(costs.begin(), costs.end());
        std::vector<float> bandEnd; // upper bounds of bands 0..B-2
        for (std::uint32_t b = 1; b < options.costBands && !costs.empty(); ++b)
            bandEnd.push_back(costs[std::min(costs.size() - 1, costs.size() * b / options.costBands)]);
        std::vector<Order> order;
        order.reserve(costs.size());
        for (std::uint32_t c = 0; c < clusters.size(); ++c)
            for (std::uint32_t s = 0; s < clusters[c].collapses.size(); ++s)
            {
                const float cost = clusters[c].collapses[s].cost;
                const auto band = std::uint32_t(std::upper_bound(bandEnd.begin(), bandEnd.end(), cost) - bandEnd.begin());
                // costBands 0: the paper's pure cost order (rank = the cost's bits, monotone for
                // non-negative floats); else the band's clusters in a fixed pseudo-random order.
                std::uint32_t costBits;
                std::memcpy(&costBits, &cost, 4);
                if (options.costBands == 0)
                    order.push_back({0, std::isfinite(cost) ? costBits : 0x7f800000u, c, s});
                else
                    order.push_back({band, std::uint32_t(mix64(c) >> 32), c, s});
            }
        std::sort(order.begin(), order.end(), [](const Order& x, const Order& y) {
            return std::tie(x.band, x.rank, x.cluster, x.step) < std::tie(y.band, y.rank, y.cluster, y.step);
        });
        // Global numbers of created leaves: L + position in Changed_group (Fig. 6 numbering).
        std::vector<std::vector<std::uint32_t>> createdNumber(clusters.size());
        for (std::uint32_t c = 0; c < clusters.size(); ++c)
            createdNumber[c].resize(clusters[c].collapses.size());
        data.changedGroup.reserve(order.size());
        for (std::uint32_t i = 0; i < order.size(); ++i)
        {
            data.changedGroup.push_back(order[i].cluster);
            createdNumber[order[i].cluster][order[i].step] = L + i;
        }

        // §3.2, Fig. 7: each cluster's array in removal order, root last.
        for (std::uint32_t c = 0; c < clusters.size(); ++c)
        {
            const ClusterBuild& b = clusters[c];
            const std::uint32_t n = std::uint32_t(b.leaves.size());
            FoliageLodCluster k;
            k.material = b.material;
            k.firstEntry = std::uint32_t(data.entries.size());
            k.entryCount = 2 * n - 1;
            k.originalLeaves = n;
            k.firstSlot = data.slotCount();
            auto addEntry = [&](std::uint32_t node) {
                FoliageLodEntry e;
                e.firstIndex = std::uint32_t(data.indices.size());
                if (node < n)
                {
                    const Unit& u = units[b.leaves[node]];
                    e.leaf = b.leaves[node];
                    e.created = 0;
                    data.indices.insert(data.indices.end(), unitIndices.begin() + u.firstIndex,
                                        unitIndices.begin() + u.firstIndex + u.indexCount);
                    e.indexCount = u.indexCount;
                    k.slotCount += u.indexCount;
                }
                else
                {
                    const std::uint32_t step = node - n; // 0-based collapse that created it
                    e.leaf = createdNumber[c][step];
                    e.created = step + 1;
                    const auto& q = b.nodes[node].corner;
                    data.indices.insert(data.indices.end(), {q[0], q[1], q[2], q[0], q[2], q[3]});
                    e.indexCount = 6;
                }
                data.entries.push_back(e);
            };
            for (const Collapse& col : b.collapses)
            {
                addEntry(col.a);
                addEntry(col.b);
            }
            addEntry(n == 1 ? 0 : std::uint32_t(b.nodes.size() - 1));
            data.clusters.push_back(k);
        }
        Result<void> ok = data.validate(label);
        if (!ok)
            return ok.error();
        return data;
    }

    TreeModel foliageLodModel(const TreeModel& model, const FoliageLodData& data, std::uint32_t leafCount)
    {
        TreeModel out = model;
        out.leafVertices.clear();
        out.leafIndices.clear();
        out.leaves.clear();
        const FoliageLodState state = FoliageLodState::fromScratch(data, leafCount);
        std::vector<std::uint32_t> remap(model.leafVertices.size(), ~0u);
        for (std::uint32_t c = 0; c < data.clusters.size(); ++c)
            state.forEachActive(c, [&](const FoliageLodEntry& e) {
                Leaf leaf;
                leaf.material = data.clusters[c].material;
                leaf.firstVertex = std::uint32_t(out.leafVertices.size());
                leaf.firstIndex = std::uint32_t(out.leafIndices.size());
                for (std::uint32_t i = e.firstIndex; i < e.firstIndex + e.indexCount; ++i)
                {
                    const std::uint32_t v = data.indices[i];
                    if (remap[v] == ~0u || remap[v] < leaf.firstVertex)
                    {
                        remap[v] = std::uint32_t(out.leafVertices.size());
                        out.leafVertices.push_back(model.leafVertices[v]);
                    }
                    out.leafIndices.push_back(remap[v]);
                }
                leaf.vertexCount = std::uint32_t(out.leafVertices.size()) - leaf.firstVertex;
                leaf.indexCount = e.indexCount;
                out.leaves.push_back(leaf);
                out.updateLeafRecord(out.leaves.size() - 1);
            });
        out.updateBounds();
        return out;
    }

    Result<void> addFoliageLodChunk(PackageWriter& writer, const TreeModel& model, const FoliageLodOptions& options,
                                    const std::string& label, const ProgressCallback& progress)
    {
        return addBakedChunk(writer, model, label, progress, FOLIAGE_LOD_CHUNK, FOLIAGE_LOD_CHUNK_FORMAT_VERSION,
                             encodeFoliageLodChunk, [&]() { return buildFoliageLod(model, options, label, progress); });
    }

    Result<void> addFoliageLodChunk(PackageWriter& writer, const TreeModel& model, const std::string& label,
                                    const ProgressCallback& progress)
    {
        return addFoliageLodChunk(writer, model, FoliageLodOptions{}, label, progress);
    }
}
