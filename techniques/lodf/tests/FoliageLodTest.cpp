// LoDF (Rebollo et al. 2006): the baker's F^r (eqs. 3, 5, 9), the "lodf" chunk, and the retrieval
// algorithms of §3.3 (eqs. 10-13) against independent recomputations, on tiny hand-made
// trees (the extremes), the bundled oak and generated trees up to 200k leaves.
#include "TreeLod/FoliageLodBaker.h"
#include "TreeLod/FoliageLodData.h"
#include "TreeLod/FoliageLodState.h"
#include "TreeLod/GltfImporter.h"
#include "TreeLod/Package.h"
#include "TreeLod/PackageWriter.h"
#include "TreeLod/TreeGenerator.h"
#include "TestTrees.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <limits>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <string>
#include <vector>

namespace TreeLod
{
    namespace
    {
        /// A leaf of quadLeaves(): a square quad of edge `size` at `centre` facing `normal`.
        struct LeafAt
        {
            glm::vec3 centre{0.0f};
            glm::vec3 normal{0.0f, 0.0f, 1.0f};
            float size = 0.2f;
            std::uint32_t material = 0; ///< leaf material index (0 .. max used)
        };

        /// Leaves as the generator makes them: 4 vertices + 6 indices each, UVs over the whole
        /// texture (0..1). Materials: leaf materials 0 .. max(material), then with `bark` a bark
        /// material and one bark triangle. Records and bounds updated.
        TreeModel quadLeaves(const std::vector<LeafAt>& leaves, bool bark = false)
        {
            TreeModel m;
            m.name = "quads";
            std::uint32_t leafMaterials = 1;
            for (const LeafAt& l : leaves)
                leafMaterials = std::max(leafMaterials, l.material + 1);
            for (std::uint32_t k = 0; k < leafMaterials; ++k)
                m.materials.push_back(test::leafMaterial("Leaves " + std::to_string(k)));
            for (const LeafAt& at : leaves)
            {
                const glm::vec3 n = glm::normalize(at.normal);
                const glm::vec3 u =
                    0.5f * at.size * glm::normalize(glm::cross(n, std::abs(n.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0)));
                test::addQuadLeaf(m, at.centre, u, glm::cross(n, u), n, at.material);
            }
            if (bark)
            {
                Material b;
                b.name = "Bark";
                m.materials.push_back(b);
                m.barkVertices = {{{0, 0, 0}, {0, 0, 1}, {0, 0}}, {{0.1f, 0, 0}, {0, 0, 1}, {1, 0}}, {{0, 1, 0}, {0, 0, 1}, {0, 1}}};
                m.barkIndices = {0, 1, 2};
                m.barkTriangleMaterial = {leafMaterials};
            }
            m.updateBounds();
            return m;
        }

        /// `n` leaves at random places (a 4 m cube at 3 m) and orientations, `materials` leaf
        /// materials in turn.
        std::vector<LeafAt> scatter(std::size_t n, std::uint32_t seed, std::uint32_t materials = 1)
        {
            std::mt19937 rng(seed);
            std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
            std::vector<LeafAt> out(n);
            // z, y, x in this order, named: the order of a call's arguments is unspecified.
            const auto draw = [&] {
                const float z = unit(rng);
                const float y = unit(rng);
                return glm::vec3(unit(rng), y, z);
            };
            for (std::size_t i = 0; i < n; ++i)
            {
                out[i].centre = glm::vec3(0.0f, 3.0f, 0.0f) + 2.0f * draw();
                out[i].normal = draw() + glm::vec3(0.0f, 0.01f, 0.0f);
                out[i].size = 0.1f + 0.05f * unit(rng);
                out[i].material = std::uint32_t(i % materials);
            }
            return out;
        }

        FoliageLodData buildOrFail(const TreeModel& m, const FoliageLodOptions& options = {})
        {
            Result<FoliageLodData> r = buildFoliageLod(m, options, "test tree");
            if (!r)
            {
                ADD_FAILURE() << r.error().message();
                return {};
            }
            return std::move(r).value();
        }

        /// Generated oak (seed 1, 32-texel texture), one per leaf count, built once per process.
        const TreeModel& generatedOak(std::uint32_t leaves)
        {
            static std::map<std::uint32_t, TreeModel> cache;
            auto it = cache.find(leaves);
            if (it == cache.end())
            {
                GeneratorOptions options;
                options.preset = TreePreset::Oak;
                options.leafCount = leaves;
                options.textureSize = 32;
                Result<TreeModel> m = generateTree(options);
                EXPECT_TRUE(m.ok()) << (m.ok() ? "" : m.error().message());
                it = cache.emplace(leaves, m.ok() ? std::move(m).value() : TreeModel()).first;
            }
            return it->second;
        }

        const FoliageLodData& generatedOakLod(std::uint32_t leaves)
        {
            static std::map<std::uint32_t, FoliageLodData> cache;
            auto it = cache.find(leaves);
            if (it == cache.end())
                it = cache.emplace(leaves, buildOrFail(generatedOak(leaves))).first;
            return it->second;
        }

        const TreeModel& bundledOak()
        {
            static const TreeModel model = [] {
                Result<TreeModel> m = importGltf(std::string(TREELOD_SOURCE_DIR) + "/media/oak.glb");
                EXPECT_TRUE(m.ok()) << (m.ok() ? "" : m.error().message());
                return m.ok() ? std::move(m).value() : TreeModel();
            }();
            return model;
        }

        void expectDataEqual(const FoliageLodData& a, const FoliageLodData& b)
        {
            EXPECT_EQ(a.originalLeafCount, b.originalLeafCount);
            EXPECT_EQ(a.leafVertexCount, b.leafVertexCount);
            ASSERT_EQ(a.clusters.size(), b.clusters.size());
            for (std::size_t c = 0; c < a.clusters.size(); ++c)
            {
                const FoliageLodCluster &x = a.clusters[c], &y = b.clusters[c];
                EXPECT_TRUE(x.material == y.material && x.firstEntry == y.firstEntry && x.entryCount == y.entryCount &&
                            x.originalLeaves == y.originalLeaves && x.firstSlot == y.firstSlot &&
                            x.slotCount == y.slotCount)
                    << "cluster " << c;
            }
            ASSERT_EQ(a.entries.size(), b.entries.size());
            for (std::size_t e = 0; e < a.entries.size(); ++e)
            {
                const FoliageLodEntry &x = a.entries[e], &y = b.entries[e];
                EXPECT_TRUE(x.leaf == y.leaf && x.created == y.created && x.firstIndex == y.firstIndex &&
                            x.indexCount == y.indexCount)
                    << "entry " << e;
            }
            EXPECT_EQ(a.indices, b.indices);
            EXPECT_EQ(a.changedGroup, b.changedGroup);
        }

        std::vector<std::uint32_t> entryIndices(const FoliageLodData& d, const FoliageLodEntry& e)
        {
            return {d.indices.begin() + e.firstIndex, d.indices.begin() + e.firstIndex + e.indexCount};
        }

        /// Collapses applied per cluster at `leafCount` (the first L - leafCount of Changed_group).
        std::vector<std::uint32_t> appliedCollapses(const FoliageLodData& d, std::uint32_t leafCount)
        {
            std::vector<std::uint32_t> applied(d.clusters.size(), 0);
            for (std::uint32_t i = 0; i < d.originalLeafCount - leafCount; ++i)
                ++applied[d.changedGroup[i]];
            return applied;
        }

        /// Active leaf numbers of cluster `c` after `steps` collapses, by replaying them on the
        /// binary tree: collapse s removes the pair at positions 2s - 2, 2s - 1 (Fig. 7 order) and
        /// adds the leaf created at step s. Sorted. Independent of FoliageLodState.
        std::vector<std::uint32_t> replayCut(const FoliageLodData& d, std::uint32_t c, std::uint32_t steps)
        {
            const FoliageLodCluster& k = d.clusters[c];
            std::set<std::uint32_t> active;
            std::vector<std::uint32_t> createdAt(k.originalLeaves, ~0u);
            for (std::uint32_t p = 0; p < k.entryCount; ++p)
            {
                const FoliageLodEntry& e = d.entries[k.firstEntry + p];
                if (e.created == 0)
                    active.insert(e.leaf);
                else
                    createdAt[e.created] = p;
            }
            for (std::uint32_t s = 1; s <= steps; ++s)
            {
                for (std::uint32_t p : {2 * s - 2, 2 * s - 1})
                    if (active.erase(d.entries[k.firstEntry + p].leaf) != 1)
                        ADD_FAILURE() << "cluster " << c << " step " << s << ": removes inactive position " << p;
                active.insert(d.entries[k.firstEntry + createdAt[s]].leaf);
            }
            return {active.begin(), active.end()};
        }

