// BillboardCloudTree (García et al. 2007: billboard clouds with multi-layered indirect texturing) through
// Plugin_TreeLod: factory and registry, bad parameters, bounds, render queue group and query
// flags, geometric LoD against pixel count, bias and distance, material LoD at its threshold,
// shader LoD visible in the picture, golden images of the bundled trees and a 50k-leaf tree
// (each also against the polygonal reference), the classic cloud, shadows (LiSPSM), extreme
// cameras and tree sizes.
//
// Packages are baked here with the core baker (small aoRays for speed) and cached in
// $TREELOD_TEST_OUT/billboardcloud, keyed by this binary's modification time: a rebuilt baker
// rebakes.
#include "OgreTestSupport.h"

#include "TreeLod/BillboardCloudBaker.h"
#include "TreeLod/BillboardCloudTree.h"
#include "TreeLod/GltfImporter.h"
#include "TreeLod/PackageWriter.h"
#include "TreeLod/TechniqueRegistry.h"
#include "TreeLod/TreeAssetManager.h"
#include "TreeLod/TreeGenerator.h"

#include <OgreRenderQueue.h>
#include <OgreRenderQueueSortingGrouping.h>
#include <OgreSceneManager.h>
#include <OgreSceneQuery.h>
#include <OgreSubMesh.h>

#include <unistd.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <map>

namespace TreeLod::BillboardCloudTreeTests
{
    namespace
    {
        struct BakedTree
        {
            TreeModel model;
            TreeAssetPtr asset;
        };

        /// `model` baked with the reference, billboard-cloud and (withClassic) classic chunks,
        /// loaded as asset "<name>.bc-test"; the package bytes are cached on disk.
        TreeAssetPtr bake(const TreeModel& model, const std::string& name, bool withClassic)
        {
            OgreEnvironment::renderer();
            const std::string assetName = name + ".bc-test";
            if (TreeAssetPtr existing = TreeAssetManager::getSingleton().getByName(assetName, Ogre::RGN_DEFAULT))
                return existing;
            const std::vector<std::uint8_t> bytes = cachedPackage("billboardcloud", name, [&] {
                PackageWriter writer;
                Result<void> added = addReferenceChunk(writer, model, name);
                EXPECT_TRUE(added.ok()) << (added.ok() ? "" : added.error().message());
                BillboardCloudOptions options;
                options.aoRays = 4;
                Result<BillboardCloudData> cloud = bakeBillboardCloud(model, options, name);
                EXPECT_TRUE(cloud.ok()) << (cloud.ok() ? "" : cloud.error().message());
                if (!cloud.ok())
                    return std::vector<std::uint8_t>();
                EXPECT_TRUE(writer.addChunk(BILLBOARD_CLOUD_CHUNK, 0, BILLBOARD_CLOUD_CHUNK_FORMAT_VERSION,
                                            encodeBillboardCloudChunk(cloud.value())).ok());
                if (withClassic)
                {
                    ClassicBillboardCloudOptions classic;
                    classic.cloud = options;
                    classic.memoryBytes = cloud->gpuBytes(); // Fig. 13: equal memory
                    Result<BillboardCloudData> flat = bakeClassicBillboardCloud(model, classic, name);
                    EXPECT_TRUE(flat.ok()) << (flat.ok() ? "" : flat.error().message());
                    if (flat.ok())
                    {
                        Result<void> added = writer.addChunk(CLASSIC_BILLBOARD_CLOUD_CHUNK, 0,
                                                             BILLBOARD_CLOUD_CHUNK_FORMAT_VERSION,
                                                             encodeBillboardCloudChunk(flat.value()));
                        EXPECT_TRUE(added.ok());
                    }
                }
                return writer.toBytes();
            });
            if (bytes.empty())
                return {};
            return TreeAssetManager::getSingleton().loadFromBytes(assetName, Ogre::RGN_DEFAULT, bytes);
        }

        const BakedTree& bundled(const std::string& name)
        {
            auto& trees = OgreEnvironment::keep<std::map<std::string, BakedTree>>(
                "billboard-cloud.bundled", [] { return std::map<std::string, BakedTree>(); });
            auto found = trees.find(name);
            if (found != trees.end())
                return found->second;
            BakedTree t;
            Result<TreeModel> model = importGltf(OgreEnvironment::sourcePath("media/" + name + ".glb"));
            EXPECT_TRUE(model.ok()) << (model.ok() ? "" : model.error().message());
            t.model = std::move(model.value());
            t.asset = bake(t.model, name, name == "oak");
            return trees.emplace(name, std::move(t)).first->second;
        }

        /// A generated oak (TreeGenerator, oak preset) of `leaves` leaves, baked as `name`.
        const BakedTree& generated(const std::string& name, std::uint32_t leaves, int textureSize,
                                   std::uint32_t leafImages = 1, std::uint32_t leafMaterials = 1,
                                   float leafFold = 0.0f)
        {
            return OgreEnvironment::keep<BakedTree>("billboard-cloud." + name, [&] {
                BakedTree t;
                GeneratorOptions options;
                options.preset = TreePreset::Oak;
                options.leafCount = leaves;
                options.textureSize = textureSize;
                options.leafImages = leafImages;
                options.leafMaterials = leafMaterials;
                options.leafFold = leafFold;
                Result<TreeModel> model = generateTree(options);
                EXPECT_TRUE(model.ok());
                t.model = std::move(model.value());
                t.asset = bake(t.model, name, false);
                return t;
            });
        }

