// Forest through Plugin_TreeLod: the factory, render queue group and query flags;
// the instanced draws against the same trees as separate objects (Entity, FoliageLodTree,
// BillboardCloudTree under SceneNodes: the test of the INSTANCED vertex programs' rotation,
// scale and normals); the quad level; culling and level counts against ForestInstances::cull;
// LoD at 10 km, inside a crown, with bias and frozen; texture shadows cast and received; bad
// input; two species of one asset, one instance, 20,000 quads and 1,000,000 in one draw; levels
// from bands; residency within an upload budget; camera states freed with their cameras; the
// shadow casters' LoD bias.
//
// The package (reference, lodf, billboard-cloud, impostor of media/oak.glb) is baked here with
// the core bakers (few AO rays) and cached in $TREELOD_TEST_OUT/forest, keyed by this binary's
// modification time.
#include "OgreTestSupport.h"
#include "TreeLod/AtomicFile.h"

#include "TreeLod/BillboardCloudResources.h"
#include "TreeLod/FoliageLodResources.h"
#include "TreeLod/BillboardCloudBaker.h"
#include "TreeLod/BillboardCloudTree.h"
#include "TreeLod/ErrorCurveMeasurer.h"
#include "TreeLod/FoliageLodBaker.h"
#include "TreeLod/FoliageLodTree.h"
#include "TreeLod/Forest.h"
#include "TreeLod/GltfImporter.h"
#include "TreeLod/ImpostorBaker.h"
#include "TreeLod/ImpostorData.h"
#include "TreeLod/LevelCalibration.h"
#include "TreeLod/PackageWriter.h"
#include "TreeLod/OgreBootstrap.h"
#include "TreeLod/QuadFloors.h"
#include "TreeLod/ShadowSetup.h"
#include "TreeLod/TreeAssetManager.h"

#include <OgreEntity.h>
#include <OgreLogManager.h>
#include <OgreManualObject.h>
#include <OgreMaterialManager.h>
#include <OgreRTShaderSystem.h>
#include <OgreRenderQueue.h>
#include <OgreRenderQueueSortingGrouping.h>
#include <OgreSceneManager.h>
#include <OgreSceneQuery.h>
#include <OgreShadowCameraSetupPSSM.h>
#include <OgreSubEntity.h>
#include <OgreTechnique.h>

#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <cmath>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>

namespace TreeLod
{
    namespace
    {
        struct ForestTree
        {
            TreeModel model;
            TreeAssetPtr asset;
        };

        /// `baked`, encoded by `encode`, added as chunk `chunk` level 0; when baking failed, a
        /// test failure naming the error.
        template <typename T, typename Encode>
        void addBakedChunk(PackageWriter& writer, const char* chunk, std::uint32_t version, const Result<T>& baked,
                           Encode encode)
        {
            EXPECT_TRUE(baked.ok()) << (baked.ok() ? "" : baked.error().message());
            if (baked.ok())
            {
                EXPECT_TRUE(writer.addChunk(chunk, 0, version, encode(baked.value())).ok()) << chunk;
            }
        }

        std::vector<std::uint8_t> bakePackage(const TreeModel& model, const std::string& name)
        {
            PackageWriter writer;
            Result<void> added = addFoliageLodChunk(writer, model, name); // and the reference
            EXPECT_TRUE(added.ok()) << (added.ok() ? "" : added.error().message());
            BillboardCloudOptions cloudOptions;
            cloudOptions.aoRays = 4;
            addBakedChunk(writer, BILLBOARD_CLOUD_CHUNK, BILLBOARD_CLOUD_CHUNK_FORMAT_VERSION,
                          bakeBillboardCloud(model, cloudOptions, name), encodeBillboardCloudChunk);
            ImpostorOptions impostorOptions;
            impostorOptions.aoRays = 4;
            impostorOptions.resolution = 128;
            addBakedChunk(writer, IMPOSTOR_CHUNK, IMPOSTOR_CHUNK_FORMAT_VERSION,
                          bakeImpostor(model, impostorOptions, name), encodeImpostorChunk);
            return writer.toBytes();
        }

        /// media/oak.glb with every chunk the Forest draws, loaded as "oak.forest-test".
        const ForestTree& oak()
        {
            return OgreEnvironment::keep<ForestTree>("forest.oak", [] {
                ForestTree t;
                Result<TreeModel> model = importGltf(OgreEnvironment::sourcePath("media/oak.glb"));
                EXPECT_TRUE(model.ok()) << (model.ok() ? "" : model.error().message());
                t.model = std::move(model.value());
                const std::vector<std::uint8_t> bytes =
                    cachedPackage("forest", "oak", [&] { return bakePackage(t.model, "oak"); });
                t.asset = TreeAssetManager::getSingleton().loadFromBytes("oak.forest-test", Ogre::RGN_DEFAULT, bytes);
                return t;
            });
        }

        const glm::vec3 BACKGROUND = LightingSpec().background;

        /// A fresh Forest (through its factory) under a child of the content node, content cleared.
        Forest* placeForest(const Ogre::NameValuePairList& params = {}, Ogre::SceneNode** node = nullptr)
        {
            static int serial = 0;
            OffscreenRenderer& r = OgreEnvironment::renderer();
            r.clearContent();
            r.setShadows(false);
            r.setLodBias(1.0f);
            Ogre::MovableObject* object =
                r.getSceneManager().createMovableObject("forest-" + std::to_string(serial++), "Forest", &params);
            Ogre::SceneNode* parent = r.getContentNode().createChildSceneNode();
            parent->attachObject(object);
            if (node)
                *node = parent;
            return static_cast<Forest*>(object);
        }

        Ogre::Camera& ogreCamera()
        {
            return *OgreEnvironment::renderer().getSceneManager().getCamera("TreeLodOffscreenCamera");
        }

        ForestInstance instance(float x, float y, float z, float rotation = 0.0f, float scale = 1.0f,
                                std::uint32_t species = 0)
        {
            return ForestInstance{glm::vec3(x, y, z), rotation, scale, species};
        }

        /// n x n trees `spacing` metres apart centred on the origin, rotations varied.
        std::vector<ForestInstance> grid(int n, float spacing, std::uint32_t species = 0)
        {
            std::vector<ForestInstance> out;
            for (int j = 0; j < n; ++j)
                for (int i = 0; i < n; ++i)
                    out.push_back(instance((float(i) - 0.5f * float(n - 1)) * spacing, 0.0f,
                                           (float(j) - 0.5f * float(n - 1)) * spacing, 0.7f * float(i * n + j),
                                           0.8f + 0.05f * float((i + 2 * j) % 8), species));
            return out;
        }

        /// A child of `parent` placed, turned and scaled as `t` (a Forest instance as a separate object).
        Ogre::SceneNode* instanceNode(Ogre::SceneNode& parent, const ForestInstance& t)
        {
            Ogre::SceneNode* node = parent.createChildSceneNode(
                Ogre::Vector3(t.position.x, t.position.y, t.position.z),
                Ogre::Quaternion(Ogre::Radian(t.rotationY), Ogre::Vector3::UNIT_Y));
            node->setScale(Ogre::Vector3(t.scale));
            return node;
        }

        /// Every `factor` x `factor` block averaged (goldens of pictures rendered large).
        Image shrink(const Image& image, int factor)
        {
            Image out(image.width / factor, image.height / factor);
            for (int y = 0; y < out.height; ++y)
                for (int x = 0; x < out.width; ++x)
                {
                    glm::vec4 sum(0.0f);
                    for (int j = 0; j < factor; ++j)
                        for (int i = 0; i < factor; ++i)
                            sum += image.at(x * factor + i, y * factor + j);
                    out.at(x, y) = sum / float(factor * factor);
                }
            return out;
        }

        /// Renderables the object queues into each (group, priority).
        std::map<std::pair<int, int>, std::size_t> queued(Ogre::MovableObject& object)
        {
            Ogre::RenderQueue queue;
            object._notifyCurrentCamera(&ogreCamera());
            object._updateRenderQueue(&queue);
            struct Counter : Ogre::QueuedRenderableVisitor
            {
                std::size_t count = 0;
                void visit(Ogre::RenderablePass*) override { ++count; }
                void visit(const Ogre::Pass*, Ogre::RenderableList& list) override { count += list.size(); }
            };
            std::map<std::pair<int, int>, std::size_t> out;
            for (std::size_t id = 0; id < Ogre::RENDER_QUEUE_COUNT; ++id)
                if (const auto& group = queue._getQueueGroups()[id])
                    for (const auto& priority : group->getIterator())
                    {
                        Counter counter;
                        priority.second->getSolidsBasic().acceptVisitor(
                            &counter, Ogre::QueuedRenderableCollection::OM_PASS_GROUP);
                        if (counter.count > 0)
                            out[{int(id), int(priority.first)}] += counter.count;
                    }
            return out;
        }

        float treeHeight(const TreeModel& model) { return model.boundsMax.y - model.boundsMin.y; }

        /// A Forest of `tree` over a 5 x 5 grid 1.4 tree heights apart, its levels (`levels`) the
        /// automatic bands'.
        Forest* autoBandsGrid(const ForestTree& tree, std::vector<ForestLevel>& levels)
        {
            Forest* forest = placeForest();
            levels = Forest::levelsForBands(*tree.asset, Forest::getAutoBands());
            forest->addSpecies(tree.asset, levels);
            forest->addInstances(grid(5, 1.4f * treeHeight(tree.model)));
            return forest;
        }

        /// Perspective camera at `eye` looking at `target`.
        CameraSpec look(const glm::vec3& eye, const glm::vec3& target, float fov = 40.0f)
        {
            CameraSpec spec;
            spec.position = eye;
            spec.target = target;
            spec.fovYDegrees = fov;
            spec.nearClip = 0.1f;
            spec.farClip = 20000.0f;
            return spec;
        }

        /// The Forest's level of every instance per species (levelCounts) as one list.
        std::vector<std::uint32_t> flatCounts(const Forest& forest)
        {
            std::vector<std::uint32_t> out;
            for (const auto& species : forest.getStats().levelCounts)
                out.insert(out.end(), species.begin(), species.end());
            return out;
        }

        /// Mean level index of the visible instances of species 0.
        double meanLevel(const Forest& forest)
        {
            const std::vector<std::uint32_t>& counts = forest.getStats().levelCounts.at(0);
            double sum = 0.0, n = 0.0;
            for (std::size_t l = 0; l < counts.size(); ++l)
            {
                sum += double(l) * counts[l];
                n += counts[l];
            }
            return n > 0.0 ? sum / n : -1.0;
        }
    }

    TEST(Forest, factoryQueueGroupAndQueryFlags)
    {
        const ForestTree& tree = oak();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        Ogre::SceneManager& sm = r.getSceneManager();
        EXPECT_TRUE(Ogre::Root::getSingleton().hasMovableObjectFactory(ForestFactory::FACTORY_TYPE_NAME));

        Ogre::NameValuePairList params{{"lodBias", "2.5"}};
        Ogre::MovableObject* object = sm.createMovableObject("forestViaFactory", "Forest", &params);
        ASSERT_NE(object, nullptr);
        EXPECT_EQ(object->getMovableType(), "Forest");
        EXPECT_FLOAT_EQ(static_cast<Forest*>(object)->getLodBias(), 2.5f);
        EXPECT_TRUE(object->getBoundingBox().isNull()) << "no instances yet";
        sm.destroyMovableObject(object);
        Ogre::NameValuePairList bad{{"lodBias", "0"}};
        try
        {
            sm.createMovableObject("forestBad", "Forest", &bad);
            ADD_FAILURE() << "lodBias 0 must throw";
        }
        catch (const Ogre::Exception& e)
        {
            EXPECT_NE(e.getDescription().find("'lodBias'"), std::string::npos) << e.getDescription();
        }

        // Render queue group and priority of the object, for every part of every level.
        Forest* forest = placeForest();
        forest->addSpecies(tree.asset, {ForestLevel{"lodf", 0, false, 0.0f}});
        forest->addInstances({instance(0, 0, 0), instance(20, 0, 0, 1.0f)});
        forest->setRenderQueueGroupAndPriority(Ogre::RENDER_QUEUE_6, 42);
        const float h = treeHeight(tree.model);
        r.render(look(glm::vec3(10, 0.5f * h, 4 * h), glm::vec3(10, 0.5f * h, 0)), 64, 64, 1);
        const auto counts = queued(*forest);
        ASSERT_EQ(counts.size(), 1u);
        EXPECT_EQ(counts.begin()->first, std::make_pair(int(Ogre::RENDER_QUEUE_6), 42));
        EXPECT_EQ(counts.begin()->second, forest->getStats().batches) << "one renderable per (bucket, part)";
        EXPECT_GT(counts.begin()->second, 1u) << "leaves and bark";

        // Query flags: a ray through the first tree's crown finds the Forest only with a matching mask.
        const glm::vec3 centre = 0.5f * (tree.model.boundsMin + tree.model.boundsMax);
        expectRayQueryHonoursFlags(
            sm, forest, Ogre::Ray(Ogre::Vector3(centre.x, centre.y, 100.0f), Ogre::Vector3::NEGATIVE_UNIT_Z));

        // Bounds: the union of the instances' spheres, in the Forest's space.
        const Ogre::AxisAlignedBox& box = forest->getBoundingBox();
        for (std::size_t i = 0; i < 2; ++i)
        {
            const glm::vec4 s = forest->getInstances().getWorldSphere(i);
            EXPECT_TRUE(box.contains(Ogre::Vector3(s.x - s.w, s.y - s.w, s.z - s.w)));
            EXPECT_TRUE(box.contains(Ogre::Vector3(s.x + s.w, s.y + s.w, s.z + s.w)));
        }
        EXPECT_FLOAT_EQ(forest->getBoundingRadius(), Ogre::Math::boundingRadiusFromAABB(box));
        EXPECT_GT(forest->getGpuBytes(), forest->getStats().instanceBufferBytes);
        EXPECT_GT(forest->getStats().instanceBufferBytes, 0u);
    }