        /// Every cluster of `state` is what eqs. 10-13 give after `applied` collapses, its active
        /// leaves are the replayed cut, and usedSlots counts their indices.
        void expectStateIsCut(const FoliageLodState& state, bool replay)
        {
            const FoliageLodData& d = state.data();
            const std::vector<std::uint32_t> applied = appliedCollapses(d, state.leafCount());
            std::uint64_t sum = 0;
            for (std::uint32_t c = 0; c < d.clusters.size(); ++c)
            {
                const FoliageLodState::ClusterState& s = state.cluster(c);
                ASSERT_EQ(s.initGroup, 2 * applied[c]) << "cluster " << c;
                ASSERT_EQ(s.activeLeaves, d.clusters[c].originalLeaves - applied[c]) << "cluster " << c;
                ASSERT_EQ(s.changesNumber, 0) << "cluster " << c;
                sum += s.activeLeaves;
                if (!replay)
                    continue;
                std::vector<std::uint32_t> active;
                state.activeLeaves(c, active);
                ASSERT_EQ(active.size(), s.activeLeaves) << "cluster " << c;
                std::uint32_t used = 0;
                for (std::uint32_t p = 0; p < d.clusters[c].entryCount; ++p)
                {
                    const FoliageLodEntry& e = d.entries[d.clusters[c].firstEntry + p];
                    if (std::find(active.begin(), active.end(), e.leaf) != active.end())
                        used += e.indexCount;
                }
                ASSERT_EQ(s.usedSlots, used) << "cluster " << c;
                std::sort(active.begin(), active.end());
                ASSERT_EQ(active, replayCut(d, c, applied[c])) << "cluster " << c;
            }
            EXPECT_EQ(sum, state.leafCount());
        }

        /// Same per-cluster state, active leaves and position.
        void expectSameState(const FoliageLodState& a, const FoliageLodState& b)
        {
            ASSERT_EQ(a.leafCount(), b.leafCount());
            EXPECT_EQ(a.initPosition(), b.initPosition());
            for (std::uint32_t c = 0; c < a.data().clusters.size(); ++c)
                ASSERT_TRUE(a.cluster(c) == b.cluster(c)) << "cluster " << c << " at " << a.leafCount() << " leaves";
            EXPECT_EQ(a.activeLeaves(), b.activeLeaves());
        }

        double leafArea(const TreeModel& m)
        {
            double sum = 0.0;
            for (const Leaf& l : m.leaves)
                sum += l.area;
            return sum;
        }

        bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

        /// Every leaf of the LoDF model at `count` leaves has a finite record and some area.
        void expectFiniteLeaves(const TreeModel& m, const FoliageLodData& d, std::uint32_t count)
        {
            const TreeModel lod = foliageLodModel(m, d, count);
            ASSERT_TRUE(lod.validate()) << lod.validate().error().message();
            ASSERT_EQ(lod.leaves.size(), count);
            for (std::size_t i = 0; i < lod.leaves.size(); ++i)
            {
                const Leaf& l = lod.leaves[i];
                EXPECT_TRUE(finite(l.centre) && finite(l.normal) && std::isfinite(l.area)) << count << " leaves, leaf " << i;
                EXPECT_GT(l.area, 0.0f) << count << " leaves, leaf " << i;
            }
        }

        /// A tiny multi-cluster chunk: 20 leaves in clusters of at most 8 (3 clusters).
        const FoliageLodData& smallData()
        {
            static const FoliageLodData d = buildOrFail(quadLeaves(scatter(20, 3)), {8, 8});
            return d;
        }

        /// Decode must fail, naming the label, "lodf" and `element` (a substring of the element).
        void expectRejected(const std::vector<std::uint8_t>& bytes, const std::string& element, const std::string& reason)
        {
            Result<FoliageLodData> r = decodeFoliageLodChunk(bytes, "bad.treelod");
            ASSERT_FALSE(r.ok()) << element;
            EXPECT_EQ(r.error().file, "bad.treelod");
            EXPECT_NE(r.error().message().find("lodf"), std::string::npos) << r.error().message();
            EXPECT_NE(r.error().element.find(element), std::string::npos) << r.error().message();
            EXPECT_NE(r.error().reason.find(reason), std::string::npos) << r.error().message();
        }
    }

    // ---- the extremes, hand-made --------------------------------------------------------

    TEST(LodfBuild, oneLeafIsItsOwnCoarsestLevel)
    {
        // One leaf: one cluster, one entry, nothing to collapse. min = max = 1, so a target of
        // 0 clamps to 1 and changes nothing; the region is the leaf's own 6 indices.
        const TreeModel m = quadLeaves({{{0, 1, 0}, {0, 0, 1}}});
        ASSERT_TRUE(m.validate());
        const FoliageLodData d = buildOrFail(m);
        EXPECT_EQ(d.minLeafCount(), 1u);
        EXPECT_EQ(d.maxLeafCount(), 1u);
        ASSERT_EQ(d.clusters.size(), 1u);
        EXPECT_EQ(d.entries.size(), 1u);
        EXPECT_TRUE(d.changedGroup.empty());
        EXPECT_EQ(d.slotCount(), 6u);

        FoliageLodState s(d);
        EXPECT_EQ(s.setLeafCount(0), 0u);
        EXPECT_EQ(s.leafCount(), 1u);
        EXPECT_TRUE(s.changedClusters().empty());
        EXPECT_EQ(s.activeLeaves(), std::vector<std::uint32_t>{0});
        std::uint32_t region[6] = {};
        EXPECT_EQ(s.writeCluster(0, region), 6u);
        EXPECT_EQ(std::vector<std::uint32_t>(region, region + 6), m.leafIndices);

        Result<FoliageLodData> back = decodeFoliageLodChunk(encodeFoliageLodChunk(d), "one");
        ASSERT_TRUE(back) << back.error().message();
        expectDataEqual(d, *back);
    }

    TEST(LodfBuild, twoLeavesCollapseIntoOneOnTheirOwnVertices)
    {
        // Two leaves side by side: one collapse. At 1 leaf the active leaf is the created one,
        // numbered L + 0 = 2 (Fig. 6), a quad on 4 distinct vertices of the two originals (eq. 3:
        // no new vertex), taking corners from both so that it covers the pair. Back at 2 leaves
        // the originals return.
        const TreeModel m = quadLeaves({{{0, 1, 0}, {0, 0, 1}}, {{0.3f, 1, 0}, {0, 0, 1}}});
        ASSERT_TRUE(m.validate());
        const FoliageLodData d = buildOrFail(m);
        ASSERT_EQ(d.entries.size(), 3u);
        EXPECT_EQ(d.changedGroup, std::vector<std::uint32_t>{0});
        EXPECT_EQ(d.minLeafCount(), 1u);

        FoliageLodState s(d);
        EXPECT_EQ(s.setLeafCount(1), 1u);
        EXPECT_EQ(s.changedClusters(), std::vector<std::uint32_t>{0});
        ASSERT_EQ(s.activeLeaves(), std::vector<std::uint32_t>{2});
        EXPECT_EQ(s.cluster(0).initGroup, 2u);
        EXPECT_EQ(s.cluster(0).usedSlots, 6u);

        const FoliageLodEntry& created = d.entries[2];
        EXPECT_EQ(created.leaf, 2u);
        EXPECT_EQ(created.created, 1u);
        ASSERT_EQ(created.indexCount, 6u);
        const std::vector<std::uint32_t> q = entryIndices(d, created);
        const std::set<std::uint32_t> corners(q.begin(), q.end());
        EXPECT_EQ(corners.size(), 4u);
        EXPECT_LT(*corners.rbegin(), 8u); // only the originals' vertices exist
        EXPECT_LT(*corners.begin(), 4u);  // some from leaf 0 ...
        EXPECT_GE(*corners.rbegin(), 4u); // ... and some from leaf 1
        std::uint32_t region[12];
        EXPECT_EQ(s.writeCluster(0, region), 6u);
        EXPECT_EQ(std::vector<std::uint32_t>(region, region + 6), q);

        EXPECT_EQ(s.setLeafCount(2), 1u);
        std::vector<std::uint32_t> back = s.activeLeaves();
        std::sort(back.begin(), back.end());
        EXPECT_EQ(back, (std::vector<std::uint32_t>{0, 1}));
    }

