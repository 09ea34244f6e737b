// FoliageLodTree (Rebollo et al. 2006, LoDF) through Plugin_TreeLod: factory and registry, the leaf
// count curve and LoD bias, partial index uploads, drift-free GPU state, golden images at
// three distances, shadows, extremes (no leaves, 100k leaves, camera inside the crown and
// 10 km away) and bad input.
#include "OgreTestSupport.h"

#include "TreeLod/FoliageLodResources.h"
#include "TreeLod/FoliageLodBaker.h"
#include "TreeLod/FoliageLodTree.h"
#include "TreeLod/GltfImporter.h"
#include "TreeLod/PackageWriter.h"
#include "TreeLod/TechniqueRegistry.h"
#include "TreeLod/TreeAssetManager.h"
#include "TreeLod/TreeGenerator.h"

#include <OgreSceneManager.h>

#include <random>

namespace TreeLod::FoliageLodTreeTests
{
    namespace
    {
        struct LodfTree
        {
            TreeModel model;
            TreeAssetPtr asset;
        };

        /// `model` baked with the lodf (and reference) chunks and loaded as asset `name`.
        TreeAssetPtr loadLodf(const TreeModel& model, const std::string& name)
        {
            PackageWriter writer;
            Result<void> added = addFoliageLodChunk(writer, model, name);
            EXPECT_TRUE(added.ok()) << (added.ok() ? "" : added.error().message());
            OgreEnvironment::renderer();
            if (TreeAssetPtr existing = TreeAssetManager::getSingleton().getByName(name, Ogre::RGN_DEFAULT))
                return existing;
            return TreeAssetManager::getSingleton().loadFromBytes(name, Ogre::RGN_DEFAULT, writer.toBytes());
        }

        const LodfTree& bundledOak()
        {
            return OgreEnvironment::keep<LodfTree>("lodf.oak", [] {
                LodfTree t;
                Result<TreeModel> model = importGltf(OgreEnvironment::sourcePath("media/oak.glb"));
                EXPECT_TRUE(model.ok());
                t.model = std::move(model.value());
                t.asset = loadLodf(t.model, "oak.lodf-test");
                return t;
            });
        }

        /// A fresh FoliageLodTree for `asset` under the content node (the content is cleared).
        FoliageLodTree* place(const TreeAssetPtr& asset, const Ogre::NameValuePairList& params = {})
        {
            return static_cast<FoliageLodTree*>(placeTechnique(FOLIAGE_LOD_CHUNK, *asset, params));
        }

        CameraSpec camera(const TreeModel& model, const std::string& text)
        {
            CameraSpec spec;
            std::string error;
            EXPECT_TRUE(CameraSpec::parse(text, model.boundsMin, model.boundsMax, spec, error)) << error;
            return spec;
        }
    }

    TEST(FoliageLodTree, registeredAsTechniqueAndFactory)
    {
        OgreEnvironment::renderer();
        const TechniqueInfo* info = TechniqueRegistry::getSingleton().find("lodf");
        ASSERT_NE(info, nullptr);
        EXPECT_EQ(info->chunkTechnique, FOLIAGE_LOD_CHUNK);
        EXPECT_EQ(info->movableType, FoliageLodTreeFactory::FACTORY_TYPE_NAME);
        EXPECT_TRUE(Ogre::Root::getSingleton().hasMovableObjectFactory("FoliageLodTree"));

        // The factory path an application uses: createMovableObject with asset=NAME.
        const LodfTree& oak = bundledOak();
        Ogre::SceneManager& sm = OgreEnvironment::renderer().getSceneManager();
        Ogre::NameValuePairList params{{"asset", oak.asset->getName()}, {"leaves", "500"}};
        Ogre::MovableObject* object = sm.createMovableObject("viaFactory", "FoliageLodTree", &params);
        ASSERT_NE(object, nullptr);
        EXPECT_EQ(object->getMovableType(), "FoliageLodTree");
        EXPECT_EQ(static_cast<FoliageLodTree*>(object)->getLeafCount(), 500u);
        static_cast<FoliageLodTree*>(object)->setFixedLeafCount(100000); // clamped
        EXPECT_EQ(static_cast<FoliageLodTree*>(object)->getLeafCount(), 3000u);
        EXPECT_FALSE(object->getBoundingBox().isNull());
        sm.destroyMovableObject(object);
    }