    TEST(Forest, instancedDrawsMatchSeparateObjects)
    {
        // Three trees with different rotations and scales, the Forest's node moved and turned:
        // the Forest's instanced draws against the same trees as separate objects under
        // SceneNodes. Rotation direction, scale, normals (lighting) and the node transform
        // all show in the picture.
        const ForestTree& tree = oak();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        Ogre::SceneManager& sm = r.getSceneManager();
        const float h = treeHeight(tree.model);
        const float w = std::max(tree.model.boundsMax.x - tree.model.boundsMin.x,
                                 tree.model.boundsMax.z - tree.model.boundsMin.z);
        const std::vector<ForestInstance> trees = {instance(-0.7f * w, 0.0f, 0.2f * w, 0.0f, 0.85f),
                                                   instance(0.0f, 0.0f, -0.3f * w, 1.2f, 1.0f),
                                                   instance(0.72f * w, 0.0f, 0.1f * w, -2.5f, 0.9f)};
        const Ogre::Vector3 nodePosition(3.0f, 0.5f, -2.0f);
        const Ogre::Quaternion nodeOrientation(Ogre::Radian(0.4f), Ogre::Vector3::UNIT_Y);
        // Looking at the middle tree from the front, a little above; trees about 260 px tall (full
        // bark detail in every separate object, as in the Forest's first level).
        const Ogre::Vector3 middle = nodePosition + nodeOrientation * Ogre::Vector3(0.0f, 0.5f * h, -0.3f * w);
        const Ogre::Vector3 eye = middle + nodeOrientation * Ogre::Vector3(0.0f, 0.25f * h, 2.0f * h);
        const CameraSpec view = look(glm::vec3(eye.x, eye.y, eye.z), glm::vec3(middle.x, middle.y, middle.z), 36.0f);
        const int width = 800, height = 340;
        const FoliageLodData& lodf = FoliageLodResources::of(*tree.asset).getFoliageLod();
        const std::uint32_t leaves = (lodf.maxLeafCount() + lodf.minLeafCount()) / 2;

        struct Case
        {
            const char* name;
            ForestLevel level;
            std::function<Ogre::MovableObject*(const std::string&)> create;
            std::function<void(Ogre::MovableObject*)> check;
        };
        const std::vector<Case> cases = {
            {"mesh", ForestLevel{"mesh", 0, false, 0.0f},
             [&](const std::string& name) {
                 Ogre::Entity* entity = sm.createEntity(name, tree.asset->getReferenceMesh());
                 entity->setMeshLodBias(1.0f, 0, 0); // full bark detail, as the Forest's first level
                 return entity;
             },
             [](Ogre::MovableObject*) {}},
            {"lodf", ForestLevel{"lodf", leaves, false, 0.0f},
             [&](const std::string& name) {
                 Ogre::NameValuePairList params{{"asset", tree.asset->getName()}, {"leaves", std::to_string(leaves)}};
                 return sm.createMovableObject(name, FoliageLodTreeFactory::FACTORY_TYPE_NAME, &params);
             },
             [&](Ogre::MovableObject* object) {
                 EXPECT_EQ(static_cast<FoliageLodTree*>(object)->getLeafCount(), leaves);
                 EXPECT_EQ(static_cast<FoliageLodTree*>(object)->getBarkLodIndex(), 0u);
             }},
            {"billboard-cloud", ForestLevel{"billboard-cloud", 0, false, 0.0f},
             [&](const std::string& name) {
                 Ogre::NameValuePairList params{{"asset", tree.asset->getName()}, {"level", "0"}};
                 return sm.createMovableObject(name, BillboardCloudTreeFactory::FACTORY_TYPE_NAME, &params);
             },
             [](Ogre::MovableObject* object) {
                 EXPECT_EQ(static_cast<BillboardCloudTree*>(object)->getMaterialLodIndex(), 0u);
                 EXPECT_EQ(static_cast<BillboardCloudTree*>(object)->getBarkLodIndex(), 0u);
             }},
            // The low-res technique of a layered level: BillboardCloudTree with list factor 0
            // draws the low-res texture alone (its material LoD index 1).
            {"billboard-cloud-lowres", ForestLevel{"billboard-cloud", 0, true, 0.0f},
             [&](const std::string& name) {
                 Ogre::NameValuePairList params{
                     {"asset", tree.asset->getName()}, {"level", "0"}, {"listFactor", "0"}};
                 return sm.createMovableObject(name, BillboardCloudTreeFactory::FACTORY_TYPE_NAME, &params);
             },
             [](Ogre::MovableObject* object) {
                 EXPECT_EQ(static_cast<BillboardCloudTree*>(object)->getMaterialLodIndex(), 1u);
             }},
        };
        std::vector<Image> strip;
        int serial = 0;
        for (const Case& c : cases)
        {
            Ogre::SceneNode* node = nullptr;
            Forest* forest = placeForest({}, &node);
            node->setPosition(nodePosition);
            node->setOrientation(nodeOrientation);
            forest->addSpecies(tree.asset, {c.level});
            forest->addInstances(trees);
            const Image instanced = toImage(r.render(view, width, height, 1));
            EXPECT_EQ(forest->getStats().visibleInstances, 3u) << c.name;
            EXPECT_EQ(forest->getStats().levelCounts.at(0).at(0), 3u) << c.name;

            r.clearContent();
            Ogre::SceneNode* parent = r.getContentNode().createChildSceneNode(nodePosition, nodeOrientation);
            std::vector<Ogre::MovableObject*> objects;
            for (const ForestInstance& t : trees)
            {
                Ogre::SceneNode* child = instanceNode(*parent, t);
                objects.push_back(c.create("separate-" + std::to_string(serial++)));
                child->attachObject(objects.back());
            }
            const Image separate = toImage(r.render(view, width, height, 1));
            for (Ogre::MovableObject* object : objects)
                c.check(object);
            const double error = flipMean(instanced, separate);
            std::printf("%s: instanced vs separate objects FLIP %.5f, coverage %.3f\n", c.name, error,
                        treeCoverage(instanced, BACKGROUND));
            EXPECT_LT(error, 0.001) << c.name;
            EXPECT_GT(treeCoverage(instanced, BACKGROUND), 0.15) << c.name;
            strip.push_back(instanced);
            strip.push_back(separate);
        }
        writePng(OgreEnvironment::outDir() + "/forest-instanced-vs-separate.png", sideBySide(strip));
        // Golden: the four Forest pictures side by side at a fifth of the size.
        compareWithGolden(shrink(sideBySide({strip[0], strip[2], strip[4], strip[6]}), 5), "forest-three-trees", 0.02);
    }

    TEST(Forest, quadLevelRenders)
    {
        const ForestTree& tree = oak();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        const float h = treeHeight(tree.model);
        const CameraSpec view = look(glm::vec3(1.5f * h, 3.0f * h, 5.5f * h), glm::vec3(0.0f, 0.2f * h, 0.0f));
        Forest* forest = placeForest();
        forest->addSpecies(tree.asset, {ForestLevel{"impostor", 0, false, 0.0f}});
        forest->addInstances(grid(4, 1.3f * h));
        const Image quads = toImage(r.render(view, 256, 192, 2));
        EXPECT_EQ(forest->getStats().visibleInstances, 16u);
        EXPECT_EQ(forest->getStats().batches, 1u);
        EXPECT_EQ(forest->getStats().triangles, 32u);
        EXPECT_GT(treeCoverage(quads, BACKGROUND), 0.1);
        // The same trees as meshes: the quad is the tree seen from afar.
        forest = placeForest();
        forest->addSpecies(tree.asset, {ForestLevel{"mesh", 0, false, 0.0f}});
        forest->addInstances(grid(4, 1.3f * h));
        const Image meshes = toImage(r.render(view, 256, 192, 2));
        // The quads stand where the trees stand (their look is the impostor's business,
        // ImpostorTest): the pixels they cover overlap the polygonal trees'.
        const double overlap = coveredOverlap(quads, meshes, BACKGROUND);
        std::printf("quad vs mesh forest: covered pixels in common %.3f, FLIP %.4f\n", overlap,
                    flipMean(meshes, quads));
        EXPECT_GT(overlap, 0.6);
        writePng(OgreEnvironment::outDir() + "/forest-quad-vs-mesh.png", sideBySide({quads, meshes}));
        compareWithGolden(quads, "forest-quad", 0.02);
    }

    TEST(Forest, cullingAndLevelCountsMatchForestInstances)
    {
        const ForestTree& tree = oak();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        const float h = treeHeight(tree.model);
        Forest* forest = placeForest();
        forest->addSpecies(tree.asset,
                           Forest::levelsForBands(*tree.asset, {{"billboard-cloud", 40.0f}, {"impostor", 0.0f}}));
        forest->addInstances(grid(12, 1.5f * h));
        // Standing inside the forest, looking along -Z: the trees behind are not drawn.
        const glm::vec3 eye(0.0f, 0.5f * h, 0.0f);
        const CameraSpec view = look(eye, eye + glm::vec3(0.3f, -0.05f, -1.0f), 60.0f);
        const int width = 160, height = 120;
        r.render(view, width, height, 1);
        const ForestStats& stats = forest->getStats();

        ForestVisibility visibility;
        ASSERT_TRUE(forest->getInstances().cull(CullCamera::fromSpec(view, float(width), float(height)), 1.0f,
                                                visibility).ok());
        EXPECT_EQ(stats.instances, 144u);
        EXPECT_EQ(stats.visibleInstances, visibility.getVisibleCount());
        EXPECT_GT(stats.visibleInstances, 10u);
        EXPECT_LT(stats.visibleInstances, 100u) << "about half the forest is behind the camera";
        for (const ForestBucket& bucket : visibility.getBuckets())
            EXPECT_EQ(stats.levelCounts.at(bucket.kind).at(bucket.level), bucket.count) << "level " << bucket.level;
        for (std::uint32_t v = 0; v < visibility.getVisibleCount(); ++v)
        {
            const glm::vec4 sphere = forest->getInstances().getWorldSphere(visibility.getIndices()[v]);
            EXPECT_LT(sphere.z - sphere.w, eye.z) << "an instance behind the camera counted visible";
        }
        std::uint32_t levelsInUse = 0;
        for (std::uint32_t count : flatCounts(*forest))
            levelsInUse += count > 0;
        EXPECT_GE(levelsInUse, 2u) << "near and far trees at different levels";
        EXPECT_GE(stats.cullMilliseconds, 0.0);

        // Looking away from the whole forest (Ogre culls the object whole): nothing visible.
        r.render(look(glm::vec3(0.0f, 5.0f * h, 0.0f), glm::vec3(0.0f, 100.0f * h, 0.0f)), width, height, 1);
        EXPECT_EQ(forest->getStats().visibleInstances, 0u);
        EXPECT_EQ(forest->getStats().batches, 0u);
        for (std::uint32_t count : flatCounts(*forest))
            EXPECT_EQ(count, 0u);
    }

    TEST(Forest, drawsDoNotGrowWithTheInstanceCount)
    {
        // One instanced draw per (species, level, part) in use, whatever the number of trees:
        // the RenderTarget's batch count for 9 and for 100 trees at one level, and for 100
        // separate objects.
        const ForestTree& tree = oak();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        const float h = treeHeight(tree.model);
        const CameraSpec view = look(glm::vec3(0.0f, 9.0f * h, 14.0f * h), glm::vec3(0.0f, 0.0f, 0.0f), 50.0f);
        std::vector<FrameTiming> frames;
        for (const int n : {3, 10})
        {
            Forest* forest = placeForest();
            forest->addSpecies(tree.asset, {ForestLevel{"billboard-cloud", 1, false, 0.0f}});
            forest->addInstances(grid(n, 1.4f * h));
            r.renderTimedFrame(view, 256, 192); // warm-up: buffers and programs
            frames.push_back(r.renderTimedFrame(view, 256, 192));
            EXPECT_EQ(forest->getStats().visibleInstances, std::uint32_t(n * n));
            EXPECT_EQ(frames.back().triangles, forest->getStats().triangles);
        }
        EXPECT_EQ(frames[0].batches, frames[1].batches);
        EXPECT_EQ(frames[1].triangles, frames[0].triangles * 100 / 9);

        // 100 trees with the billboard cloud's own levels (and the bark's), against 100
        // BillboardCloudTrees choosing theirs: the same triangles, in a few draws.
        Forest* forest = placeForest();
        forest->addSpecies(tree.asset, Forest::levelsForBands(*tree.asset, {{"billboard-cloud", 0.0f}}));
        forest->addInstances(grid(10, 1.4f * h));
        r.renderTimedFrame(view, 256, 192);
        const FrameTiming levels = r.renderTimedFrame(view, 256, 192);
        r.clearContent();
        int serial = 0;
        for (const ForestInstance& t : grid(10, 1.4f * h))
        {
            Ogre::SceneNode* node = instanceNode(r.getContentNode(), t);
            Ogre::NameValuePairList params{{"asset", tree.asset->getName()}};
            node->attachObject(r.getSceneManager().createMovableObject(
                "bcGrid" + std::to_string(serial++), BillboardCloudTreeFactory::FACTORY_TYPE_NAME, &params));
        }
        r.renderTimedFrame(view, 256, 192);
        const FrameTiming separate = r.renderTimedFrame(view, 256, 192);
        r.clearContent();
        std::printf("billboard-cloud level 1: Forest 9 trees %zu batches %zu triangles %.1f ms, 100 trees %zu "
                    "batches %zu triangles %.1f ms; its levels: Forest %zu batches %zu triangles %.1f ms, "
                    "100 BillboardCloudTrees %zu batches %zu triangles %.1f ms\n",
                    frames[0].batches, frames[0].triangles, frames[0].frameMilliseconds, frames[1].batches,
                    frames[1].triangles, frames[1].frameMilliseconds, levels.batches, levels.triangles,
                    levels.frameMilliseconds, separate.batches, separate.triangles, separate.frameMilliseconds);
        // Near-equal, not equal: BillboardCloudTree measures its LoD with the cloud's radius, the
        // Forest with the reference's (the bark's switch moves a little).
        EXPECT_NEAR(double(levels.triangles), double(separate.triangles), 0.05 * double(separate.triangles));
        EXPECT_GE(separate.batches, 100u);
        EXPECT_LT(levels.batches, 12u);
    }