    TEST(LodfBuild, treeWithoutLeavesGivesEmptyData)
    {
        // Bark only: no clusters, min = max = 0, every target is 0, the chunk round-trips and
        // the LoDF model keeps the bark.
        const TreeModel m = quadLeaves({}, true);
        ASSERT_TRUE(m.validate());
        const FoliageLodData d = buildOrFail(m);
        EXPECT_EQ(d.originalLeafCount, 0u);
        EXPECT_TRUE(d.clusters.empty() && d.entries.empty() && d.indices.empty() && d.changedGroup.empty());
        EXPECT_EQ(d.minLeafCount(), 0u);
        EXPECT_EQ(d.maxLeafCount(), 0u);
        EXPECT_EQ(d.slotCount(), 0u);
        EXPECT_TRUE(d.validate("empty"));

        FoliageLodState s(d);
        EXPECT_EQ(s.setLeafCount(10), 0u);
        EXPECT_EQ(s.leafCount(), 0u);
        EXPECT_TRUE(s.activeLeaves().empty());
        EXPECT_EQ(FoliageLodState::fromScratch(d, 5).leafCount(), 0u);

        Result<FoliageLodData> back = decodeFoliageLodChunk(encodeFoliageLodChunk(d), "empty");
        ASSERT_TRUE(back) << back.error().message();
        expectDataEqual(d, *back);

        const TreeModel lod = foliageLodModel(m, d, 0);
        EXPECT_TRUE(lod.leaves.empty());
        EXPECT_EQ(lod.barkIndices, m.barkIndices);
        EXPECT_TRUE(lod.validate());
    }

    TEST(LodfBuild, identicalLeavesCollapseWithoutNaN)
    {
        // 50 copies of one leaf: every collapse cost is 0 and every candidate quad is the same
        // leaf. It must still build a valid F^r whose leaves have finite records at every level.
        const TreeModel m = quadLeaves(std::vector<LeafAt>(50, LeafAt{{1, 2, 3}, {0.3f, 1, 0}}));
        ASSERT_TRUE(m.validate());
        const FoliageLodData d = buildOrFail(m);
        ASSERT_TRUE(d.validate("copies")) << d.validate("copies").error().message();
        EXPECT_EQ(d.minLeafCount(), 1u);
        for (std::uint32_t count = 1; count <= 50; ++count)
            expectFiniteLeaves(m, d, count);
    }

    TEST(LodfBuild, zeroAreaLeavesCollapseWithoutNaN)
    {
        // Leaves shrunk to points (area 0, so the mean area is 0): costs and created leaves must
        // stay finite. Only finiteness is checked, zero-area leaves stay zero-area.
        const TreeModel m = [] {
            std::vector<LeafAt> leaves = scatter(30, 5);
            for (LeafAt& l : leaves)
                l.size = 0.0f;
            return quadLeaves(leaves);
        }();
        ASSERT_TRUE(m.validate());
        const FoliageLodData d = buildOrFail(m);
        ASSERT_TRUE(d.validate("points"));
        for (std::uint32_t count : {30u, 15u, 1u})
        {
            const TreeModel lod = foliageLodModel(m, d, count);
            ASSERT_EQ(lod.leaves.size(), count);
            for (const Leaf& l : lod.leaves)
                EXPECT_TRUE(finite(l.centre) && finite(l.normal) && std::isfinite(l.area));
        }
    }

    TEST(LodfBuild, coplanarLeavesStayInTheirPlaneUnfolded)
    {
        // A 10 x 10 grid of leaves in the plane y = 2, all facing +Y: every created leaf lies in
        // that plane, faces +-Y, has area and is not folded (its two triangles face the same way,
        // the baker's "without folding").
        std::vector<LeafAt> grid;
        for (int i = 0; i < 10; ++i)
            for (int j = 0; j < 10; ++j)
                grid.push_back({{0.3f * float(i), 2.0f, 0.3f * float(j)}, {0, 1, 0}});
        const TreeModel m = quadLeaves(grid);
        ASSERT_TRUE(m.validate());
        const FoliageLodData d = buildOrFail(m);
        ASSERT_EQ(d.clusters.size(), 2u); // 100 leaves, clusters of 64 at most
        for (const FoliageLodEntry& e : d.entries)
        {
            if (e.created == 0)
                continue;
            const std::vector<std::uint32_t> q = entryIndices(d, e);
            ASSERT_EQ(q.size(), 6u);
            const glm::vec3 p0 = m.leafVertices[q[0]].position, p1 = m.leafVertices[q[1]].position;
            const glm::vec3 p2 = m.leafVertices[q[2]].position, p3 = m.leafVertices[q[5]].position;
            EXPECT_GT(glm::dot(glm::cross(p1 - p0, p2 - p0), glm::cross(p2 - p0, p3 - p0)), 0.0f) << "leaf " << e.leaf;
        }
        for (std::uint32_t count : {99u, 50u, 10u, 2u})
        {
            expectFiniteLeaves(m, d, count);
            for (const Leaf& l : foliageLodModel(m, d, count).leaves)
            {
                EXPECT_NEAR(std::abs(l.normal.y), 1.0f, 1e-5f);
                EXPECT_NEAR(l.centre.y, 2.0f, 1e-5f);
            }
        }
    }

    // ---- F^r: eqs. 3, 5, 9 ---------------------------------------------------------------

    TEST(LodfBuild, leafCountIsTwoLMinusClusters)
    {
        // eq. 5: |L^r| = 2L - 1 with one cluster (clusterSize >= L); with G clusters each one
        // stops at its own root, so |L^r| = 2L - G and Changed_group has L - G collapses. Two
        // leaf materials: no cluster mixes them and the clusters are sorted by material.
        const TreeModel m = quadLeaves(scatter(300, 1, 2));
        ASSERT_TRUE(m.validate());
        for (std::uint32_t size : {1u, 16u, 64u, 150u, 300u, 4096u})
        {
            SCOPED_TRACE("clusterSize " + std::to_string(size));
            const FoliageLodData d = buildOrFail(m, {size, 8});
            const std::uint32_t L = 300, G = std::uint32_t(d.clusters.size());
            EXPECT_GE(G, std::max(2u, (150 + size - 1) / size * 2)); // per material
            EXPECT_EQ(d.entries.size(), 2 * L - G);
            EXPECT_EQ(d.changedGroup.size(), L - G);
            EXPECT_EQ(d.minLeafCount(), G);
            EXPECT_EQ(d.slotCount(), 6 * L);
            EXPECT_EQ(d.indices.size(), 6 * std::size_t(2 * L - G));
            for (const FoliageLodCluster& k : d.clusters)
            {
                EXPECT_LE(k.originalLeaves, size);
                for (std::uint32_t p = 0; p < k.entryCount; ++p)
                {
                    const FoliageLodEntry& e = d.entries[k.firstEntry + p];
                    if (e.created == 0)
                    {
                        EXPECT_EQ(m.leaves[e.leaf].material, k.material);
                    }
                }
            }
        }
        // One material, one cluster: exactly the paper's worst case 2L - 1 (eq. 5, G = 1, eq. 6).
        const FoliageLodData one = buildOrFail(quadLeaves(scatter(300, 1)), {300, 8});
        EXPECT_EQ(one.clusters.size(), 1u);
        EXPECT_EQ(one.entries.size(), 2u * 300 - 1);
        EXPECT_EQ(one.changedGroup.size(), 299u);
    }