    TEST(FoliageLodTree, badParametersAreNamed)
    {
        const LodfTree& oak = bundledOak();
        Ogre::SceneManager& sm = OgreEnvironment::renderer().getSceneManager();
        Ogre::NameValuePairList none;
        try
        {
            sm.createMovableObject("noAsset", "FoliageLodTree", &none);
            FAIL() << "no asset parameter must throw";
        }
        catch (const Ogre::Exception& e)
        {
            EXPECT_NE(e.getDescription().find("'asset'"), std::string::npos) << e.getDescription();
        }
        Ogre::NameValuePairList bad{{"asset", oak.asset->getName()}, {"pixelsPerLeaf", "-3"}};
        try
        {
            sm.createMovableObject("badPixels", "FoliageLodTree", &bad);
            FAIL() << "a negative pixelsPerLeaf must throw";
        }
        catch (const Ogre::Exception& e)
        {
            EXPECT_NE(e.getDescription().find("pixelsPerLeaf"), std::string::npos) << e.getDescription();
        }
    }

    TEST(FoliageLodTree, packageWithoutLodfChunkIsAClearError)
    {
        OgreEnvironment::renderer();
        TreeModel model = bundledOak().model;
        PackageWriter writer;
        ASSERT_TRUE(addReferenceChunk(writer, model, "ref-only").ok());
        TreeAssetPtr asset =
            TreeAssetManager::getSingleton().loadFromBytes("ref-only.lodf-test", Ogre::RGN_DEFAULT, writer.toBytes());
        try
        {
            place(asset);
            FAIL() << "a package without the lodf chunk must throw";
        }
        catch (const Ogre::Exception& e)
        {
            EXPECT_NE(e.getDescription().find("--technique lodf"), std::string::npos) << e.getDescription();
        }
    }

    TEST(FoliageLodTree, leafCountFollowsScreenSizeAndBias)
    {
        const LodfTree& oak = bundledOak();
        FoliageLodTree* tree = place(oak.asset);
        OffscreenRenderer& r = OgreEnvironment::renderer();
        std::vector<std::uint32_t> counts;
        for (const char* view : {"orbit:30,10,1.0", "orbit:30,10,3", "orbit:30,10,8", "orbit:30,10,30"})
        {
            r.render(camera(oak.model, view), 256, 256, 1);
            counts.push_back(tree->getLeafCount());
        }
        // Full detail close up, fewer leaves with each step back, never below one per cluster.
        EXPECT_EQ(counts[0], tree->getMaxLeafCount());
        for (std::size_t i = 1; i < counts.size(); ++i)
            EXPECT_LT(counts[i], counts[i - 1]);
        EXPECT_GE(counts.back(), tree->getMinLeafCount());

        // The curve is linear in pixels: bias 2 doubles the count where it is not clamped, and
        // supersampling does not change it (OffscreenRenderer scales the bias).
        r.render(camera(oak.model, "orbit:30,10,8"), 256, 256, 1);
        const std::uint32_t base = tree->getLeafCount();
        r.setLodBias(2.0f);
        r.render(camera(oak.model, "orbit:30,10,8"), 256, 256, 1);
        EXPECT_NEAR(double(tree->getLeafCount()), 2.0 * base, 2.0);
        r.setLodBias(1.0f);
        r.render(camera(oak.model, "orbit:30,10,8"), 256, 256, 3);
        EXPECT_NEAR(double(tree->getLeafCount()), double(base), 1.0);
        EXPECT_EQ(tree->leafCountForPixels(4000.0f, 1.0f), 1000u);
    }