    TEST(Forest, levelOfDetailExtremesBiasAndFreeze)
    {
        const ForestTree& tree = oak();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        const float h = treeHeight(tree.model);
        std::vector<ForestLevel> levels;
        Forest* forest = autoBandsGrid(tree, levels);
        const std::size_t last = levels.size() - 1;

        // 10 km away: everything at the last level (the quad), a few pixels.
        const Image distant = toImage(r.render(look(glm::vec3(0.0f, 200.0f, 10000.0f), glm::vec3(0.0f)), 96, 96, 1));
        EXPECT_EQ(forest->getStats().visibleInstances, 25u);
        EXPECT_EQ(forest->getStats().levelCounts[0][last], 25u);
        EXPECT_EQ(levels[last].technique, "impostor");
        EXPECT_LT(treeCoverage(distant, BACKGROUND), 0.01);
        // ... at the floor's cost: what a quad-only Forest of the same trees submits (one draw,
        // two triangles a tree), and nothing but the quad level built.
        EXPECT_EQ(forest->getStats().batches, 1u);
        EXPECT_EQ(forest->getStats().triangles, 25u * 2u);
        for (std::size_t l = 0; l < last; ++l)
            EXPECT_FALSE(forest->isResident(0, std::uint32_t(l))) << "level " << l << " built for a view from 10 km";

        // Inside the middle tree's crown: no failure, leaves all around.
        const glm::vec3 centre = 0.5f * (tree.model.boundsMin + tree.model.boundsMax);
        const CameraSpec crown =
            look(centre + glm::vec3(0.0f, 0.0f, 0.3f), centre + glm::vec3(0.0f, 0.0f, -5.0f), 70.0f);
        const Image inside = toImage(r.render(crown, 96, 96, 1));
        EXPECT_GT(treeCoverage(inside, BACKGROUND), 0.3);
        EXPECT_GT(forest->getStats().visibleInstances, 0u);

        // LoD bias raises detail: the Forest's and the camera's multiply.
        const CameraSpec mid = look(glm::vec3(0.0f, 3.0f * h, 10.0f * h), glm::vec3(0.0f, 0.3f * h, 0.0f));
        r.render(mid, 256, 192, 1);
        EXPECT_EQ(forest->getStats().visibleInstances, 25u);
        const double plain = meanLevel(*forest);
        std::printf("25 trees, automatic bands, mid view: %u batches, %llu triangles, levels",
                    forest->getStats().batches, (unsigned long long)forest->getStats().triangles);
        for (std::uint32_t count : flatCounts(*forest))
            std::printf(" %u", count);
        std::printf("\n");
        forest->setLodBias(8.0f);
        r.render(mid, 256, 192, 1);
        const double biased = meanLevel(*forest);
        forest->setLodBias(1.0f);
        r.setLodBias(8.0f);
        r.render(mid, 256, 192, 1);
        const double cameraBiased = meanLevel(*forest);
        r.setLodBias(1.0f);
        std::printf("mean level: bias 1 %.2f, Forest bias 8 %.2f, camera bias 8 %.2f\n", plain, biased, cameraBiased);
        EXPECT_LT(biased, plain);
        EXPECT_DOUBLE_EQ(cameraBiased, biased);

        // Frozen LoD: levels stay while the camera moves back (every tree stays in view).
        r.render(mid, 256, 192, 1);
        const std::vector<std::uint32_t> before = flatCounts(*forest);
        forest->setLodFrozen(true);
        const CameraSpec back = look(glm::vec3(0.0f, 4.0f * h, 30.0f * h), glm::vec3(0.0f, 0.3f * h, 0.0f));
        r.render(back, 256, 192, 1);
        EXPECT_EQ(flatCounts(*forest), before);
        forest->setLodFrozen(false);
        r.render(back, 256, 192, 1);
        EXPECT_NE(flatCounts(*forest), before) << "unfrozen, the far view drops detail";
        EXPECT_EQ(forest->getStats().visibleInstances, 25u);
    }

    TEST(Forest, aThousandKilometresAway)
    {
        // A camera 10^6 m from the forest (far clip beyond it): every tree culled or at the last
        // level, nothing NaN, nothing built but that level.
        const ForestTree& tree = oak();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        const float h = treeHeight(tree.model);
        std::vector<ForestLevel> levels;
        Forest* forest = autoBandsGrid(tree, levels);
        CameraSpec distant = look(glm::vec3(1.0e6f, 1.0e6f, 1.0e6f), glm::vec3(0.0f), 1.0f);
        distant.farClip = 3.0e6f;
        distant.nearClip = 10.0f;
        const Image far = toImage(r.render(distant, 64, 64, 1));
        const ForestStats& stats = forest->getStats();
        EXPECT_EQ(stats.visibleInstances, 25u) << "the far clip reaches the forest";
        EXPECT_EQ(stats.levelCounts[0].back(), 25u);
        EXPECT_TRUE(std::isfinite(stats.cullMilliseconds));
        for (std::size_t l = 0; l + 1 < levels.size(); ++l)
            EXPECT_FALSE(forest->isResident(0, std::uint32_t(l))) << "level " << l << " built for a view from 1000 km";
        for (const glm::vec4& p : far.pixels)
            ASSERT_TRUE(std::isfinite(p.r) && std::isfinite(p.g) && std::isfinite(p.b));

        // The forest and the camera both 10^6 m from the origin (floats step by 6 cm there):
        // the picture of a tree seen from 2 heights is the one at the origin.
        forest = placeForest();
        forest->addSpecies(tree.asset, levels);
        const glm::vec3 offset(1.0e6f, 0.0f, -1.0e6f);
        const CameraSpec nearView = look(glm::vec3(0.0f, 0.6f * h, 2.0f * h), glm::vec3(0.0f, 0.5f * h, 0.0f));
        forest->addInstances({instance(0.0f, 0.0f, 0.0f)});
        const Image atOrigin = toImage(r.render(nearView, 128, 128, 1));
        forest = placeForest();
        forest->addSpecies(tree.asset, levels);
        forest->addInstances({instance(offset.x, offset.y, offset.z)});
        CameraSpec moved = nearView;
        moved.position += offset;
        moved.target += offset;
        const Image away = toImage(r.render(moved, 128, 128, 1));
        writePng(OgreEnvironment::outDir() + "/forest-1000km.png", sideBySide({atOrigin, away}));
        EXPECT_GT(treeCoverage(atOrigin, BACKGROUND), 0.1);
        // Vertices step by up to 6 cm (about 0.6 px here), which moves leaf edges: about 0.9 of
        // the covered pixels overlap.
        const double overlap = coveredOverlap(atOrigin, away, BACKGROUND);
        std::cout << "covered pixels overlapping 1000 km away: " << overlap << "\n";
        EXPECT_GT(overlap, 0.85);
        EXPECT_LT(flipMean(atOrigin, away), 0.1);
    }

    TEST(Forest, castsAndReceivesTextureShadows)
    {
        const ForestTree& tree = oak();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        Ogre::SceneManager& sm = r.getSceneManager();
        const float h = treeHeight(tree.model);
        // A ground material receiving the sun's shadow (TreeLod/BarkShadowed, untextured).
        Ogre::MaterialManager& materials = Ogre::MaterialManager::getSingleton();
        for (const char* suffix : {"", "Shadowed"})
        {
            const Ogre::String name = Ogre::String("ForestTest/Ground") + suffix;
            if (materials.resourceExists(name, "TreeLod"))
                continue;
            Ogre::MaterialPtr ground =
                materials.getByName(Ogre::String("TreeLod/Bark") + suffix, "TreeLod")->clone(name);
            ground->getTechnique(0)->getPass(0)->getFragmentProgramParameters()->setNamedConstant(
                "baseColour", Ogre::ColourValue(0.45f, 0.5f, 0.3f, 1.0f));
            ground->load();
        }
        auto place = [&](const std::function<void(Ogre::SceneNode&)>& trees, bool shadowed) {
            r.clearContent();
            Ogre::ManualObject* ground = sm.createManualObject();
            ground->setCastShadows(false);
            ground->begin(shadowed ? "ForestTest/GroundShadowed" : "ForestTest/Ground",
                          Ogre::RenderOperation::OT_TRIANGLE_LIST, "TreeLod");
            const float s = 4.0f * h;
            for (const glm::vec2 c : {glm::vec2(-s, -s), glm::vec2(s, -s), glm::vec2(s, s), glm::vec2(-s, s)})
            {
                ground->position(c.x, 0.0f, c.y);
                ground->normal(0.0f, 1.0f, 0.0f);
                ground->textureCoord(0.0f, 0.0f);
            }
            ground->quad(0, 3, 2, 1); // counter-clockwise seen from above
            ground->end();
            r.getContentNode().createChildSceneNode()->attachObject(ground);
            trees(*r.getContentNode().createChildSceneNode());
        };
        const std::vector<ForestInstance> trees = {instance(-0.6f * h, 0, 0.3f * h, 0.5f, 0.9f),
                                                   instance(0.5f * h, 0, -0.4f * h, 2.0f, 1.1f)};
        // The polygonal trees: the Forest's mesh level against Entities of the reference mesh
        // with its shadow-receiving materials and full bark detail.
        // A Forest of `trees` drawn with `levels`.
        auto forestOf = [&](const std::vector<ForestLevel>& levels) {
            return [&, levels](Ogre::SceneNode& node) {
                static int serial = 0;
                auto* forest =
                    static_cast<Forest*>(sm.createMovableObject("forestShadow" + std::to_string(serial++), "Forest"));
                forest->addSpecies(tree.asset, levels);
                forest->addInstances(trees);
                node.attachObject(forest);
            };
        };
        const auto forestTrees = forestOf({ForestLevel{"mesh", 0, false, 0.0f}});
        auto separateTrees = [&](Ogre::SceneNode& node) {
            const std::vector<Ogre::String>& plainNames = tree.asset->getMaterialNames();
            const std::vector<Ogre::String>& shadowedNames = tree.asset->getShadowedMaterialNames();
            for (const ForestInstance& t : trees)
            {
                Ogre::SceneNode* child = instanceNode(node, t);
                Ogre::Entity* entity = sm.createEntity(tree.asset->getReferenceMesh());
                entity->setMeshLodBias(1.0f, 0, 0);
                for (unsigned i = 0; i < entity->getNumSubEntities(); ++i)
                {
                    Ogre::SubEntity* sub = entity->getSubEntity(i);
                    const auto it = std::find(plainNames.begin(), plainNames.end(), sub->getMaterialName());
                    ASSERT_NE(it, plainNames.end());
                    sub->setMaterialName(shadowedNames[std::size_t(it - plainNames.begin())], tree.asset->getGroup());
                }
                child->attachObject(entity);
            }
        };
        const CameraSpec view = look(glm::vec3(0.5f * h, 1.3f * h, 2.3f * h), glm::vec3(0.0f, 0.25f * h, 0.0f), 45.0f);
        place(forestTrees, false);
        const Image plain = toImage(r.render(view, 192, 160, 2));
        place(forestTrees, true);
        r.setShadows(true, 1024);
        const Image shadowed = toImage(r.render(view, 192, 160, 2));
        place(separateTrees, true);
        const Image separate = toImage(r.render(view, 192, 160, 2));
        // Billboard clouds (their own levels): the cloud's instanced casters against BillboardCloudTrees'.
        const auto forestClouds = forestOf(Forest::levelsForBands(*tree.asset, {{"billboard-cloud", 0.0f}}));
        auto separateClouds = [&](Ogre::SceneNode& node) {
            static int serial = 0;
            for (const ForestInstance& t : trees)
            {
                Ogre::SceneNode* child = instanceNode(node, t);
                Ogre::NameValuePairList params{{"asset", tree.asset->getName()}};
                child->attachObject(sm.createMovableObject("cloudShadow" + std::to_string(serial++),
                                                           BillboardCloudTreeFactory::FACTORY_TYPE_NAME, &params));
            }
        };
        place(forestClouds, true);
        const Image cloudForest = toImage(r.render(view, 192, 160, 2));
        place(separateClouds, true);
        const Image cloudSeparate = toImage(r.render(view, 192, 160, 2));
        // Shadow LoD bias: the view keeps its levels (the mesh), the casters drop to the quad.
        Forest* biased = nullptr;
        auto meshOrQuad = [&](Ogre::Real shadowLodBias) {
            return [&, shadowLodBias](Ogre::SceneNode& node) {
                forestOf({ForestLevel{"mesh", 0, false, 1.0f}, ForestLevel{"impostor", 0, false, 0.0f}})(node);
                biased = static_cast<Forest*>(node.getAttachedObject(0));
                biased->setShadowLodBias(shadowLodBias);
            };
        };
        place(meshOrQuad(1.0f), true);
        const Image casterMesh = toImage(r.render(view, 192, 160, 2));
        place(meshOrQuad(1e-9f), true);
        const Image casterQuad = toImage(r.render(view, 192, 160, 2));
        EXPECT_EQ(biased->getStats().levelCounts.at(0), (std::vector<std::uint32_t>{2u, 0u})) << "the view's levels";
        EXPECT_THROW(biased->setShadowLodBias(0.0f), Ogre::InvalidParametersException);
        EXPECT_THROW(biased->setShadowLodBias(std::nanf("")), Ogre::InvalidParametersException);
        // LiSPSM (García et al. 2007 §5.2): a perspective shadow camera with its own matrices culls too.
        place(forestTrees, true);
        r.setShadows(true, 1024, ShadowCamera::LiSPSM);
        const Image lispsm = toImage(r.render(view, 192, 160, 2));
        r.setShadows(false);
        r.clearContent();
        const double drop = meanLuminance(plain) - meanLuminance(shadowed);
        const double error = flipMean(shadowed, separate);
        std::printf("shadows: luminance drop %.4f, Forest vs separate Entities FLIP %.5f\n", drop, error);
        EXPECT_GT(drop, 0.01) << "the trees' shadows must darken the ground and the crowns";
        const double cloudError = flipMean(cloudForest, cloudSeparate);
        std::printf("shadows: billboard-cloud Forest vs separate BillboardCloudTrees FLIP %.5f\n", cloudError);
        EXPECT_LT(cloudError, 0.015);
        const double dropLispsm = meanLuminance(plain) - meanLuminance(lispsm);
        std::printf("LiSPSM: luminance drop %.4f\n", dropLispsm);
        EXPECT_NEAR(dropLispsm, drop, 0.5 * drop);
        // Not 0: the focused shadow camera frames the Forest's bounds (spheres), not the
        // Entities' boxes, so the shadow texels fall differently.
        EXPECT_LT(error, 0.015) << "instanced casters and receivers as the separate objects'";
        const double sameCasters = flipMean(casterMesh, shadowed), quadCasters = flipMean(casterQuad, casterMesh);
        const double dropQuadCasters = meanLuminance(plain) - meanLuminance(casterQuad);
        std::printf("shadow LoD bias: mesh casters vs the mesh Forest FLIP %.5f, quad casters vs mesh casters FLIP "
                    "%.5f, luminance drop %.4f\n", sameCasters, quadCasters, dropQuadCasters);
        // Not 0 either: this Forest's bounds hold the quad level too (the focused camera frames them).
        EXPECT_LT(sameCasters, 0.015) << "bias 1: the casters are the view's levels";
        EXPECT_GT(quadCasters, 3.0 * sameCasters) << "bias 1e-9: the casters must be the quads";
        EXPECT_GT(dropQuadCasters, 0.25 * drop) << "quad casters still shade the ground";
        writePng(OgreEnvironment::outDir() + "/forest-shadows-strip.png",
                 sideBySide({plain, shadowed, separate, lispsm, cloudForest, cloudSeparate, casterMesh, casterQuad}));
        compareWithGolden(shadowed, "forest-shadows", 0.02);
    }

