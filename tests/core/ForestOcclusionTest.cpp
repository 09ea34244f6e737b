// Occlusion between the trees (ForestOcclusion.h, ForestInstances::cull with a camera's occlusion
// on): the grid's transmittance and visible shares against hand-computed values, a tree behind a
// wall hidden and one beside it seen whole, a lone tree's level unchanged, a partly hidden tree of a
// kind with height scales drawn at the level its scaled value gives; the silhouette mask of crossed
// quads and of a leaf whose texture the alpha test halves.
#include "TreeLod/ForestInstances.h"

#include <glm/gtc/matrix_transform.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

namespace TreeLod
{
    namespace
    {
        std::shared_ptr<const OcclusionMask> uniformMask(float coverage)
        {
            auto mask = std::make_shared<OcclusionMask>();
            mask->coverage.fill(coverage);
            mask->solid.fill(coverage);
            mask->finish();
            return mask;
        }

        /// A camera at the origin looking down -z, 90 degrees wide, 800 x 800 px.
        CullCamera frontCamera()
        {
            const glm::mat4 view = glm::lookAt(glm::vec3(0.0f), glm::vec3(0.0f, 0.0f, -1.0f), glm::vec3(0, 1, 0));
            const glm::mat4 projection = glm::perspective(glm::radians(90.0f), 1.0f, 0.1f, 1000.0f);
            CullCamera camera = CullCamera::fromMatrices(view, projection, 800.0f, 800.0f);
            camera.occlusion = true;
            return camera;
        }

        /// The bucket level an instance was drawn at in `vis`, or -1 when it was not drawn.
        int drawnLevel(const ForestVisibility& vis, std::uint32_t index)
        {
            for (const ForestBucket& bucket : vis.getBuckets())
                for (std::uint32_t k = 0; k < bucket.count; ++k)
                    if (vis.getIndices()[bucket.first + k] == index)
                        return int(bucket.level);
            return -1;
        }
    }

    TEST(OcclusionGrid, transmittanceAndVisibleShares)
    {
        OcclusionGrid grid;
        grid.clear(4, 4); // cells of 0.5 x 0.5 in NDC
        // An opaque square over cell (0, 0) and half of cell (1, 0): seen whole, then hides the cell
        // inside it, and half of the other by estimate, none of it conservatively.
        const OcclusionShare first = grid.addTree(uniformMask(1.0f).get(), -1.0f, -1.0f, -0.25f, -0.5f);
        EXPECT_FLOAT_EQ(first.estimate, 1.0f);
        EXPECT_FLOAT_EQ(first.conservative, 1.0f);
        EXPECT_FLOAT_EQ(grid.getTransmittance(0, 0), 0.0f);
        EXPECT_FLOAT_EQ(grid.getTransmittance(1, 0), 0.5f);
        EXPECT_FLOAT_EQ(grid.getTransmittance(2, 0), 1.0f);
        EXPECT_FLOAT_EQ(grid.getConservativeTransmittance(0, 0), 0.0f);
        EXPECT_FLOAT_EQ(grid.getConservativeTransmittance(1, 0), 1.0f);
        // A tree over cells (0, 0) .. (3, 0) evenly: (0 + 0.5 + 1 + 1) / 4 of it is visible by
        // estimate, (0 + 1 + 1 + 1) / 4 conservatively.
        const OcclusionShare second = grid.addTree(uniformMask(0.5f).get(), -1.0f, -1.0f, 1.0f, -0.5f);
        EXPECT_NEAR(second.estimate, 0.625f, 1e-6f);
        EXPECT_NEAR(second.conservative, 0.75f, 1e-6f);
        EXPECT_NEAR(grid.getTransmittance(3, 0), 0.5f, 1e-6f);
        EXPECT_NEAR(grid.getConservativeTransmittance(3, 0), 0.5f, 1e-6f);
        // A null mask is weighed evenly and hides nothing.
        const OcclusionShare third = grid.addTree(nullptr, -1.0f, -1.0f, 1.0f, -0.5f);
        EXPECT_NEAR(third.estimate, (0.0f + 0.25f + 0.5f + 0.5f) / 4.0f, 1e-6f);
        EXPECT_NEAR(third.conservative, (0.0f + 0.5f + 0.5f + 0.5f) / 4.0f, 1e-6f);
        EXPECT_NEAR(grid.getTransmittance(3, 0), 0.5f, 1e-6f);
        // A mask open in one of its cells: by estimate a grid cell that takes it in hides by the
        // mean, conservatively nothing.
        auto open = std::make_shared<OcclusionMask>();
        open->coverage.fill(1.0f);
        open->coverage[0] = 0.0f; // bottom-left
        open->solid = open->coverage;
        open->finish();
        grid.clear(2, 2);
        grid.addTree(open.get(), -1.0f, -1.0f, 1.0f, 1.0f);
        EXPECT_FLOAT_EQ(grid.getTransmittance(0, 0), 1.0f / 64.0f);
        EXPECT_FLOAT_EQ(grid.getConservativeTransmittance(0, 0), 1.0f);
        EXPECT_FLOAT_EQ(grid.getConservativeTransmittance(1, 0), 0.0f);
        EXPECT_FLOAT_EQ(grid.getConservativeTransmittance(1, 1), 0.0f);
        EXPECT_FLOAT_EQ(open->minOver(0.0f, 0.0f, 8.0f, 8.0f), 0.0f);
        EXPECT_FLOAT_EQ(open->minOver(1.0f, 0.0f, 8.0f, 8.0f), 1.0f);
        // Off the screen, or empty: visible.
        EXPECT_FLOAT_EQ(grid.addTree(uniformMask(1.0f).get(), 2.0f, 2.0f, 3.0f, 3.0f).estimate, 1.0f);
        EXPECT_FLOAT_EQ(grid.addTree(uniformMask(0.0f).get(), -1.0f, -1.0f, 1.0f, 1.0f).conservative, 1.0f);
    }