    TEST(FoliageLodTree, onlyChangedClustersAreUploaded)
    {
        const LodfTree& oak = bundledOak();
        FoliageLodTree* tree = place(oak.asset);
        const FoliageLodData& data = FoliageLodResources::of(*oak.asset).getFoliageLod();
        const std::uint64_t fullBytes = std::uint64_t(data.slotCount()) * 2; // 16-bit indices
        tree->updateLeafCount(2000);
        // A 1 % change (30 leaves) rewrites a few clusters' regions, not the buffer.
        std::uint32_t written = tree->updateLeafCount(1970);
        const FoliageLodUpdateStats& stats = tree->getUpdateStats();
        EXPECT_EQ(stats.leafCount, 1970u);
        EXPECT_EQ(written, stats.clustersWritten);
        EXPECT_GT(stats.bytesUploaded, 0u);
        EXPECT_LT(stats.bytesUploaded * 5, fullBytes) << "a 1 % change must upload < 20 % of the index buffer";
        std::uint64_t expected = 0;
        for (std::uint32_t c : tree->getState().changedClusters())
            expected += std::uint64_t(data.clusters[c].slotCount) * 2;
        EXPECT_EQ(stats.bytesUploaded, expected);
        // No change, no upload.
        EXPECT_EQ(tree->updateLeafCount(1970), 0u);
    }

    TEST(FoliageLodTree, gpuStateNeverDrifts)
    {
        // 300 random moves, then the picture must equal a fresh object's at the same count:
        // the index buffer, written region by region, holds exactly the state's leaves.
        const LodfTree& oak = bundledOak();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        const CameraSpec view = camera(oak.model, "orbit:30,10,1.0");
        FoliageLodTree* tree = place(oak.asset, {{"leaves", "3000"}});
        tree->setFixedLeafCount(0);
        std::mt19937 rng(7);
        for (int i = 0; i < 300; ++i)
            tree->updateLeafCount(std::uniform_int_distribution<std::uint32_t>(1, 3200)(rng));
        tree->setFixedLeafCount(777);
        const Image moved = toImage(r.render(view, 160, 160, 1));
        place(oak.asset, {{"leaves", "777"}});
        const Image fresh = toImage(r.render(view, 160, 160, 1));
        ASSERT_EQ(moved.pixels.size(), fresh.pixels.size());
        std::size_t differ = 0;
        for (std::size_t i = 0; i < moved.pixels.size(); ++i)
            differ += moved.pixels[i] != fresh.pixels[i];
        EXPECT_EQ(differ, 0u);
        EXPECT_GT(treeCoverage(fresh, LightingSpec().background), 0.05);
    }

    // Golden images at three distances, and the polygonal reference's picture beside
    // each, both compared over the tree's own pixels: the far tree covers 0.4 % of the frame, where
    // a mean over the frame stays below any bound. Near and mid, LoDF draws every leaf and matches
    // the mesh (measured 0.000); far it keeps 638 of 3000 leaves (measured 0.172). Broken variants
    // measured against these bounds: half the leaves 0.14-0.28 from the golden and 0.216 from the
    // mesh far, every leaf at the far view 0.166 from its golden, tree pixels black 0.75-0.81.
    TEST(FoliageLodTree, goldenAtThreeDistances)
    {
        const LodfTree& oak = bundledOak();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        const struct
        {
            const char* view;
            const char* golden;
            double minCoverage, meshBound;
        } cases[] = {{"orbit:30,10,1.0", "oak-lodf-near", 0.08, 0.02},
                     {"orbit:30,10,2.5", "oak-lodf-mid", 0.015, 0.02},
                     {"orbit:30,10,6", "oak-lodf-far", 0.002, 0.2}};
        std::uint32_t previous = ~0u;
        for (const auto& c : cases)
        {
            FoliageLodTree* tree = place(oak.asset);
            const Image lodf = toImage(r.render(camera(oak.model, c.view), 256, 256, 3));
            const std::uint32_t count = tree->getLeafCount();
            EXPECT_LE(count, previous);
            previous = count;
            EXPECT_GT(treeCoverage(lodf, LightingSpec().background), c.minCoverage) << c.golden;
            compareWithGolden(lodf, c.golden, 0.02);

            r.clearContent();
            Ogre::MovableObject* mesh =
                TechniqueRegistry::getSingleton().createInstance("mesh", r.getSceneManager(), "ref", *oak.asset);
            r.getContentNode().createChildSceneNode()->attachObject(mesh);
            const Image reference = toImage(r.render(camera(oak.model, c.view), 256, 256, 3));
            EXPECT_LT(flipMean(reference, lodf, FlipOver::Tree), c.meshBound) << c.golden << " with " << count << " leaves";
        }
        EXPECT_LT(previous, oak.model.leaves.size()) << "the far view must drop leaves";
    }