    /// Texture shadows for the tests below: Forest trees (mesh level) on a ground (a clone of
    /// TreeLod/Bark, or of TreeLod/BarkShadowed where `receiving`: the sun's depth shadow), or
    /// none where `groundSize` is 0.
    void placeShadowScene(const std::vector<ForestInstance>& trees, float groundSize, bool receiving)
    {
        OffscreenRenderer& r = OgreEnvironment::renderer();
        Ogre::SceneManager& sm = r.getSceneManager();
        Ogre::MaterialManager& materials = Ogre::MaterialManager::getSingleton();
        for (const char* suffix : {"", "Shadowed"})
        {
            const Ogre::String name = Ogre::String("ForestTest/ShadowSceneGround") + suffix;
            if (materials.resourceExists(name, "TreeLod"))
                continue;
            Ogre::MaterialPtr material = materials.getByName(Ogre::String("TreeLod/Bark") + suffix, "TreeLod")->clone(name);
            material->getTechnique(0)->getPass(0)->getFragmentProgramParameters()->setNamedConstant(
                "baseColour", Ogre::ColourValue(0.45f, 0.5f, 0.3f, 1.0f));
            material->load();
        }
        r.clearContent();
        if (groundSize > 0.0f)
        {
            Ogre::ManualObject* quad = sm.createManualObject();
            quad->setCastShadows(false);
            quad->begin(receiving ? "ForestTest/ShadowSceneGroundShadowed" : "ForestTest/ShadowSceneGround",
                        Ogre::RenderOperation::OT_TRIANGLE_LIST, "TreeLod");
            const float s = groundSize;
            for (const glm::vec2 c : {glm::vec2(-s, -s), glm::vec2(s, -s), glm::vec2(s, s), glm::vec2(-s, s)})
            {
                quad->position(c.x, 0.0f, c.y);
                quad->normal(0.0f, 1.0f, 0.0f);
                quad->textureCoord(0.0f, 0.0f);
            }
            quad->quad(0, 3, 2, 1);
            quad->end();
            r.getContentNode().createChildSceneNode()->attachObject(quad);
        }
        static int serial = 0;
        auto* forest = static_cast<Forest*>(sm.createMovableObject("shadowSetup" + std::to_string(serial++), "Forest"));
        forest->addSpecies(oak().asset, {ForestLevel{"mesh", 0, false, 0.0f}});
        forest->addInstances(trees);
        r.getContentNode().createChildSceneNode()->attachObject(forest);
    }

    /// Whether a render target's texture reads back (RenderSystem_GLES2 reads zeros: ES has no
    /// texture read-back).
    bool texturesReadBack()
    {
        return Ogre::Root::getSingleton().getRenderSystem()->getName().find("OpenGL ES") == Ogre::String::npos;
    }

    /// Mean luminance of the rows [top, bottom) of `image` (fractions of its height).
    double bandLuminance(const Image& image, double top, double bottom)
    {
        Image band;
        band.width = image.width;
        const int y0 = int(top * image.height), y1 = int(bottom * image.height);
        band.height = y1 - y0;
        band.pixels.assign(image.pixels.begin() + std::ptrdiff_t(y0) * image.width,
                           image.pixels.begin() + std::ptrdiff_t(y1) * image.width);
        return meanLuminance(band);
    }

    // PSSM (three splits, as OGRE's Terrain sample) through setupSunShadows: every split's texture
    // holds casters, and the receivers read the far splits too, so the far trees' shadows are there.
    TEST(Forest, pssmShadowsReachTheFarTrees)
    {
        const ForestTree& tree = oak();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        Ogre::SceneManager& sm = r.getSceneManager();
        const float h = treeHeight(tree.model);
        // The first tree stands within the first split (about 0.5 h from a near clip of 0.05 h).
        std::vector<ForestInstance> row;
        for (int i = 0; i < 8; ++i)
            row.push_back(instance((i % 2 ? 0.5f : -0.5f) * h, 0.0f, -1.6f * h * float(i), 0.7f * float(i)));
        CameraSpec view = look(glm::vec3(0.1f * h, 0.6f * h, 0.5f * h), glm::vec3(0.0f, 0.3f * h, -6.0f * h), 60.0f);
        view.nearClip = 0.05f * h;
        const float far = 12.0f * h;
        r.setShadowFarDistance(far);
        auto render = [&](Ogre::ShadowTechnique technique, ShadowCamera camera) {
            SunShadowSettings settings;
            settings.technique = technique;
            settings.camera = camera;
            settings.textureSize = 1024;
            placeShadowScene(row, 20.0f * h, technique != Ogre::SHADOWTYPE_NONE);
            r.setShadows(settings);
            r.render(view, 256, 160, 1); // Ogre frames shadow cameras with the previous frame's receivers
            return toImage(r.render(view, 256, 160, 2));
        };
        const Image plain = render(Ogre::SHADOWTYPE_NONE, ShadowCamera::Focused);
        const Image focused = render(Ogre::SHADOWTYPE_TEXTURE_ADDITIVE_INTEGRATED, ShadowCamera::Focused);
        const Image pssm = render(Ogre::SHADOWTYPE_TEXTURE_ADDITIVE_INTEGRATED, ShadowCamera::PSSM);
        ASSERT_EQ(sm.getShadowTextureConfigList().size(), std::size_t(PSSM_SPLITS));
        std::vector<double> casterFraction;
        for (std::size_t i = 0; i < std::size_t(texturesReadBack() ? PSSM_SPLITS : 0); ++i)
        {
            const Ogre::TexturePtr& texture = sm.getShadowTexture(i);
            ASSERT_EQ(texture->getFormat(), Ogre::PF_FLOAT32_R);
            std::vector<float> depth(texture->getWidth() * texture->getHeight());
            texture->getBuffer()->blitToMemory(
                Ogre::PixelBox(texture->getWidth(), texture->getHeight(), 1, Ogre::PF_FLOAT32_R, depth.data()));
            casterFraction.push_back(double(std::count_if(depth.begin(), depth.end(), [](float d) { return d < 1.0f; })) /
                                     double(depth.size()));
        }
        r.setShadows(false);
        r.setShadowFarDistance(0.0f);
        r.clearContent();
        const double nearDrop = bandLuminance(plain, 0.6, 1.0) - bandLuminance(pssm, 0.6, 1.0);
        const double farDrop = bandLuminance(plain, 0.3, 0.6) - bandLuminance(pssm, 0.3, 0.6);
        const double focusedDrop = meanLuminance(plain) - meanLuminance(focused);
        for (double f : casterFraction)
            std::printf("PSSM: casters cover %.3f of a split's texture\n", f);
        std::printf("PSSM: luminance drop near %.4f, far %.4f; focused drop %.4f, PSSM %.4f\n", nearDrop, farDrop,
                    focusedDrop, meanLuminance(plain) - meanLuminance(pssm));
        writePng(OgreEnvironment::outDir() + "/forest-shadows-pssm-strip.png", sideBySide({plain, focused, pssm}));
        for (double f : casterFraction)
            EXPECT_GT(f, 0.001) << "every split's texture holds casters";
        EXPECT_GT(nearDrop, 0.014) << "the near trees' shadows (the first splits)";
        EXPECT_GT(farDrop, 0.01) << "the far trees' shadows: the receivers read the far splits (0.006 with the first only)";
        EXPECT_NEAR(meanLuminance(plain) - meanLuminance(pssm), focusedDrop, 0.5 * focusedDrop);
        compareWithGolden(pssm, "forest-shadows-pssm", 0.02);
    }

    // Ogre's colour texture shadows: the casters write what Ogre's own caster pass would (the
    // shadow colour, black), and the trees, casters that do not receive there, draw as unshadowed.
    // Stencil shadows are refused by setupSunShadows and logged once by the objects.
    TEST(Forest, castersFollowOgresShadowTechniqueAndStencilIsRefused)
    {
        const ForestTree& tree = oak();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        Ogre::SceneManager& sm = r.getSceneManager();
        const float h = treeHeight(tree.model);
        const std::vector<ForestInstance> trees = {instance(-0.6f * h, 0, 0.3f * h, 0.5f, 0.9f),
                                                   instance(0.5f * h, 0, -0.4f * h, 2.0f, 1.1f)};
        const CameraSpec view = look(glm::vec3(0.5f * h, 1.3f * h, 2.3f * h), glm::vec3(0.0f, 0.25f * h, 0.0f), 45.0f);
        placeShadowScene(trees, 0.0f, false);
        r.setShadows(false);
        const Image plain = toImage(r.render(view, 160, 128, 1));
        /// The shadow texture's darkest and brightest red, 0..1.
        auto textureRange = [&] {
            const Ogre::TexturePtr& texture = sm.getShadowTexture(0);
            std::vector<float> red(texture->getWidth() * texture->getHeight() * 4);
            texture->getBuffer()->blitToMemory(
                Ogre::PixelBox(texture->getWidth(), texture->getHeight(), 1, Ogre::PF_FLOAT32_RGBA, red.data()));
            float lo = 1e9f, hi = -1e9f;
            for (std::size_t i = 0; i < red.size(); i += 4)
            {
                lo = std::min(lo, red[i]);
                hi = std::max(hi, red[i]);
            }
            return std::make_pair(lo, hi);
        };
        sm.setShadowColour(Ogre::ColourValue(0.25f, 0.25f, 0.25f));
        for (Ogre::ShadowTechnique technique : {Ogre::SHADOWTYPE_TEXTURE_MODULATIVE, Ogre::SHADOWTYPE_TEXTURE_ADDITIVE,
                                                Ogre::SHADOWTYPE_TEXTURE_ADDITIVE_INTEGRATED})
        {
            SunShadowSettings settings;
            settings.technique = technique;
            settings.textureSize = 512;
            r.setShadows(settings);
            const Image shadowed = toImage(r.render(view, 160, 128, 1));
            const bool integrated = technique & Ogre::SHADOWDETAILTYPE_INTEGRATED;
            if (!integrated)
            {
                EXPECT_LT(flipMean(shadowed, plain), 0.002) << "casters do not receive colour shadows";
            }
            if (!texturesReadBack())
                continue;
            const auto [lo, hi] = textureRange();
            std::printf("shadow technique %d: shadow texture red %.3f..%.3f; FLIP against unshadowed %.5f\n",
                        int(technique), lo, hi, flipMean(shadowed, plain));
            EXPECT_FLOAT_EQ(hi, 1.0f) << "cleared where nothing casts";
            if (technique == Ogre::SHADOWTYPE_TEXTURE_MODULATIVE)
            {
                EXPECT_NEAR(lo, 0.25f, 0.01f) << "modulative casters write the shadow colour";
            }
            else if (!integrated)
            {
                EXPECT_NEAR(lo, 0.0f, 0.01f) << "additive casters write black";
            }
            else
            {
                EXPECT_GT(lo, 0.0f) << "integrated casters write depth";
                EXPECT_LT(lo, 1.0f);
            }
        }
        // Stencil: refused by the set-up, logged once by the objects when set on Ogre directly.
        SunShadowSettings stencil;
        stencil.technique = Ogre::SHADOWTYPE_STENCIL_MODULATIVE;
        try
        {
            r.setShadows(stencil);
            ADD_FAILURE() << "stencil shadows must be refused";
        }
        catch (const Ogre::InvalidParametersException& e)
        {
            EXPECT_NE(e.getDescription().find("stencil"), std::string::npos) << e.getDescription();
        }
        struct Counter : Ogre::LogListener
        {
            int stencilLines = 0;
            void messageLogged(const Ogre::String& message, Ogre::LogMessageLevel, bool, const Ogre::String&,
                               bool&) override
            {
                stencilLines += message.find("do not support stencil shadows") != Ogre::String::npos;
            }
        } counter;
        Ogre::LogManager::getSingleton().getDefaultLog()->addListener(&counter);
        sm.setShadowTechnique(Ogre::SHADOWTYPE_STENCIL_MODULATIVE);
        const Image stencilled = toImage(r.render(view, 160, 128, 1));
        r.render(view, 160, 128, 1);
        Ogre::LogManager::getSingleton().getDefaultLog()->removeListener(&counter);
        r.setShadows(false);
        r.clearContent();
        EXPECT_EQ(counter.stencilLines, 1) << "one log line per scene manager";
        EXPECT_LT(flipMean(stencilled, plain), 0.002) << "trees draw unshadowed under stencil shadows";
    }

    /// An application's own materials drawn by OGRE's RTSS (the way OgreBites does it): the
    /// shader generator on the renderer's scene manager, its scheme on the viewport, techniques
    /// generated for materials without programs; with `pssm`, the RTSS's integrated PSSM
    /// receiver (IntegratedPSSM3, as OGRE's Shadows and Terrain samples) on the generated
    /// techniques. Undone by its destructor.
    class RtssApplication : public Ogre::MaterialManager::Listener
    {
    public:
        RtssApplication()
        {
            Ogre::ResourceGroupManager& rgm = Ogre::ResourceGroupManager::getSingleton();
            for (const char* folder : {"/RTShaderLib/GLSL", "/RTShaderLib/materials"})
                rgm.addResourceLocation(ogreMediaDirectory() + folder, "FileSystem", GROUP);
            rgm.initialiseResourceGroup(GROUP);
            EXPECT_TRUE(Ogre::RTShader::ShaderGenerator::initialize());
            mGenerator = Ogre::RTShader::ShaderGenerator::getSingletonPtr();
            mGenerator->addSceneManager(&OgreEnvironment::renderer().getSceneManager());
            Ogre::MaterialManager::getSingleton().addListener(this);
            OgreEnvironment::renderer().setMaterialScheme(Ogre::RTShader::ShaderGenerator::DEFAULT_SCHEME_NAME);
        }
        ~RtssApplication() override
        {
            OgreEnvironment::renderer().setMaterialScheme(Ogre::MaterialManager::DEFAULT_SCHEME_NAME);
            Ogre::MaterialManager::getSingleton().removeListener(this);
            Ogre::RTShader::ShaderGenerator::destroy();
            Ogre::ResourceGroupManager::getSingleton().destroyResourceGroup(GROUP);
        }

        /// Integrated PSSM receiving on every generated technique, split at the scene manager's
        /// PSSM camera setup's points.
        void receivePssm()
        {
            auto* setup = dynamic_cast<Ogre::PSSMShadowCameraSetup*>(
                OgreEnvironment::renderer().getSceneManager().getShadowCameraSetup().get());
            ASSERT_TRUE(setup);
            Ogre::RTShader::RenderState* state =
                mGenerator->getRenderState(Ogre::RTShader::ShaderGenerator::DEFAULT_SCHEME_NAME);
            if (!mPssm)
            {
                mPssm = static_cast<Ogre::RTShader::IntegratedPSSM3*>(
                    mGenerator->createSubRenderState(Ogre::RTShader::IntegratedPSSM3::Type));
                state->addTemplateSubRenderState(mPssm);
            }
            mPssm->setSplitPoints(setup->getSplitPoints());
            mGenerator->invalidateScheme(Ogre::RTShader::ShaderGenerator::DEFAULT_SCHEME_NAME);
        }

        Ogre::Technique* handleSchemeNotFound(unsigned short, const Ogre::String& scheme, Ogre::Material* material,
                                              unsigned short, const Ogre::Renderable*) override
        {
            // TreeLod's materials have programs: the RTSS leaves them, Ogre draws their own technique.
            if (!mGenerator->createShaderBasedTechnique(*material, Ogre::MaterialManager::DEFAULT_SCHEME_NAME, scheme))
                return nullptr;
            mGenerator->validateMaterial(scheme, material->getName(), material->getGroup());
            for (Ogre::Technique* technique : material->getTechniques())
                if (technique->getSchemeName() == scheme)
                    return technique;
            return nullptr;
        }

