// The crossed quads through Plugin_TreeLod, as an application meets them: the registry and the
// factory know "CrossedQuadsTree"; an object made by createMovableObject draws the tree (the
// polygonal reference's silhouette, FLIP, a golden image); a Forest draws a crossed-quads level
// instanced; unloading the asset removes what the technique made.
#include "OgreTestSupport.h"

#include "TreeLod/CrossedQuadsBaker.h"
#include "TreeLod/CrossedQuadsResources.h"
#include "TreeLod/CrossedQuadsTree.h"
#include "TreeLod/Forest.h"
#include "TreeLod/PackageWriter.h"
#include "TreeLod/TechniqueRegistry.h"
#include "TreeLod/TreeAssetManager.h"
#include "TreeLod/TreeGenerator.h"

#include <OgreMaterialManager.h>
#include <OgreRoot.h>
#include <OgreSceneManager.h>
#include <OgreTextureManager.h>

namespace TreeLod
{
    namespace
    {
        const glm::vec3 BACKGROUND = LightingSpec().background;

        struct Oak
        {
            TreeModel model;
            TreeAssetPtr asset;
        };

        /// A generated oak with the reference and crossed-quads chunks (default options, as
        /// `treelod bake --technique crossed-quads` writes them), loaded as "oak.crossed-quads-test".
        const Oak& oak()
        {
            return OgreEnvironment::keep<Oak>("crossed-quads.oak", [] {
                Oak t;
                GeneratorOptions generator;
                generator.leafCount = 3000;
                generator.textureSize = 64;
                Result<TreeModel> model = generateTree(generator);
                EXPECT_TRUE(model.ok());
                t.model = std::move(model.value());
                const std::vector<std::uint8_t> bytes = cachedPackage("crossed-quads", "oak", [&] {
                    PackageWriter writer;
                    Result<void> added = addCrossedQuadsChunk(writer, t.model, "oak");
                    EXPECT_TRUE(added.ok()) << (added.ok() ? "" : added.error().message());
                    return added.ok() ? writer.toBytes() : std::vector<std::uint8_t>();
                });
                t.asset = TreeAssetManager::getSingleton().loadFromBytes("oak.crossed-quads-test", Ogre::RGN_DEFAULT,
                                                                         bytes);
                return t;
            });
        }

        /// Golden images of this example live beside it (examples/crossed-quads/golden/NAME.png).
        void compareWithExampleGolden(const Image& actual, const std::string& name, double bound)
        {
            compareWithGoldenFile(actual, std::string(TREELOD_EXAMPLE_DIR) + "/golden/" + name + ".png", name, bound);
        }

        /// Pixels that are not background in `a`, in `b`, in both.
        struct Overlap
        {
            std::size_t a = 0, b = 0, both = 0;
            double iou() const { return double(both) / double(std::max<std::size_t>(a + b - both, 1)); }
        };

        Overlap overlap(const Image& a, const Image& b)
        {
            Overlap o;
            for (std::size_t i = 0; i < a.pixels.size(); ++i)
            {
                const bool inA = glm::length(glm::vec3(a.pixels[i]) - BACKGROUND) > 0.02f;
                const bool inB = glm::length(glm::vec3(b.pixels[i]) - BACKGROUND) > 0.02f;
                o.a += inA;
                o.b += inB;
                o.both += inA && inB;
            }
            return o;
        }

        Ogre::MovableObject* placeCrossedQuads(const Ogre::String& name)
        {
            OffscreenRenderer& r = OgreEnvironment::renderer();
            r.clearContent();
            Ogre::NameValuePairList params{{"asset", oak().asset->getName()}, {"group", Ogre::RGN_DEFAULT}};
            Ogre::MovableObject* object = r.getSceneManager().createMovableObject(name, "CrossedQuadsTree", &params);
            r.getContentNode().createChildSceneNode()->attachObject(object);
            return object;
        }

        void placeReference()
        {
            OffscreenRenderer& r = OgreEnvironment::renderer();
            r.clearContent();
            r.getContentNode().createChildSceneNode()->attachObject(
                r.getSceneManager().createEntity(oak().asset->getReferenceMesh()));
        }
    }