    TEST(FoliageLodTree, castsAndReceivesShadows)
    {
        const LodfTree& oak = bundledOak();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        const CameraSpec view = camera(oak.model, "orbit:30,10,1.0");
        FoliageLodTree* tree = place(oak.asset);
        const Image plain = toImage(r.render(view, 192, 192, 2));
        r.setShadows(true, 1024);
        const Image shadowed = toImage(r.render(view, 192, 192, 2));
        // The shadow camera sees the viewer's level (its LoD camera is the viewer's): a second
        // frame from the same view changes nothing, so no re-upload per shadow pass.
        const std::uint32_t changes = tree->getUpdateStats().changes;
        r.render(camera(oak.model, "orbit:30,10,4"), 192, 192, 2);
        const std::uint32_t farCount = tree->getLeafCount();
        const std::uint32_t farChanges = tree->getUpdateStats().changes;
        r.render(camera(oak.model, "orbit:30,10,4"), 192, 192, 2);
        EXPECT_EQ(tree->getUpdateStats().changes, farChanges);
        EXPECT_EQ(tree->getLeafCount(), farCount);
        EXPECT_LE(farChanges, changes + 1);
        r.setShadows(false);
        // Self-shadowing darkens the crown's inside; the background is untouched.
        const double drop = meanLuminance(plain) - meanLuminance(shadowed);
        EXPECT_GT(drop, 0.002) << "shadows must darken the tree";
        EXPECT_EQ(shadowed.pixels[0], plain.pixels[0]);
        compareWithGolden(shadowed, "oak-lodf-shadows", 0.02);
    }

    TEST(FoliageLodTree, extremeCamerasAndTrees)
    {
        const LodfTree& oak = bundledOak();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        FoliageLodTree* tree = place(oak.asset);
        // Inside the crown: full detail, something drawn.
        const glm::vec3 centre = 0.5f * (oak.model.boundsMin + oak.model.boundsMax);
        CameraSpec inside = camera(oak.model, std::to_string(centre.x) + "," + std::to_string(centre.y) + "," +
                                                  std::to_string(centre.z + 0.3f) + ",0," + std::to_string(centre.y) + ",-50,70");
        const Image in = toImage(r.render(inside, 96, 96, 1));
        EXPECT_EQ(tree->getLeafCount(), tree->getMaxLeafCount());
        EXPECT_GT(treeCoverage(in, LightingSpec().background), 0.3);
        // 10 km away: the coarsest level, and the render still works.
        CameraSpec far = camera(oak.model, "0,5,10000,0,5,0,40");
        far.farClip = 20000.0f;
        r.render(far, 96, 96, 1);
        EXPECT_EQ(tree->getLeafCount(), tree->getMinLeafCount());

        // A bare trunk: no clusters, no leaf draw, the bark still renders.
        TreeModel bare = oak.model;
        bare.leaves.clear();
        bare.leafVertices.clear();
        bare.leafIndices.clear();
        bare.updateBounds();
        FoliageLodTree* trunk = place(loadLodf(bare, "bare.lodf-test"));
        const Image trunkImage = toImage(r.render(camera(bare, "orbit:30,10,1.0"), 96, 96, 1));
        EXPECT_EQ(trunk->getLeafCount(), 0u);
        EXPECT_GT(treeCoverage(trunkImage, LightingSpec().background), 0.01);
    }