        const BakedTree& generated50k() { return generated("oak50k", 50000, 64); }

        /// The bundled oak's generator settings with a 2 x 2 leaf atlas under six leaf materials
        /// (cutoffs 0.3 .. 0.7): what game and SpeedTree assets look like to the baker.
        const BakedTree& atlasOak() { return generated("oak-atlas6", 3000, 128, 4, 6); }

        /// The bundled oak's generator settings with every leaf one mesh of two quads folded 45
        /// degrees along its midrib: a leaf in several planes.
        const BakedTree& foldedOak() { return generated("oak-folded45", 3000, 128, 1, 1, 45.0f); }

        /// A fresh object of `technique` for `asset` under the content node (content cleared).
        Ogre::MovableObject* place(const TreeAssetPtr& asset, const Ogre::NameValuePairList& params = {},
                                   const char* technique = BILLBOARD_CLOUD_CHUNK)
        {
            return placeTechnique(technique, *asset, params);
        }

        BillboardCloudTree* placeCloud(const TreeAssetPtr& asset, const Ogre::NameValuePairList& params = {})
        {
            return static_cast<BillboardCloudTree*>(place(asset, params));
        }

        CameraSpec camera(const TreeModel& model, const std::string& text)
        {
            CameraSpec spec;
            std::string error;
            EXPECT_TRUE(CameraSpec::parse(text, model.boundsMin, model.boundsMax, spec, error)) << error;
            return spec;
        }

        /// Orbit camera from which the tree is `pixels` tall in an image `imageHeight` high.
        CameraSpec cameraForHeight(const TreeModel& model, float pixels, int imageHeight)
        {
            const float fov = 45.0f;
            const float height = model.boundsMax.y - model.boundsMin.y;
            const float radius = 0.5f * glm::length(model.boundsMax - model.boundsMin);
            const float distance = height * float(imageHeight) / (2.0f * pixels * std::tan(glm::radians(0.5f * fov)));
            return CameraSpec::framing(model.boundsMin, model.boundsMax, 30.0f, 10.0f,
                                       distance * std::sin(glm::radians(0.5f * fov)) / radius, fov);
        }

        const glm::vec3 BACKGROUND = LightingSpec().background;
    }

    TEST(BillboardCloudTree, registeredAsTechniquesAndFactory)
    {
        OgreEnvironment::renderer();
        for (const char* chunk : {BILLBOARD_CLOUD_CHUNK, CLASSIC_BILLBOARD_CLOUD_CHUNK})
        {
            const TechniqueInfo* info = TechniqueRegistry::getSingleton().find(chunk);
            ASSERT_NE(info, nullptr) << chunk;
            EXPECT_EQ(info->chunkTechnique, chunk);
            EXPECT_EQ(info->movableType, BillboardCloudTreeFactory::FACTORY_TYPE_NAME);
        }
        EXPECT_TRUE(Ogre::Root::getSingleton().hasMovableObjectFactory("BillboardCloudTree"));

        // The factory path an application uses: createMovableObject with asset=NAME.
        const BakedTree& oak = bundled("oak");
        Ogre::SceneManager& sm = OgreEnvironment::renderer().getSceneManager();
        Ogre::NameValuePairList params{{"asset", oak.asset->getName()}, {"level", "1"}, {"listFactor", "2.5"}};
        Ogre::MovableObject* object = sm.createMovableObject("bcViaFactory", "BillboardCloudTree", &params);
        ASSERT_NE(object, nullptr);
        EXPECT_EQ(object->getMovableType(), "BillboardCloudTree");
        auto* tree = static_cast<BillboardCloudTree*>(object);
        EXPECT_EQ(tree->getLevel(), 1u);
        EXPECT_EQ(tree->getListFactor(), 2.5f);
        EXPECT_EQ(tree->getLevelCount(), 3u);
        EXPECT_FALSE(tree->isClassic());
        // Local bounds hold the tree (reference) and every billboard; the radius is Ogre's
        // sphere about the origin holding them.
        const Ogre::AxisAlignedBox& box = object->getBoundingBox();
        const BillboardCloudData& data = BillboardCloudResources::of(*oak.asset, false).getData();
        EXPECT_TRUE(box.contains(Ogre::Vector3(oak.model.boundsMin.x, oak.model.boundsMin.y, oak.model.boundsMin.z)));
        EXPECT_TRUE(box.contains(Ogre::Vector3(oak.model.boundsMax.x, oak.model.boundsMax.y, oak.model.boundsMax.z)));
        for (const Billboard& b : data.billboards)
            for (const glm::vec3& c : {b.origin, b.origin + b.axisU, b.origin + b.axisV, b.origin + b.axisU + b.axisV})
                EXPECT_TRUE(box.contains(Ogre::Vector3(c.x, c.y, c.z)));
        EXPECT_FLOAT_EQ(object->getBoundingRadius(), Ogre::Math::boundingRadiusFromAABB(box));
        sm.destroyMovableObject(object);

        Ogre::NameValuePairList classic{{"asset", oak.asset->getName()}, {"classic", "true"}};
        object = sm.createMovableObject("bcClassic", "BillboardCloudTree", &classic);
        EXPECT_TRUE(static_cast<BillboardCloudTree*>(object)->isClassic());
        EXPECT_EQ(static_cast<BillboardCloudTree*>(object)->getLevelCount(), 1u);
        sm.destroyMovableObject(object);
    }

