// The bench's floors (QuadFloors.h) against the Forest's quad level through Plugin_TreeLod.
#include "ForestTestSupport.h"

namespace TreeLod
{
    namespace
    {
        /// The Forest's quad level drawing `trees` of `tree` from `view` (256 x 192, 1 spp); the
        /// content is cleared afterwards, for a floor to draw the same trees.
        Image quadLevelImage(const ForestTree& tree, const std::vector<ForestInstance>& trees, const CameraSpec& view)
        {
            Forest* forest = placeForest();
            forest->addSpecies(tree.asset, {ForestLevel{"impostor", 0, false, 0.0f}});
            forest->addInstances(trees);
            OffscreenRenderer& r = OgreEnvironment::renderer();
            const Image image = toImage(r.render(view, 256, 192, 1));
            r.clearContent();
            return image;
        }
    }

    TEST(Forest, quadFloorsDrawWhatTheQuadLevelDraws)
    {
        const ForestTree& tree = oak();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        const float h = treeHeight(tree.model);
        const CameraSpec view = look(glm::vec3(1.5f * h, 3.0f * h, 5.5f * h), glm::vec3(0.0f, 0.2f * h, 0.0f));
        const std::vector<ForestInstance> trees = grid(4, 1.3f * h);
        const Image quads = quadLevelImage(tree, trees, view);
        Ogre::SceneManager& sm = r.getSceneManager();
        Image entities, merged;
        {
            EntityFloor floor(sm, r.getContentNode(), {tree.asset}, trees);
            EXPECT_EQ(floor.getEntityCount(), trees.size());
            entities = toImage(r.render(view, 256, 192, 1));
        }
        {
            MergedQuadFloor floor(sm, r.getContentNode(), {tree.asset}, trees);
            EXPECT_EQ(floor.getBatchCount(), 1u);
            EXPECT_GT(floor.getGpuBytes(), trees.size() * 4 * 44);
            merged = toImage(r.render(view, 256, 192, 1));
        }
        writePng(OgreEnvironment::outDir() + "/forest-quad-floors.png", sideBySide({quads, entities, merged}));
        EXPECT_GT(treeCoverage(merged, BACKGROUND), 0.1);
        const double flipEntities = flipMean(quads, entities), flipMerged = flipMean(quads, merged);
        std::printf("quad level vs floors: FLIP entities %.5f, merged quads %.5f\n", flipEntities, flipMerged);
        EXPECT_LE(flipEntities, 0.002);
        EXPECT_LE(flipMerged, 0.002);
        compareWithGolden(merged, "forest-quad-merged", 0.02);

        // Batches: two species, more trees than a batch holds; none; an asset without the impostor.
        const std::vector<ForestInstance> many = grid(100, 1.3f * h); // 10,000 trees, species 0
        std::vector<ForestInstance> two = many;
        for (std::size_t i = 0; i < two.size(); i += 2)
            two[i].kind = 1;
        {
            MergedQuadFloor floor(sm, r.getContentNode(), {tree.asset, tree.asset}, two);
            EXPECT_EQ(floor.getBatchCount(), 2u * ((5000 + MergedQuadFloor::BATCH_TREES - 1) / MergedQuadFloor::BATCH_TREES));
        }
        {
            MergedQuadFloor none(sm, r.getContentNode(), {tree.asset}, {});
            EXPECT_EQ(none.getBatchCount(), 0u);
            EntityFloor noEntities(sm, r.getContentNode(), {tree.asset}, {});
            EXPECT_EQ(noEntities.getEntityCount(), 0u);
        }
        EXPECT_THROW(MergedQuadFloor(sm, r.getContentNode(), {tree.asset}, two), Ogre::Exception); // kind 1 unknown
        PackageWriter writer;
        ASSERT_TRUE(addFoliageLodChunk(writer, tree.model, "bare").ok());
        TreeAssetPtr bare = TreeAssetManager::getSingleton().loadFromBytes("bare.floor-test", Ogre::RGN_DEFAULT,
                                                                           writer.toBytes());
        try
        {
            EntityFloor floor(sm, r.getContentNode(), {bare}, trees);
            ADD_FAILURE() << "an asset without impostor was accepted";
        }
        catch (const Ogre::Exception& e)
        {
            EXPECT_NE(e.getDescription().find("bare.floor-test"), std::string::npos) << e.getDescription();
        }
    }