    private:
        static constexpr const char* GROUP = "ForestTest/Rtss";
        Ogre::RTShader::ShaderGenerator* mGenerator = nullptr;
        Ogre::RTShader::IntegratedPSSM3* mPssm = nullptr;
    };

    // The application's set-up, not TreeLod's: an RTSS-drawn ground receives the trees' shadows
    // (integrated PSSM through the RTSS; Ogre's modulative texture shadows), and an application
    // object, cast with TreeLod/BarkCaster as the scene's caster material, shadows the trees.
    TEST(Forest, shadowsInAnRtssApplication)
    {
        const ForestTree& tree = oak();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        Ogre::SceneManager& sm = r.getSceneManager();
        const float h = treeHeight(tree.model);
        RtssApplication application;
        Ogre::MaterialManager& materials = Ogre::MaterialManager::getSingleton();
        for (const auto& [name, colour] : {std::make_pair("ForestTest/AppGround", Ogre::ColourValue(0.45f, 0.5f, 0.3f)),
                                           std::make_pair("ForestTest/AppBox", Ogre::ColourValue(0.6f, 0.6f, 0.6f))})
            if (!materials.resourceExists(name, "TreeLod"))
            {
                Ogre::MaterialPtr material = materials.create(name, "TreeLod");
                Ogre::Pass* pass = material->getTechnique(0)->getPass(0);
                pass->setAmbient(colour);
                pass->setDiffuse(colour);
                material->setReceiveShadows(std::string(name) == "ForestTest/AppGround");
            }
        const LightingSpec lighting;
        const glm::vec3 treeAt(0.0f, 0.0f, 0.0f);
        const glm::vec3 boxAt = treeAt + glm::vec3(0.0f, 0.6f * h, 0.0f) + lighting.sunDirection * (0.9f * h);
        Ogre::MovableObject* forest = nullptr;
        Ogre::MovableObject* box = nullptr;
        auto place = [&](bool trees) {
            r.clearContent();
            Ogre::ManualObject* ground = sm.createManualObject();
            ground->setCastShadows(false);
            ground->begin("ForestTest/AppGround", Ogre::RenderOperation::OT_TRIANGLE_LIST, "TreeLod");
            const float s = 6.0f * h;
            for (const glm::vec2 c : {glm::vec2(-s, -s), glm::vec2(s, -s), glm::vec2(s, s), glm::vec2(-s, s)})
            {
                ground->position(c.x, 0.0f, c.y);
                ground->normal(0.0f, 1.0f, 0.0f);
            }
            ground->quad(0, 3, 2, 1);
            ground->end();
            r.getContentNode().createChildSceneNode()->attachObject(ground);
            auto* cube = sm.createManualObject();
            cube->begin("ForestTest/AppBox", Ogre::RenderOperation::OT_TRIANGLE_LIST, "TreeLod");
            const float b = 0.2f * h;
            for (int face = 0; face < 6; ++face)
            {
                const int axis = face / 2;
                const float sign = face % 2 ? -1.0f : 1.0f;
                Ogre::Vector3 n(0.0f), u(0.0f), v(0.0f);
                n[axis] = sign;
                u[(axis + 1) % 3] = 1.0f;
                v[(axis + 2) % 3] = sign;
                const Ogre::Vector3 base(boxAt.x, boxAt.y, boxAt.z);
                for (const auto& [du, dv] : {std::make_pair(-1.0f, -1.0f), std::make_pair(1.0f, -1.0f),
                                            std::make_pair(1.0f, 1.0f), std::make_pair(-1.0f, 1.0f)})
                {
                    cube->position(base + b * (n + du * u + dv * v));
                    cube->normal(n);
                }
                cube->quad(Ogre::uint32(4 * face), Ogre::uint32(4 * face + 1), Ogre::uint32(4 * face + 2),
                           Ogre::uint32(4 * face + 3));
            }
            cube->end();
            box = cube;
            r.getContentNode().createChildSceneNode()->attachObject(cube);
            forest = nullptr;
            if (trees)
            {
                static int serial = 0;
                auto* f = static_cast<Forest*>(sm.createMovableObject("rtssForest" + std::to_string(serial++), "Forest"));
                f->addSpecies(tree.asset, {ForestLevel{"mesh", 0, false, 0.0f}});
                f->addInstances({instance(treeAt.x, treeAt.y, treeAt.z, 0.5f), instance(-1.2f * h, 0.0f, -0.8f * h, 2.0f)});
                r.getContentNode().createChildSceneNode()->attachObject(f);
                forest = f;
            }
        };
        const CameraSpec view = look(glm::vec3(0.6f * h, 0.9f * h, 1.7f * h), glm::vec3(-0.4f * h, 0.3f * h, -0.3f * h), 50.0f);
        auto render = [&](bool treesCast, bool boxCasts) {
            if (forest)
                forest->setCastShadows(treesCast);
            box->setCastShadows(boxCasts);
            r.render(view, 192, 144, 1); // shadow cameras framed by this view's receivers
            return toImage(r.render(view, 192, 144, 1));
        };
        // Which pixels are trees: they differ from the scene without trees (both unshadowed).
        r.setShadows(false);
        place(false);
        const Image noTrees = render(false, false);
        place(true);
        const Image unshadowed = render(false, false);
        std::vector<bool> treePixel(unshadowed.pixels.size());
        for (std::size_t i = 0; i < treePixel.size(); ++i)
            treePixel[i] = glm::length(glm::vec3(unshadowed.pixels[i] - noTrees.pixels[i])) > 0.02f;
        auto meanOver = [&](const Image& image, bool trees) {
            double sum = 0.0;
            std::size_t n = 0;
            for (std::size_t i = 0; i < treePixel.size(); ++i)
                if (treePixel[i] == trees)
                {
                    const glm::vec4& p = image.pixels[i];
                    sum += 0.2126 * p.r + 0.7152 * p.g + 0.0722 * p.b;
                    ++n;
                }
            return n ? sum / double(n) : 0.0;
        };
        sm.setShadowTextureCasterMaterial(materials.getByName("TreeLod/BarkCaster", "TreeLod"));
        // Integrated PSSM: TreeLod's receivers and the RTSS's read the same depth textures.
        SunShadowSettings settings;
        settings.camera = ShadowCamera::PSSM;
        settings.textureSize = 1024;
        settings.farDistance = 12.0f * h;
        r.setShadows(settings);
        r.render(view, 192, 144, 1); // the view's near clip sets the split points
        application.receivePssm();
        const Image pssmNoCasters = render(false, false);
        const Image pssmTrees = render(true, false);
        const Image pssmBox = render(true, true);
        // Ogre's modulative texture shadows: the RTSS draws Ogre's receiver pass on the ground.
        settings.technique = Ogre::SHADOWTYPE_TEXTURE_MODULATIVE;
        settings.camera = ShadowCamera::Focused;
        r.setShadows(settings);
        const Image modulativeNoCasters = render(false, false);
        const Image modulativeTrees = render(true, false);
        sm.setShadowTextureCasterMaterial(Ogre::MaterialPtr());
        r.setShadows(false);
        r.clearContent();
        const double groundDrop = meanOver(pssmNoCasters, false) - meanOver(pssmTrees, false);
        const double treeDrop = meanOver(pssmTrees, true) - meanOver(pssmBox, true);
        const double modulativeDrop = meanOver(modulativeNoCasters, false) - meanOver(modulativeTrees, false);
        std::printf("RTSS application: ground darkened by the trees' PSSM shadows %.4f, trees by the box's %.4f; "
                    "modulative: ground %.4f, trees FLIP against unshadowed %.5f\n", groundDrop, treeDrop,
                    modulativeDrop, flipMean(modulativeTrees, unshadowed));
        writePng(OgreEnvironment::outDir() + "/forest-shadows-rtss-strip.png",
                 sideBySide({unshadowed, pssmNoCasters, pssmTrees, pssmBox, modulativeTrees}));
        EXPECT_GT(groundDrop, 0.005) << "the RTSS ground receives the trees' depth shadows";
        EXPECT_GT(treeDrop, 0.005) << "the trees receive the application's caster";
        EXPECT_GT(modulativeDrop, 0.005) << "the RTSS ground receives the trees' modulative shadows";
        compareWithGolden(pssmBox, "forest-shadows-rtss-pssm", 0.02);
        compareWithGolden(modulativeTrees, "forest-shadows-rtss-modulative", 0.02);
    }

    TEST(Forest, badInputIsRefusedAndNamed)
    {
        const ForestTree& tree = oak();
        Forest* forest = placeForest();
        forest->addSpecies(tree.asset, {ForestLevel{"impostor", 0, false, 0.0f}});
        forest->addInstances({instance(0, 0, 0)});
        const Ogre::AxisAlignedBox bounds = forest->getBoundingBox();
        const float nan = std::numeric_limits<float>::quiet_NaN();
        const std::pair<std::vector<ForestInstance>, const char*> cases[] = {
            {{instance(1, 0, 0), instance(2, 0, 0), instance(nan, 0, 0)}, "instance 2"},
            {{instance(1, 0, 0), instance(2, 0, 0, 0.0f, 0.0f)}, "instance 1"},
            {{instance(1, 0, 0, std::numeric_limits<float>::infinity())}, "instance 0"},
            {{instance(1, 0, 0, 0.0f, 1.0f, 7)}, "instance 0"},
        };
        for (const auto& c : cases)
        {
            try
            {
                forest->addInstances(c.first);
                ADD_FAILURE() << c.second << " must be refused";
            }
            catch (const Ogre::InvalidParametersException& e)
            {
                EXPECT_NE(e.getDescription().find(c.second), std::string::npos) << e.getDescription();
            }
            EXPECT_EQ(forest->getInstances().size(), 1u) << "nothing added";
            EXPECT_EQ(forest->getBoundingBox(), bounds);
        }

        // Species: bad level lists are named, nothing is added.
        const std::pair<std::vector<ForestLevel>, const char*> levels[] = {
            {{}, "0 levels"},
            {{ForestLevel{"mesh", 0, false, 10.0f}, ForestLevel{"impostor", 0, false, 20.0f}}, "level 1 'impostor'"},
            {{ForestLevel{"mesh", 0, false, 10.0f}}, "level 0 'mesh'"},
            {{ForestLevel{"trees", 0, false, 0.0f}}, "unknown technique"},
            {{ForestLevel{"lodf", 0, true, 0.0f}}, "lowRes"},
            {{ForestLevel{"billboard-cloud", 9, false, 0.0f}}, "cloud level 9"},
        };
        for (const auto& c : levels)
        {
            try
            {
                forest->addSpecies(tree.asset, c.first);
                ADD_FAILURE() << c.second << " must be refused";
            }
            catch (const Ogre::Exception& e)
            {
                EXPECT_NE(e.getDescription().find(c.second), std::string::npos) << e.getDescription();
            }
            EXPECT_EQ(forest->getSpeciesCount(), 1u);
        }
        EXPECT_THROW(forest->setLodBias(0.0f), Ogre::InvalidParametersException);

        // Bands: an unknown technique, bands out of order, a package without the chunk.
        try
        {
            Forest::levelsForBands(*tree.asset, {{"lodf", 100.0f}, {"bush", 0.0f}});
            ADD_FAILURE() << "an unknown technique must throw";
        }
        catch (const Ogre::Exception& e)
        {
            EXPECT_NE(e.getDescription().find("band 1 'bush'"), std::string::npos) << e.getDescription();
        }
        EXPECT_THROW(Forest::levelsForBands(*tree.asset, {{"lodf", 10.0f}, {"mesh", 20.0f}, {"impostor", 0.0f}}),
                     Ogre::InvalidParametersException);
        EXPECT_THROW(Forest::levelsForBands(*tree.asset, {{"lodf", 10.0f}}), Ogre::InvalidParametersException);
        PackageWriter writer;
        ASSERT_TRUE(addReferenceChunk(writer, tree.model, "ref-only").ok());
        TreeAssetPtr refOnly =
            TreeAssetManager::getSingleton().loadFromBytes("ref-only.forest-test", Ogre::RGN_DEFAULT, writer.toBytes());
        try
        {
            Forest::levelsForBands(*refOnly, {{"mesh", 100.0f}, {"lodf", 0.0f}});
            ADD_FAILURE() << "a package without lodf must throw";
        }
        catch (const Ogre::Exception& e)
        {
            EXPECT_NE(e.getDescription().find("band 1 'lodf'"), std::string::npos) << e.getDescription();
            EXPECT_NE(e.getDescription().find("--technique lodf"), std::string::npos) << e.getDescription();
        }
    }

    TEST(Forest, sharedAssetOneInstanceAndTwentyThousandQuads)
    {
        const ForestTree& tree = oak();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        const float h = treeHeight(tree.model);

        // Two species of one asset: each draws its own technique.
        Forest* forest = placeForest();
        EXPECT_EQ(forest->addSpecies(tree.asset, {ForestLevel{"lodf", 0, false, 0.0f}}), 0u);
        EXPECT_EQ(forest->addSpecies(tree.asset, {ForestLevel{"billboard-cloud", 1, false, 0.0f}}), 1u);
        forest->addInstances({instance(-0.6f * h, 0, 0, 0.0f, 1.0f, 0), instance(0.6f * h, 0, 0, 0.0f, 1.0f, 1)});
        const CameraSpec pair = look(glm::vec3(0.0f, 0.5f * h, 2.5f * h), glm::vec3(0.0f, 0.5f * h, 0.0f));
        const Image two = toImage(r.render(pair, 128, 96, 1));
        EXPECT_EQ(forest->getStats().levelCounts, (std::vector<std::vector<std::uint32_t>>{{1u}, {1u}}));
        EXPECT_GT(treeCoverage(two, BACKGROUND), 0.1);
        EXPECT_EQ(forest->getAsset(0), forest->getAsset(1));

        // One instance.
        forest = placeForest();
        forest->addSpecies(tree.asset, Forest::levelsForBands(*tree.asset, Forest::getAutoBands()));
        forest->addInstances({instance(0, 0, 0)});
        const Image one = toImage(r.render(pair, 96, 96, 1));
        EXPECT_EQ(forest->getStats().visibleInstances, 1u);
        EXPECT_GT(treeCoverage(one, BACKGROUND), 0.05);

        // 20,000 quads (a 142 x 142 grid, 1.2 tree heights apart) seen from a little above the edge.
        forest = placeForest();
        forest->addSpecies(tree.asset, {ForestLevel{"impostor", 0, false, 0.0f}});
        forest->addInstances(grid(142, 1.2f * h));
        const float half = 71.0f * 1.2f * h;
        const CameraSpec over = look(glm::vec3(0.0f, 4.0f * h, half + 8.0f * h), glm::vec3(0.0f, 0.0f, 0.0f), 60.0f);
        const auto start = std::chrono::steady_clock::now();
        const Image many = toImage(r.render(over, 256, 160, 1));
        const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        const ForestStats& stats = forest->getStats();
        std::printf("20164 quads: %u visible, %u batches, %llu triangles, cull %.3f ms, frame %.0f ms\n",
                    stats.visibleInstances, stats.batches, (unsigned long long)stats.triangles,
                    stats.cullMilliseconds, ms);
        EXPECT_EQ(stats.instances, 142u * 142u);
        EXPECT_GT(stats.visibleInstances, 10000u);
        EXPECT_EQ(stats.batches, 1u);
        EXPECT_EQ(stats.triangles, 2u * stats.visibleInstances);
        EXPECT_GT(treeCoverage(many, BACKGROUND), 0.2);
        // 24 bytes per instance on the GPU, grown by doubling; the next frame allocates nothing.
        const std::uint64_t bytes = stats.instanceBufferBytes;
        EXPECT_GE(bytes, 24u * stats.visibleInstances);
        EXPECT_LE(bytes, 2u * 24u * stats.visibleInstances);
        r.render(over, 256, 160, 1);
        EXPECT_EQ(forest->getStats().instanceBufferBytes, bytes);
        compareWithGolden(many, "forest-20k-quads", 0.02);
    }