    TEST(BillboardCloudTree, badParametersAreNamed)
    {
        const BakedTree& oak = bundled("oak");
        Ogre::SceneManager& sm = OgreEnvironment::renderer().getSceneManager();
        const std::string asset = oak.asset->getName();
        const std::pair<Ogre::NameValuePairList, const char*> cases[] = {
            {{}, "'asset'"},
            {{{"asset", asset}, {"classic", "yes"}}, "'classic'"},
            {{{"asset", asset}, {"level", "7"}}, "'level'"},
            {{{"asset", asset}, {"level", "1.5"}}, "'level'"},
            {{{"asset", asset}, {"lodStrategy", "screen"}}, "'lodStrategy'"},
            {{{"asset", asset}, {"listFactor", "-1"}}, "'listFactor'"},
            {{{"asset", asset}, {"lodBias", "0"}}, "'lodBias'"},
        };
        int serial = 0;
        for (const auto& c : cases)
        {
            try
            {
                sm.createMovableObject("bcBad" + std::to_string(serial++), "BillboardCloudTree", &c.first);
                ADD_FAILURE() << "parameters naming " << c.second << " must throw";
            }
            catch (const Ogre::Exception& e)
            {
                EXPECT_NE(e.getDescription().find(c.second), std::string::npos) << e.getDescription();
            }
        }
        // A package without the chunk: the error names the bake option that makes it.
        PackageWriter writer;
        ASSERT_TRUE(addReferenceChunk(writer, oak.model, "ref-only").ok());
        TreeAssetPtr refOnly =
            TreeAssetManager::getSingleton().loadFromBytes("ref-only.bc-test", Ogre::RGN_DEFAULT, writer.toBytes());
        for (const char* technique : {BILLBOARD_CLOUD_CHUNK, CLASSIC_BILLBOARD_CLOUD_CHUNK})
            try
            {
                place(refOnly, {}, technique);
                ADD_FAILURE() << "a package without " << technique << " must throw";
            }
            catch (const Ogre::Exception& e)
            {
                EXPECT_NE(e.getDescription().find(std::string("--technique ") + technique), std::string::npos)
                    << e.getDescription();
            }
    }

    TEST(BillboardCloudTree, renderQueueGroupAndQueryFlags)
    {
        const BakedTree& oak = bundled("oak");
        OffscreenRenderer& r = OgreEnvironment::renderer();
        BillboardCloudTree* tree = placeCloud(oak.asset);
        tree->setRenderQueueGroup(Ogre::RENDER_QUEUE_6);
        tree->setRenderQueueGroupAndPriority(Ogre::RENDER_QUEUE_6, 42);
        r.render(camera(oak.model, "orbit:30,10,1.0"), 64, 64, 1); // LoD from a camera

        Ogre::RenderQueue queue;
        tree->_updateRenderQueue(&queue);
        struct Counter : Ogre::QueuedRenderableVisitor
        {
            std::size_t count = 0;
            void visit(Ogre::RenderablePass*) override { ++count; }
            void visit(const Ogre::Pass*, Ogre::RenderableList& list) override { count += list.size(); }
        };
        std::size_t inGroup = 0, elsewhere = 0;
        for (std::size_t id = 0; id < Ogre::RENDER_QUEUE_COUNT; ++id)
            if (const auto& group = queue._getQueueGroups()[id])
                for (const auto& priority : group->getIterator())
                {
                    Counter counter;
                    priority.second->getSolidsBasic().acceptVisitor(&counter,
                                                                     Ogre::QueuedRenderableCollection::OM_PASS_GROUP);
                    (id == Ogre::RENDER_QUEUE_6 && priority.first == 42 ? inGroup : elsewhere) += counter.count;
                }
        EXPECT_GT(inGroup, 0u) << "the cloud and bark parts go to the object's group and priority";
        EXPECT_EQ(elsewhere, 0u);

        // Query flags: a ray through the crown finds the tree only with a matching mask.
        const glm::vec3 centre = 0.5f * (oak.model.boundsMin + oak.model.boundsMax);
        expectRayQueryHonoursFlags(
            r.getSceneManager(), tree,
            Ogre::Ray(Ogre::Vector3(centre.x, centre.y, centre.z + 100.0f), Ogre::Vector3::NEGATIVE_UNIT_Z));
    }