    // 400,000 leaf vertices: the index ranges are 32-bit. Every leaf drawn is the polygonal tree's
    // picture (over the tree's pixels, measured 0.000), and half of them stay near it (measured
    // 0.252); 5,000 leaves measured 0.284, tree pixels black 0.511.
    TEST(FoliageLodTree, hundredThousandLeavesUse32BitRanges)
    {
        GeneratorOptions options;
        options.leafCount = 100000;
        options.textureSize = 64;
        Result<TreeModel> model = generateTree(options);
        ASSERT_TRUE(model.ok());
        TreeAssetPtr asset = loadLodf(model.value(), "oak100k.lodf-test");
        OffscreenRenderer& r = OgreEnvironment::renderer();
        const CameraSpec view = camera(model.value(), "orbit:30,10,1.2");
        Ogre::MovableObject* mesh =
            TechniqueRegistry::getSingleton().createInstance("mesh", r.getSceneManager(), "ref100k", *asset);
        r.clearContent();
        r.setShadows(false);
        r.setLodBias(1.0f);
        r.getContentNode().createChildSceneNode()->attachObject(mesh);
        const Image reference = toImage(r.render(view, 128, 128, 1));
        EXPECT_GT(treeCoverage(reference, LightingSpec().background), 0.02); // measured 0.037

        FoliageLodTree* tree = place(asset);
        EXPECT_GT(FoliageLodResources::of(*asset).getLeafVertexData()->vertexCount, 65535u);
        tree->setFixedLeafCount(100000);
        EXPECT_EQ(tree->getLeafCount(), 100000u);
        const Image all = toImage(r.render(view, 128, 128, 1));
        tree->setFixedLeafCount(50000);
        EXPECT_EQ(tree->getLeafCount(), 50000u);
        const Image half = toImage(r.render(view, 128, 128, 1));
        EXPECT_LT(flipMean(reference, all, FlipOver::Tree), 0.02);
        EXPECT_LT(flipMean(reference, half, FlipOver::Tree), 0.27);
    }

    TEST(FoliageLodTree, quantisedInstancesShareLevelsAndUploadNothing)
    {
        // A Forest's distant instances: quantise=8 snaps to 8 levels whose index buffers the
        // asset builds once; instances switch by pointing at them.
        const LodfTree& oak = bundledOak();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        const CameraSpec view = camera(oak.model, "orbit:30,10,1.0");
        FoliageLodTree* a = place(oak.asset, {{"quantise", "8"}, {"leaves", "500"}});
        Ogre::MovableObject* second = TechniqueRegistry::getSingleton().createInstance(
            "lodf", r.getSceneManager(), "quantised-b", *oak.asset, {{"quantise", "8"}, {"leaves", "3000"}});
        auto* b = static_cast<FoliageLodTree*>(second);
        EXPECT_TRUE(a->isQuantised());
        EXPECT_GE(a->getLeafCount(), 500u); // snapped up, never fewer leaves than asked
        EXPECT_EQ(b->getLeafCount(), 3000u);
        const std::size_t levels = FoliageLodResources::of(*oak.asset).getFoliageLodLevelCount();
        b->setFixedLeafCount(a->getLeafCount()); // to a level that exists: nothing is built or sent
        EXPECT_EQ(b->getLeafCount(), a->getLeafCount());
        EXPECT_EQ(FoliageLodResources::of(*oak.asset).getFoliageLodLevelCount(), levels);
        EXPECT_EQ(b->getUpdateStats().bytesUploaded, 0u);
        EXPECT_GT(FoliageLodResources::of(*oak.asset).getFoliageLodLevelBytes(), 0u);
        r.getSceneManager().destroyMovableObject(second);

        // A shared level draws exactly what a continuous instance draws at that count.
        const std::uint32_t count = a->getLeafCount();
        const Image quantised = toImage(r.render(view, 128, 128, 1));
        place(oak.asset, {{"leaves", std::to_string(count)}});
        const Image continuous = toImage(r.render(view, 128, 128, 1));
        std::size_t differ = 0;
        for (std::size_t i = 0; i < quantised.pixels.size(); ++i)
            differ += quantised.pixels[i] != continuous.pixels[i];
        EXPECT_EQ(differ, 0u);
        EXPECT_GT(treeCoverage(quantised, LightingSpec().background), 0.05);
    }
}