    TEST(CrossedQuadsTree, registryAndFactoryKnowTheTechnique)
    {
        OgreEnvironment::renderer();
        const TechniqueInfo* info = TechniqueRegistry::getSingleton().find("crossed-quads");
        ASSERT_NE(info, nullptr) << TechniqueRegistry::getSingleton().describe();
        EXPECT_EQ(info->chunkTechnique, "crossed-quads");
        EXPECT_EQ(info->movableType, CrossedQuadsTreeFactory::FACTORY_TYPE_NAME);
        EXPECT_TRUE(info->forestLevels);
        EXPECT_TRUE(Ogre::Root::getSingleton().hasMovableObjectFactory("CrossedQuadsTree"));

        Ogre::SceneManager& sm = OgreEnvironment::renderer().getSceneManager();
        try
        {
            sm.createMovableObject("noAsset", "CrossedQuadsTree", nullptr);
            ADD_FAILURE() << "a CrossedQuadsTree without 'asset' must throw";
        }
        catch (const Ogre::Exception& e)
        {
            EXPECT_NE(e.getDescription().find("'asset'"), std::string::npos) << e.getDescription();
        }
        // Through the registry, as `treelod render` and the browser make it.
        Ogre::MovableObject* object = TechniqueRegistry::getSingleton().createInstance("crossed-quads", sm,
                                                                                       "viaRegistry", *oak().asset);
        ASSERT_NE(object, nullptr);
        EXPECT_EQ(object->getMovableType(), "CrossedQuadsTree");
        EXPECT_EQ(static_cast<CrossedQuadsTree*>(object)->getQuadCount(), 2u);
        ASSERT_TRUE(info->describeState);
        EXPECT_EQ(info->describeState(*object).at(0).label, "quads 2");
        EXPECT_FALSE(object->getBoundingBox().isNull());
        sm.destroyMovableObject(object);
    }

    TEST(CrossedQuadsTree, drawsTheTreeLikeTheReference)
    {
        // From between the quads (30 degrees) and square-on to one (0 degrees): the quads cover
        // about what the polygonal tree covers, on the same pixels, with a moderate FLIP.
        const Oak& t = oak();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        r.setShadows(false);
        std::vector<Image> strip;
        for (float azimuth : {30.0f, 0.0f})
        {
            const CameraSpec camera = CameraSpec::framing(t.model.boundsMin, t.model.boundsMax, azimuth, 5.0f);
            placeCrossedQuads("quads-" + std::to_string(int(azimuth)));
            const Image quads = toImage(r.render(camera, 160, 160, 2));
            placeReference();
            const Image reference = toImage(r.render(camera, 160, 160, 2));
            r.clearContent();
            const Overlap o = overlap(quads, reference);
            const double error = flipMean(reference, quads, FlipOver::Tree);
            std::printf("azimuth %.0f: quads cover %zu px, reference %zu px, IoU %.3f, FLIP %.4f\n", azimuth, o.a,
                        o.b, o.iou(), error);
            EXPECT_GT(treeCoverage(quads, BACKGROUND), 0.08) << "azimuth " << azimuth;
            EXPECT_NEAR(double(o.a), double(o.b), 0.3 * double(o.b)) << "azimuth " << azimuth;
            EXPECT_GT(o.iou(), 0.6) << "azimuth " << azimuth;
            EXPECT_LT(error, 0.52) << "azimuth " << azimuth; // over the tree's pixels, measured 0.465 and 0.315
            strip.push_back(reference);
            strip.push_back(quads);
        }
        writePng(OgreEnvironment::outDir() + "/crossed-quads-vs-reference.png", sideBySide(strip));
        compareWithExampleGolden(strip[1], "oak-crossed-quads", 0.02);
    }