    TEST(BillboardCloudTree, levelFollowsPixelCountBiasAndDistance)
    {
        const BakedTree& oak = bundled("oak");
        OffscreenRenderer& r = OgreEnvironment::renderer();
        BillboardCloudTree* tree = placeCloud(oak.asset);
        const BillboardCloudGpu& gpu = BillboardCloudResources::of(*oak.asset, false).getGpu();
        // §6: level 0 -> 1 where level 0 walks SWITCH_ENTRIES entries, 1 -> 2 exactly where level
        // 1's material LoD switches to the low-res technique (one entry).
        EXPECT_FLOAT_EQ(tree->getSwitchPixelCount(0),
                        billboardCloudPixelCount(BillboardCloudTree::SWITCH_ENTRIES, gpu.levels[0].cellSize,
                                                 float(gpu.radius), gpu.listFactor));
        EXPECT_FLOAT_EQ(tree->getSwitchPixelCount(1), gpu.levels[1].lowResPixelCount);
        EXPECT_GT(tree->getSwitchPixelCount(0), tree->getSwitchPixelCount(1));

        std::vector<std::uint32_t> levels;
        std::vector<Ogre::Real> values;
        for (const char* view : {"orbit:30,10,0.5", "orbit:30,10,2", "orbit:30,10,6", "orbit:30,10,20", "orbit:30,10,80"})
        {
            r.render(camera(oak.model, view), 128, 128, 1);
            levels.push_back(tree->getLevel());
            values.push_back(tree->getLodValue());
            EXPECT_EQ(tree->getLevel(), tree->levelForValue(tree->getLodValue())) << view;
        }
        EXPECT_EQ(levels.front(), 0u);
        EXPECT_EQ(levels.back(), 2u);
        for (std::size_t i = 1; i < levels.size(); ++i)
        {
            EXPECT_GE(levels[i], levels[i - 1]);
            EXPECT_LT(values[i], values[i - 1]);
        }
        // Ogre's strategy (unscaled node: the same value), and the bias multiplying it; the
        // supersampling factor is compensated (OffscreenRenderer divides the bias by s^2).
        const CameraSpec mid = camera(oak.model, "orbit:30,10,2");
        r.render(mid, 128, 128, 1);
        const Ogre::Real base = tree->getLodValue();
        r.setLodBias(2.0f);
        r.render(mid, 128, 128, 1);
        EXPECT_NEAR(tree->getLodValue(), 2.0f * base, 1e-3f * base);
        r.setLodBias(1.0f);
        r.render(mid, 128, 128, 2);
        EXPECT_NEAR(tree->getLodValue(), base, 1e-3f * base);
        // The lodBias parameter multiplies the camera's: enough bias keeps level 0 far away.
        tree = placeCloud(oak.asset, {{"lodBias", "1000"}});
        r.render(camera(oak.model, "orbit:30,10,6"), 128, 128, 1);
        EXPECT_EQ(tree->getLevel(), 0u);

        // Distance strategy: the value is the squared distance to the box, levels still step
        // down with distance, consistently with levelForValue.
        tree = placeCloud(oak.asset, {{"lodStrategy", "distance"}});
        std::vector<std::uint32_t> byDistance;
        for (const char* view : {"orbit:30,10,0.5", "orbit:30,10,2", "orbit:30,10,6", "orbit:30,10,20", "orbit:30,10,80"})
        {
            const CameraSpec spec = camera(oak.model, view);
            r.render(spec, 128, 128, 1);
            const Ogre::AxisAlignedBox box = tree->getWorldBoundingBox(true);
            const Ogre::Real d = box.distance(Ogre::Vector3(spec.position.x, spec.position.y, spec.position.z));
            EXPECT_NEAR(tree->getLodValue(), d * d, 1e-3f * d * d + 1e-3f) << view;
            EXPECT_EQ(tree->getLevel(), tree->levelForValue(tree->getLodValue())) << view;
            byDistance.push_back(tree->getLevel());
        }
        EXPECT_EQ(byDistance.front(), 0u);
        EXPECT_EQ(byDistance.back(), 2u);
        for (std::size_t i = 1; i < byDistance.size(); ++i)
            EXPECT_GE(byDistance[i], byDistance[i - 1]);
    }

