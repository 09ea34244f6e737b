// The volumetric octree tree through Plugin_TreeLod: a VolumeOctreeTree made by its factory draws
// what the CPU twin (renderVolumeOctree) draws, pixel for pixel within FLIP bounds, at a forced
// level and at the level its distance planes choose; nearer trees get finer levels and the camera
// LoD bias moves them; the view octant reorders the cells; bad parameters and a package without
// the chunk are named; a golden image of the oak. As a Forest level: each instance draws what a
// VolumeOctreeTree placed like it draws, trees blend far to near, levels follow screen size, the
// trees cast shadows.
#include "OgreTestSupport.h"

#include "TreeLod/CaptureSet.h"
#include "TreeLod/Forest.h"
#include "TreeLod/PackageWriter.h"
#include "TreeLod/TreeAssetManager.h"
#include "TreeLod/TreeGenerator.h"
#include "TreeLod/TreeViews.h"
#include "TreeLod/VolumeOctreeBaker.h"
#include "TreeLod/VolumeOctreeTree.h"

#include <OgreEntity.h>
#include <OgreMeshManager.h>
#include <OgreSceneManager.h>

namespace TreeLod::VolumeOctreeTreeTests
{
    namespace
    {
        struct BakedOak
        {
            TreeModel model;
            VolumeOctreeData data;
            TreeAssetPtr asset;
        };

        /// A generated oak photographed by 16 cameras and reconstructed in 6 levels.
        const BakedOak& oak()
        {
            return OgreEnvironment::keep<BakedOak>("volume-octree.oak", [] {
                BakedOak t;
                GeneratorOptions generator;
                generator.leafCount = 1500;
                generator.textureSize = 64;
                Result<TreeModel> model = generateTree(generator);
                EXPECT_TRUE(model.ok());
                t.model = std::move(model.value());
                const std::vector<std::uint8_t> bytes = cachedPackage("volume-octree", "oak", [&] {
                    CaptureSynthesisOptions capture;
                    capture.cameraCount = 16;
                    capture.resolution = 128;
                    capture.samplesPerPixel = 1;
                    VolumeOctreeOptions options;
                    options.levelCount = 6;
                    options.quantisation.colourCodebookSize = 256;
                    options.quantisation.alphaCodebookSize = 256;
                    PackageWriter writer;
                    Result<void> added = addVolumeOctreeChunk(writer, t.model, capture, options, "oak");
                    EXPECT_TRUE(added.ok()) << (added.ok() ? "" : added.error().message());
                    return added.ok() ? writer.toBytes() : std::vector<std::uint8_t>();
                });
                t.asset = TreeAssetManager::getSingleton().loadFromBytes("oak.volume-octree-test", Ogre::RGN_DEFAULT,
                                                                         bytes);
                t.data = VolumeOctreeResources::of(*t.asset).getData();
                return t;
            });
        }

        const glm::vec3 BACKGROUND = LightingSpec().background;

        struct Drawn
        {
            Image image;
            std::uint32_t activeLevel = 0;
            std::size_t cells = 0;
        };

        Drawn renderTree(const CameraSpec& camera, int size, const Ogre::NameValuePairList& extra = {},
                         float lodBias = 1.0f)
        {
            const BakedOak& t = oak();
            OffscreenRenderer& r = OgreEnvironment::renderer();
            r.clearContent();
            r.setLodBias(lodBias);
            Ogre::NameValuePairList params = {{"asset", t.asset->getName()}, {"group", t.asset->getGroup()}};
            params.insert(extra.begin(), extra.end());
            auto* tree = static_cast<VolumeOctreeTree*>(r.getSceneManager().createMovableObject(
                "volume", VolumeOctreeTreeFactory::FACTORY_TYPE_NAME, &params));
            r.getContentNode().attachObject(tree);
            Drawn d;
            d.image = toImage(r.render(camera, size, size, 1));
            d.activeLevel = tree->getActiveLevel();
            d.cells = tree->getDrawnCellCount();
            r.clearContent();
            r.setLodBias(1.0f);
            return d;
        }

        Image twin(const CameraSpec& camera, int size, int level)
        {
            VolumeOctreeRenderOptions o;
            o.width = o.height = size;
            o.activeLevel = level;
            o.background = BACKGROUND;
            Image image = renderVolumeOctree(oak().data, volumeOctreeAtlasSource(oak().data), camera, o);
            // 8 bits a channel, as the GPU's frame (float against 8-bit sky alone costs FLIP ~0.03).
            for (glm::vec4& p : image.pixels)
                p = glm::round(p * 255.0f) / 255.0f;
            return image;
        }

        /// FLIP of `test` against `reference` over the square around the tree in either.
        double boxFlip(const Image& reference, const Image& test)
        {
            const Crop crop = cropAround(unite(treeExtent(reference), treeExtent(test)), reference.width,
                                         reference.height);
            return flipMean(cropImage(reference, crop), cropImage(test, crop));
        }

