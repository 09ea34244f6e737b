#include "TreeLod/LeafExtraction.h"

#include <algorithm>
#include <cstring>
#include <numeric>

namespace TreeLod
{
    namespace detail
    {
        namespace
        {
            constexpr std::uint32_t kNone = 0xffffffffu;

            /// Disjoint sets over vertex ids: path halving, roots link to the smaller id so
            /// the result does not depend on the order of unions.
            class UnionFind
            {
            public:
                explicit UnionFind(std::size_t n) : mParent(n) { std::iota(mParent.begin(), mParent.end(), 0u); }

                std::uint32_t find(std::uint32_t x)
                {
                    while (mParent[x] != x)
                    {
                        mParent[x] = mParent[mParent[x]];
                        x = mParent[x];
                    }
                    return x;
                }

                void unite(std::uint32_t a, std::uint32_t b)
                {
                    a = find(a);
                    b = find(b);
                    if (a == b)
                        return;
                    if (a < b)
                        mParent[b] = a;
                    else
                        mParent[a] = b;
                }

            private:
                std::vector<std::uint32_t> mParent;
            };

            /// Float bits with -0 folded onto +0, so that equal values give equal keys.
            std::uint32_t floatKey(float f)
            {
                if (f == 0.0f)
                    f = 0.0f;
                std::uint32_t bits;
                std::memcpy(&bits, &f, sizeof bits);
                return bits;
            }

            std::uint64_t mix(std::uint64_t h, std::uint64_t v)
            {
                // splitmix64 finaliser over a running combination
                h ^= v + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
                h ^= h >> 30;
                h *= 0xbf58476d1ce4e5b9ull;
                h ^= h >> 27;
                h *= 0x94d049bb133111ebull;
                h ^= h >> 31;
                return h;
            }

            /// Group the items 0..n-1 by `groupOf[item]` (0..groupCount-1), keeping item order
            /// inside a group: returns offsets (groupCount + 1) and the items.
            void bucket(const std::vector<std::uint32_t>& groupOf, std::size_t groupCount,
                        std::vector<std::uint32_t>& offsets, std::vector<std::uint32_t>& items)
            {
                offsets.assign(groupCount + 1, 0);
                for (std::uint32_t g : groupOf)
                    ++offsets[g + 1];
                for (std::size_t g = 0; g < groupCount; ++g)
                    offsets[g + 1] += offsets[g];
                items.resize(groupOf.size());
                std::vector<std::uint32_t> cursor(offsets.begin(), offsets.end() - 1);
                for (std::uint32_t i = 0; i < groupOf.size(); ++i)
                    items[cursor[groupOf[i]]++] = i;
            }

            /// Number the components of the triangles' first corners in order of first triangle.
            std::size_t rankComponents(UnionFind& uf, const std::vector<std::uint32_t>& indices,
                                       std::size_t vertexCount, std::vector<std::uint32_t>& triangleGroup)
            {
                const std::size_t triangleCount = indices.size() / 3;
                std::vector<std::uint32_t> rankOfRoot(vertexCount, kNone);
                triangleGroup.resize(triangleCount);
                std::uint32_t next = 0;
                for (std::size_t t = 0; t < triangleCount; ++t)
                {
                    std::uint32_t root = uf.find(indices[3 * t]);
                    if (rankOfRoot[root] == kNone)
                        rankOfRoot[root] = next++;
                    triangleGroup[t] = rankOfRoot[root];
                }
                return next;
            }
        }