    TEST(BillboardCloudTree, materialLodSwitchesAtTheShaderLodThreshold)
    {
        const BakedTree& oak = bundled("oak");
        const BillboardCloudGpu& gpu = BillboardCloudResources::of(*oak.asset, false).getGpu();
        // The clone's lod_values: one entry walked (listFactor * projected diagonal = 1).
        const Ogre::Real threshold = gpu.levels[1].lowResPixelCount;
        EXPECT_FLOAT_EQ(threshold, billboardCloudPixelCount(1.0f, gpu.levels[1].cellSize, float(gpu.radius),
                                                            gpu.listFactor));
        BillboardCloudTree* tree = placeCloud(oak.asset, {{"level", "1"}});
        EXPECT_EQ(tree->materialLodIndexForPixelCount(threshold * 1.01f), 0u);
        EXPECT_EQ(tree->materialLodIndexForPixelCount(threshold * 0.99f), 1u);
        // A list factor twice the chunk's walks one entry at half the pixel radius.
        tree->setListFactor(2.0f * gpu.listFactor);
        EXPECT_EQ(tree->materialLodIndexForPixelCount(threshold * 0.26f), 0u);
        EXPECT_EQ(tree->materialLodIndexForPixelCount(threshold * 0.24f), 1u);
        tree->setListFactor(gpu.listFactor);

        // Rendering: the index follows the camera, and the drawn technique is the LowRes one.
        OffscreenRenderer& r = OgreEnvironment::renderer();
        r.render(camera(oak.model, "orbit:30,10,1"), 96, 96, 1);
        EXPECT_EQ(tree->getMaterialLodIndex(), 0u);
        r.render(camera(oak.model, "orbit:30,10,80"), 96, 96, 1);
        EXPECT_LT(tree->getPixelCountValue(), threshold);
        EXPECT_EQ(tree->getMaterialLodIndex(), 1u);
        Ogre::MaterialPtr material = Ogre::MaterialManager::getSingleton().getByName(gpu.levels[1].material,
                                                                                     oak.asset->getGroup());
        ASSERT_TRUE(material);
        EXPECT_EQ(material->getLodIndex(tree->getPixelCountValue()), 1u);
        EXPECT_EQ(material->getBestTechnique(1)->getName(), "LowRes");
        // §5.2: its shadow casters follow: the layers close up, the low-res texture far away.
        const Ogre::MaterialPtr nearCaster = material->getBestTechnique(0)->getShadowCasterMaterial();
        const Ogre::MaterialPtr farCaster = material->getBestTechnique(1)->getShadowCasterMaterial();
        ASSERT_TRUE(nearCaster && farCaster);
        EXPECT_NE(nearCaster->getName().find("/BillboardCloudCaster"), std::string::npos) << nearCaster->getName();
        EXPECT_NE(farCaster->getName().find("/BillboardCloudLowResCaster"), std::string::npos) << farCaster->getName();
        EXPECT_EQ(nearCaster->getGroup(), oak.asset->getGroup()); // the asset's clone, textures bound
        // Level 2 (no lists) is low-res only whatever the distance.
        EXPECT_FALSE(gpu.levels[2].layered);
        EXPECT_EQ(Ogre::MaterialManager::getSingleton()
                      .getByName(gpu.levels[2].material, oak.asset->getGroup())
                      ->getBestTechnique(0)
                      ->getName(),
                  "LowRes");
    }

    TEST(BillboardCloudTree, shaderLodIsVisible)
    {
        // The same billboards (level 0) and view: every list walked vs none (the low-res
        // texture alone); a default factor from far enough walks some entries.
        const BakedTree& oak = bundled("oak");
        OffscreenRenderer& r = OgreEnvironment::renderer();
        const CameraSpec view = camera(oak.model, "orbit:30,10,1.0");
        placeCloud(oak.asset, {{"level", "0"}, {"listFactor", "1000"}});
        const Image layers = toImage(r.render(view, 160, 160, 1));
        BillboardCloudTree* low = placeCloud(oak.asset, {{"level", "0"}, {"listFactor", "0"}});
        const Image lowRes = toImage(r.render(view, 160, 160, 1));
        EXPECT_EQ(low->getMaterialLodIndex(), 1u);
        EXPECT_GT(treeCoverage(layers, BACKGROUND), 0.1);
        EXPECT_GT(treeCoverage(lowRes, BACKGROUND), 0.02);
        const double difference = flipMean(layers, lowRes, FlipOver::Tree);
        std::printf("every list walked vs low-res only: FLIP %.4f\n", difference); // over the tree, measured 0.370
        EXPECT_GT(difference, 0.2) << "the lists must change the picture";
        writePng(OgreEnvironment::outDir() + "/bc-shader-lod.png", sideBySide({layers, lowRes}));
    }

    // Golden images (FLIP bound 0.02 as the other goldens) of the bundled trees and a
    // 50k-leaf tree, near (the tree fills the view) and far (about 32 px tall), and the FLIP
    // against the polygonal reference rendered the same way, under bounds measured on this
    // machine (stated per case, about 1.5x the measured value). Side-by-side images
    // (reference | billboard cloud) are left in test-out/ogre/bc-*.png.
    struct GoldenCase
    {
        const char* tree;
        bool far;
        double minCoverage;
        double referenceBound;
    };

    void checkGolden(const BakedTree& tree, const std::string& name, const GoldenCase& c)
    {
        OffscreenRenderer& r = OgreEnvironment::renderer();
        const int size = c.far ? 128 : 256;
        const CameraSpec view = cameraForHeight(tree.model, c.far ? 32.0f : 0.85f * float(size), size);
        BillboardCloudTree* cloud = placeCloud(tree.asset);
        const Image image = toImage(r.render(view, size, size, 2));
        const std::uint32_t level = cloud->getLevel();
        place(tree.asset, {}, "mesh");
        const Image reference = toImage(r.render(view, size, size, 2));
        const double coverage = treeCoverage(image, BACKGROUND);
        const double error = flipMean(reference, image, FlipOver::Tree);
        std::printf("%s: level %u coverage %.3f (reference %.3f), FLIP vs reference %.4f over the tree\n", name.c_str(),
                    level, coverage, treeCoverage(reference, BACKGROUND), error);
        writePng(OgreEnvironment::outDir() + "/bc-" + name + "-vs-reference.png", sideBySide({reference, image}));
        EXPECT_GT(coverage, c.minCoverage) << name;
        EXPECT_LT(error, c.referenceBound) << name;
        compareWithGolden(image, name, 0.02);
    }

