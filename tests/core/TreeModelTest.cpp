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