        /// A tree placed in the content node: position, rotation about +Y (radians), uniform scale.
        struct Placed
        {
            glm::vec3 position{0.0f};
            float rotation = 0.0f;
            float scale = 1.0f;
        };

        /// `trees` as VolumeOctreeTrees with `params`, each on its own node; tree `early` (if any) in
        /// a render queue before the others'.
        void placeObjects(const std::vector<Placed>& trees, const Ogre::NameValuePairList& extra = {},
                          std::size_t early = std::size_t(-1))
        {
            OffscreenRenderer& r = OgreEnvironment::renderer();
            Ogre::NameValuePairList params = {{"asset", oak().asset->getName()}, {"group", oak().asset->getGroup()}};
            params.insert(extra.begin(), extra.end());
            for (std::size_t i = 0; i < trees.size(); ++i)
            {
                Ogre::MovableObject* tree = r.getSceneManager().createMovableObject(
                    "volume" + std::to_string(i), VolumeOctreeTreeFactory::FACTORY_TYPE_NAME, &params);
                if (i == early)
                    tree->setRenderQueueGroup(Ogre::RENDER_QUEUE_MAIN - 1);
                Ogre::SceneNode* node = r.getContentNode().createChildSceneNode(
                    Ogre::Vector3(trees[i].position.x, trees[i].position.y, trees[i].position.z),
                    Ogre::Quaternion(Ogre::Radian(trees[i].rotation), Ogre::Vector3::UNIT_Y));
                node->setScale(Ogre::Vector3(trees[i].scale));
                node->attachObject(tree);
            }
        }

        /// `trees` as one Forest species of `levels`.
        Forest& placeForest(const std::vector<Placed>& trees, const std::vector<ForestLevel>& levels)
        {
            OffscreenRenderer& r = OgreEnvironment::renderer();
            auto* forest = static_cast<Forest*>(r.getSceneManager().createMovableObject("volume-forest", "Forest"));
            forest->setLodHysteresis(0.0f);
            forest->addSpecies(oak().asset, levels);
            std::vector<ForestInstance> instances;
            for (const Placed& t : trees)
                instances.push_back(ForestInstance{t.position, t.rotation, t.scale, 0});
            forest->addInstances(instances);
            r.getContentNode().attachObject(forest);
            return *forest;
        }

        Image renderContent(const CameraSpec& camera, int width, int height)
        {
            OffscreenRenderer& r = OgreEnvironment::renderer();
            Image image = toImage(r.render(camera, width, height, 1));
            r.clearContent();
            return image;
        }

        /// Pixels that differ from the background.
        std::size_t covered(const Image& image)
        {
            std::size_t n = 0;
            for (const glm::vec4& p : image.pixels)
                n += glm::length(glm::vec3(p) - BACKGROUND) > 2.0f / 255.0f ? 1 : 0;
            return n;
        }
    }

    TEST(VolumeOctreeTree, drawsWhatTheCpuTwinDraws)
    {
        OgreEnvironment::renderer().setShadows(false);
        const BakedOak& t = oak();
        const CameraSpec camera = CameraSpec::framing(t.model.boundsMin, t.model.boundsMax, 30.0f, 15.0f, 1.0f);
        std::vector<Image> strip;
        for (int level : {2, 4, 5})
        {
            const Drawn gpu = renderTree(camera, 160, {{"level", std::to_string(level)}});
            const Image cpu = twin(camera, 160, level);
            EXPECT_EQ(gpu.activeLevel, std::uint32_t(level));
            const double error = boxFlip(cpu, gpu.image);
            EXPECT_LT(error, 0.03) << "level " << level;
            // Not a blank frame: the tree covers a good part of it, on both.
            EXPECT_GT(covered(gpu.image), std::size_t(160 * 160 / 8)) << "level " << level;
            // The GPU rounds each blend to 8 bits: faint edges of the coarse levels differ a little.
            EXPECT_NEAR(double(covered(gpu.image)) / double(covered(cpu)), 1.0, 0.1) << "level " << level;
            std::printf("level %d: tree-box FLIP %.4f against the CPU twin\n", level, error);
            strip.push_back(cpu);
            strip.push_back(gpu.image);
        }
        writePng(OgreEnvironment::outDir() + "/volume-octree-twin.png", sideBySide(strip));
    }

    TEST(VolumeOctreeTree, distancePlanesPickTheLevel)
    {
        OgreEnvironment::renderer().setShadows(false);
        const BakedOak& t = oak();
        const CameraSpec near = CameraSpec::framing(t.model.boundsMin, t.model.boundsMax, 0.0f, 10.0f, 0.8f);
        const CameraSpec far = CameraSpec::framing(t.model.boundsMin, t.model.boundsMax, 0.0f, 10.0f, 8.0f);
        const Drawn n = renderTree(near, 160), f = renderTree(far, 160);
        EXPECT_GT(n.activeLevel, f.activeLevel);
        EXPECT_GT(n.cells, f.cells);
        // The chosen level draws as the twin draws it, the near camera mixing two levels by its plane.
        EXPECT_LT(boxFlip(twin(near, 160, -1), n.image), 0.03);
        EXPECT_LT(boxFlip(twin(far, 160, -1), f.image), 0.03);
        // A level off is a visibly different picture: the bound above can fail.
        EXPECT_GT(boxFlip(twin(near, 160, int(n.activeLevel) - 1), n.image), 0.05);
        // A lower LoD bias draws coarser.
        const Drawn coarse = renderTree(near, 160, {}, 0.25f);
        EXPECT_LT(coarse.activeLevel, n.activeLevel);
        compareWithGolden(n.image, "oak-volume-octree", 0.02);
        writePng(OgreEnvironment::outDir() + "/volume-octree-near-far.png", sideBySide({n.image, f.image, coarse.image}));
    }