    TEST(LodfBuild, storageIsEq9ForTheBundledOak)
    {
        // eq. 9: 3V + 6|L^r| + 3G + |Changed_group| ~ 6.25 V for quad leaves (V = 4L); with G
        // clusters the exact count is 25L - 4G, within 5 % of 6.25 V. byteSize() counts the arrays
        // and the encoded chunk adds at most 64 bytes of counts and padding.
        const TreeModel& m = bundledOak();
        ASSERT_FALSE(m.leaves.empty());
        const FoliageLodData d = buildOrFail(m);
        const std::uint64_t L = d.originalLeafCount, G = d.clusters.size();
        ASSERT_EQ(d.leafVertexCount, 4 * L); // quad leaves, as eq. 4 assumes
        EXPECT_EQ(d.paperWords(), 25 * L - 4 * G);
        EXPECT_EQ(d.paperEq9Words(), 25 * L);
        EXPECT_NEAR(double(d.paperWords()) / double(d.paperEq9Words()), 1.0, 0.05);
        EXPECT_EQ(d.byteSize(), 24 * G + 16 * d.entries.size() + 4 * d.indices.size() + 4 * d.changedGroup.size());
        const std::size_t encoded = encodeFoliageLodChunk(d).size();
        EXPECT_GE(encoded, d.byteSize());
        EXPECT_LE(encoded, d.byteSize() + 64);
        std::cout << "[ lodf     ] oak.glb: L = " << L << ", G = " << G << ", paperWords = " << d.paperWords()
                  << ", eq. 9 = " << d.paperEq9Words() << ", byteSize = " << d.byteSize() << " B (" << d.byteSize() / L
                  << " B per leaf), chunk = " << encoded << " B\n";
        RecordProperty("byteSize", std::to_string(d.byteSize()));
    }

    namespace
    {
        /// eq. 3 and the numbering of Fig. 6 on real data: see the two tests below.
        void expectCreatedLeavesReuseVertices(const TreeModel& m, const FoliageLodData& d)
    {
        const std::uint32_t L = d.originalLeafCount;
        ASSERT_EQ(d.leafVertexCount, m.leafVertices.size());
        for (std::size_t i = 0; i < d.indices.size(); ++i)
            ASSERT_LT(d.indices[i], d.leafVertexCount) << "index " << i;
        std::vector<std::uint32_t> seen(L + d.changedGroup.size(), 0);
        // Collapse k of cluster c (k = 1, 2, ...) is its k-th entry in Changed_group.
        std::vector<std::uint32_t> stepOf(d.changedGroup.size());
        std::vector<std::uint32_t> perCluster(d.clusters.size(), 0);
        for (std::size_t i = 0; i < d.changedGroup.size(); ++i)
            stepOf[i] = ++perCluster[d.changedGroup[i]];
        for (std::uint32_t c = 0; c < d.clusters.size(); ++c)
        {
            const FoliageLodCluster& k = d.clusters[c];
            std::set<std::uint32_t> clusterVertices;
            for (std::uint32_t p = 0; p < k.entryCount; ++p)
            {
                const FoliageLodEntry& e = d.entries[k.firstEntry + p];
                ASSERT_LT(e.leaf, seen.size());
                ++seen[e.leaf];
                if (e.created != 0)
                    continue;
                const Leaf& leaf = m.leaves[e.leaf];
                ASSERT_EQ(entryIndices(d, e), std::vector<std::uint32_t>(m.leafIndices.begin() + leaf.firstIndex,
                                                                         m.leafIndices.begin() + leaf.firstIndex + leaf.indexCount));
                clusterVertices.insert(d.indices.begin() + e.firstIndex, d.indices.begin() + e.firstIndex + e.indexCount);
            }
            for (std::uint32_t p = 0; p < k.entryCount; ++p)
            {
                const FoliageLodEntry& e = d.entries[k.firstEntry + p];
                if (e.created == 0)
                    continue;
                ASSERT_GE(e.leaf, L);
                ASSERT_EQ(d.changedGroup[e.leaf - L], c) << "leaf " << e.leaf;
                ASSERT_EQ(stepOf[e.leaf - L], e.created) << "leaf " << e.leaf;
                ASSERT_EQ(e.indexCount, 6u);
                const std::vector<std::uint32_t> q = entryIndices(d, e);
                const std::set<std::uint32_t> corners(q.begin(), q.end());
                ASSERT_EQ(corners.size(), 4u) << "leaf " << e.leaf;
                // Its corners are vertices of its own cluster's original leaves.
                for (std::uint32_t v : corners)
                    ASSERT_TRUE(clusterVertices.count(v)) << "leaf " << e.leaf << " vertex " << v;
            }
        }
        for (std::size_t n = 0; n < seen.size(); ++n)
            ASSERT_EQ(seen[n], 1u) << "leaf number " << n;
    }
    }

    TEST(LodfBuild, createdLeavesUseOnlyVerticesOfTheirOwnCluster)
    {
        // eq. 3 (|V^r| = V): every index addresses the reference's leaf vertices; originals keep
        // their model indices; a created leaf is a quad on 4 distinct corners of its own
        // cluster's original leaves; leaf L + i is created by collapse i of
        // Changed_group in its cluster (Fig. 6), and every number appears once.
        expectCreatedLeavesReuseVertices(bundledOak(), buildOrFail(bundledOak()));
    }

    TEST(LodfBuild, createdLeavesUseOnlyVerticesOfTheirOwnClusterGenerated)
    {
        // Same on a generated 20k-leaf oak (many clusters, all cost bands).
        expectCreatedLeavesReuseVertices(generatedOak(20000), generatedOakLod(20000));
    }

    // ---- retrieval: eqs. 10-13 -------------------------------------------------------------

    TEST(LodfState, setLeafCountAppliesEqs10To13ToTheChangedClustersOnly)
    {
        // After each move: initGroup = 2 x collapses applied, activeLeaves = originals - applied
        // (recomputed from Changed_group), the active leaves are the cut obtained by replaying the
        // collapses on each binary tree, they sum to leafCount(); changedClusters() lists exactly
        // the clusters whose state differs from before, once each; targets are clamped both sides.
        const FoliageLodData& d = generatedOakLod(5000);
        ASSERT_EQ(d.originalLeafCount, 5000u);
        const std::uint32_t L = d.maxLeafCount(), lo = d.minLeafCount();
        FoliageLodState s(d);
        expectStateIsCut(s, true);
        const std::uint32_t targets[] = {L - 1, L - 10, L / 2, L / 2 + 1, L / 2 + 1, lo + 1, lo, 0, lo - 1, L / 3,
                                         L + 5, L, std::numeric_limits<std::uint32_t>::max(), L - 1000, 4000, 1234};
        for (std::uint32_t target : targets)
        {
            SCOPED_TRACE("target " + std::to_string(target));
            std::vector<FoliageLodState::ClusterState> before(d.clusters.size());
            for (std::uint32_t c = 0; c < d.clusters.size(); ++c)
                before[c] = s.cluster(c);
            const std::uint32_t n = s.setLeafCount(target);
            EXPECT_EQ(s.leafCount(), std::clamp(target, lo, L));
            EXPECT_EQ(s.initPosition(), L - s.leafCount());
            expectStateIsCut(s, true);

            std::vector<std::uint32_t> listed = s.changedClusters();
            EXPECT_EQ(n, listed.size());
            std::sort(listed.begin(), listed.end());
            EXPECT_EQ(std::unique(listed.begin(), listed.end()), listed.end()) << "a cluster listed twice";
            std::vector<std::uint32_t> differ;
            for (std::uint32_t c = 0; c < d.clusters.size(); ++c)
                if (!(before[c] == s.cluster(c)))
                    differ.push_back(c);
            EXPECT_EQ(listed, differ);
        }
        // Clamped both sides: below min gives min, above max gives max.
        s.setLeafCount(0);
        EXPECT_EQ(s.leafCount(), lo);
        EXPECT_GT(lo, 1u);
        s.setLeafCount(L + 1);
        EXPECT_EQ(s.leafCount(), L);
    }