    TEST(Forest, aMillionTreesInOneDraw)
    {
        // The extreme: 1,000,000 instances all in view draw in one instanced call of 2 M
        // triangles (no 16-bit count anywhere on the way), the store at ~30 bytes a tree and the
        // instance buffer at 24 (grown by doubling) a visible tree.
        const ForestTree& tree = oak();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        const float h = treeHeight(tree.model);
        Forest* forest = placeForest();
        forest->addSpecies(tree.asset, {ForestLevel{"impostor", 0, false, 0.0f}});
        // Trees 16x their size (overlapping) so that each covers pixels from afar: were only the first
        // 1,000,000 mod 65,536 instances drawn (a 16-bit count), they would fill one corner of the
        // Z-ordered store, not every part of the picture.
        std::vector<ForestInstance> trees = grid(1000, 0.5f * h);
        for (ForestInstance& t : trees)
            t.scale *= 16.0f;
        forest->addInstances(trees);
        const float half = 500.0f * 0.5f * h;
        // 45 degrees down onto the middle (the quads are upright: seen from straight above they vanish).
        const CameraSpec above = look(glm::vec3(0.0f, 1.6f * half, 1.6f * half), glm::vec3(0.0f), 60.0f);
        const Image image = toImage(r.render(above, 160, 120, 1));
        const ForestStats& stats = forest->getStats();
        std::printf("1M quads: %u visible, %u batches, %llu triangles, cull %.1f ms, store %.1f B a tree, "
                    "instance buffer %.1f MB\n",
                    stats.visibleInstances, stats.batches, (unsigned long long)stats.triangles, stats.cullMilliseconds,
                    double(forest->getInstances().getMemoryBytes()) / double(stats.instances),
                    double(stats.instanceBufferBytes) / 1e6);
        EXPECT_EQ(stats.instances, 1000000u);
        EXPECT_EQ(stats.visibleInstances, 1000000u);
        EXPECT_EQ(stats.batches, 1u);
        EXPECT_EQ(stats.triangles, 2000000u);
        EXPECT_LE(forest->getInstances().getMemoryBytes(), 32u * 1000000u);
        EXPECT_GE(stats.instanceBufferBytes, 24u * 1000000u);
        EXPECT_LE(stats.instanceBufferBytes, 2u * 24u * 1000000u);
        writePng(OgreEnvironment::outDir() + "/forest-1m-quads.png", image);
        // Trees around the middle of each quarter of the grid (projected with the camera).
        const Ogre::Matrix4 viewProjection = ogreCamera().getProjectionMatrix() * ogreCamera().getViewMatrix();
        for (const glm::vec2 q : {glm::vec2(-0.5f, -0.5f), glm::vec2(0.5f, -0.5f), glm::vec2(-0.5f, 0.5f),
                                  glm::vec2(0.5f, 0.5f)})
        {
            const Ogre::Vector3 ndc = viewProjection * Ogre::Vector3(q.x * half, 0.0f, q.y * half);
            const int cx = int((ndc.x * 0.5f + 0.5f) * float(image.width));
            const int cy = int((0.5f - ndc.y * 0.5f) * float(image.height));
            Image window(6, 4);
            for (int y = 0; y < window.height; ++y)
                for (int x = 0; x < window.width; ++x)
                    window.at(x, y) = image.at(std::clamp(cx - 3 + x, 0, image.width - 1),
                                               std::clamp(cy - 2 + y, 0, image.height - 1));
            EXPECT_GT(treeCoverage(window, BACKGROUND), 0.9) << "quarter " << q.x << ", " << q.y << " at pixel "
                                                             << cx << ", " << cy;
        }
    }

    TEST(Forest, levelsForBandsFollowTheTechniquesCurves)
    {
        const ForestTree& tree = oak();
        TreeAsset& asset = *tree.asset;
        const std::vector<ForestLevel> levels = Forest::levelsForBands(asset, Forest::getAutoBands());
        ASSERT_GE(levels.size(), 3u);
        for (std::size_t l = 1; l < levels.size(); ++l)
            EXPECT_LT(levels[l].minPixelCount, levels[l - 1].minPixelCount);
        EXPECT_EQ(levels.back().minPixelCount, 0.0f);
        EXPECT_EQ(levels.back().technique, "impostor");
        EXPECT_EQ(levels.front().technique, "lodf");
        EXPECT_EQ(levels.front().techniqueLevel, FoliageLodResources::of(asset).getFoliageLod().maxLeafCount());

        // Band edges: a tree h_px tall has r_px = h_px * R / h, value 4 pi r_px^2.
        const Ogre::AxisAlignedBox bounds = asset.getBounds();
        const double radius = Ogre::Math::boundingRadiusFromAABB(bounds);
        const double height = bounds.getMaximum().y - bounds.getMinimum().y;
        auto value = [&](double pixels) {
            const double r = pixels * radius / height;
            return 4.0 * Ogre::Math::PI * r * r;
        };
        std::size_t lastLodf = 0, lastCloud = 0;
        for (std::size_t l = 0; l < levels.size(); ++l)
        {
            if (levels[l].technique == "lodf")
                lastLodf = l;
            if (levels[l].technique == "billboard-cloud")
                lastCloud = l;
        }
        EXPECT_NEAR(levels[lastLodf].minPixelCount, value(160.0), 1e-3 * value(160.0));
        EXPECT_NEAR(levels[lastCloud].minPixelCount, value(24.0), 1e-3 * value(24.0));
        // A level repeated with the same drawable: split where its bark mesh's LoD switches.
        auto isBarkSwitch = [](const Ogre::MeshPtr& bark, Ogre::Real value) {
            for (unsigned short i = 1; i < bark->getNumLodLevels(); ++i)
                if (bark->getLodLevel(i).value == value)
                    return true;
            return false;
        };
        auto same = [](const ForestLevel& a, const ForestLevel& b) {
            return a.technique == b.technique && a.techniqueLevel == b.techniqueLevel && a.lowRes == b.lowRes;
        };
        std::size_t barkSplits = 0;
        // lodf: halving counts, each kept while FoliageLodTree's curve asks for more than the next.
        for (std::size_t l = 0; l < lastLodf; ++l)
        {
            if (same(levels[l], levels[l + 1]))
            {
                EXPECT_TRUE(isBarkSwitch(asset.getBarkMesh(), levels[l].minPixelCount)) << "level " << l;
                ++barkSplits;
                continue;
            }
            EXPECT_EQ(levels[l + 1].techniqueLevel, (levels[l].techniqueLevel + 1) / 2);
            EXPECT_FLOAT_EQ(levels[l].minPixelCount,
                            FoliageLodTree::pixelCountForLeaves(levels[l + 1].techniqueLevel,
                                                                FoliageLodTree::DEFAULT_PIXELS_PER_LEAF));
        }
        // Billboard cloud: BillboardCloudTree's switches (in the same units) inside the band.
        const BillboardCloudGpu& gpu = BillboardCloudResources::of(asset, false).getGpu();
        const std::vector<Ogre::Real> switches =
            BillboardCloudTree::switchPixelCounts(gpu, gpu.listFactor, float(radius));
        for (std::size_t l = lastLodf + 1; l < lastCloud; ++l)
        {
            const ForestLevel& level = levels[l];
            const ForestLevel& next = levels[l + 1];
            if (same(level, next))
            {
                EXPECT_TRUE(isBarkSwitch(BillboardCloudResources::of(asset, false).getBarkAoMesh(), level.minPixelCount)) << "level " << l;
                ++barkSplits;
            }
            else if (next.techniqueLevel == level.techniqueLevel)
                EXPECT_TRUE(!level.lowRes && next.lowRes) << "a layered level, then its low-res technique";
            else
                EXPECT_FLOAT_EQ(level.minPixelCount, switches.at(level.techniqueLevel));
        }
        EXPECT_GT(barkSplits, 0u) << "the bark's LoD switches inside the billboard-cloud band";
        std::printf("auto levels of oak:");
        for (const ForestLevel& level : levels)
            std::printf(" %s/%u%s>=%.0f", level.technique.c_str(), level.techniqueLevel, level.lowRes ? "lowres" : "",
                        level.minPixelCount);
        std::printf("\n");

        // A single band: the technique's own levels from the finest to 0.
        const std::vector<ForestLevel> lodf = Forest::levelsForBands(asset, {{"lodf", 0.0f}});
        EXPECT_EQ(lodf.back().techniqueLevel, FoliageLodResources::of(asset).getFoliageLod().minLeafCount());
        const std::vector<ForestLevel> mesh = Forest::levelsForBands(asset, {{"mesh", 0.0f}});
        const Ogre::MeshPtr reference = asset.getReferenceMesh();
        ASSERT_EQ(mesh.size(), std::size_t(reference->getNumLodLevels()));
        for (std::size_t l = 0; l + 1 < mesh.size(); ++l)
        {
            EXPECT_EQ(mesh[l].technique, "mesh");
            EXPECT_EQ(mesh[l].minPixelCount, reference->getLodLevel(std::uint16_t(l + 1)).value);
        }
    }

    // The bench's floors (QuadFloors.h) draw the Forest's quad level as plain Ogre objects: one
    // entity per tree, and merged static batches. Same impostor, same program: the same picture.
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

    TEST(Forest, levelsBecomeResidentWithinTheUploadBudget)
    {
        const ForestTree& tree = oak();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        const float h = treeHeight(tree.model);
        const std::vector<ForestLevel> levels = Forest::levelsForBands(*tree.asset, Forest::getAutoBands());
        const std::uint32_t last = std::uint32_t(levels.size() - 1);
        const std::vector<ForestInstance> trees = grid(5, 1.4f * h);
        // Near trees at lodf, farther ones at cloud levels: several levels in one view.
        const CameraSpec view = look(glm::vec3(0.0f, 1.2f * h, 4.5f * h), glm::vec3(0.0f, 0.4f * h, -2.0f * h));

        // addSpecies builds the last level only (the fallback); 10 km away nothing more is built.
        Forest* lazy = placeForest();
        lazy->addSpecies(tree.asset, levels);
        lazy->addInstances(trees);
        EXPECT_TRUE(lazy->isResident(0, last));
        for (std::uint32_t l = 0; l < last; ++l)
        {
            EXPECT_FALSE(lazy->isResident(0, l)) << "level " << l;
            EXPECT_EQ(lazy->getDrawnLevel(0, l), last);
        }
        const std::uint64_t planned = lazy->getGpuBytes();
        r.render(look(glm::vec3(0.0f, 200.0f, 10000.0f), glm::vec3(0.0f)), 96, 96, 1);
        EXPECT_EQ(lazy->getStats().uploadedLevels, 0u);
        EXPECT_EQ(lazy->getGpuBytes() - lazy->getStats().instanceBufferBytes, planned) << "a far view uploads nothing";

        // A budget of one byte: one level per frame; meanwhile the trees draw their fallback.
        lazy->setUploadBudget(1);
        const Image first = toImage(r.render(view, 256, 192, 1));
        const ForestStats firstStats = lazy->getStats();
        EXPECT_EQ(firstStats.uploadedLevels, 1u);
        EXPECT_GT(firstStats.uploadedBytes, 0u);
        EXPECT_GT(firstStats.pendingLevels, 0u);
        EXPECT_GT(firstStats.fallbackInstances, 0u);
        EXPECT_GT(firstStats.visibleInstances, 15u);
        EXPECT_GT(treeCoverage(first, BACKGROUND), 0.1) << "the fallback draws every tree";
        std::uint32_t frames = 1, pending = firstStats.pendingLevels;
        std::uint64_t maxUploaded = firstStats.uploadedBytes;
        while (lazy->getStats().pendingLevels > 0 && frames < 40)
        {
            r.render(view, 256, 192, 1);
            ++frames;
            EXPECT_LE(lazy->getStats().uploadedLevels, 1u);
            EXPECT_LT(lazy->getStats().pendingLevels, pending + 1);
            pending = lazy->getStats().pendingLevels;
            maxUploaded = std::max(maxUploaded, lazy->getStats().uploadedBytes);
        }
        const Image converged = toImage(r.render(view, 256, 192, 1));
        const ForestStats done = lazy->getStats();
        EXPECT_EQ(done.pendingLevels, 0u);
        EXPECT_EQ(done.fallbackInstances, 0u);
        EXPECT_EQ(done.uploadedLevels, 0u);
        std::uint32_t used = 0, resident = 0;
        for (std::uint32_t l = 0; l < levels.size(); ++l)
        {
            used += done.levelCounts[0][l] > 0 ? 1 : 0;
            resident += lazy->isResident(0, l) ? 1 : 0;
        }
        std::printf("upload budget 1 B: %u levels in view became resident over %u frames (largest frame %.2f MB, "
                    "%u of %zu levels resident; %.2f MB planned, %.2f MB after)\n",
                    used, frames, double(maxUploaded) / 1e6, resident, levels.size(), double(planned) / 1e6,
                    double(lazy->getGpuBytes()) / 1e6);
        EXPECT_GE(used, 3u) << "the view should show several levels";
        EXPECT_LT(resident, std::uint32_t(levels.size())) << "levels never seen stay unbuilt";
        EXPECT_GT(lazy->getGpuBytes(), planned);

        // No budget: a fresh Forest builds what the view needs in its first frame, same picture.
        Forest* eager = placeForest();
        eager->addSpecies(tree.asset, levels);
        eager->addInstances(trees);
        const Image unlimited = toImage(r.render(view, 256, 192, 1));
        EXPECT_EQ(eager->getStats().pendingLevels, 0u);
        EXPECT_EQ(eager->getStats().fallbackInstances, 0u);
        EXPECT_EQ(eager->getStats().uploadedLevels, used);
        const double flipConverged = flipMean(unlimited, converged), flipFirst = flipMean(unlimited, first);
        std::printf("FLIP against the unlimited first frame: budget's first frame %.4f, converged %.5f\n", flipFirst,
                    flipConverged);
        EXPECT_LT(flipConverged, 0.002);
        EXPECT_GT(flipFirst, 0.01) << "the first frame drew fallbacks, it should differ";
        compareWithGolden(sideBySide({first, converged}), "forest-residency", 0.03);

        // Preloading builds every level.
        eager->makeAllResident();
        for (std::uint32_t l = 0; l < levels.size(); ++l)
            EXPECT_TRUE(eager->isResident(0, l)) << "level " << l;
        EXPECT_EQ(eager->getStats().pendingLevels, 0u);
    }