    TEST(ForestOcclusion, aTreeBehindAWallIsHiddenAndOneBesideItSeenWhole)
    {
        ForestInstances forest;
        ForestKind wall;
        wall.name = "wall";
        wall.boundsCentre = glm::vec3(0.0f, 0.0f, 0.0f);
        wall.boundsRadius = 1.0f;
        wall.occlusionMask = uniformMask(1.0f);
        ForestKind tree = wall;
        tree.name = "tree";
        tree.occlusionMask = uniformMask(0.6f);
        ASSERT_TRUE(forest.addKind(wall));
        ASSERT_TRUE(forest.addKind(tree));
        // The wall: an opaque square at 10 m over x in [-10, -1], y in [-4.5, 4.5] (most of the left
        // half of the screen, whose half-width at 10 m is 10 m).
        ASSERT_TRUE(forest.add(ForestInstance{glm::vec3(-5.5f, 0.0f, -10.0f), 0.0f, 4.5f, 0}));
        const ForestHandle hidden = *forest.add(ForestInstance{glm::vec3(-30.0f, 0.0f, -60.0f), 0.0f, 2.0f, 1});
        const ForestHandle open = *forest.add(ForestInstance{glm::vec3(30.0f, 0.0f, -60.0f), 0.0f, 2.0f, 1});

        CullCamera camera = frontCamera();
        ForestVisibility vis;
        ASSERT_TRUE(forest.cull(camera, 1.0f, vis));
        const std::uint32_t h = forest.getIndexOf(hidden), o = forest.getIndexOf(open);
        EXPECT_LT(vis.getVisibility(h), OCCLUSION_HIDDEN);
        EXPECT_FLOAT_EQ(vis.getVisibility(o), 1.0f);
        EXPECT_EQ(drawnLevel(vis, h), -1) << "a hidden tree is not drawn";
        EXPECT_EQ(drawnLevel(vis, o), 0);
        EXPECT_EQ(vis.getOccludedCount(), 1u);
        EXPECT_EQ(vis.getVisibleCount() + vis.getOccludedCount() + vis.getCulledCount(), forest.size());

        // The same wall seen on a 10-pixel viewport (its square 4.5 px tall) hides nothing: a few
        // pixels of leaves draw less than their area.
        camera.viewportHeight = 10.0f;
        ASSERT_TRUE(forest.cull(camera, 1.0f, vis));
        EXPECT_FLOAT_EQ(vis.getVisibility(h), 1.0f);
        EXPECT_EQ(drawnLevel(vis, h), 0);
        camera.viewportHeight = 800.0f;

        // Off: both drawn, nothing estimated.
        camera.occlusion = false;
        ASSERT_TRUE(forest.cull(camera, 1.0f, vis));
        EXPECT_EQ(drawnLevel(vis, h), 0);
        EXPECT_EQ(vis.getVisibility(h), -1.0f);
        EXPECT_EQ(vis.getOccludedCount(), 0u);
    }