    TEST(LodfState, tenThousandMovesEndWhereFromScratchIs)
    {
        // Drift: 10,000 moves in a row (small steps of 1..20 leaves and jumps anywhere, some
        // past the ends) must leave every cluster exactly as FoliageLodState::fromScratch builds
        // it at that count; checked along the way too.
        const FoliageLodData& d = generatedOakLod(20000);
        ASSERT_EQ(d.originalLeafCount, 20000u);
        const std::int64_t lo = d.minLeafCount(), hi = d.maxLeafCount();
        FoliageLodState s(d);
        std::mt19937 rng(20240611);
        std::uniform_int_distribution<int> kind(0, 9), step(1, 20);
        std::uniform_int_distribution<std::int64_t> anywhere(lo - 50, hi + 50);
        for (int i = 1; i <= 10000; ++i)
        {
            std::int64_t target = s.leafCount();
            const int k = kind(rng);
            if (k < 7)
                target += (k % 2 ? 1 : -1) * step(rng);
            else
                target = anywhere(rng);
            s.setLeafCount(std::uint32_t(std::max<std::int64_t>(target, 0)));
            ASSERT_EQ(s.leafCount(), std::uint32_t(std::clamp(target, lo, hi))) << "move " << i;
            if (i % 2500 == 0 || i == 1 || i == 333)
            {
                SCOPED_TRACE("move " + std::to_string(i));
                expectSameState(s, FoliageLodState::fromScratch(d, s.leafCount()));
            }
        }
        expectSameState(s, FoliageLodState::fromScratch(d, s.leafCount()));
        expectStateIsCut(s, true);
    }

    TEST(LodfState, writeClusterFillsActiveIndicesThenDegenerateTriangles)
    {
        // For uint16 and uint32: a region holds its active leaves' indices in array order, then
        // degenerate triangles (three equal indices) up to slotCount, nothing past it; the count
        // returned is usedSlots. Checked at several levels on every cluster.
        const FoliageLodData& d = generatedOakLod(5000);
        ASSERT_LE(d.leafVertexCount, 65536u);
        const std::uint32_t L = d.maxLeafCount();
        FoliageLodState s(d);
        for (std::uint32_t count : {L, L - 1, L * 3 / 5, L / 5, d.minLeafCount()})
        {
            s.setLeafCount(count);
            for (std::uint32_t c = 0; c < d.clusters.size(); ++c)
            {
                SCOPED_TRACE(std::to_string(count) + " leaves, cluster " + std::to_string(c));
                const FoliageLodCluster& k = d.clusters[c];
                std::vector<std::uint32_t> expected;
                std::vector<std::uint32_t> active;
                s.activeLeaves(c, active);
                for (std::uint32_t leaf : active)
                    for (std::uint32_t p = 0; p < k.entryCount; ++p)
                        if (d.entries[k.firstEntry + p].leaf == leaf)
                        {
                            const std::vector<std::uint32_t> q = entryIndices(d, d.entries[k.firstEntry + p]);
                            expected.insert(expected.end(), q.begin(), q.end());
                        }
                std::vector<std::uint32_t> r32(k.slotCount + 3, 0xdeadbeefu);
                std::vector<std::uint16_t> r16(k.slotCount + 3, 0xffffu);
                const std::uint32_t n32 = s.writeCluster(c, r32.data());
                const std::uint32_t n16 = s.writeCluster(c, r16.data());
                ASSERT_EQ(n32, s.cluster(c).usedSlots);
                ASSERT_EQ(n16, n32);
                ASSERT_EQ(n32, expected.size());
                ASSERT_EQ(std::vector<std::uint32_t>(r32.begin(), r32.begin() + n32), expected);
                ASSERT_EQ((k.slotCount - n32) % 3, 0u);
                for (std::uint32_t i = n32; i < k.slotCount; i += 3)
                {
                    ASSERT_TRUE(r32[i] == r32[i + 1] && r32[i] == r32[i + 2]) << "slot " << i;
                    ASSERT_LT(r32[i], d.leafVertexCount);
                }
                for (std::uint32_t i = 0; i < k.slotCount; ++i)
                    ASSERT_EQ(std::uint32_t(r16[i]), r32[i]) << "slot " << i;
                for (std::uint32_t i = k.slotCount; i < k.slotCount + 3; ++i)
                {
                    ASSERT_EQ(r32[i], 0xdeadbeefu) << "wrote past the region";
                    ASSERT_EQ(r16[i], 0xffffu) << "wrote past the region";
                }
            }
        }
    }

    TEST(LodfState, sweepOfA200kLeafTreeKeepsTheLeafCount)
    {
        // 200k leaves (the generator's maximum): 800k leaf vertices need 32-bit indices. A sweep
        // L -> min -> L in 100 steps each way keeps the clusters' active leaves summing to
        // leafCount() and their used slots inside the regions, and ends back at F_0.
        const TreeModel& m = generatedOak(200000);
        ASSERT_EQ(m.leaves.size(), 200000u);
        const FoliageLodData d = buildOrFail(m);
        ASSERT_TRUE(d.validate("200k")) << d.validate("200k").error().message();
        EXPECT_GT(d.leafVertexCount, 65535u);
        EXPECT_EQ(d.slotCount(), 6u * 200000);
        const std::uint32_t L = d.maxLeafCount(), lo = d.minLeafCount();
        const std::uint32_t step = (L - lo + 99) / 100;
        std::vector<std::uint32_t> targets;
        for (std::uint32_t i = 1; i <= 100; ++i)
            targets.push_back(L - std::min(L - lo, i * step));
        for (std::uint32_t i = 1; i <= 100; ++i)
            targets.push_back(lo + std::min(L - lo, i * step));
        FoliageLodState s(d);
        for (std::uint32_t target : targets)
        {
            EXPECT_GT(s.setLeafCount(target), 0u);
            ASSERT_EQ(s.leafCount(), target);
            std::uint64_t active = 0;
            for (std::uint32_t c = 0; c < d.clusters.size(); ++c)
            {
                active += s.cluster(c).activeLeaves;
                ASSERT_LE(s.cluster(c).usedSlots, d.clusters[c].slotCount);
            }
            ASSERT_EQ(active, s.leafCount()) << "target " << target;
        }
        EXPECT_EQ(targets[99], lo);
        expectSameState(s, FoliageLodState(d));
    }

    // ---- chunk "lodf" -------------------------------------------------------------------

    TEST(LodfChunk, roundTripKeepsEveryArray)
    {
        // Encode/decode gives the same clusters, entries, indices and Changed_group (two leaf
        // materials, many clusters), and encoding the result gives the same bytes.
        const FoliageLodData d = buildOrFail(quadLeaves(scatter(500, 9, 2)), {32, 4});
        ASSERT_GT(d.clusters.size(), 10u);
        const std::vector<std::uint8_t> bytes = encodeFoliageLodChunk(d);
        Result<FoliageLodData> back = decodeFoliageLodChunk(bytes, "trip");
        ASSERT_TRUE(back) << back.error().message();
        expectDataEqual(d, *back);
        EXPECT_EQ(encodeFoliageLodChunk(*back), bytes);
    }

    TEST(LodfChunk, truncatedOrTrailingBytesAreRejected)
    {
        // Every proper prefix fails (each part has a count and data); so do extra bytes at the
        // end. The element is the chunk.
        const std::vector<std::uint8_t> bytes = encodeFoliageLodChunk(smallData());
        for (std::size_t n = 0; n < bytes.size(); ++n)
        {
            Result<FoliageLodData> r = decodeFoliageLodChunk({bytes.begin(), bytes.begin() + std::ptrdiff_t(n)}, "cut");
            ASSERT_FALSE(r.ok()) << n << " of " << bytes.size() << " bytes";
            ASSERT_EQ(r.error().element, chunkElement(FOLIAGE_LOD_CHUNK, 0));
        }
        std::vector<std::uint8_t> trailing = bytes;
        trailing.insert(trailing.end(), 4, 0);
        expectRejected(trailing, chunkElement(FOLIAGE_LOD_CHUNK, 0), "trailing bytes");
    }

    TEST(LodfChunk, inconsistentContentIsRejectedNamingTheElement)
    {
        // Each invariant FoliageLodState relies on, broken once in a valid chunk.
        const FoliageLodData& good = smallData();
        ASSERT_EQ(good.clusters.size(), 3u);
        {
            FoliageLodData d = good; // a cluster whose entry count is not 2n - 1
            d.clusters[1].entryCount += 2;
            expectRejected(encodeFoliageLodChunk(d), "lodf cluster 1", "2n - 1");
        }
        {
            FoliageLodData d = good; // an index past the reference's leaf vertices
            d.indices[7] = d.leafVertexCount;
            expectRejected(encodeFoliageLodChunk(d), "lodf index 7", "out of range");
        }
        {
            FoliageLodData d = good; // Changed_group naming a cluster that does not exist
            d.changedGroup[3] = std::uint32_t(d.clusters.size());
            expectRejected(encodeFoliageLodChunk(d), "lodf Changed_group 3", "out of range");
        }
        {
            FoliageLodData d = good; // one collapse moved to another cluster: counts n - 1 broken
            const std::uint32_t from = d.changedGroup[0];
            const auto other = std::find_if(d.changedGroup.begin(), d.changedGroup.end(),
                                            [&](std::uint32_t c) { return c != from; });
            ASSERT_NE(other, d.changedGroup.end());
            const std::uint32_t to = *other;
            d.changedGroup[0] = to;
            expectRejected(encodeFoliageLodChunk(d), "lodf cluster " + std::to_string(std::min(from, to)),
                           "collapses in Changed_group");
        }
        {
            FoliageLodData d = good; // the original leaf count disagrees with the clusters
            d.originalLeafCount += 1;
            expectRejected(encodeFoliageLodChunk(d), "lodf", "header says");
        }
    }

