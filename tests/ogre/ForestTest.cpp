// Forest through Plugin_TreeLod: the factory, render queue group and query flags; the instanced
// draws against the same trees as separate objects (Entity, FoliageLodTree, BillboardCloudTree under
// SceneNodes: the test of the INSTANCED vertex programs' rotation, scale and normals); the quad
// level; culling and level counts against ForestInstances::cull; LoD at 10 km, inside a crown, with
// bias and frozen; bad input; two species of one asset, one instance, 20,000 quads and 1,000,000 in
// one draw; residency within an upload budget; camera states freed with their cameras; the mesh
// level's LoD bias. Shadows, level plans and floors have files of their own.
#include "ForestTestSupport.h"

namespace TreeLod
{
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
        forest->setOcclusion(false); // compared with a cull that does not estimate it
        // Standing inside the forest, looking along -Z: the trees behind are not drawn.
        const glm::vec3 eye(0.0f, 0.5f * h, 0.0f);
        const CameraSpec view = look(eye, eye + glm::vec3(0.3f, -0.05f, -1.0f), 60.0f);
        const int width = 160, height = 120;
        r.render(view, width, height, 1);
        const ForestStats& stats = forest->getStats();

        ForestVisibility visibility;
        ASSERT_TRUE(forest->getInstances()
                        .cull(CullCamera::fromSpec(view, float(width), float(height)), 1.0f, visibility,
                              forest->getLodHysteresis(), forest->getLodTransition())
                        .ok());
        EXPECT_EQ(stats.instances, 144u);
        EXPECT_EQ(stats.visibleInstances, visibility.getVisibleCount());
        EXPECT_GT(stats.visibleInstances, 10u);
        EXPECT_LT(stats.visibleInstances, 100u) << "about half the forest is behind the camera";
        for (const ForestBucket& bucket : visibility.getBuckets())
            EXPECT_EQ(stats.levelCounts.at(bucket.kind).at(bucket.level), bucket.count) << "level " << bucket.level;
        for (std::uint32_t v = 0; v < visibility.getDrawCount(); ++v)
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

    TEST(Forest, treesHiddenBehindTreesAreNotDrawnAndThePictureStays)
    {
        // Looking into a dense wood from its edge, level with the crowns: most trees stand behind
        // others. With occlusion the hidden ones are not drawn; the picture is what it was.
        const ForestTree& tree = oak();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        const float h = treeHeight(tree.model);
        const glm::vec3 eye(0.0f, 0.5f * h, 8.0f * h);
        const CameraSpec view = look(eye, glm::vec3(0.0f, 0.45f * h, 0.0f), 50.0f);
        Forest* forest = placeForest();
        EXPECT_TRUE(forest->getOcclusion()) << "on by default";
        forest->addSpecies(tree.asset, {ForestLevel{"mesh", 0, false, 0.0f}});
        forest->addInstances(grid(20, 0.7f * h));
        const Image on = toImage(r.render(view, 256, 192, 1));
        const ForestStats occluded = forest->getStats();
        forest->setOcclusion(false);
        const Image off = toImage(r.render(view, 256, 192, 1));
        const ForestStats all = forest->getStats();
        const double error = flipMean(off, on);
        std::printf("occlusion: %u of %u trees in view drawn, %u hidden; triangles %llu of %llu; FLIP %.5f\n",
                    occluded.visibleInstances, all.visibleInstances, occluded.occludedInstances,
                    static_cast<unsigned long long>(occluded.triangles), static_cast<unsigned long long>(all.triangles),
                    error);
        writePng(OgreEnvironment::outDir() + "/forest-occlusion-on-off.png", sideBySide({on, off}));
        EXPECT_EQ(all.occludedInstances, 0u);
        EXPECT_EQ(occluded.visibleInstances + occluded.occludedInstances, all.visibleInstances);
        EXPECT_GT(occluded.occludedInstances, all.visibleInstances / 4) << "most of the wood is behind its edge";
        EXPECT_LT(occluded.triangles, all.triangles);
        EXPECT_GT(treeCoverage(on, BACKGROUND), 0.3);
        EXPECT_LT(error, 0.01) << "a hidden tree drew visible pixels";
        compareWithGolden(on, "forest-occlusion", 0.02);
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
        EXPECT_GT(forest->getStats().levelSwitches, 0u) << "camera bias 8, then 1";
        r.render(mid, 256, 192, 1);
        EXPECT_EQ(forest->getStats().levelSwitches, 0u) << "the same view twice";
        const std::vector<std::uint32_t> before = flatCounts(*forest);
        forest->setLodFrozen(true);
        const CameraSpec back = look(glm::vec3(0.0f, 4.0f * h, 30.0f * h), glm::vec3(0.0f, 0.3f * h, 0.0f));
        r.render(back, 256, 192, 1);
        EXPECT_EQ(flatCounts(*forest), before);
        EXPECT_EQ(forest->getStats().levelSwitches, 0u) << "frozen";
        forest->setLodFrozen(false);
        r.render(back, 256, 192, 1);
        const std::vector<std::uint32_t> after = flatCounts(*forest);
        EXPECT_NE(after, before) << "unfrozen, the far view drops detail";
        EXPECT_EQ(forest->getStats().visibleInstances, 25u);
        // The switches are the trees that changed level: at least the change of the histogram.
        std::uint32_t moved = 0;
        for (std::size_t l = 0; l < after.size(); ++l)
            moved += after[l] > before[l] ? after[l] - before[l] : 0u;
        EXPECT_GE(forest->getStats().levelSwitches, moved);
        EXPECT_GT(forest->getStats().levelSwitches, 0u);
        EXPECT_LE(forest->getStats().levelSwitches, 25u);
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
        // The resources of the resident levels; a level that adds none (a bark LoD split of a level
        // drawn already: the mesh holds all its LoD levels) uploads nothing and takes no budget.
        auto heldResources = [&] {
            std::set<const void*> held;
            for (std::uint32_t l = 0; l <= last; ++l)
                if (lazy->isResident(0, l))
                    for (const ForestGpuResource& resource : lazy->getGpuResources(0, l))
                        held.insert(resource.handle.get());
            return held;
        };
        while (lazy->getStats().pendingLevels > 0 && frames < 40)
        {
            const std::set<const void*> before = heldResources();
            std::vector<bool> wasResident;
            for (std::uint32_t l = 0; l <= last; ++l)
                wasResident.push_back(lazy->isResident(0, l));
            r.render(view, 256, 192, 1);
            ++frames;
            std::uint32_t uploading = 0; // levels built this frame that added resources
            for (std::uint32_t l = 0; l <= last; ++l)
                if (!wasResident[l] && lazy->isResident(0, l))
                {
                    bool added = false;
                    for (const ForestGpuResource& resource : lazy->getGpuResources(0, l))
                        added = added || before.count(resource.handle.get()) == 0;
                    uploading += added ? 1 : 0;
                }
            EXPECT_LE(uploading, 1u);
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