    TEST(ForestOcclusion, aLoneTreeKeepsItsLevelAndAPartlyHiddenOneTakesItsScaledValue)
    {
        ForestInstances forest;
        ForestKind tree;
        tree.name = "tree";
        tree.boundsRadius = 1.0f;
        tree.thresholds = {40000.0f, 10000.0f, 400.0f};
        tree.occlusionMask = uniformMask(0.5f);
        tree.occlusionHeightScales = {1.0f, 0.5f, 0.25f, 0.25f, 0.25f, 0.25f};
        ForestKind screen;
        screen.name = "screen";
        screen.boundsRadius = 1.0f;
        screen.occlusionMask = uniformMask(0.5f);
        ASSERT_TRUE(forest.addKind(tree));
        ASSERT_TRUE(forest.addKind(screen));
        CullCamera camera = frontCamera();
        CullCamera off = camera;
        off.occlusion = false;

        // Alone, at distances through every level: the same level with and without occlusion.
        for (float d = 2.0f; d < 200.0f; d *= 1.3f)
        {
            ForestInstances lone;
            ASSERT_TRUE(lone.addKind(tree));
            ASSERT_TRUE(lone.add(ForestInstance{glm::vec3(0.0f, 0.0f, -d), 0.0f, 1.0f, 0}));
            ForestVisibility a, b;
            ASSERT_TRUE(lone.cull(camera, 1.0f, a));
            ASSERT_TRUE(lone.cull(off, 1.0f, b));
            EXPECT_FLOAT_EQ(a.getVisibility(0), 1.0f);
            EXPECT_EQ(drawnLevel(a, 0), drawnLevel(b, 0)) << "at " << d << " m";
        }

        // Behind a screen that hides half of it: its value times s(1/2)^2 = 1/4 picks its level. Both
        // squares span NDC [-0.125, 0.125], 16 x 16 cells of the 128 x 128 grid exactly.
        ASSERT_TRUE(forest.add(ForestInstance{glm::vec3(0.0f, 0.0f, -12.0f), 0.0f, 1.5f, 0}));
        ASSERT_TRUE(forest.add(ForestInstance{glm::vec3(0.0f, 0.0f, -3.0f), 0.0f, 0.375f, 1}));
        ForestVisibility vis;
        ASSERT_TRUE(forest.cull(camera, 1.0f, vis));
        EXPECT_NEAR(vis.getVisibility(0), 0.5f, 1e-5f);
        const float value = forest.lodValue(0, camera, 1.0f);
        const std::uint32_t unscaled = forest.levelForValue(0, value);
        const std::uint32_t scaled = forest.levelForValue(0, value * 0.25f);
        ASSERT_NE(unscaled, scaled) << "the distance should put the tree where the scale changes its level";
        EXPECT_EQ(drawnLevel(vis, 0), int(scaled));
        ASSERT_TRUE(forest.cull(off, 1.0f, vis));
        EXPECT_EQ(drawnLevel(vis, 0), int(unscaled));

        // Scales are checked.
        tree.occlusionHeightScales[2] = 1.5f;
        EXPECT_FALSE(forest.addKind(tree));
        EXPECT_FALSE(forest.setKindOcclusion(0, nullptr, {1.0f, 0.0f, 1.0f, 1.0f, 1.0f, 1.0f}));
        EXPECT_FALSE(forest.setKindOcclusion(0, nullptr, {1.0f, NAN, 1.0f, 1.0f, 1.0f, 1.0f}));
    }