    TEST(Forest, cameraStatesGoWithTheirCameras)
    {
        // Every camera that renders the Forest gets instance buffers; a destroyed camera's go
        // with it (50 short-lived cameras leave nothing behind), and a Forest destroyed before a
        // camera it saw leaves that camera no dangling listener.
        const ForestTree& tree = oak();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        Ogre::SceneManager& manager = r.getSceneManager();
        const float h = treeHeight(tree.model);
        const CameraSpec view = look(glm::vec3(0.0f, 4.0f * h, 9.0f * h), glm::vec3(0.0f, 0.0f, 0.0f), 50.0f);
        Forest* forest = placeForest();
        forest->addSpecies(tree.asset, {ForestLevel{"impostor", 0, false, 0.0f}});
        forest->addInstances(grid(6, 1.4f * h));
        const Image before = toImage(r.render(view, 96, 72, 1));
        const std::uint64_t viewerBytes = forest->getGpuBytes();
        ASSERT_GT(forest->getStats().instanceBufferBytes, 0u);

        Ogre::SceneNode* holder = manager.getRootSceneNode()->createChildSceneNode(
            Ogre::Vector3(0.0f, 2.0f * h, 12.0f * h));
        holder->lookAt(Ogre::Vector3::ZERO, Ogre::Node::TS_WORLD);
        auto renderWith = [&](Ogre::Camera* camera) {
            Ogre::RenderQueue queue;
            forest->_notifyCurrentCamera(camera);
            forest->_updateRenderQueue(&queue);
        };
        for (int i = 0; i < 50; ++i)
        {
            Ogre::Camera* extra = manager.createCamera("forest-extra-" + std::to_string(i));
            extra->setAspectRatio(4.0f / 3.0f);
            extra->setNearClipDistance(0.1f);
            holder->attachObject(extra);
            renderWith(extra);
            EXPECT_GT(forest->getGpuBytes(), viewerBytes) << "camera " << i << " drew with its own buffers";
            holder->detachObject(extra);
            manager.destroyCamera(extra);
            EXPECT_EQ(forest->getGpuBytes(), viewerBytes) << "camera " << i << "'s buffers outlived it";
        }
        // The viewer still draws what it drew.
        const Image after = toImage(r.render(view, 96, 72, 1));
        EXPECT_LT(flipMean(before, after), 1e-6);
        EXPECT_GT(treeCoverage(after, BACKGROUND), 0.05);

        // The Forest goes first: destroying the camera afterwards must not call into it.
        Ogre::Camera* survivor = manager.createCamera("forest-survivor");
        survivor->setAspectRatio(4.0f / 3.0f);
        holder->attachObject(survivor);
        renderWith(survivor);
        r.clearContent();
        holder->detachObject(survivor);
        manager.destroyCamera(survivor);
        manager.destroySceneNode(holder);
    }
}

namespace TreeLod
{
    namespace
    {
        /// Few heights and views: the curves of the oak's levels in seconds.
        ErrorCurveOptions smallCurveOptions()
        {
            ErrorCurveOptions o;
            o.heightsPx = {16.0f, 64.0f, 192.0f};
            o.views = {{0.0f, 10.0f}, {100.0f, 45.0f}};
            o.referenceSupersample = 2;
            return o;
        }

        /// The oak's package with its error curves (smallCurveOptions), loaded as "oak.budget-test".
        TreeAssetPtr oakWithCurves()
        {
            return OgreEnvironment::keep<TreeAssetPtr>("forest.oak-curves", [] {
                const ForestTree& tree = oak();
                const std::vector<std::uint8_t> bytes = cachedPackage("forest", "oak-curves", [&] {
                    Result<std::vector<std::uint8_t>> with = addErrorCurves(
                        OgreEnvironment::renderer(), cachedPackage("forest", "oak", [&] { return bakePackage(tree.model, "oak"); }),
                        "oak", smallCurveOptions());
                    EXPECT_TRUE(with.ok()) << (with.ok() ? "" : with.error().message());
                    return with.ok() ? with.value() : std::vector<std::uint8_t>{};
                });
                return TreeAssetManager::getSingleton().loadFromBytes("oak.budget-test", Ogre::RGN_DEFAULT, bytes);
            });
        }

        /// Costs fixed here, not calibrated, so that the levels (and the golden) do not follow the
        /// machine's noise: the mesh dearest, lodf by its leaves, clouds cheap, the impostor nearly free.
        std::vector<LevelCost> fixedCosts(TreeAsset& asset)
        {
            std::vector<LevelCost> costs;
            for (const ForestLevel& level : Forest::getCandidateLevels(asset))
            {
                LevelCost c;
                c.technique = level.technique;
                c.techniqueLevel = level.techniqueLevel;
                c.lowRes = level.lowRes;
                c.heightsPx = {16.0f, 256.0f};
                const float base = level.technique == "mesh"              ? 2.0f
                                   : level.technique == "lodf"            ? 0.2f + 1.5e-4f * float(level.techniqueLevel)
                                   : level.technique == "billboard-cloud" ? 0.3f - 0.1f * float(level.techniqueLevel)
                                                                          : 0.005f;
                c.msPerTree = {base, 16.0f * base};
                costs.push_back(c);
            }
            return costs;
        }
    }

    TEST(Forest, errorCurvesRankTheLevelsAgainstTheCpuReference)
    {
        const TreeAssetPtr asset = oakWithCurves();
        ASSERT_TRUE(asset->hasChunk(ERROR_CURVES_CHUNK));
        Result<ErrorCurves> curves = decodeErrorCurves(asset->readChunk(ERROR_CURVES_CHUNK), "oak");
        ASSERT_TRUE(curves) << curves.error().message();
        EXPECT_TRUE(coversCandidateLevels(*curves, *asset, smallCurveOptions()));
        EXPECT_EQ(curves->levels.size(), Forest::getCandidateLevels(*asset).size());
        const int mesh = curves->find("mesh", 0, false), quad = curves->find("impostor", 0, false);
        ASSERT_GE(mesh, 0);
        ASSERT_GE(quad, 0);
        int fullLodf = -1;
        for (std::size_t l = 0; l < curves->levels.size(); ++l)
            if (curves->levels[l].technique == "lodf" &&
                (fullLodf < 0 || curves->levels[l].techniqueLevel > curves->levels[std::size_t(fullLodf)].techniqueLevel))
                fullLodf = int(l);
        ASSERT_GE(fullLodf, 0);
        for (std::size_t h = 0; h < curves->heightsPx.size(); ++h)
        {
            const float m = curves->levels[std::size_t(mesh)].flip[h];
            std::printf("%5.0f px: mesh %.4f, lodf (all leaves) %.4f, impostor %.4f\n", double(curves->heightsPx[h]),
                        double(m), double(curves->levels[std::size_t(fullLodf)].flip[h]),
                        double(curves->levels[std::size_t(quad)].flip[h]));
            // The GPU's mesh against the CPU's: the same tree, one sample a pixel against four, over
            // the tree's own pixels (0.23 at 16 px, where most of them are edges; 0.15 at 192 px).
            EXPECT_GT(m, 0.0f);
            EXPECT_LT(m, 0.3f);
            // LoDF with every leaf draws what the mesh draws.
            EXPECT_NEAR(curves->levels[std::size_t(fullLodf)].flip[h], m, 0.01f);
        }
        // Close up, one quad is far from the tree; every curve's worst view is at least its mean.
        EXPECT_GT(curves->levels[std::size_t(quad)].flip.back(), curves->levels[std::size_t(mesh)].flip.back() + 0.05f);
        for (const ErrorCurveLevel& level : curves->levels)
            for (std::size_t h = 0; h < level.flip.size(); ++h)
                EXPECT_GE(level.flipMax[h], level.flip[h]);

        // The chunk is added once: a package that holds curves covering its levels is not measured again.
        const std::string path = OgreEnvironment::outDir() + "/oak-curves.treelod";
        const std::vector<std::uint8_t> bytes = cachedPackage("forest", "oak-curves", [] {
            ADD_FAILURE() << "oakWithCurves() cached the package";
            return std::vector<std::uint8_t>{};
        });
        ASSERT_TRUE(writeFileAtomic(path, bytes));
        Result<bool> again = ensureErrorCurves(OgreEnvironment::renderer(), path, smallCurveOptions());
        ASSERT_TRUE(again) << again.error().message();
        EXPECT_FALSE(*again);
        EXPECT_EQ(readFile(path).value(), bytes);
        // Other heights: measured again, the other chunks' bytes unchanged.
        ErrorCurveOptions other = smallCurveOptions();
        other.heightsPx = {32.0f};
        again = ensureErrorCurves(OgreEnvironment::renderer(), path, other);
        ASSERT_TRUE(again) << again.error().message();
        EXPECT_TRUE(*again);
        Result<PackageReader> rewritten = PackageReader::open(path);
        ASSERT_TRUE(rewritten);
        for (const ChunkInfo& info : asset->getPackage().chunks())
        {
            if (info.technique == ERROR_CURVES_CHUNK)
                continue;
            EXPECT_EQ(rewritten->readChunk(info.technique, info.level).value(),
                      asset->getPackage().readChunk(info.technique, info.level).value())
                << info.element();
        }
        Result<ErrorCurves> remeasured = decodeErrorCurves(rewritten->readChunk(ERROR_CURVES_CHUNK, 0).value(), path);
        ASSERT_TRUE(remeasured);
        EXPECT_EQ(remeasured->heightsPx, other.heightsPx);
    }

    TEST(Forest, calibrationTimesEveryLevelAndIsCachedPerRenderer)
    {
        const TreeAssetPtr asset = oakWithCurves();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        CalibrationOptions options;
        options.heightsPx = {16.0f, 64.0f};
        options.viewport = 128;
        options.frames = 1;
        options.targetFrameMs = 10.0;
        const std::string dir = OgreEnvironment::outDir() + "/calibration";
        std::filesystem::remove_all(dir);
        bool calibrated = false;
        Result<std::vector<LevelCost>> costs = requireLevelCosts(r, *asset, dir, options, {}, &calibrated);
        ASSERT_TRUE(costs) << costs.error().message();
        EXPECT_TRUE(calibrated);
        ASSERT_EQ(costs->size(), Forest::getCandidateLevels(*asset, Forest::getAutoTechniques()).size());
        for (const LevelCost& c : *costs)
        {
            ASSERT_EQ(c.msPerTree.size(), 2u) << c.technique;
            for (const float ms : c.msPerTree)
                EXPECT_TRUE(std::isfinite(ms) && ms >= 0.0f) << c.technique;
        }
        // The cache answers the second time, for this renderer only.
        Result<std::vector<LevelCost>> cached = requireLevelCosts(r, *asset, dir, options, {}, &calibrated);
        ASSERT_TRUE(cached);
        EXPECT_FALSE(calibrated);
        EXPECT_EQ(cached->front().msPerTree, costs->front().msPerTree);
        const std::string renderer = rendererString(r.getRoot());
        EXPECT_NE(renderer.find("OpenGL"), std::string::npos) << renderer;
        Result<CostCalibration> file = readCostCalibration(costCalibrationPath(dir, renderer), renderer);
        ASSERT_TRUE(file) << file.error().message();
        // The same costs under another renderer's name: not this renderer's, so calibrated again.
        CostCalibration foreign = *file;
        foreign.renderer = "OpenGL 3+ Rendering Subsystem | some GPU | 4.6";
        ASSERT_TRUE(writeCostCalibration(costCalibrationPath(dir, renderer), foreign));
        cached = requireLevelCosts(r, *asset, dir, options, {}, &calibrated);
        ASSERT_TRUE(cached);
        EXPECT_TRUE(calibrated);
    }

    TEST(Forest, anErrorBudgetChoosesTheCheapestLevelWithinIt)
    {
        const TreeAssetPtr asset = oakWithCurves();
        const ForestTree& tree = oak();
        const std::vector<LevelCost> costs = fixedCosts(*asset);

        const std::vector<ForestLevel> reference = Forest::levelsForErrorBudget(*asset, costs, 0.0f);
        ASSERT_EQ(reference.size(), 1u);
        EXPECT_EQ(reference[0].technique, "mesh");
        const std::vector<ForestLevel> cheapest = Forest::levelsForErrorBudget(*asset, costs, 1.0f);
        ASSERT_EQ(cheapest.size(), 1u);
        EXPECT_EQ(cheapest[0].technique, "impostor");
        const std::vector<ForestLevel> budgeted = Forest::levelsForErrorBudget(*asset, costs, 0.03f);
        ASSERT_GE(budgeted.size(), 2u);
        std::string described;
        for (const ForestLevel& level : budgeted)
            described += Forest::describeLevel(level) + " >= " +
                         std::to_string(int(Forest::heightForPixelCount(*asset, level.minPixelCount))) + " px; ";
        std::printf("budget 0.03: %s\n", described.c_str());
        EXPECT_NE(budgeted.front().technique, "impostor") << described;
        EXPECT_EQ(budgeted.back().minPixelCount, 0.0f);

        for (const float bad : {-0.1f, 1.5f, std::nanf("")})
            EXPECT_THROW(Forest::levelsForErrorBudget(*asset, costs, bad), Ogre::InvalidParametersException) << bad;
        try
        {
            Forest::levelsForErrorBudget(*tree.asset, costs, 0.03f);
            ADD_FAILURE() << "an asset without curves was accepted";
        }
        catch (const Ogre::InvalidParametersException& e)
        {
            EXPECT_NE(e.getDescription().find("oak.forest-test"), std::string::npos) << e.getDescription();
            EXPECT_NE(e.getDescription().find("no error curves"), std::string::npos) << e.getDescription();
        }

        // Drawn: a grid from near to far, one sample a pixel as the curves measured, against the
        // mesh supersampled 4x4: within the budget of the mesh's own error (and a margin for a
        // whole frame where the curves saw one tree), better than the cheapest, not a black picture.
        OffscreenRenderer& r = OgreEnvironment::renderer();
        const float h = treeHeight(tree.model);
        const CameraSpec view = look(glm::vec3(0.3f * h, 1.4f * h, 7.0f * h), glm::vec3(0.0f, 0.0f, -4.0f * h));
        std::vector<Image> pictures;
        Image supersampled;
        for (const std::vector<ForestLevel>* levels : {&reference, &budgeted, &cheapest})
        {
            Forest* forest = placeForest();
            forest->addSpecies(asset, *levels);
            forest->addInstances(grid(6, 1.6f * h));
            if (levels == &reference)
                supersampled = toImage(r.render(view, 320, 180, 4));
            pictures.push_back(toImage(r.render(view, 320, 180, 1)));
        }
        const double flipMesh = flipMean(supersampled, pictures[0]), flipBudgeted = flipMean(supersampled, pictures[1]),
                     flipCheapest = flipMean(supersampled, pictures[2]);
        std::printf("FLIP against the mesh 4x4: mesh %.4f, budget 0.03 %.4f, budget 1 %.4f\n", flipMesh, flipBudgeted,
                    flipCheapest);
        EXPECT_GT(treeCoverage(pictures[1], BACKGROUND), 0.15);
        EXPECT_LT(flipBudgeted, flipMesh + 0.03 + 0.01);
        EXPECT_LT(flipBudgeted + 0.02, flipCheapest);
        writePng(OgreEnvironment::outDir() + "/forest-budgets.png", sideBySide(pictures));
        compareWithGolden(pictures[1], "forest-budget", 0.03);
    }
}