    TEST(VolumeOctreeTree, everyViewOctantDrawsBackToFront)
    {
        // Eight cells of level 1, each an even colour at alpha 0.8. Looking along a diagonal of the
        // cube, the corner cell nearest the camera and the opposite one cover the centre pixel:
        // the near colour must lie over the far one, from every octant.
        const glm::vec3 colours[8] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0},
                                      {1, 0, 1}, {0, 1, 1}, {1, 1, 1}, {0.5f, 0.25f, 0}};
        VolumeOctreeData d;
        d.levelCount = 2;
        d.origin = glm::vec3(-1.0f, 0.0f, -1.0f);
        d.size = 2.0f;
        d.cameraDirections = {glm::vec3(0.0f, 0.0f, 1.0f)};
        d.levelCellCounts = {1, 8};
        d.cells.push_back(volumeCellCode(0, 0, 0));
        d.slots.push_back({}); // the root draws nothing
        for (std::uint32_t k = 0; k < 8; ++k) // Morton order: x lowest
        {
            d.cells.push_back(volumeCellCode(k & 1, (k >> 1) & 1, k >> 2));
            d.slots.push_back({std::uint16_t(k), 0});
        }
        d.colourCodewords = 8;
        d.alphaCodewords = 1;
        d.atlas.name = "eight colours";
        d.atlas.width = 16;
        d.atlas.height = 8;
        d.atlas.mipCount = 1;
        d.atlas.data.assign(16 * 8 * 4, 0);
        for (std::uint32_t y = 0; y < 8; ++y)
            for (std::uint32_t x = 0; x < 16; ++x)
            {
                std::uint8_t* t = &d.atlas.data[(y * 16 + x) * 4];
                const glm::vec3& c = colours[(y / 4) * 4 + x / 4];
                t[0] = unitToByte(c.r);
                t[1] = unitToByte(c.g);
                t[2] = unitToByte(c.b);
                t[3] = 204;
            }
        ASSERT_TRUE(d.validate("eight cells"));
        PackageWriter writer;
        ASSERT_TRUE(addReferenceChunkIfMissing(writer, oak().model, "eight cells", {}).ok());
        ASSERT_TRUE(writer.addChunk(VOLUME_OCTREE_CHUNK, 0, VOLUME_OCTREE_CHUNK_FORMAT_VERSION,
                                    encodeVolumeOctreeChunk(d)).ok());
        TreeAssetPtr asset =
            TreeAssetManager::getSingleton().loadFromBytes("eight.volume-octree-test", Ogre::RGN_DEFAULT, writer.toBytes());

        OgreEnvironment::renderer().setShadows(false);
        OffscreenRenderer& r = OgreEnvironment::renderer();
        for (std::uint32_t corner = 0; corner < 8; ++corner)
        {
            const glm::vec3 sign(corner & 1 ? 1.0f : -1.0f, (corner >> 1) & 1 ? 1.0f : -1.0f, corner >> 2 ? 1.0f : -1.0f);
            CameraSpec camera;
            camera.target = glm::vec3(0.0f, 1.0f, 0.0f);
            camera.position = camera.target + 6.0f * glm::normalize(sign);
            camera.up = std::abs(sign.y) > 0.0f ? glm::vec3(1.0f, 0.0f, 0.0f) : camera.up;
            r.clearContent();
            const Ogre::NameValuePairList params = {{"asset", asset->getName()}, {"group", asset->getGroup()},
                                                    {"level", "1"}, {"lodPixels", "0.001"}};
            r.getContentNode().attachObject(r.getSceneManager().createMovableObject(
                "eight", VolumeOctreeTreeFactory::FACTORY_TYPE_NAME, &params));
            const Image image = toImage(r.render(camera, 32, 32, 1));
            r.clearContent();
            const glm::vec3 near = colours[corner], far = colours[7 - corner];
            const glm::vec3 expected = 0.8f * near + 0.2f * (0.8f * far + 0.2f * BACKGROUND);
            const glm::vec3 centre(image.at(16, 16));
            EXPECT_LT(glm::length(centre - expected), 0.03f)
                << "corner " << corner << ": centre (" << centre.r << ", " << centre.g << ", " << centre.b
                << "), expected (" << expected.r << ", " << expected.g << ", " << expected.b << ")";
        }
        TreeAssetManager::getSingleton().remove(asset);
    }

    TEST(VolumeOctreeTree, castsItsShadowOnTheGround)
    {
        // The oak on a white ground under the sun, casting and not casting: the ground darkens
        // where the crown's billboards (hashed alpha test) block the light.
        const BakedOak& t = oak();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        const float h = t.model.boundsMax.y - t.model.boundsMin.y;
        CameraSpec camera;
        camera.position = glm::vec3(0.0f, 1.5f * h, 3.0f * h);
        camera.target = glm::vec3(0.0f, 0.4f * h, 0.0f);
        camera.nearClip = 0.1f * h;
        camera.farClip = 20.0f * h;
        Ogre::MeshPtr plane = Ogre::MeshManager::getSingleton().getByName("volume-test-ground", Ogre::RGN_DEFAULT);
        if (!plane)
            plane = Ogre::MeshManager::getSingleton().createPlane(
                "volume-test-ground", Ogre::RGN_DEFAULT, Ogre::Plane(Ogre::Vector3::UNIT_Y, 0.0f), 8.0f * h, 8.0f * h,
                1, 1, true, 1, 1.0f, 1.0f, Ogre::Vector3::NEGATIVE_UNIT_Z);
        const auto render = [&](bool casts) {
            r.clearContent();
            r.setShadows(true, 1024, ShadowCamera::Focused);
            const Ogre::NameValuePairList params = {{"asset", t.asset->getName()}, {"group", t.asset->getGroup()}};
            Ogre::MovableObject* tree =
                r.getSceneManager().createMovableObject("volume", VolumeOctreeTreeFactory::FACTORY_TYPE_NAME, &params);
            tree->setCastShadows(casts);
            r.getContentNode().attachObject(tree);
            Ogre::Entity* ground = r.getSceneManager().createEntity(plane);
            ground->setMaterialName("TreeLod/BarkShadowed");
            ground->setCastShadows(false);
            r.getContentNode().createChildSceneNode()->attachObject(ground);
            Image image = toImage(r.render(camera, 200, 160, 1));
            r.clearContent();
            r.setShadows(false);
            return image;
        };
        const Image lit = render(false), shadowed = render(true);
        auto luminance = [](const glm::vec4& p) { return 0.2126 * p.r + 0.7152 * p.g + 0.0722 * p.b; };
        std::size_t groundShadow = 0, changed = 0;
        for (std::size_t i = 0; i < lit.pixels.size(); ++i)
        {
            groundShadow += luminance(lit.pixels[i]) > 0.9 && luminance(shadowed.pixels[i]) < 0.8;
            changed += glm::length(glm::vec3(lit.pixels[i]) - glm::vec3(shadowed.pixels[i])) > 0.02f;
        }
        std::printf("%zu ground pixels in the tree's shadow, %zu pixels changed\n", groundShadow, changed);
        EXPECT_GT(groundShadow, 300u);
        writePng(OgreEnvironment::outDir() + "/volume-octree-shadows.png", sideBySide({lit, shadowed}));
        compareWithGolden(shadowed, "oak-volume-octree-shadows", 0.02);
    }

    TEST(VolumeOctreeTree, badParametersAndMissingChunkAreNamed)
    {
        OffscreenRenderer& r = OgreEnvironment::renderer();
        const BakedOak& t = oak();
        const Ogre::NameValuePairList params = {{"asset", t.asset->getName()}, {"group", t.asset->getGroup()},
                                                {"level", "6"}};
        try
        {
            r.getSceneManager().createMovableObject("bad", VolumeOctreeTreeFactory::FACTORY_TYPE_NAME, &params);
            FAIL() << "level 6 of 6 levels accepted";
        }
        catch (const Ogre::Exception& e)
        {
            EXPECT_NE(e.getFullDescription().find("not a level of the octree (6 levels)"), std::string::npos)
                << e.getFullDescription();
        }
        PackageWriter writer;
        ASSERT_TRUE(addReferenceChunkIfMissing(writer, t.model, "plain", {}).ok());
        TreeAssetPtr plain =
            TreeAssetManager::getSingleton().loadFromBytes("oak.plain-volume-test", Ogre::RGN_DEFAULT, writer.toBytes());
        const Ogre::NameValuePairList plainParams = {{"asset", plain->getName()}, {"group", plain->getGroup()}};
        try
        {
            r.getSceneManager().createMovableObject("missing", VolumeOctreeTreeFactory::FACTORY_TYPE_NAME, &plainParams);
            FAIL() << "a package without the chunk accepted";
        }
        catch (const Ogre::Exception& e)
        {
            EXPECT_NE(e.getFullDescription().find("volume-octree"), std::string::npos) << e.getFullDescription();
            EXPECT_NE(e.getFullDescription().find("oak.plain-volume-test"), std::string::npos)
                << e.getFullDescription();
        }
        TreeAssetManager::getSingleton().remove(plain);
    }

    TEST(VolumeOctreeTree, forestLevelDrawsWhatTheObjectDraws)
    {
        // One instance per Forest, turned and scaled, at a fixed level: its own view octant, camera
        // pair and distance plane, as a VolumeOctreeTree on a node placed alike.
        OgreEnvironment::renderer().setShadows(false);
        const BakedOak& t = oak();
        struct Case
        {
            std::uint32_t level;
            Placed tree;
            float distance; ///< of the camera, in framing distances
        };
        std::vector<Image> strip;
        for (const Case& c : {Case{4, Placed{}, 0.9f}, Case{5, Placed{glm::vec3(0.0f), 2.2f, 1.0f}, 1.6f},
                              Case{3, Placed{glm::vec3(1.0f, 0.0f, -2.0f), -0.7f, 1.5f}, 0.9f}})
        {
            const glm::vec3 lo = c.tree.position + c.tree.scale * t.model.boundsMin;
            const glm::vec3 hi = c.tree.position + c.tree.scale * t.model.boundsMax;
            const CameraSpec camera = CameraSpec::framing(lo, hi, 30.0f, 15.0f, c.distance);
            placeObjects({c.tree}, {{"level", std::to_string(c.level)}});
            const Image object = renderContent(camera, 160, 160);
            // Whether the level's distance plane cuts the crown here (level L - 1 behind it).
            placeObjects({c.tree}, {{"level", std::to_string(c.level)}, {"lodPixels", "0.001"}});
            const double planeShows = boxFlip(object, renderContent(camera, 160, 160));
            placeForest({c.tree}, {ForestLevel{VOLUME_OCTREE_CHUNK, c.level, false, 0.0f}});
            const Image forest = renderContent(camera, 160, 160);
            const double error = boxFlip(object, forest);
            std::printf("level %u: forest against object, tree-box FLIP %.4f (the plane changes %.4f)\n", c.level,
                        error, planeShows);
            EXPECT_LT(error, 0.003) << "level " << c.level;
            if (c.distance > 1.0f)
            {
                EXPECT_GT(planeShows, 0.01) << "the plane of level " << c.level << " misses the crown";
            }
            EXPECT_GT(covered(forest), std::size_t(160 * 160 / 16)) << "level " << c.level;
            strip.push_back(object);
            strip.push_back(forest);
        }
        writePng(OgreEnvironment::outDir() + "/volume-octree-forest-vs-object.png", sideBySide(strip));
    }

    TEST(VolumeOctreeTree, forestBlendsItsTreesFarToNear)
    {
        // Two trees one behind the other, seen from either side. The objects are sorted by Ogre
        // (one renderable each); the Forest draws both in one instanced draw, listed far to near,
        // whatever order it stores them in.
        OgreEnvironment::renderer().setShadows(false);
        const BakedOak& t = oak();
        const float h = t.model.boundsMax.y - t.model.boundsMin.y;
        const std::vector<Placed> trees = {Placed{glm::vec3(0.0f), 0.3f, 1.0f},
                                           Placed{glm::vec3(0.25f * h, 0.0f, -1.0f * h), 1.1f, 1.0f}};
        const Ogre::NameValuePairList level = {{"level", "4"}};
        std::vector<Image> strip;
        for (int side : {1, -1})
        {
            CameraSpec camera;
            camera.position = glm::vec3(0.3f * h, 0.5f * h, -0.5f * h + float(side) * 2.9f * h);
            camera.target = glm::vec3(0.3f * h, 0.45f * h, -0.5f * h - float(side) * 0.1f * h);
            camera.nearClip = 0.05f * h;
            camera.farClip = 20.0f * h;
            placeObjects(trees, level);
            const Image sorted = renderContent(camera, 200, 160);
            // The near tree in an earlier render queue: drawn first, the far one over it.
            placeObjects(trees, level, side > 0 ? 0 : 1);
            const Image wrong = renderContent(camera, 200, 160);
            placeForest(trees, {ForestLevel{VOLUME_OCTREE_CHUNK, 4, false, 0.0f}});
            const Image forest = renderContent(camera, 200, 160);
            const double error = boxFlip(sorted, forest), wrongError = boxFlip(sorted, wrong);
            std::printf("side %d: forest against sorted objects: FLIP %.4f; near tree drawn first: %.4f\n", side,
                        error, wrongError);
            EXPECT_LT(error, 0.003) << "side " << side;
            EXPECT_GT(wrongError, 3.0 * 0.003) << "side " << side; // the order shows: the bound can fail
            strip.insert(strip.end(), {sorted, forest, wrong});
        }
        writePng(OgreEnvironment::outDir() + "/volume-octree-forest-order.png", sideBySide(strip));
    }

    TEST(VolumeOctreeTree, forestLevelsFollowScreenSize)
    {
        // The technique's levels over all screen sizes: one per octree level, finest first, each
        // while a cell of it covers 4 pixels at the tree's centre. A near tree draws a finer level
        // than a far one, and never a finer one than a VolumeOctreeTree (nearest point) picks.
        OgreEnvironment::renderer().setShadows(false);
        const BakedOak& t = oak();
        const std::vector<ForestLevel> levels =
            Forest::levelsForBands(*t.asset, {ForestBand{VOLUME_OCTREE_CHUNK, 0.0f}});
        ASSERT_EQ(levels.size(), std::size_t(t.data.levelCount));
        for (std::size_t i = 0; i < levels.size(); ++i)
            EXPECT_EQ(levels[i].techniqueLevel, t.data.levelCount - 1 - i);
        const float h = t.model.boundsMax.y - t.model.boundsMin.y;
        const float expectedHeight = 4.0f * h / t.data.cellEdge(3);
        EXPECT_NEAR(Forest::heightForPixelCount(*t.asset, levels[t.data.levelCount - 1 - 3].minPixelCount),
                    expectedHeight, 1e-3f * expectedHeight);

        std::vector<std::uint32_t> drawn;
        for (float distance : {0.8f, 3.0f, 12.0f})
        {
            const CameraSpec camera = CameraSpec::framing(t.model.boundsMin, t.model.boundsMax, 0.0f, 10.0f, distance);
            placeObjects({Placed{}});
            OffscreenRenderer& r = OgreEnvironment::renderer();
            r.render(camera, 160, 160, 1);
            const std::uint32_t objectLevel =
                static_cast<VolumeOctreeTree*>(r.getSceneManager().getMovableObject("volume0", VolumeOctreeTreeFactory::FACTORY_TYPE_NAME))
                    ->getActiveLevel();
            r.clearContent();
            Forest& forest = placeForest({Placed{}}, levels);
            r.render(camera, 160, 160, 1);
            const std::vector<std::uint32_t>& counts = forest.getStats().levelCounts[0];
            const auto at = std::find(counts.begin(), counts.end(), 1u);
            ASSERT_NE(at, counts.end()) << "distance " << distance;
            const std::uint32_t level = levels[std::size_t(at - counts.begin())].techniqueLevel;
            std::printf("distance %.1f: forest level %u, object level %u\n", distance, level, objectLevel);
            EXPECT_LE(level, objectLevel);
            EXPECT_GE(level + 1, objectLevel);
            drawn.push_back(level);
            r.clearContent();
        }
        EXPECT_GT(drawn.front(), drawn.back());
    }

    TEST(VolumeOctreeTree, forestInsideTheCrownAndKilometresAway)
    {
        // Inside the crown the finest level fills the view; 5 km away the root cell alone.
        OgreEnvironment::renderer().setShadows(false);
        const BakedOak& t = oak();
        const std::vector<ForestLevel> levels =
            Forest::levelsForBands(*t.asset, {ForestBand{VOLUME_OCTREE_CHUNK, 0.0f}});
        const glm::vec3 centre = 0.5f * (t.model.boundsMin + t.model.boundsMax);
        CameraSpec inside;
        inside.position = centre + glm::vec3(0.0f, 0.1f, 0.5f);
        inside.target = centre + glm::vec3(0.0f, 0.1f, -1.0f);
        inside.nearClip = 0.01f;
        CameraSpec far = inside;
        far.position = centre + glm::vec3(0.0f, 0.0f, 5000.0f);
        far.target = centre;
        far.farClip = 10000.0f;
        for (const bool isInside : {true, false})
        {
            const CameraSpec& camera = isInside ? inside : far;
            Forest& forest = placeForest({Placed{}}, levels);
            OffscreenRenderer& r = OgreEnvironment::renderer();
            const Image image = toImage(r.render(camera, 96, 96, 1));
            const std::vector<std::uint32_t>& counts = forest.getStats().levelCounts[0];
            const auto at = std::find(counts.begin(), counts.end(), 1u);
            ASSERT_NE(at, counts.end());
            const std::uint32_t level = levels[std::size_t(at - counts.begin())].techniqueLevel;
            r.clearContent();
            if (isInside)
            {
                EXPECT_EQ(level, t.data.levelCount - 1);
                EXPECT_GT(covered(image), std::size_t(96 * 96 / 2));
            }
            else
            {
                EXPECT_EQ(level, 0u);
                EXPECT_LT(covered(image), std::size_t(4));
            }
        }
    }

    TEST(VolumeOctreeTree, forestOfOctreesGolden)
    {
        // Nine trees, turned and scaled, at the levels their screen sizes give, casting shadows on
        // a white ground (and not casting, to find the shadows).
        const BakedOak& t = oak();
        const float h = t.model.boundsMax.y - t.model.boundsMin.y;
        std::vector<Placed> trees;
        for (int i = 0; i < 9; ++i)
            trees.push_back(Placed{glm::vec3(float(i % 3 - 1) * 1.1f * h, 0.0f, float(i / 3 - 1) * 1.1f * h - 0.5f * h),
                                   0.7f * float(i), 0.8f + 0.05f * float(i)});
        CameraSpec camera;
        camera.position = glm::vec3(0.3f * h, 1.2f * h, 3.2f * h);
        camera.target = glm::vec3(0.0f, 0.3f * h, -0.5f * h);
        camera.nearClip = 0.05f * h;
        camera.farClip = 20.0f * h;
        Ogre::MeshPtr plane = Ogre::MeshManager::getSingleton().createPlane(
            "volume-forest-ground", Ogre::RGN_DEFAULT, Ogre::Plane(Ogre::Vector3::UNIT_Y, 0.0f), 8.0f * h, 8.0f * h, 1, 1,
            true, 1, 1.0f, 1.0f, Ogre::Vector3::NEGATIVE_UNIT_Z);
        OffscreenRenderer& r = OgreEnvironment::renderer();
        std::uint32_t levelsDrawn = 0, visible = 0;
        const auto render = [&](bool casts) {
            r.setShadows(true, 1024, ShadowCamera::Focused);
            Forest& forest =
                placeForest(trees, Forest::levelsForBands(*t.asset, {ForestBand{VOLUME_OCTREE_CHUNK, 0.0f}}));
            forest.setCastShadows(casts);
            Ogre::Entity* ground = r.getSceneManager().createEntity(plane);
            ground->setMaterialName("TreeLod/BarkShadowed");
            ground->setCastShadows(false);
            r.getContentNode().createChildSceneNode()->attachObject(ground);
            Image image = toImage(r.render(camera, 240, 180, 1));
            levelsDrawn = 0;
            for (std::uint32_t n : forest.getStats().levelCounts[0])
                levelsDrawn += n > 0 ? 1 : 0;
            visible = forest.getStats().visibleInstances;
            r.clearContent();
            r.setShadows(false);
            return image;
        };
        const Image lit = render(false), shadowed = render(true);
        Ogre::MeshManager::getSingleton().remove(plane);
        EXPECT_EQ(visible, 9u);
        EXPECT_GE(levelsDrawn, 2u); // near and far trees at different levels
        std::size_t groundShadow = 0;
        auto luminance = [](const glm::vec4& p) { return 0.2126 * p.r + 0.7152 * p.g + 0.0722 * p.b; };
        for (std::size_t i = 0; i < lit.pixels.size(); ++i)
            groundShadow += luminance(lit.pixels[i]) > 0.9 && luminance(shadowed.pixels[i]) < 0.8;
        std::printf("%u levels drawn, %zu ground pixels in the trees' shadows\n", levelsDrawn, groundShadow);
        EXPECT_GT(groundShadow, 1000u);
        writePng(OgreEnvironment::outDir() + "/volume-octree-forest-shadows.png", sideBySide({lit, shadowed}));
        compareWithGolden(shadowed, "forest-volume-octree", 0.02);
    }
}