    TEST(BillboardCloudTree, goldenBundledTrees)
    {
        // FLIP against the reference over the tree's pixels measured 0.401 / 0.220 (oak near /
        // far), 0.389 / 0.211 (conifer), 0.321 / 0.215 (birch); bounds about 15 % above. Close up
        // the leaves are where the reference has them only to the clustering's plane error, and
        // AO darkens the crown (the reference has none); far away both are a few hundred pixels
        // of foliage. The low-res level drawn near measured 0.57-0.73, the tree black 0.67-0.88.
        const GoldenCase cases[] = {{"oak", false, 0.3, 0.46},      {"oak", true, 0.02, 0.25},
                                    {"conifer", false, 0.15, 0.45}, {"conifer", true, 0.01, 0.24},
                                    {"birch", false, 0.09, 0.37},   {"birch", true, 0.008, 0.25}};
        for (const GoldenCase& c : cases)
            checkGolden(bundled(c.tree), std::string(c.tree) + "-billboardcloud-" + (c.far ? "far" : "near"), c);
    }

    TEST(BillboardCloudTree, goldenFiftyThousandLeaves)
    {
        const BakedTree& tree = generated50k();
        ASSERT_EQ(tree.model.leaves.size(), 50000u);
        // FLIP against the reference over the tree's pixels measured 0.299 near, 0.239 far.
        checkGolden(tree, "oak50k-billboardcloud-near", {"oak50k", false, 0.3, 0.34});
        checkGolden(tree, "oak50k-billboardcloud-far", {"oak50k", true, 0.02, 0.27});
    }

    TEST(BillboardCloudTree, goldenLeafAtlasAndSixLeafMaterials)
    {
        const BakedTree& tree = atlasOak();
        ASSERT_EQ(tree.model.materials.size(), 7u);
        // Every leaf shows its own atlas cell under its own material's cutoff. FLIP against the
        // reference over the tree's pixels measured 0.420 near and 0.218 far. Drawing the whole atlas on every leaf
        // doubled the error (treelod_bc_study, tree-box FLIP at a quarter of the view: 0.223
        // against 0.110).
        checkGolden(tree, "oak-atlas6-billboardcloud-near", {"oak-atlas6", false, 0.3, 0.48});
        checkGolden(tree, "oak-atlas6-billboardcloud-far", {"oak-atlas6", true, 0.02, 0.25});
    }

    TEST(BillboardCloudTree, goldenFoldedLeaves)
    {
        const BakedTree& tree = foldedOak();
        ASSERT_EQ(tree.model.leaves[0].indexCount, 12u);
        // Each wing is a leaf of the cloud, showing its half of the leaf image. FLIP against the
        // reference over the tree's pixels measured 0.364 near and 0.225 far.
        checkGolden(tree, "oak-folded45-billboardcloud-near", {"oak-folded45", false, 0.3, 0.42});
        checkGolden(tree, "oak-folded45-billboardcloud-far", {"oak-folded45", true, 0.02, 0.26});
    }

    TEST(BillboardCloudTree, classicCloudRenders)
    {
        // The baseline of Fig. 13: one level, low-res technique only, same memory as the layered cloud.
        const BakedTree& oak = bundled("oak");
        const BillboardCloudData& classic = BillboardCloudResources::of(*oak.asset, true).getData();
        EXPECT_TRUE(classic.classic);
        ASSERT_EQ(classic.levels.size(), 1u);
        EXPECT_FALSE(classic.levels[0].layered);
        OffscreenRenderer& r = OgreEnvironment::renderer();
        const CameraSpec view = cameraForHeight(oak.model, 0.85f * 256.0f, 256);
        auto* tree = static_cast<BillboardCloudTree*>(place(oak.asset, {}, CLASSIC_BILLBOARD_CLOUD_CHUNK));
        const Image image = toImage(r.render(view, 256, 256, 2));
        EXPECT_TRUE(tree->isClassic());
        EXPECT_EQ(tree->getLevel(), 0u);
        EXPECT_EQ(tree->getMaterialLodIndex(), 0u);
        EXPECT_GT(treeCoverage(image, BACKGROUND), 0.2);
        place(oak.asset, {}, "mesh");
        const Image reference = toImage(r.render(view, 256, 256, 2));
        placeCloud(oak.asset);
        const Image layered = toImage(r.render(view, 256, 256, 2));
        // Measured against the reference over the tree's pixels: classic 0.415, multi-layered 0.401
        // (oak, equal memory).
        const double error = flipMean(reference, image, FlipOver::Tree),
                     layeredError = flipMean(reference, layered, FlipOver::Tree);
        std::printf("oak near, FLIP vs reference: classic %.4f, multi-layered %.4f\n", error, layeredError);
        EXPECT_LT(error, 0.47);
        writePng(OgreEnvironment::outDir() + "/bc-oak-reference-classic-layered.png",
                 sideBySide({reference, image, layered}));
        compareWithGolden(image, "oak-classicbillboardcloud-near", 0.02);
    }