namespace TreeLod
{
    TEST(Forest, budgetedSpeciesReplanInPlaceForAnErrorAFrameAndAShadowBudget)
    {
        const TreeAssetPtr asset = oakWithCurves();
        const ForestTree& tree = oak();
        const std::vector<LevelCost> costs = fixedCosts(*asset);
        OffscreenRenderer& r = OgreEnvironment::renderer();
        const float h = treeHeight(tree.model);
        const CameraSpec view = look(glm::vec3(0.3f * h, 1.4f * h, 7.0f * h), glm::vec3(0.0f, 0.0f, -4.0f * h));
        const std::vector<ForestInstance> trees = grid(6, 1.6f * h);
        auto sameLevels = [](const std::vector<ForestLevel>& a, const std::vector<ForestLevel>& b) {
            return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](const auto& x, const auto& y) {
                       return x.technique == y.technique && x.techniqueLevel == y.techniqueLevel &&
                              x.lowRes == y.lowRes && x.minPixelCount == y.minPixelCount;
                   });
        };
        const std::vector<ForestLevel> planned = Forest::levelsForErrorBudget(*asset, costs, DEFAULT_ERROR_BUDGET);
        ASSERT_GE(planned.size(), 2u);

        // The same levels added as fixed: the picture a budgeted species must give. A frame budget
        // has nothing to plan there: the error budget stays.
        Forest* fixed = placeForest();
        fixed->addSpecies(asset, planned);
        fixed->addInstances(trees);
        EXPECT_FALSE(fixed->isBudgeted(0));
        EXPECT_EQ(fixed->getShadowLevels(0).size(), planned.size());
        const Image expected = toImage(r.render(view, 320, 180, 1));
        fixed->setFrameBudgetMs(1e-6f);
        r.render(view, 320, 180, 1);
        r.render(view, 320, 180, 1);
        EXPECT_EQ(fixed->getErrorBudget(), DEFAULT_ERROR_BUDGET);
        EXPECT_TRUE(sameLevels(fixed->getLevels(0), planned));

        Forest* forest = placeForest();
        EXPECT_EQ(forest->getErrorBudget(), DEFAULT_ERROR_BUDGET);
        EXPECT_EQ(forest->getShadowErrorBudget(), DEFAULT_SHADOW_ERROR_BUDGET);
        try
        {
            forest->addBudgetedSpecies(tree.asset, costs);
            ADD_FAILURE() << "an asset without curves was accepted";
        }
        catch (const Ogre::InvalidParametersException& e)
        {
            EXPECT_NE(e.getDescription().find("no error curves"), std::string::npos) << e.getDescription();
        }
        EXPECT_EQ(forest->getSpeciesCount(), 0u) << "nothing added";
        const std::uint32_t s = forest->addBudgetedSpecies(asset, costs);
        EXPECT_TRUE(forest->isBudgeted(s));
        EXPECT_TRUE(sameLevels(forest->getLevels(s), planned));
        forest->addInstances(trees);
        const Image first = toImage(r.render(view, 320, 180, 1));
        const std::vector<std::uint32_t> firstCounts = forest->getStats().levelCounts.at(s);
        // Not bit-identical in general: passes of one hash are ordered by address in Ogre's queue, and
        // the order decides ties of equal depth; a level drawn wrong differs by 100 times more.
        EXPECT_LT(flipMean(expected, first), 2e-4);
        EXPECT_GT(treeCoverage(first, BACKGROUND), 0.15);

        // 0: the reference everywhere; 1: the cheapest everywhere; back: the first picture again.
        forest->setErrorBudget(0.0f);
        ASSERT_EQ(forest->getLevels(s).size(), 1u);
        EXPECT_EQ(forest->getLevels(s)[0].technique, "mesh");
        const Image reference = toImage(r.render(view, 320, 180, 1));
        EXPECT_EQ(forest->getStats().levelCounts.at(s), (std::vector<std::uint32_t>{forest->getStats().visibleInstances}));
        forest->setErrorBudget(1.0f);
        ASSERT_EQ(forest->getLevels(s).size(), 1u);
        EXPECT_EQ(forest->getLevels(s)[0].technique, "impostor");
        const Image cheapest = toImage(r.render(view, 320, 180, 1));
        EXPECT_EQ(forest->getStats().levelCounts.at(s), (std::vector<std::uint32_t>{forest->getStats().visibleInstances}));
        forest->setErrorBudget(DEFAULT_ERROR_BUDGET);
        EXPECT_TRUE(sameLevels(forest->getLevels(s), planned));
        const Image again = toImage(r.render(view, 320, 180, 1));
        EXPECT_EQ(forest->getStats().levelCounts.at(s), firstCounts);
        EXPECT_LT(flipMean(expected, again), 2e-4) << "levels, buckets and hysteresis as a new Forest's";
        EXPECT_GT(flipMean(reference, cheapest), 0.02);
        writePng(OgreEnvironment::outDir() + "/forest-replanned.png", sideBySide({reference, again, cheapest}));

        for (const float bad : {std::nanf(""), -0.1f, 1.5f})
        {
            EXPECT_THROW(forest->setErrorBudget(bad), Ogre::InvalidParametersException) << bad;
            EXPECT_THROW(forest->setShadowErrorBudget(bad), Ogre::InvalidParametersException) << bad;
        }
        for (const float bad : {std::nanf(""), -1.0f, INFINITY})
            EXPECT_THROW(forest->setFrameBudgetMs(bad), Ogre::InvalidParametersException) << bad;
        EXPECT_EQ(forest->getErrorBudget(), DEFAULT_ERROR_BUDGET) << "refused budgets change nothing";

        // A frame budget nothing fits: the cheapest step, taken the viewer frame after a measurement.
        forest->setFrameBudgetMs(1e-6f);
        r.render(view, 160, 90, 1);
        EXPECT_GT(forest->getStats().predictedMilliseconds, 0.0);
        r.render(view, 160, 90, 1);
        EXPECT_EQ(forest->getErrorBudget(), frameBudgetLadder().back());
        EXPECT_EQ(forest->getLevels(s).back().technique, "impostor");
        // One everything fits: the reference; its prediction, the mesh's fixed cost (2 ms at 16 px,
        // growing with the height) summed over the 36 trees.
        forest->setFrameBudgetMs(1e6f);
        for (unsigned f = 0; f < Forest::FRAME_BUDGET_INTERVAL + 2; ++f)
            r.render(view, 160, 90, 1);
        EXPECT_EQ(forest->getErrorBudget(), 0.0f);
        EXPECT_EQ(forest->getLevels(s).size(), 1u);
        const double meshMs = forest->getStats().predictedMilliseconds;
        EXPECT_GT(meshMs, 36.0 * 2.0);
        EXPECT_LT(meshMs, 36.0 * 64.0);
        // Measured frames reported at 4x the model: the controller scales its predictions by the
        // running ratio and leaves the reference, which the model alone keeps.
        forest->setFrameBudgetMs(float(2.0 * meshMs));
        for (unsigned f = 0; f < Forest::FRAME_BUDGET_INTERVAL + 2; ++f)
            r.render(view, 160, 90, 1);
        EXPECT_EQ(forest->getErrorBudget(), 0.0f) << "the model alone: the reference fits";
        EXPECT_EQ(forest->getFrameTimeRatio(), 1.0);
        for (unsigned f = 0; f < 3 * Forest::FRAME_BUDGET_INTERVAL + 1; ++f)
        {
            r.render(view, 160, 90, 1);
            forest->notifyFrameTime(float(4.0 * meshMs));
            forest->notifyFrameTime(std::nanf("")); // ignored
        }
        EXPECT_GT(forest->getFrameTimeRatio(), 1.5);
        EXPECT_GT(forest->getErrorBudget(), 0.0f) << "measured frames 4x the model: a coarser step";
        // Half of that: a step predicted within it, coarser than the reference.
        forest->setFrameBudgetMs(float(0.5 * meshMs));
        for (unsigned f = 0; f < 2 * Forest::FRAME_BUDGET_INTERVAL + 1; ++f)
            r.render(view, 160, 90, 1);
        EXPECT_GT(forest->getErrorBudget(), 0.0f);
        EXPECT_LE(forest->getStats().predictedMilliseconds, 0.5 * meshMs);
        // Off: the error budget set last.
        forest->setFrameBudgetMs(0.0f);
        EXPECT_EQ(forest->getErrorBudget(), DEFAULT_ERROR_BUDGET);
        EXPECT_TRUE(sameLevels(forest->getLevels(s), planned));

        // Shadow casters: their own budget picks coarser levels for them; the view keeps its own.
        forest->setShadowErrorBudget(1.0f);
        const std::uint32_t last = std::uint32_t(planned.size() - 1);
        EXPECT_EQ(forest->getShadowLevels(s), std::vector<std::uint32_t>(planned.size(), last));
        r.setShadows(true, 1024);
        const Image coarseCasters = toImage(r.render(view, 320, 180, 1));
        const std::vector<std::uint32_t> viewCounts = forest->getStats().levelCounts.at(s);
        forest->setShadowErrorBudget(0.0f);
        for (std::uint32_t l = 0; l < planned.size(); ++l)
            EXPECT_GE(forest->getShadowLevels(s)[l], l) << "never finer than the view";
        const Image viewCasters = toImage(r.render(view, 320, 180, 1));
        const Image viewCastersAgain = toImage(r.render(view, 320, 180, 1));
        // Re-planned while the shadow camera has buckets of its own: they move with the view's.
        forest->setErrorBudget(0.05f);
        const Image coarserView = toImage(r.render(view, 320, 180, 1));
        forest->setErrorBudget(DEFAULT_ERROR_BUDGET);
        const Image replannedCasters = toImage(r.render(view, 320, 180, 1));
        EXPECT_LT(flipMean(viewCasters, replannedCasters), 2e-4);
        EXPECT_GT(treeCoverage(coarserView, BACKGROUND), 0.15);
        r.setShadows(false);
        EXPECT_EQ(forest->getStats().levelCounts.at(s), viewCounts);
        const double noise = flipMean(viewCasters, viewCastersAgain), casters = flipMean(viewCasters, coarseCasters);
        std::printf("shadow error budget 1 vs 0: FLIP %.5f (the same frame twice: %.5f)\n", casters, noise);
        EXPECT_GT(casters, 0.002);
        EXPECT_GT(casters, 5.0 * noise);
        EXPECT_GT(treeCoverage(coarseCasters, BACKGROUND), 0.15);
        writePng(OgreEnvironment::outDir() + "/forest-shadow-budget.png", sideBySide({viewCasters, coarseCasters}));
        // Bound under half the casters' difference: the view's casters in their place fail it.
        compareWithGolden(coarseCasters, "forest-shadow-budget", 0.005);

        // A frame budget on a Forest whose error budget is off the ladder (never set: the default
        // is on it; 0.045 is not): the controller's first choice is taken.
        for (const float start : {-1.0f, 0.045f})
        {
            Forest* other = placeForest();
            if (start >= 0.0f)
                other->setErrorBudget(start);
            other->addBudgetedSpecies(asset, costs);
            other->addInstances(trees);
            other->setFrameBudgetMs(1e6f);
            r.render(view, 160, 90, 1);
            r.render(view, 160, 90, 1);
            EXPECT_EQ(other->getErrorBudget(), 0.0f) << "start " << start;
        }
    }
}

namespace TreeLod
{
    TEST(Forest, meshLodBiasActsAsEntitysOnEveryInstance)
    {
        // setMeshLodBias's factor is setLodBias (the Forest's factor, with the camera's); its
        // detail indices clamp every instance's level.
        const ForestTree& tree = oak();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        const float h = treeHeight(tree.model);
        std::vector<ForestLevel> levels;
        Forest* forest = autoBandsGrid(tree, levels);
        ASSERT_GE(levels.size(), 3u);
        const std::size_t last = levels.size() - 1;
        const CameraSpec mid = look(glm::vec3(0.0f, 3.0f * h, 10.0f * h), glm::vec3(0.0f, 0.3f * h, 0.0f));
        r.render(mid, 256, 192, 1);
        const double plain = meanLevel(*forest);
        forest->setMeshLodBias(4.0f);
        EXPECT_FLOAT_EQ(forest->getLodBias(), 4.0f);
        r.render(mid, 256, 192, 1);
        const double finer = meanLevel(*forest);
        forest->setMeshLodBias(1.0f);
        r.setLodBias(4.0f);
        r.render(mid, 256, 192, 1);
        r.setLodBias(1.0f);
        EXPECT_DOUBLE_EQ(meanLevel(*forest), finer) << "the camera's bias 4 acts as factor 4";
        forest->setMeshLodBias(0.25f);
        r.render(mid, 256, 192, 1);
        const double coarser = meanLevel(*forest);
        std::printf("mean level: factor 1 %.2f, 4 %.2f, 0.25 %.2f\n", plain, finer, coarser);
        EXPECT_LT(finer, plain);
        EXPECT_GT(coarser, plain);

        // From 10 km every tree draws the last level; minDetailIndex 1 stops them at level 1,
        // and maxDetailIndex 1 keeps them from level 0 close up.
        const CameraSpec distant = look(glm::vec3(0.0f, 200.0f, 10000.0f), glm::vec3(0.0f));
        forest->setMeshLodBias(1.0f, 0, 1);
        r.render(distant, 96, 96, 1);
        EXPECT_EQ(forest->getStats().levelCounts[0][1], forest->getStats().visibleInstances);
        EXPECT_GT(forest->getStats().visibleInstances, 0u);
        forest->setMeshLodBias(1e4f, 1, 99);
        r.render(mid, 256, 192, 1);
        EXPECT_EQ(forest->getStats().levelCounts[0][0], 0u);
        EXPECT_EQ(forest->getStats().levelCounts[0][1], forest->getStats().visibleInstances);
        forest->setMeshLodBias(1.0f);
        r.render(distant, 96, 96, 1);
        EXPECT_EQ(forest->getStats().levelCounts[0][last], forest->getStats().visibleInstances);
    }
}