namespace TreeLod::FoliageLodTreeTests
{
    TEST(FoliageLodTree, meshLodBiasScalesTheCurveAndClampsTheBark)
    {
        // The factor multiplies the curve's pixels as the camera's bias does (both through
        // treelod_screen_size); the detail indices clamp the bark mesh's LoD index.
        const LodfTree& oak = bundledOak();
        FoliageLodTree* tree = place(oak.asset);
        OffscreenRenderer& r = OgreEnvironment::renderer();
        const CameraSpec view = camera(oak.model, "orbit:30,10,8");
        r.render(view, 256, 256, 1);
        const std::uint32_t base = tree->getLeafCount();
        ASSERT_LT(2 * base, tree->getMaxLeafCount());
        tree->setMeshLodBias(2.0f);
        r.render(view, 256, 256, 1);
        const std::uint32_t doubled = tree->getLeafCount();
        EXPECT_NEAR(double(doubled), 2.0 * base, 2.0);
        tree->setMeshLodBias(1.0f);
        r.setLodBias(2.0f);
        r.render(view, 256, 256, 1);
        r.setLodBias(1.0f);
        EXPECT_EQ(tree->getLeafCount(), doubled) << "the camera's bias 2 acts as factor 2";

        Ogre::MeshPtr bark = oak.asset->getBarkMesh();
        ASSERT_GT(bark->getNumLodLevels(), 2u);
        const CameraSpec far = camera(oak.model, "orbit:30,10,30");
        r.render(far, 256, 256, 1);
        const unsigned short farBark = tree->getBarkLodIndex();
        ASSERT_GT(farBark, 0u);
        tree->setMeshLodBias(1.0f, farBark + 1, 99);
        r.render(camera(oak.model, "orbit:30,10,1"), 256, 256, 1);
        EXPECT_EQ(tree->getBarkLodIndex(), std::min<unsigned short>(farBark + 1, bark->getNumLodLevels() - 1));
        tree->setMeshLodBias(1.0f, 0, 0);
        r.render(far, 256, 256, 1);
        EXPECT_EQ(tree->getBarkLodIndex(), 0u);
        tree->setMeshLodBias(1e4f);
        r.render(far, 256, 256, 1);
        EXPECT_LT(tree->getBarkLodIndex(), farBark) << "a factor on the bark mesh's pixel_count values";
    }

    TEST(FoliageLodTree, lodStrategyParameterNamesOgresStrategies)
    {
        // The leaf count: more is finer; pixel_count's value is the default's within rounding.
        const LodfTree& oak = bundledOak();
        FoliageLodTree* tree = nullptr;
        std::vector<CameraSpec> views;
        for (const char* view : {"orbit:30,10,4", "orbit:30,10,8", "orbit:30,10,16", "orbit:30,10,32"})
            views.push_back(camera(oak.model, view));
        expectLodStrategyParameter([&](const Ogre::NameValuePairList& params) { tree = place(oak.asset, params); },
                                   [&] { return unsigned(tree->getLeafCount()); },
                                   [&](const CameraSpec& view) { OgreEnvironment::renderer().render(view, 128, 128, 1); },
                                   views, true, 2);
    }
}