    TEST(CrossedQuadsTree, forestDrawsACrossedQuadsLevel)
    {
        // 16 trees on a grid, one crossed-quads level: two instanced batches (one per quad), four
        // triangles a tree, standing where the polygonal trees stand.
        const Oak& t = oak();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        r.setShadows(false);
        const float h = t.model.boundsMax.y - t.model.boundsMin.y;
        std::vector<ForestInstance> grid;
        for (int z = 0; z < 4; ++z)
            for (int x = 0; x < 4; ++x)
                grid.push_back({glm::vec3((float(x) - 1.5f) * 1.3f * h, 0.0f, (float(z) - 1.5f) * 1.3f * h),
                                0.7f * float(x + 4 * z), 1.0f, 0});
        CameraSpec camera;
        camera.position = glm::vec3(1.5f * h, 3.0f * h, 5.5f * h);
        camera.target = glm::vec3(0.0f, 0.2f * h, 0.0f);
        camera.nearClip = 0.1f * h;
        camera.farClip = 30.0f * h;
        auto render = [&](const char* technique) {
            r.clearContent();
            Ogre::MovableObject* object = r.getSceneManager().createMovableObject(
                std::string("forest-") + technique, "Forest", nullptr);
            r.getContentNode().createChildSceneNode()->attachObject(object);
            auto* forest = static_cast<Forest*>(object);
            forest->addSpecies(t.asset, {ForestLevel{technique, 0, false, 0.0f}});
            forest->addInstances(grid);
            forest->makeAllResident();
            const Image image = toImage(r.render(camera, 256, 192, 2));
            return std::make_pair(image, forest->getStats());
        };
        const auto [quads, stats] = render("crossed-quads");
        const auto [meshes, meshStats] = render("mesh");
        r.clearContent();
        writePng(OgreEnvironment::outDir() + "/crossed-quads-forest.png", sideBySide({meshes, quads}));
        EXPECT_EQ(stats.visibleInstances, 16u);
        EXPECT_EQ(stats.batches, 2u);
        EXPECT_EQ(stats.triangles, 16u * 4u);
        EXPECT_GT(treeCoverage(quads, BACKGROUND), 0.1);
        const Overlap o = overlap(quads, meshes);
        std::printf("forest: quads %zu px, meshes %zu px, IoU %.3f\n", o.a, o.b, o.iou());
        EXPECT_GT(o.iou(), 0.5);
        compareWithExampleGolden(quads, "forest-crossed-quads", 0.02);
    }

    TEST(CrossedQuadsTree, missingChunkIsNamedAndUnloadFreesEverything)
    {
        OgreEnvironment::renderer();
        GeneratorOptions generator;
        generator.leafCount = 200;
        generator.textureSize = 16;
        Result<TreeModel> model = generateTree(generator);
        ASSERT_TRUE(model.ok());
        PackageWriter writer;
        ASSERT_TRUE(addReferenceChunk(writer, model.value(), "plain").ok());
        TreeAssetPtr plain = TreeAssetManager::getSingleton().loadFromBytes("plain.crossed-quads-test",
                                                                            Ogre::RGN_DEFAULT, writer.toBytes());
        try
        {
            CrossedQuadsResources::of(*plain).getGpu();
            FAIL() << "a package without the crossed-quads chunk must throw";
        }
        catch (const Ogre::Exception& e)
        {
            const std::string text = e.getDescription();
            EXPECT_NE(text.find("plain.crossed-quads-test"), std::string::npos) << text;
            EXPECT_NE(text.find("chunk 'crossed-quads' level 0"), std::string::npos) << text;
        }

        ASSERT_TRUE(addCrossedQuadsChunk(writer, model.value(), "small").ok());
        TreeAssetPtr small = TreeAssetManager::getSingleton().loadFromBytes("small.crossed-quads-test",
                                                                            Ogre::RGN_DEFAULT, writer.toBytes());
        const CrossedQuadsGpu& gpu = CrossedQuadsResources::of(*small).getGpu();
        ASSERT_EQ(gpu.parts.size(), 2u);
        EXPECT_GT(small->getTechniqueGpuBytes(), 0u);
        std::vector<Ogre::String> materials, textures;
        for (const CrossedQuadsPart& p : gpu.parts)
        {
            materials.insert(materials.end(), {p.material, p.shadowedMaterial, p.casterMaterial});
            textures.push_back(p.texture);
            Ogre::MaterialPtr m = Ogre::MaterialManager::getSingleton().getByName(p.material, Ogre::RGN_DEFAULT);
            ASSERT_TRUE(m);
            EXPECT_EQ(m->getTechnique(0)->getPass(0)->getTextureUnitState(0)->getTextureName(), p.texture);
            EXPECT_EQ(m->getTechnique(0)->getShadowCasterMaterial()->getName(), p.casterMaterial);
        }
        for (const Ogre::String& m : materials)
            EXPECT_TRUE(Ogre::MaterialManager::getSingleton().resourceExists(m, Ogre::RGN_DEFAULT)) << m;
        small->unload();
        for (const Ogre::String& m : materials)
            EXPECT_FALSE(Ogre::MaterialManager::getSingleton().resourceExists(m, Ogre::RGN_DEFAULT)) << m;
        for (const Ogre::String& tex : textures)
            EXPECT_FALSE(Ogre::TextureManager::getSingleton().resourceExists(tex, Ogre::RGN_DEFAULT)) << tex;
        small->load();
        EXPECT_EQ(CrossedQuadsResources::of(*small).getGpu().parts.size(), 2u); // built again after a reload
        TreeAssetManager::getSingleton().remove(small);
        TreeAssetManager::getSingleton().remove(plain);
    }
}
