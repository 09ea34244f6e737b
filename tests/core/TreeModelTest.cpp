// TreeModel: leaf records, bounds and validation on tiny hand-made models.
#include "TreeLod/TreeModel.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace TreeLod
{
    namespace
    {
        /// One 2 m x 1 m leaf quad in the XY plane at z = 3, facing +Z, full UV square.
        TreeModel oneLeaf()
        {
            TreeModel m;
            Material leaf;
            leaf.isLeaf = true;
            m.materials.push_back(leaf);
            m.leafVertices = {{{0, 0, 3}, {0, 0, 1}, {0, 1}}, {{2, 0, 3}, {0, 0, 1}, {1, 1}},
                              {{2, 1, 3}, {0, 0, 1}, {1, 0}}, {{0, 1, 3}, {0, 0, 1}, {0, 0}}};
            m.leafIndices = {0, 1, 2, 0, 2, 3};
            Leaf l;
            l.vertexCount = 4;
            l.indexCount = 6;
            m.leaves.push_back(l);
            m.updateLeafRecord(0);
            m.updateBounds();
            return m;
        }
    }

    TEST(TreeModel, leafRecordOfAQuad)
    {
        // Area 2 x 1 = 2 m^2; centre at the middle of the rectangle; CCW seen from +Z.
        TreeModel m = oneLeaf();
        const Leaf& l = m.leaves[0];
        EXPECT_FLOAT_EQ(l.area, 2.0f);
        EXPECT_NEAR(glm::length(l.centre - glm::vec3(1.0f, 0.5f, 3.0f)), 0.0f, 1e-6f);
        EXPECT_NEAR(glm::length(l.normal - glm::vec3(0, 0, 1)), 0.0f, 1e-6f);
        EXPECT_EQ(l.uvMin, glm::vec2(0.0f));
        EXPECT_EQ(l.uvMax, glm::vec2(1.0f));
        EXPECT_EQ(m.boundsMin, glm::vec3(0, 0, 3));
        EXPECT_EQ(m.boundsMax, glm::vec3(2, 1, 3));
        EXPECT_TRUE(m.validate().ok());
    }

    TEST(TreeModel, leafPlanesSplitAFoldedLeafAndKeepAFlatOneWhole)
    {
        // oneLeaf's quad, then a leaf of one mesh: a 1 x 1 square in z = 0 (u 0..0.5) and one in
        // x = 1 (u 0.5..1) sharing the edge x = 1, z = 0, plus a sliver triangle in a third plane
        // (under 10 % of the area: joins the most parallel plane) and a degenerate one.
        TreeModel m = oneLeaf();
        const std::uint32_t v0 = std::uint32_t(m.leafVertices.size());
        m.leafVertices.insert(m.leafVertices.end(), {{{0, 0, 0}, {0, 0, 1}, {0, 1}},
                                                     {{1, 0, 0}, {0, 0, 1}, {0.5f, 1}},
                                                     {{1, 1, 0}, {0, 0, 1}, {0.5f, 0}},
                                                     {{0, 1, 0}, {0, 0, 1}, {0, 0}},
                                                     {{1, 0, -1}, {1, 0, 0}, {1, 1}},
                                                     {{1, 1, -1}, {1, 0, 0}, {1, 0}},
                                                     {{0.9f, 1.1f, 0.1f}, {0, 1, 0}, {0.5f, 0}}});
        Leaf folded;
        folded.firstVertex = v0;
        folded.vertexCount = 7;
        folded.firstIndex = std::uint32_t(m.leafIndices.size());
        const std::vector<std::uint32_t> local = {0, 1, 2, 0, 2, 3, 1, 4, 5, 1, 5, 2, 2, 1, 6, 0, 0, 1};
        for (std::uint32_t k : local)
            m.leafIndices.push_back(v0 + k);
        folded.indexCount = std::uint32_t(local.size());
        m.leaves.push_back(folded);
        m.updateLeafRecord(1);
        m.updateBounds();
        ASSERT_TRUE(m.validate()) << m.validate().error().message();

        EXPECT_EQ(m.leafPlanes(0).size(), 1u);
        EXPECT_EQ(m.leafPlanes(0)[0].size(), 6u);
        const std::vector<std::vector<std::uint32_t>> planes = m.leafPlanes(1);
        ASSERT_EQ(planes.size(), 2u);
        std::size_t indices = 0;
        for (const auto& plane : planes)
            indices += plane.size();
        EXPECT_EQ(indices, local.size()); // nothing dropped
        // With the sliver's own plane kept (no area share), three planes.
        EXPECT_EQ(m.leafPlanes(1, 0.9f, 0.0f).size(), 3u);

        const std::optional<TreeModel> split = leafPlanesAsLeaves(m);
        ASSERT_TRUE(split);
        ASSERT_TRUE(split->validate()) << split->validate().error().message();
        ASSERT_EQ(split->leaves.size(), 3u);
        EXPECT_EQ(split->leaves[0].indexCount, 6u);
        EXPECT_NEAR(split->leaves[0].area, m.leaves[0].area, 1e-6f);
        EXPECT_NEAR(split->leaves[1].area + split->leaves[2].area, m.leaves[1].area, 1e-5f);
        // Each plane shows its half of the leaf image.
        for (std::size_t i : {1u, 2u})
            EXPECT_NEAR(split->leaves[i].uvMax.x - split->leaves[i].uvMin.x, 0.5f, 1e-6f) << i;
        EXPECT_GT(std::abs(glm::dot(split->leaves[1].normal, glm::vec3(0, 0, 1))) +
                      std::abs(glm::dot(split->leaves[2].normal, glm::vec3(0, 0, 1))),
                  0.95f);
        EXPECT_LT(std::abs(glm::dot(split->leaves[1].normal, split->leaves[2].normal)), 0.2f);
        // A model of flat leaves is left as it is.
        EXPECT_FALSE(leafPlanesAsLeaves(oneLeaf()));
    }

    TEST(TreeModel, zeroAreaLeafKeepsAFiniteRecord)
    {
        // All corners on one line: no area, the normal falls back to +Y, the centre to the
        // vertex mean, nothing becomes NaN.
        TreeModel m = oneLeaf();
        for (Vertex& v : m.leafVertices)
            v.position.y = 0.0f;
        m.updateLeafRecord(0);
        EXPECT_EQ(m.leaves[0].area, 0.0f);
        EXPECT_EQ(m.leaves[0].normal, glm::vec3(0, 1, 0));
        EXPECT_TRUE(std::isfinite(m.leaves[0].centre.x));
    }

    TEST(TreeModel, emptyModelIsValidWithZeroBounds)
    {
        TreeModel m;
        m.updateBounds();
        EXPECT_EQ(m.boundsMin, glm::vec3(0.0f));
        EXPECT_EQ(m.boundsMax, glm::vec3(0.0f));
        EXPECT_TRUE(m.validate().ok());
    }

    TEST(TreeModel, validateNamesTheBadElement)
    {
        TreeModel m = oneLeaf();
        m.leafIndices[4] = 9; // outside the leaf's 4 vertices
        Result<void> r = m.validate("tree.glb");
        ASSERT_FALSE(r.ok());
        EXPECT_EQ(r.error().file, "tree.glb");
        EXPECT_EQ(r.error().element, "leaf 0");

        m = oneLeaf();
        m.leafVertices[2].position.x = std::numeric_limits<float>::quiet_NaN();
        r = m.validate();
        ASSERT_FALSE(r.ok());
        EXPECT_EQ(r.error().element, "leaf vertex 2");

        m = oneLeaf();
        m.barkVertices.push_back({});
        m.barkIndices = {0, 0, 1};
        m.barkTriangleMaterial = {0};
        r = m.validate();
        ASSERT_FALSE(r.ok());
        EXPECT_NE(r.error().reason.find("out of range"), std::string::npos);

        m = oneLeaf();
        m.skeleton = {{{0, 0, 0}, 0.1f, 0}}; // its own parent
        EXPECT_FALSE(m.validate().ok());
    }
}