    TEST(BillboardCloudTree, castsAndReceivesShadowsWithLiSPSM)
    {
        // §5.2: LiSPSM texture shadows; the cloud's casters evaluate the layers close up.
        const BakedTree& oak = bundled("oak");
        OffscreenRenderer& r = OgreEnvironment::renderer();
        const CameraSpec view = camera(oak.model, "orbit:30,10,1.0");
        placeCloud(oak.asset);
        const Image plain = toImage(r.render(view, 192, 192, 2));
        r.setShadows(true, 1024, ShadowCamera::LiSPSM);
        const Image lispsm = toImage(r.render(view, 192, 192, 2));
        r.setShadows(true, 1024, ShadowCamera::Focused);
        const Image focused = toImage(r.render(view, 192, 192, 2));
        r.setShadows(false);
        const double dropLispsm = meanLuminance(plain) - meanLuminance(lispsm);
        const double dropFocused = meanLuminance(plain) - meanLuminance(focused);
        std::printf("shadow darkening: LiSPSM %.4f, focused %.4f, FLIP between them %.4f\n", dropLispsm, dropFocused,
                    flipMean(focused, lispsm));
        EXPECT_GT(dropLispsm, 0.003) << "self-shadowing must darken the crown";
        EXPECT_GT(dropFocused, 0.003);
        // Both camera setups see the same occluders: similar darkening.
        EXPECT_NEAR(dropLispsm, dropFocused, 0.5 * dropFocused);
        EXPECT_EQ(lispsm.pixels[0], plain.pixels[0]); // the background is untouched
        writePng(OgreEnvironment::outDir() + "/bc-shadows.png", sideBySide({plain, focused, lispsm}));
        compareWithGolden(lispsm, "oak-billboardcloud-shadows", 0.02);
    }

    TEST(BillboardCloudTree, barkIsDrawnWithItsLodLevelsAndAo)
    {
        const BakedTree& oak = bundled("oak");
        Ogre::MeshPtr bark = BillboardCloudResources::of(*oak.asset, false).getBarkAoMesh();
        ASSERT_GT(bark->getNumSubMeshes(), 0u);
        EXPECT_GT(bark->getNumLodLevels(), 1u);
        for (Ogre::SubMesh* sub : bark->getSubMeshes())
        {
            EXPECT_NE(sub->vertexData->vertexDeclaration->findElementBySemantic(Ogre::VES_DIFFUSE), nullptr);
            EXPECT_NE(sub->getMaterialName().find("/BarkAo"), std::string::npos);
        }
        OffscreenRenderer& r = OgreEnvironment::renderer();
        BillboardCloudTree* tree = placeCloud(oak.asset);
        r.render(camera(oak.model, "orbit:30,10,0.5"), 256, 256, 1);
        const unsigned short nearLod = tree->getBarkLodIndex();
        r.render(camera(oak.model, "orbit:30,10,20"), 64, 64, 1);
        EXPECT_EQ(nearLod, 0u);
        EXPECT_GT(tree->getBarkLodIndex(), nearLod);
    }

    TEST(BillboardCloudTree, extremeCamerasAndTreeSizes)
    {
        const BakedTree& oak = bundled("oak");
        OffscreenRenderer& r = OgreEnvironment::renderer();
        BillboardCloudTree* tree = placeCloud(oak.asset);
        // Inside the crown: the finest level, leaves all around.
        const glm::vec3 centre = 0.5f * (oak.model.boundsMin + oak.model.boundsMax);
        const CameraSpec inside = camera(oak.model, std::to_string(centre.x) + "," + std::to_string(centre.y) + "," +
                                                        std::to_string(centre.z + 0.3f) + ",0," +
                                                        std::to_string(centre.y) + ",-50,70");
        const Image in = toImage(r.render(inside, 96, 96, 1));
        EXPECT_EQ(tree->getLevel(), 0u);
        EXPECT_EQ(tree->getMaterialLodIndex(), 0u);
        EXPECT_GT(treeCoverage(in, BACKGROUND), 0.3);
        // 10 km away: the coarsest level, a few pixels at most, no failure.
        CameraSpec far = camera(oak.model, "0,5,10000,0,5,0,40");
        far.farClip = 20000.0f;
        const Image distant = toImage(r.render(far, 96, 96, 1));
        EXPECT_EQ(tree->getLevel(), tree->getLevelCount() - 1);
        EXPECT_LT(treeCoverage(distant, BACKGROUND), 0.01);

        // A bare trunk: a cloud without billboards, the bark still drawn.
        TreeModel bare = oak.model;
        bare.leaves.clear();
        bare.leafVertices.clear();
        bare.leafIndices.clear();
        bare.updateBounds();
        BillboardCloudTree* trunk = placeCloud(bake(bare, "oak-bare", false));
        const Image trunkImage = toImage(r.render(camera(bare, "orbit:30,10,1.0"), 96, 96, 1));
        EXPECT_EQ(BillboardCloudResources::of(*trunk->getAsset(), false).getData().billboards.size(), 0u);
        EXPECT_GT(treeCoverage(trunkImage, BACKGROUND), 0.01);

        // 0.5 m and 500 m tall trees (the model scaled, then baked): the same picture at the
        // same screen size, and the same levels (thresholds are in pixels).
        std::vector<Image> images;
        std::vector<std::uint32_t> levels;
        const float height = oak.model.boundsMax.y - oak.model.boundsMin.y;
        for (const float target : {0.5f, 500.0f})
        {
            TreeModel scaled = oak.model;
            const float s = target / height;
            for (std::vector<Vertex>* vertices : {&scaled.barkVertices, &scaled.leafVertices})
                for (Vertex& v : *vertices)
                    v.position *= s;
            for (Leaf& leaf : scaled.leaves)
            {
                leaf.centre *= s;
                leaf.area *= s * s;
            }
            for (SkeletonNode& node : scaled.skeleton)
            {
                node.position *= s;
                node.radius *= s;
            }
            scaled.updateBounds();
            BillboardCloudTree* t = placeCloud(bake(scaled, "oak-" + std::to_string(int(target * 10)) + "dm", false));
            for (const char* view : {"orbit:30,10,1.0", "orbit:30,10,4"})
            {
                images.push_back(toImage(r.render(camera(scaled, view), 128, 128, 1)));
                levels.push_back(t->getLevel());
            }
        }
        EXPECT_EQ(levels[0], levels[2]);
        EXPECT_EQ(levels[1], levels[3]);
        const double nearError = flipMean(images[0], images[2], FlipOver::Tree),
                     farError = flipMean(images[1], images[3], FlipOver::Tree);
        std::printf("0.5 m vs 500 m: FLIP near %.4f far %.4f\n", nearError, farError);
        EXPECT_LT(nearError, 0.03); // over the tree's pixels, measured 0.012
        EXPECT_LT(farError, 0.03);  // measured 0.019
        EXPECT_GT(treeCoverage(images[0], BACKGROUND), 0.1);
        writePng(OgreEnvironment::outDir() + "/bc-scales.png", sideBySide(images));
    }
}