    TEST(Forest, billboardSetFloorCoversWhatTheQuadLevelCovers)
    {
        // The plain Ogre BillboardSet floor: the impostor's colour unlit, so its shading differs,
        // but its quads stand where the quad level's stand: the same pixels covered.
        const ForestTree& tree = oak();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        const float h = treeHeight(tree.model);
        const CameraSpec view = look(glm::vec3(1.5f * h, 3.0f * h, 5.5f * h), glm::vec3(0.0f, 0.2f * h, 0.0f));
        std::vector<ForestInstance> trees = grid(4, 1.3f * h);
        for (std::size_t i = 0; i < trees.size(); ++i)
            trees[i].scale = 0.8f + 0.05f * float(i % 8); // per-billboard sizes
        const Image quads = quadLevelImage(tree, trees, view);
        Ogre::SceneManager& sm = r.getSceneManager();
        Image sets;
        {
            BillboardSetFloor floor(sm, r.getContentNode(), {tree.asset}, trees);
            ASSERT_EQ(floor.getSetCount(), 1u);
            EXPECT_EQ(floor.getSet(0).getNumBillboards(), int(trees.size()));
            EXPECT_FALSE(floor.getSet(0).getCastShadows());
            EXPECT_GT(floor.getGpuBytes(), trees.size() * 4 * 24);
            sets = toImage(r.render(view, 256, 192, 1));
        }
        writePng(OgreEnvironment::outDir() + "/forest-billboard-set-floor.png", sideBySide({quads, sets}));
        const double overlap = coveredOverlap(quads, sets, BACKGROUND);
        std::printf("billboard-set floor vs quad level: covered pixels overlap %.4f\n", overlap);
        EXPECT_GT(treeCoverage(sets, BACKGROUND), 0.1);
        EXPECT_GE(overlap, 0.97);
        compareWithGolden(sets, "forest-billboard-set", 0.02);

        // Sets of at most MAX_SET_TREES billboards; two species; none; an unknown species.
        const std::vector<ForestInstance> many = grid(130, 1.3f * h); // 16,900 trees
        std::vector<ForestInstance> two = many;
        for (std::size_t i = 0; i < two.size(); i += 2)
            two[i].kind = 1;
        {
            BillboardSetFloor floor(sm, r.getContentNode(), {tree.asset}, many);
            EXPECT_EQ(floor.getSetCount(), 2u);
            std::size_t billboards = 0;
            for (std::size_t i = 0; i < floor.getSetCount(); ++i)
            {
                EXPECT_LE(std::size_t(floor.getSet(i).getNumBillboards()), BillboardSetFloor::MAX_SET_TREES);
                billboards += std::size_t(floor.getSet(i).getNumBillboards());
            }
            EXPECT_EQ(billboards, many.size());
        }
        {
            BillboardSetFloor floor(sm, r.getContentNode(), {tree.asset, tree.asset}, two);
            EXPECT_EQ(floor.getSetCount(), 2u);
            BillboardSetFloor none(sm, r.getContentNode(), {tree.asset}, {});
            EXPECT_EQ(none.getSetCount(), 0u);
        }
        try
        {
            BillboardSetFloor floor(sm, r.getContentNode(), {tree.asset}, two);
            ADD_FAILURE() << "species 1 of 1 was accepted";
        }
        catch (const Ogre::Exception& e)
        {
            EXPECT_NE(e.getDescription().find("species 1 of 1"), std::string::npos) << e.getDescription();
        }
    }
}