        LeafExtractionStats extractLeaves(const LeafSoup& soup, TreeModel& model,
                                          const ProgressCallback& progress)
        {
            LeafExtractionStats stats;
            const std::size_t vertexCount = soup.vertices.size();
            const std::size_t triangleCount = soup.indices.size() / 3;
            const std::vector<std::uint32_t>& idx = soup.indices;
            if (triangleCount == 0)
                return stats;

            // 1. Pieces: components by shared vertex index.
            UnionFind uf(vertexCount);
            for (std::size_t t = 0; t < triangleCount; ++t)
            {
                uf.unite(idx[3 * t], idx[3 * t + 1]);
                uf.unite(idx[3 * t], idx[3 * t + 2]);
            }
            std::vector<std::uint32_t> trianglePiece;
            const std::size_t pieceCount = rankComponents(uf, idx, vertexCount, trianglePiece);
            std::vector<std::uint32_t> pieceOffsets, pieceTriangles;
            bucket(trianglePiece, pieceCount, pieceOffsets, pieceTriangles);
            report(progress, "leaves", 0.2f);

            // 2. Copy number of each piece: how many earlier pieces have exactly its geometry.
            auto samePiece = [&](std::uint32_t a, std::uint32_t b)
            {
                std::uint32_t na = pieceOffsets[a + 1] - pieceOffsets[a];
                if (na != pieceOffsets[b + 1] - pieceOffsets[b])
                    return false;
                for (std::uint32_t k = 0; k < na; ++k)
                {
                    std::uint32_t ta = pieceTriangles[pieceOffsets[a] + k];
                    std::uint32_t tb = pieceTriangles[pieceOffsets[b] + k];
                    for (int c = 0; c < 3; ++c)
                        if (soup.vertices[idx[3 * ta + c]].position != soup.vertices[idx[3 * tb + c]].position)
                            return false;
                }
                return true;
            };
            std::vector<std::pair<std::uint64_t, std::uint32_t>> pieceHash(pieceCount);
            for (std::uint32_t p = 0; p < pieceCount; ++p)
            {
                std::uint64_t h = pieceOffsets[p + 1] - pieceOffsets[p];
                for (std::uint32_t k = pieceOffsets[p]; k < pieceOffsets[p + 1]; ++k)
                    for (int c = 0; c < 3; ++c)
                    {
                        const glm::vec3& q = soup.vertices[idx[3 * pieceTriangles[k] + c]].position;
                        h = mix(h, (std::uint64_t(floatKey(q.x)) << 32) | floatKey(q.y));
                        h = mix(h, floatKey(q.z));
                    }
                pieceHash[p] = {h, p};
            }
            std::sort(pieceHash.begin(), pieceHash.end());
            std::vector<std::uint32_t> pieceCopy(pieceCount, 0);
            {
                // Within a run of equal hashes (pieces in file order), keep one representative
                // per distinct geometry with the number of times it was seen.
                std::vector<std::pair<std::uint32_t, std::uint32_t>> seen; // representative, count
                for (std::size_t i = 0; i < pieceCount;)
                {
                    std::size_t j = i;
                    while (j < pieceCount && pieceHash[j].first == pieceHash[i].first)
                        ++j;
                    seen.clear();
                    for (std::size_t k = i; k < j; ++k)
                    {
                        std::uint32_t p = pieceHash[k].second;
                        bool found = false;
                        for (auto& s : seen)
                            if (samePiece(s.first, p))
                            {
                                pieceCopy[p] = s.second++;
                                found = true;
                                break;
                            }
                        if (!found)
                            seen.push_back({p, 1});
                    }
                    i = j;
                }
            }
            report(progress, "leaves", 0.4f);

            // 3. Weld equal positions of pieces with the same copy number (sort, not a map).
            struct WeldKey
            {
                std::uint32_t copy, x, y, z, vertex;
                bool sameSpot(const WeldKey& o) const { return copy == o.copy && x == o.x && y == o.y && z == o.z; }
                bool operator<(const WeldKey& o) const
                {
                    if (copy != o.copy)
                        return copy < o.copy;
                    if (x != o.x)
                        return x < o.x;
                    if (y != o.y)
                        return y < o.y;
                    if (z != o.z)
                        return z < o.z;
                    return vertex < o.vertex;
                }
            };
            std::vector<std::uint32_t> vertexCopy(vertexCount, kNone);
            for (std::size_t t = 0; t < triangleCount; ++t)
                for (int c = 0; c < 3; ++c)
                    vertexCopy[idx[3 * t + c]] = pieceCopy[trianglePiece[t]];
            std::vector<WeldKey> keys;
            keys.reserve(vertexCount);
            for (std::uint32_t v = 0; v < vertexCount; ++v)
                if (vertexCopy[v] != kNone)
                {
                    const glm::vec3& q = soup.vertices[v].position;
                    keys.push_back({vertexCopy[v], floatKey(q.x), floatKey(q.y), floatKey(q.z), v});
                }
            std::sort(keys.begin(), keys.end());
            for (std::size_t i = 1; i < keys.size(); ++i)
                if (keys[i].sameSpot(keys[i - 1]))
                    uf.unite(keys[i - 1].vertex, keys[i].vertex);
            report(progress, "leaves", 0.7f);

            // 4. Leaves in order of first triangle; copy their vertices and indices.
            std::vector<std::uint32_t> triangleLeaf;
            const std::size_t leafCount = rankComponents(uf, idx, vertexCount, triangleLeaf);
            std::vector<std::uint32_t> leafOffsets, leafTriangles;
            bucket(triangleLeaf, leafCount, leafOffsets, leafTriangles);

            std::vector<std::uint32_t> remap(vertexCount, kNone);
            model.leaves.reserve(model.leaves.size() + leafCount);
            for (std::size_t l = 0; l < leafCount; ++l)
            {
                const std::uint32_t* tris = leafTriangles.data() + leafOffsets[l];
                const std::uint32_t n = leafOffsets[l + 1] - leafOffsets[l];
                double area = 0.0;
                glm::dvec3 lo(soup.vertices[idx[3 * tris[0]]].position), hi = lo;
                for (std::uint32_t k = 0; k < n; ++k)
                {
                    const glm::dvec3 a(soup.vertices[idx[3 * tris[k]]].position);
                    const glm::dvec3 b(soup.vertices[idx[3 * tris[k] + 1]].position);
                    const glm::dvec3 c(soup.vertices[idx[3 * tris[k] + 2]].position);
                    area += 0.5 * glm::length(glm::cross(b - a, c - a));
                    lo = glm::min(lo, glm::min(a, glm::min(b, c)));
                    hi = glm::max(hi, glm::max(a, glm::max(b, c)));
                }
                const glm::dvec3 extent = hi - lo;
                const double side = std::max(extent.x, std::max(extent.y, extent.z));
                if (!(area > kDegenerateAreaRatio * side * side))
                {
                    ++stats.degenerate;
                    continue;
                }
                Leaf leaf;
                leaf.firstVertex = std::uint32_t(model.leafVertices.size());
                leaf.firstIndex = std::uint32_t(model.leafIndices.size());
                leaf.material = soup.triangleMaterial[tris[0]];
                for (std::uint32_t k = 0; k < n; ++k)
                    for (int c = 0; c < 3; ++c)
                    {
                        std::uint32_t v = idx[3 * tris[k] + c];
                        if (remap[v] == kNone)
                        {
                            remap[v] = std::uint32_t(model.leafVertices.size());
                            model.leafVertices.push_back(soup.vertices[v]);
                        }
                        model.leafIndices.push_back(remap[v]);
                    }
                leaf.vertexCount = std::uint32_t(model.leafVertices.size()) - leaf.firstVertex;
                leaf.indexCount = 3 * n;
                if (pieceCopy[trianglePiece[tris[0]]] > 0)
                    ++stats.duplicates;
                model.leaves.push_back(leaf);
                model.updateLeafRecord(model.leaves.size() - 1);
            }
            report(progress, "leaves", 1.0f);
            return stats;
        }
    }
}