namespace TreeLod::VolumeOctreeTreeTests
{
    TEST(VolumeOctreeTree, photographedTreeDrawsAsVolumeOctreeOnly)
    {
        // A package baked from photographs (no polygons, the capture's volume as bounds) draws as a
        // VolumeOctreeTree and as Forest levels; the mesh technique is refused naming the asset.
        OgreEnvironment::renderer().setShadows(false);
        GeneratorOptions generator;
        generator.leafCount = 300;
        generator.textureSize = 32;
        Result<TreeModel> model = generateTree(generator);
        ASSERT_TRUE(model.ok());
        CaptureSynthesisOptions synthesis;
        synthesis.cameraCount = 8;
        synthesis.resolution = 64;
        synthesis.samplesPerPixel = 1;
        Result<CaptureSet> capture = synthesiseCaptureSet(model.value(), synthesis, "photos");
        ASSERT_TRUE(capture.ok()) << capture.error().message();
        VolumeOctreeOptions options;
        options.levelCount = 4;
        options.quantisation.colourCodebookSize = 32;
        options.quantisation.alphaCodebookSize = 32;
        PackageWriter writer;
        Result<void> added = addVolumeOctreeChunk(writer, capture.value(), "photos", options, "photos");
        ASSERT_TRUE(added.ok()) << added.error().message();
        TreeAssetPtr asset =
            TreeAssetManager::getSingleton().loadFromBytes("photos.volume-octree-test", Ogre::RGN_DEFAULT, writer.toBytes());

        const std::vector<ForestLevel> candidates = Forest::getCandidateLevels(*asset);
        ASSERT_EQ(candidates.size(), std::size_t(4));
        for (const ForestLevel& level : candidates)
            EXPECT_EQ(level.technique, VOLUME_OCTREE_CHUNK);
        const auto refused = [&](const std::function<void()>& f, const std::vector<std::string>& needles) {
            try
            {
                f();
                ADD_FAILURE() << "accepted: " << needles.front();
            }
            catch (const Ogre::Exception& e)
            {
                for (const std::string& needle : needles)
                    EXPECT_NE(e.getFullDescription().find(needle), std::string::npos) << e.getFullDescription();
            }
        };
        refused([&] { Forest::levelsForBands(*asset, {ForestBand{"mesh", 0.0f}}); },
                {"photos.volume-octree-test", "nothing this technique draws"});
        refused([&] { asset->getReferenceMesh(); }, {"photos.volume-octree-test", "baked from photographs"});
        OffscreenRenderer& r = OgreEnvironment::renderer();
        auto* forest = static_cast<Forest*>(r.getSceneManager().createMovableObject("photo-forest", "Forest"));
        refused([&] { forest->addSpecies(asset, {ForestLevel{"mesh", 0, false, 0.0f}}); },
                {"photos.volume-octree-test", "baked from photographs", "technique 'mesh'"});
        r.getSceneManager().destroyMovableObject(forest);

        const glm::vec3 lo(capture->volumeMin), hi(capture->volumeMax);
        CameraSpec camera;
        camera.target = 0.5f * (lo + hi);
        camera.position = camera.target + glm::vec3(0.3f, 0.2f, 1.0f) * 2.0f * glm::length(hi - lo);
        const Ogre::NameValuePairList params = {{"asset", asset->getName()}, {"group", asset->getGroup()}};
        r.getContentNode().attachObject(r.getSceneManager().createMovableObject(
            "photo-tree", VolumeOctreeTreeFactory::FACTORY_TYPE_NAME, &params));
        const Image single = renderContent(camera, 96, 96);
        forest = static_cast<Forest*>(r.getSceneManager().createMovableObject("photo-forest", "Forest"));
        forest->setLodHysteresis(0.0f);
        forest->addSpecies(asset, Forest::levelsForBands(*asset, {ForestBand{VOLUME_OCTREE_CHUNK, 0.0f}}));
        forest->addInstances({ForestInstance{glm::vec3(0.0f), 0.0f, 1.0f, 0}});
        r.getContentNode().attachObject(forest);
        const Image forestImage = renderContent(camera, 96, 96);
        writePng(OgreEnvironment::outDir() + "/volume-octree-photographs.png", sideBySide({single, forestImage}));
        EXPECT_GT(covered(single), std::size_t(96 * 96 / 50));
        EXPECT_GT(covered(forestImage), std::size_t(96 * 96 / 50));
        EXPECT_LT(boxFlip(single, forestImage), 0.01);
        TreeAssetManager::getSingleton().remove(asset);
    }
}