    TEST(LodfChunk, randomByteFlipsNeverCrashDecode)
    {
        // 200 single-byte corruptions of a small chunk: decode returns an error or data that
        // validates and that FoliageLodState can walk with every region's used slots inside it.
        const std::vector<std::uint8_t> bytes = encodeFoliageLodChunk(smallData());
        std::mt19937 rng(77);
        std::uniform_int_distribution<std::size_t> where(0, bytes.size() - 1);
        std::uniform_int_distribution<int> mask(1, 255);
        int rejected = 0;
        for (int i = 0; i < 200; ++i)
        {
            std::vector<std::uint8_t> b = bytes;
            const std::size_t at = where(rng);
            b[at] = std::uint8_t(b[at] ^ mask(rng));
            Result<FoliageLodData> r = decodeFoliageLodChunk(b, "flip");
            if (!r)
            {
                ++rejected;
                EXPECT_FALSE(r.error().message().empty());
                continue;
            }
            ASSERT_TRUE(r->validate("flip"));
            FoliageLodState s(*r);
            for (std::uint32_t n = r->maxLeafCount(); n + 1 > r->minLeafCount() && n > 0; --n)
            {
                s.setLeafCount(n);
                for (std::uint32_t c = 0; c < r->clusters.size(); ++c)
                    ASSERT_LE(s.cluster(c).usedSlots, r->clusters[c].slotCount) << "flip at byte " << at;
            }
        }
        EXPECT_GT(rejected, 100); // most flips hit a checked field (165 of 200; an entry's leaf number is not one)
    }

    TEST(LodfChunk, createdLeafLargerThanItsRegionIsRejected)
    {
        // A created leaf with more indices than the leaves it replaces would make writeCluster
        // write past its cluster's region: validate() replays the steps and refuses it.
        FoliageLodData d = buildOrFail(quadLeaves({{{0, 1, 0}, {0, 0, 1}}, {{0.3f, 1, 0}, {0, 0, 1}}}));
        ASSERT_EQ(d.entries.size(), 3u);
        d.entries[2].firstIndex = 0;
        d.entries[2].indexCount = 18; // 3 leaves' worth, in range of the 18 stored indices
        ASSERT_EQ(d.indices.size(), 18u);
        Result<FoliageLodData> r = decodeFoliageLodChunk(encodeFoliageLodChunk(d), "big");
        EXPECT_FALSE(r.ok());
    }

    TEST(LodfBuild, extremeCoordinatesStillCollapseEveryLeaf)
    {
        // Finite positions that validate but overflow float in the baker (leaf areas of 1e40,
        // centres 6e38 apart): every collapse cost of a cluster is NaN or inf; the baker then
        // collapses the first live pair. The structure is the one the same leaves give at
        // ordinary coordinates: every leaf, one entry per leaf and per collapse, the same clusters
        // and collapse count.
        const std::vector<LeafAt> plain = scatter(10, 5);
        std::vector<LeafAt> big = plain, far = plain;
        for (LeafAt& l : big)
        {
            l.centre *= 1e19f;
            l.size = 1e20f;
        }
        for (std::size_t i = 0; i < far.size(); ++i)
            far[i].centre = glm::vec3(i % 2 ? 3e38f : -3e38f, 0.0f, 0.0f);
        Result<FoliageLodData> ordinary = buildFoliageLod(quadLeaves(plain));
        ASSERT_TRUE(ordinary.ok()) << ordinary.error().message();
        for (const std::vector<LeafAt>* leaves : {&big, &far})
        {
            const TreeModel m = quadLeaves(*leaves);
            ASSERT_TRUE(m.validate());
            Result<FoliageLodData> r = buildFoliageLod(m);
            ASSERT_TRUE(r.ok()) << r.error().message();
            EXPECT_TRUE(r->validate("extreme"));
            EXPECT_EQ(r->maxLeafCount(), 10u);
            EXPECT_EQ(r->minLeafCount(), ordinary->minLeafCount());
            EXPECT_EQ(r->entries.size(), ordinary->entries.size());
            EXPECT_EQ(r->changedGroup.size(), ordinary->changedGroup.size());
            EXPECT_EQ(r->indices.size(), ordinary->indices.size());
        }
    }

    // ---- baker: options, errors, determinism, coverage, package -----------------------------

    TEST(LodfBuild, optionsOutOfRangeAreErrorsNamingTheOption)
    {
        const TreeModel m = quadLeaves(scatter(10, 2));
        for (FoliageLodOptions o : {FoliageLodOptions{0, 8}, FoliageLodOptions{5000, 8}})
        {
            Result<FoliageLodData> r = buildFoliageLod(m, o, "opts");
            ASSERT_FALSE(r.ok());
            EXPECT_NE(r.error().element.find("clusterSize"), std::string::npos) << r.error().message();
            EXPECT_EQ(r.error().file, "opts");
        }
        for (FoliageLodOptions o : {FoliageLodOptions{64, 65}, FoliageLodOptions{64, 1000}})
        {
            Result<FoliageLodData> r = buildFoliageLod(m, o, "opts");
            ASSERT_FALSE(r.ok());
            EXPECT_NE(r.error().element.find("costBands"), std::string::npos) << r.error().message();
        }
        // The ends of the ranges are accepted (costBands 0 = the paper's pure cost order).
        for (FoliageLodOptions o : {FoliageLodOptions{1, 0}, FoliageLodOptions{4096, 64}})
            EXPECT_TRUE(buildFoliageLod(m, o).ok());
    }

    TEST(LodfBuild, invalidModelIsAnError)
    {
        // The model is validated first: a NaN position fails, naming the vertex.
        TreeModel m = quadLeaves(scatter(10, 2));
        m.leafVertices[5].position.y = std::numeric_limits<float>::quiet_NaN();
        Result<FoliageLodData> r = buildFoliageLod(m, {}, "nan.glb");
        ASSERT_FALSE(r.ok());
        EXPECT_EQ(r.error().file, "nan.glb");
        EXPECT_EQ(r.error().element, "leaf vertex 5");
    }

    TEST(LodfBuild, buildIsDeterministicWhateverTheThreadCount)
    {
        // Same model and options: byte-identical chunks, built twice and on one thread.
        const TreeModel& m = generatedOak(5000);
        const std::vector<std::uint8_t> first = encodeFoliageLodChunk(buildOrFail(m));
        EXPECT_EQ(encodeFoliageLodChunk(buildOrFail(m)), first);
        tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
        EXPECT_EQ(encodeFoliageLodChunk(buildOrFail(m)), first);
    }

    TEST(LodfBuild, coarserLevelsKeepMostOfTheCoveredArea)
    {
        // The baker's created leaves aim at the area of the leaves they replace (header, step 3),
        // so the crown stays covered as leaves disappear. Measured on oak.glb (3000 leaves, 47
        // clusters of <= 64): 94.7 % of the area at L/4, 48.8 % at the coarsest level (47
        // leaves; a cluster's vertices do not reach 64 leaves' area). Taking corners from the two
        // collapsing leaves only, as eq. 3 has it, kept 70.5 % and 38.0 %.
        const TreeModel& m = bundledOak();
        ASSERT_FALSE(m.leaves.empty());
        const FoliageLodData d = buildOrFail(m);
        const double full = leafArea(m);
        const std::uint32_t L = d.maxLeafCount();
        EXPECT_NEAR(leafArea(foliageLodModel(m, d, L)) / full, 1.0, 1e-4);
        const double quarter = leafArea(foliageLodModel(m, d, L / 4)) / full;
        const double coarsest = leafArea(foliageLodModel(m, d, d.minLeafCount())) / full;
        std::cout << "[ lodf     ] oak.glb covered area: " << quarter << " at L/4, " << coarsest << " at "
                  << d.minLeafCount() << " leaves\n";
        EXPECT_GE(quarter, 0.9);
        EXPECT_LE(quarter, 1.1);
        EXPECT_GE(coarsest, 0.45);
    }