namespace TreeLod::BillboardCloudTreeTests
{
    TEST(BillboardCloudTree, meshLodBiasActsAsEntitysOnTheCloudLevel)
    {
        // The cloud level is the mesh LoD: the factor multiplies the screen size as the camera's
        // LoD bias does, the detail indices clamp it; lodBias=4 is setMeshLodBias(4).
        const BakedTree& oak = bundled("oak");
        BillboardCloudTree* tree = placeCloud(oak.asset);
        std::vector<CameraSpec> views;
        for (const char* view : {"orbit:30,10,8", "orbit:30,10,16", "orbit:30,10,32", "orbit:30,10,64", "orbit:30,10,128"})
            views.push_back(camera(oak.model, view));
        MeshLodBiasProbe probe;
        probe.setBias = [&](Ogre::Real f, unsigned short max, unsigned short min) { tree->setMeshLodBias(f, max, min); };
        probe.index = [&] { return unsigned(tree->getLevel()); };
        probe.render = [&](const CameraSpec& view) { OgreEnvironment::renderer().render(view, 128, 128, 1); };
        probe.indexCount = tree->getLevelCount();
        expectMeshLodBiasLikeEntity(probe, views);

        tree = placeCloud(oak.asset, {{"lodBias", "4"}});
        EXPECT_FLOAT_EQ(tree->getLodBias().meshFactor, 4.0f);
        EXPECT_THROW(tree->setMeshLodBias(0.0f), Ogre::InvalidParametersException);
        EXPECT_THROW(tree->setMaterialLodBias(std::nanf("")), Ogre::InvalidParametersException);
    }

    TEST(BillboardCloudTree, lodStrategyParameterNamesOgresStrategies)
    {
        const BakedTree& oak = bundled("oak");
        BillboardCloudTree* tree = nullptr;
        std::vector<CameraSpec> views;
        for (const char* view : {"orbit:30,10,4", "orbit:30,10,8", "orbit:30,10,16", "orbit:30,10,32", "orbit:30,10,64", "orbit:30,10,128"})
            views.push_back(camera(oak.model, view));
        expectLodStrategyParameter([&](const Ogre::NameValuePairList& params) { tree = placeCloud(oak.asset, params); },
                                   [&] { return unsigned(tree->getLevel()); },
                                   [&](const CameraSpec& view) { OgreEnvironment::renderer().render(view, 128, 128, 1); },
                                   views);
    }

    TEST(BillboardCloudTree, materialLodBiasMovesTheLowResSwitch)
    {
        // A layered level drawn far away (forced) takes its material LoD 1, the low-res texture
        // alone: a large material factor brings the layers back, maxDetailIndex 1 keeps them off.
        const BakedTree& oak = bundled("oak");
        BillboardCloudTree* tree = placeCloud(oak.asset, {{"level", "1"}});
        OffscreenRenderer& r = OgreEnvironment::renderer();
        const CameraSpec far = camera(oak.model, "orbit:30,10,512");
        r.render(far, 128, 128, 1);
        ASSERT_EQ(tree->getLevel(), 1u);
        EXPECT_EQ(tree->getMaterialLodIndex(), 1u);
        tree->setMaterialLodBias(1e6f);
        r.render(far, 128, 128, 1);
        EXPECT_EQ(tree->getMaterialLodIndex(), 0u);
        tree->setMaterialLodBias(1e6f, 1, 99);
        r.render(far, 128, 128, 1);
        EXPECT_EQ(tree->getMaterialLodIndex(), 1u);
        // The camera's bias moves it as the factor does; the mesh factor leaves it.
        tree->setMaterialLodBias(1.0f);
        tree->setMeshLodBias(1e6f);
        r.render(far, 128, 128, 1);
        EXPECT_EQ(tree->getMaterialLodIndex(), 1u);
        tree->setMeshLodBias(1.0f);
        r.setLodBias(1e6f);
        r.render(far, 128, 128, 1);
        r.setLodBias(1.0f);
        EXPECT_EQ(tree->getMaterialLodIndex(), 0u);
    }
}