namespace TreeLod::VolumeOctreeTreeTests
{
    TEST(VolumeOctreeTree, meshLodBiasActsAsEntitysOnTheActiveLevel)
    {
        // Detail index = levels from the finest: levelCount - 1 - active level.
        OgreEnvironment::renderer().setShadows(false);
        const BakedOak& t = oak();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        r.clearContent();
        Ogre::NameValuePairList params = {{"asset", t.asset->getName()}, {"group", t.asset->getGroup()}};
        auto* tree = static_cast<VolumeOctreeTree*>(r.getSceneManager().createMovableObject(
            "volume-bias", VolumeOctreeTreeFactory::FACTORY_TYPE_NAME, &params));
        r.getContentNode().attachObject(tree);
        std::vector<CameraSpec> views;
        for (const float distance : {0.5f, 1.0f, 2.0f, 4.0f, 8.0f, 16.0f})
            views.push_back(CameraSpec::framing(t.model.boundsMin, t.model.boundsMax, 0.0f, 10.0f, distance));
        MeshLodBiasProbe probe;
        probe.setBias = [&](Ogre::Real f, unsigned short max, unsigned short min) { tree->setMeshLodBias(f, max, min); };
        probe.index = [&] { return tree->getLevelCount() - 1 - tree->getActiveLevel(); };
        probe.render = [&](const CameraSpec& view) { r.render(view, 96, 96, 1); };
        probe.indexCount = tree->getLevelCount();
        expectMeshLodBiasLikeEntity(probe, views);
        r.clearContent();
    }