    /// Share of the leaf area of `m` in leaves with another leaf in a different plane beside
    /// them: |n_a . n_b| < `parallel`, centres within `reach` leaf sizes.
    double shareBesideAnotherPlane(const TreeModel& m, float parallel, float reach)
    {
        double beside = 0.0, all = 0.0;
        for (std::size_t i = 0; i < m.leaves.size(); ++i)
        {
            const Leaf& a = m.leaves[i];
            all += a.area;
            for (std::size_t j = 0; j < m.leaves.size(); ++j)
            {
                const Leaf& b = m.leaves[j];
                if (j != i && std::abs(glm::dot(a.normal, b.normal)) < parallel &&
                    glm::length(a.centre - b.centre) < reach * std::sqrt(std::min(a.area, b.area)))
                {
                    beside += a.area;
                    break;
                }
            }
        }
        return all > 0.0 ? beside / all : 0.0;
    }

    /// Crossed leaves: another plane within half a leaf size (|n_a . n_b| < 0.7).
    double crossedShare(const TreeModel& m) { return shareBesideAnotherPlane(m, 0.7f, 0.5f); }

    TEST(LodfBuild, crossedLeavesCollapseIntoCrossedLeaves)
    {
        // 300 crossed leaves as ez-tree makes them ("double billboards": two 0.3 m quads through
        // one centre, the second turned 90 degrees about the vertical), random yaw, in a 3 m crown.
        // Collapsed part with part, more of them stay crossed and the covered area is kept. Created
        // leaves have no new vertices, so a part's quad lands where the cluster's vertices allow
        // and some parts drift apart. Measured (crossed share of the area / area kept, at L/2, L/4,
        // L/8): 0.59 / 0.98, 0.48 / 1.04, 0.25 / 0.85; collapsed leaf by leaf, as flat leaves are
        // (crossedLeaves false), 0.40 / 0.73, 0.06 / 0.83, 0.00 / 0.80.
        std::mt19937 rng(7);
        std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
        std::vector<LeafAt> leaves;
        while (leaves.size() < 600)
        {
            const glm::vec3 c(unit(rng), unit(rng), unit(rng));
            if (glm::length(c) > 1.0f)
                continue;
            const float yaw = 3.14159265f * unit(rng);
            leaves.push_back({3.0f * c + glm::vec3(0, 4, 0), {std::cos(yaw), 0.0f, std::sin(yaw)}, 0.3f});
            leaves.push_back({3.0f * c + glm::vec3(0, 4, 0), {-std::sin(yaw), 0.0f, std::cos(yaw)}, 0.3f});
        }
        const TreeModel m = quadLeaves(leaves);
        const FoliageLodData d = buildOrFail(m);
        ASSERT_TRUE(d.validate("crossed").ok());
        const std::uint32_t L = d.maxLeafCount();
        EXPECT_NEAR(crossedShare(foliageLodModel(m, d, L)), 1.0, 1e-9);
        const double full = leafArea(m);
        FoliageLodOptions flatOptions;
        flatOptions.crossedLeaves = false;
        const FoliageLodData flat = buildOrFail(m, flatOptions);
        ASSERT_EQ(flat.maxLeafCount(), L);
        // (The collapse order depends on float rounding, so other compiler flags give other
        // numbers: with ASan, 0.65 / 0.99, 0.40 / 1.03, 0.18 / 0.85 against 0.46 / 0.71, 0.10 /
        // 0.82, 0.08 / 0.83 as flat leaves. The bounds hold for both.)
        struct Bound
        {
            std::uint32_t count;
            double share, area, overFlat;
        };
        for (const Bound& b : {Bound{L / 2, 0.5, 0.9, 0.15}, Bound{L / 4, 0.35, 0.9, 0.15}, Bound{L / 8, 0.15, 0.82, 0.05}})
        {
            const TreeModel lod = foliageLodModel(m, d, b.count);
            const double share = crossedShare(lod), area = leafArea(lod) / full;
            std::cout << "[ lodf     ] crossed leaves at " << b.count << " of " << L << ": " << share
                      << " of the area crossed, area kept " << area << "\n";
            EXPECT_GE(share, b.share) << b.count;
            EXPECT_GE(area, b.area) << b.count;
            EXPECT_LE(area, 1.1) << b.count;
            const TreeModel flatLod = foliageLodModel(m, flat, b.count);
            const double flatShare = crossedShare(flatLod), flatArea = leafArea(flatLod) / full;
            std::cout << "[ lodf     ]   as flat leaves: " << flatShare << " crossed, area kept " << flatArea << "\n";
            EXPECT_GT(share, flatShare + b.overFlat) << b.count;
            EXPECT_GT(area, flatArea) << b.count;
        }
        // The coarsest level is one leaf per cluster.
        EXPECT_EQ(foliageLodModel(m, d, d.minLeafCount()).leaves.size(), d.clusters.size());
        expectFiniteLeaves(m, d, L / 4);
    }

    TEST(LodfBuild, aLoneCrossedLeafAndATripleCrossCollapseToOneLeafEach)
    {
        // Two quads crossing at one centre: one crossed leaf, whose parts merge in the last step.
        const TreeModel two = quadLeaves({{{0, 1, 0}, {1, 0, 0}, 0.3f}, {{0, 1, 0}, {0, 0, 1}, 0.3f}});
        const FoliageLodData d2 = buildOrFail(two);
        ASSERT_TRUE(d2.validate("two").ok());
        EXPECT_EQ(d2.minLeafCount(), 1u);
        EXPECT_EQ(d2.entries.size(), 3u);
        expectFiniteLeaves(two, d2, 1);
        // Three quads through one centre and a plain leaf beside them.
        const TreeModel four = quadLeaves({{{0, 1, 0}, {1, 0, 0}, 0.3f},
                                           {{0, 1, 0}, {0, 0, 1}, 0.3f},
                                           {{0, 1, 0}, {0, 1, 0}, 0.3f},
                                           {{0.5f, 1, 0}, {1, 0, 0}, 0.3f}});
        const FoliageLodData d4 = buildOrFail(four);
        ASSERT_TRUE(d4.validate("four").ok());
        EXPECT_EQ(d4.minLeafCount(), 1u);
        EXPECT_EQ(d4.entries.size(), 7u);
        for (std::uint32_t count = 1; count <= 4; ++count)
            expectFiniteLeaves(four, d4, count);
        // The plain leaf goes first, into the part it is parallel to: the other two parts stay.
        const TreeModel three = foliageLodModel(four, d4, 3);
        ASSERT_EQ(three.leaves.size(), 3u);
        for (const glm::vec3 axis : {glm::vec3(0, 0, 1), glm::vec3(0, 1, 0)})
            EXPECT_TRUE(std::any_of(three.leaves.begin(), three.leaves.end(), [&](const Leaf& l) {
                return std::abs(glm::dot(l.normal, axis)) > 0.999f;
            })) << "no part facing (" << axis.x << ", " << axis.y << ", " << axis.z << ")";
    }

    /// A leaf folded along its midrib, one mesh of two quads (6 vertices, 4 triangles): the
    /// midrib from centre - half * spine to centre + half * spine, each wing `half` wide, the
    /// wings `fold` radians apart about the midrib, opening towards `normal`. UVs as
    /// test::addQuadLeaf's over the whole leaf (the midrib at u = 0.5).
    void addFoldedLeaf(TreeModel& m, const glm::vec3& centre, const glm::vec3& spine, const glm::vec3& normal,
                       float half, float fold)
    {
        Leaf l;
        l.firstVertex = std::uint32_t(m.leafVertices.size());
        l.vertexCount = 6;
        l.firstIndex = std::uint32_t(m.leafIndices.size());
        l.indexCount = 12;
        const glm::vec3 s = glm::normalize(spine), n = glm::normalize(normal), w = glm::cross(n, s);
        const float across = std::sin(0.5f * fold), up = std::cos(0.5f * fold);
        const glm::vec3 left = half * (-across * w + up * n), right = half * (across * w + up * n);
        const glm::vec3 bottom = centre - half * s, top = centre + half * s;
        const glm::vec3 p[6] = {bottom + left, bottom, bottom + right, top + left, top, top + right};
        const glm::vec2 uv[6] = {{0, 1}, {0.5f, 1}, {1, 1}, {0, 0}, {0.5f, 0}, {1, 0}};
        for (int k = 0; k < 6; ++k)
            m.leafVertices.push_back({p[k], n, uv[k]});
        for (std::uint32_t k : {0u, 1u, 4u, 0u, 4u, 3u, 1u, 2u, 5u, 1u, 5u, 4u})
            m.leafIndices.push_back(l.firstVertex + k);
        m.leaves.push_back(l);
        m.updateLeafRecord(m.leaves.size() - 1);
    }