    TEST(OcclusionMask, crossedQuadsAndAHalfTransparentLeaf)
    {
        // The sphere: centre (0, 1, 0), radius 1; its square spans x (or z) -1..1, y 0..2.
        ReferenceChunk reference;
        TreeModel& model = reference.model;
        model.materials.resize(2);
        model.materials[1].isLeaf = true;
        model.materials[1].texture = 0;
        auto quad = [](std::vector<Vertex>& vertices, std::vector<std::uint32_t>& indices, glm::vec3 a, glm::vec3 b,
                       glm::vec3 c, glm::vec3 d) {
            const std::uint32_t first = std::uint32_t(vertices.size());
            for (const glm::vec3& p : {a, b, c, d})
                vertices.push_back(Vertex{p, glm::vec3(0, 0, 1), glm::vec2(0.0f)});
            for (std::uint32_t k : {0u, 1u, 2u, 0u, 2u, 3u})
                indices.push_back(first + k);
        };
        // Bark: crossed quads over the lower-left quarter of both views.
        quad(model.barkVertices, model.barkIndices, {-1, 0, 0}, {0, 0, 0}, {0, 1, 0}, {-1, 1, 0});
        quad(model.barkVertices, model.barkIndices, {0, 0, -1}, {0, 0, 0}, {0, 1, 0}, {0, 1, -1});
        model.barkTriangleMaterial.assign(4, 0);
        // A leaf over the upper-right quarter of the view along z, edge-on along x; its texture's
        // left half opaque, its right half clear.
        quad(model.leafVertices, model.leafIndices, {0, 1, 0.5f}, {1, 1, 0.5f}, {1, 2, 0.5f}, {0, 2, 0.5f});
        const glm::vec2 uvs[4] = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
        for (int k = 0; k < 4; ++k)
            model.leafVertices[std::size_t(k)].uv = uvs[k];
        Leaf leaf;
        leaf.vertexCount = 4;
        leaf.indexCount = 6;
        leaf.material = 1;
        model.leaves.push_back(leaf);
        model.updateLeafRecord(0);
        GpuTexture texture;
        texture.width = 4;
        texture.height = 4;
        texture.mipCount = 1;
        texture.data.assign(64, 255);
        for (int y = 0; y < 4; ++y)
            for (int x = 2; x < 4; ++x)
                texture.data[std::size_t((y * 4 + x) * 4 + 3)] = 0;
        reference.textures.push_back(texture);

        const OcclusionMask mask = makeOcclusionMask(reference, glm::vec3(0.0f, 1.0f, 0.0f), 1.0f);
        constexpr int S = OcclusionMask::SIZE, H = S / 2;
        for (int y = 0; y < S; ++y)
            for (int x = 0; x < S; ++x)
            {
                const float c = mask.coverage[std::size_t(y * S + x)];
                const float expected = x < H && y < H ? 1.0f : x >= H && y >= H ? 0.25f : 0.0f;
                EXPECT_NEAR(c, expected, 1e-5f) << "cell " << x << ", " << y;
                EXPECT_NEAR(mask.solid[std::size_t(y * S + x)], expected, 1e-5f) << "cell " << x << ", " << y;
            }
        EXPECT_NEAR(mask.mean, (1.0f + 0.25f) / 4.0f, 1e-5f);
        EXPECT_NEAR(mask.meanOver(0.0f, 0.0f, float(S), float(S)), mask.mean, 1e-5f);
        EXPECT_NEAR(mask.meanOver(4.0f, 4.0f, 12.0f, 12.0f), (1.0f + 0.25f) / 4.0f, 1e-5f);
        EXPECT_NEAR(mask.meanOver(0.5f, 0.5f, 1.5f, 1.5f), 1.0f, 1e-5f);

        // An edge across a cell: a quad to y = 0.0625 m, half of the lowest row of cells (and of
        // their 4 x 4 blocks, two rows of four samples each), seen along z only. The mean counts the
        // covered half of each view's samples, the blocks' least is an open block.
        ReferenceChunk edge;
        quad(edge.model.barkVertices, edge.model.barkIndices, {-1, 0, 0}, {1, 0, 0}, {1, 0.0625f, 0}, {-1, 0.0625f, 0});
        edge.model.barkTriangleMaterial.assign(2, 0);
        edge.model.materials.resize(1);
        const OcclusionMask edged = makeOcclusionMask(edge, glm::vec3(0.0f, 1.0f, 0.0f), 1.0f);
        EXPECT_NEAR(edged.coverage[0], 0.25f, 1e-5f);
        EXPECT_NEAR(edged.solid[0], 0.0f, 1e-5f);
        EXPECT_NEAR(edged.coverage[std::size_t(S)], 0.0f, 1e-5f);

        // Nothing to cover: an empty mask.
        const OcclusionMask empty = makeOcclusionMask(ReferenceChunk{}, glm::vec3(0.0f), 1.0f);
        EXPECT_EQ(empty.mean, 0.0f);
    }
}