    TEST(VolumeOctreeTree, lodStrategyParameterNamesOgresStrategies)
    {
        OgreEnvironment::renderer().setShadows(false);
        const BakedOak& t = oak();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        VolumeOctreeTree* tree = nullptr;
        std::vector<CameraSpec> views;
        for (const float distance : {0.5f, 1.0f, 2.0f, 4.0f, 8.0f, 16.0f})
            views.push_back(CameraSpec::framing(t.model.boundsMin, t.model.boundsMax, 0.0f, 10.0f, distance));
        expectLodStrategyParameter(
            [&](const Ogre::NameValuePairList& extra) {
                static int serial = 0;
                r.clearContent();
                Ogre::NameValuePairList params = {{"asset", t.asset->getName()}, {"group", t.asset->getGroup()}};
                params.insert(extra.begin(), extra.end());
                tree = static_cast<VolumeOctreeTree*>(r.getSceneManager().createMovableObject(
                    "volume-strategy" + std::to_string(serial++), VolumeOctreeTreeFactory::FACTORY_TYPE_NAME, &params));
                r.getContentNode().attachObject(tree);
            },
            [&] { return tree->getLevelCount() - 1 - tree->getActiveLevel(); },
            [&](const CameraSpec& view) { r.render(view, 96, 96, 1); }, views);
        r.clearContent();
    }
}