    /// The wings of folded leaves: another plane within one leaf size (|n_a . n_b| < 0.8).
    double foldedShare(const TreeModel& m) { return shareBesideAnotherPlane(m, 0.8f, 1.0f); }

    TEST(LodfBuild, foldedLeavesCollapseIntoFoldedLeaves)
    {
        // 400 leaves that are one mesh folded along the midrib (wings 90 degrees apart, 0.3 m),
        // random yaw, in a 3 m crown. Each wing is an original of LoDF (800 in all, one quad
        // each), and the two wings collapse part with part as crossed leaves do, so the created
        // quads stay folded and keep the area; as flat leaves (crossedLeaves false) each leaf is
        // one original and collapses into one quad. A created quad takes existing vertices, so
        // some folds open or close past the bound.
        std::mt19937 rng(11);
        std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
        TreeModel m;
        m.name = "folded";
        m.materials.push_back(test::leafMaterial("Leaves"));
        while (m.leaves.size() < 400)
        {
            const glm::vec3 c(unit(rng), unit(rng), unit(rng));
            if (glm::length(c) > 1.0f)
                continue;
            const float yaw = 3.14159265f * unit(rng);
            addFoldedLeaf(m, 3.0f * c + glm::vec3(0, 4, 0), {std::cos(yaw), 0.3f, std::sin(yaw)}, {0, 1, 0}, 0.15f,
                          1.5707963f);
        }
        m.updateBounds();
        ASSERT_TRUE(m.validate()) << m.validate().error().message();
        const FoliageLodData d = buildOrFail(m);
        ASSERT_TRUE(d.validate("folded").ok());
        const std::uint32_t L = d.maxLeafCount();
        ASSERT_EQ(L, 800u);
        const TreeModel whole = foliageLodModel(m, d, L);
        EXPECT_NEAR(foldedShare(whole), 1.0, 1e-9);
        const double full = leafArea(m);
        EXPECT_NEAR(leafArea(whole) / full, 1.0, 1e-5);
        FoliageLodOptions flatOptions;
        flatOptions.crossedLeaves = false;
        const FoliageLodData flat = buildOrFail(m, flatOptions);
        ASSERT_EQ(flat.maxLeafCount(), 400u);
        // At equal quads: the flat collapse at half the leaves (its originals are two quads).
        for (const std::uint32_t quads : {L / 2, L / 4, L / 8})
        {
            const TreeModel lod = foliageLodModel(m, d, quads), flatLod = foliageLodModel(m, flat, quads / 2);
            const double share = foldedShare(lod), area = leafArea(lod) / full;
            const double flatShare = foldedShare(flatLod), flatArea = leafArea(flatLod) / full;
            std::cout << "[ lodf     ] folded leaves at " << quads << " quads: " << share
                      << " of the area folded, area kept " << area << "; as flat leaves " << flatShare << ", "
                      << flatArea << "\n";
            if (quads >= L / 4) // coarser, grown quads lie beside others in other planes either way
            {
                EXPECT_GE(share, 0.5) << quads;
                EXPECT_GE(share, flatShare + 0.3) << quads;
            }
            EXPECT_GE(area, 0.85) << quads;
            EXPECT_LE(area, 1.15) << quads;
            expectFiniteLeaves(m, d, quads);
        }
        EXPECT_EQ(foliageLodModel(m, d, d.minLeafCount()).leaves.size(), d.clusters.size());
    }

    TEST(LodfBuild, aLeafOfOneTrianglePerPlaneCollapsesLikeQuads)
    {
        // Three triangles in three planes: three originals of one triangle each (3 index slots,
        // a created quad takes 6 from two of them). With it, a folded leaf (two originals) and a
        // plain one: six originals, down to one leaf, valid at every count.
        TreeModel m;
        m.name = "fan";
        m.materials.push_back(test::leafMaterial("Leaves"));
        Leaf fan;
        fan.firstVertex = 0;
        fan.vertexCount = 4;
        fan.firstIndex = 0;
        fan.indexCount = 9;
        m.leafVertices = {{{0, 0, 0}, {0, 1, 0}, {0, 0}},
                          {{0.3f, 0, 0}, {0, 1, 0}, {1, 0}},
                          {{0, 0.3f, 0}, {0, 1, 0}, {0, 1}},
                          {{0, 0, 0.3f}, {0, 1, 0}, {1, 1}}};
        m.leafIndices = {0, 1, 2, 0, 2, 3, 0, 3, 1};
        m.leaves.push_back(fan);
        m.updateLeafRecord(0);
        addFoldedLeaf(m, {0.4f, 0.1f, 0}, {0, 1, 0}, {1, 0, 0}, 0.15f, 1.2f);
        test::addQuadLeaf(m, {0.2f, 0.4f, 0}, {0.15f, 0, 0}, {0, 0.15f, 0}, {0, 0, 1});
        m.updateBounds();
        ASSERT_TRUE(m.validate()) << m.validate().error().message();
        const FoliageLodData d = buildOrFail(m);
        ASSERT_TRUE(d.validate("fan").ok());
        EXPECT_EQ(d.maxLeafCount(), 6u);
        EXPECT_EQ(d.minLeafCount(), 1u);
        for (std::uint32_t count = 1; count <= 6; ++count)
            expectFiniteLeaves(m, d, count);
        const TreeModel whole = foliageLodModel(m, d, 6);
        EXPECT_NEAR(leafArea(whole), leafArea(m), 1e-6);
    }

    TEST(LodfBuild, addFoliageLodChunkAddsReferenceOnce)
    {
        // addFoliageLodChunk adds "lodf" and the "reference" chunk whose vertices it indexes;
        // again, or with a reference already there, it adds no second one and keeps the one
        // present. The stored lodf chunk decodes to what buildFoliageLod gives.
        const TreeModel m = quadLeaves(scatter(40, 4), true);
        PackageWriter w;
        ASSERT_TRUE(addFoliageLodChunk(w, m, "tiny"));
        EXPECT_TRUE(w.hasChunk(FOLIAGE_LOD_CHUNK, 0));
        EXPECT_TRUE(w.hasChunk(REFERENCE_CHUNK, 0));
        EXPECT_EQ(w.chunkCount(), 2u);
        ASSERT_TRUE(addFoliageLodChunk(w, m, "tiny"));
        EXPECT_EQ(w.chunkCount(), 2u);

        PackageWriter kept;
        ASSERT_TRUE(kept.addChunk(REFERENCE_CHUNK, 0, 1, {1, 2, 3, 4}));
        ASSERT_TRUE(addFoliageLodChunk(kept, m, "tiny"));
        EXPECT_EQ(kept.chunkCount(), 2u);
        Result<PackageReader> reader = PackageReader::fromMemory(kept.toBytes(), "mem");
        ASSERT_TRUE(reader) << reader.error().message();
        Result<std::vector<std::uint8_t>> ref = reader->readChunk(REFERENCE_CHUNK, 0);
        ASSERT_TRUE(ref);
        EXPECT_EQ(*ref, (std::vector<std::uint8_t>{1, 2, 3, 4}));
        Result<std::vector<std::uint8_t>> lodf = reader->readChunk(FOLIAGE_LOD_CHUNK, 0);
        ASSERT_TRUE(lodf);
        Result<FoliageLodData> decoded = decodeFoliageLodChunk(*lodf, "mem");
        ASSERT_TRUE(decoded) << decoded.error().message();
        expectDataEqual(*decoded, buildOrFail(m));
    }
}
