// The browser's terrain sample in-process, on the test binaries' headless Root: Ogre's Terrain
// carries the trees ForestScene placed (its heights are the script's), and the trees' PSSM depth
// shadows darken both the trees and the Terrain's own material (TerrainMaterialGeneratorA).
#include "../ogre/OgreTestSupport.h"

#include "TerrainSample.h"
#include "TreeLod/CacheTreeBaker.h"
#include "TreeLod/OgreBootstrap.h"

#include <OgreTerrain.h>

#include <gtest/gtest.h>

#include <cmath>

namespace TreeLod
{
    namespace
    {
        constexpr int SHOT_WIDTH = 480, SHOT_HEIGHT = 270;

        float luminance(const glm::vec4& p) { return 0.2126f * p.r + 0.7152f * p.g + 0.0722f * p.b; }

        /// One frame of the sample into `target`, after it settled (levels uploaded, the Terrain's
        /// derived data and material built).
        Image shoot(Ogre::Root& root, TerrainSample& sample, Ogre::RenderTarget& target)
        {
            for (int f = 0; f < 100 && !sample.isSettled(); ++f)
            {
                sample.frame(0.0);
                root.renderOneFrame();
            }
            for (int f = 0; f < 2; ++f)
            {
                sample.frame(0.0);
                root.renderOneFrame();
            }
            Ogre::Image pixels(Ogre::PF_BYTE_RGBA, target.getWidth(), target.getHeight());
            target.copyContentsToMemory(Ogre::Box(0, 0, target.getWidth(), target.getHeight()), pixels.getPixelBox());
            Image image(int(target.getWidth()), int(target.getHeight()));
            for (int y = 0; y < image.height; ++y)
                for (int x = 0; x < image.width; ++x)
                {
                    const Ogre::ColourValue c = pixels.getColourAt(Ogre::uint32(x), Ogre::uint32(y), 0);
                    image.at(x, y) = glm::vec4(c.r, c.g, c.b, 1.0f);
                }
            return image;
        }
    }

    TEST(TerrainSample, treesStandOnTheTerrainAndItsShadowsFallOnTerrainAndTrees)
    {
        OffscreenRenderer& renderer = OgreEnvironment::renderer();
        Ogre::Root& root = renderer.getRoot();
        // What the browser adds: the Terrain's GLSL includes and OGRE's shader library.
        Ogre::ResourceGroupManager& rgm = Ogre::ResourceGroupManager::getSingleton();
        for (const char* folder : {"/RTShaderLib/GLSL", "/Terrain"})
            rgm.addResourceLocation(ogreMediaDirectory() + folder, "FileSystem", Ogre::RGN_INTERNAL);
        CacheTreeBaker baker; // the browser's cache ($XDG_CACHE_HOME/treelod): the test's
        TreeAssetManager::getSingleton().setBaker(&baker);

        Result<SceneScript> script =
            loadSceneScript(OgreEnvironment::sourcePath("samples/scenes/terrain-pssm.json"), readGreyImage);
        ASSERT_TRUE(script.ok()) << script.error().message();
        script->shadows.textureSize = 1024;
        // One fixed technique: "auto" would plan with this machine's level costs when the cache
        // holds a calibration (other tests write one), and the picture would depend on test order.
        ASSERT_EQ(script->species.size(), 1u);
        script->species[0].autoTechnique = false;
        script->species[0].bands = {TechniqueBand{"lodf", 0.0f, 0.0f}};
        {
            TerrainSample sample(root, *script);
            sample.build({});
            Ogre::Terrain& terrain = sample.getTerrain();

            // Heights: at the Terrain's vertices they are the script's; between them the Terrain's
            // two triangles per cell and the script's bilinear surface part by the cell's twist only.
            const SceneGround& ground = script->ground;
            const float step = ground.size / float(TerrainSample::TERRAIN_SIZE - 1);
            float vertexError = 0.0f;
            for (int j = 0; j < TerrainSample::TERRAIN_SIZE; j += 8)
                for (int i = 0; i < TerrainSample::TERRAIN_SIZE; i += 8)
                {
                    const float x = -0.5f * ground.size + float(i) * step, z = -0.5f * ground.size + float(j) * step;
                    vertexError = std::max(vertexError,
                                           std::abs(terrain.getHeightAtWorldPosition(x, 0.0f, z) - groundHeight(ground, x, z)));
                }
            EXPECT_LT(vertexError, 1e-3f) << "the Terrain's vertices are not at the script's heights";
            const std::vector<PlacedTree>& trees = sample.getForestScene().getPlacements();
            ASSERT_EQ(trees.size(), 300u);
            float treeError = 0.0f;
            for (const PlacedTree& tree : trees)
                treeError = std::max(treeError, std::abs(terrain.getHeightAtWorldPosition(tree.position.x, 0.0f, tree.position.z) -
                                                         tree.position.y));
            EXPECT_LT(treeError, 0.1f) << "a tree's base is off the Terrain";
            std::cout << "Terrain heights: at vertices within " << vertexError << " m, at the 300 trees within "
                      << treeError << " m" << std::endl;

            // Shadows on and off, the forest shown and hidden, from the path's first frame.
            Ogre::TexturePtr texture = Ogre::TextureManager::getSingleton().createManual(
                "TerrainSampleTest/Target", Ogre::RGN_INTERNAL, Ogre::TEX_TYPE_2D, SHOT_WIDTH, SHOT_HEIGHT, 0,
                Ogre::PF_BYTE_RGBA, Ogre::TU_RENDERTARGET);
            Ogre::RenderTarget& target = *texture->getBuffer()->getRenderTarget();
            target.setAutoUpdated(true);
            sample.attach(target, PixelRect{0, 0, SHOT_WIDTH, SHOT_HEIGHT}, 0);
            sample.setScreenshotView(0, 2);
            ASSERT_TRUE(sample.getShadows());
            Forest& forest = sample.getForestScene().getForest();
            const Image shadowed = shoot(root, sample, target);
            sample.setShadows(false);
            const Image lit = shoot(root, sample, target);
            forest.setVisible(false);
            const Image bare = shoot(root, sample, target);
            forest.setVisible(true);
            sample.setShadows(true);
            const Image again = shoot(root, sample, target);
            sample.detach();
            Ogre::TextureManager::getSingleton().remove(texture);

            const std::string out = OgreEnvironment::outDir();
            compareWithGolden(sideBySide({shadowed, lit}), "terrain-sample-pssm", 0.02); // shadows on | off
            writePng(out + "/terrain-sample-bare.png", bare);
            EXPECT_LT(flipMean(shadowed, again), 0.01) << "shadows on, off and on again differ";

            // Trees: where the forest changes the unshadowed picture; terrain: the rest below the sky.
            const glm::vec3 sky = glm::vec3(bare.at(0, 0));
            std::size_t treePixels = 0, treeDarker = 0, terrainPixels = 0, terrainDarker = 0;
            double treeLit = 0, treeShadowed = 0, terrainLit = 0, terrainShadowed = 0;
            for (std::size_t k = 0; k < lit.pixels.size(); ++k)
            {
                const float l = luminance(lit.pixels[k]), s = luminance(shadowed.pixels[k]);
                const bool isTree = glm::length(glm::vec3(lit.pixels[k] - bare.pixels[k])) > 0.05f;
                const bool isSky = glm::length(glm::vec3(bare.pixels[k]) - sky) < 0.02f;
                if (isTree)
                {
                    ++treePixels, treeLit += l, treeShadowed += s;
                    treeDarker += s < 0.85f * l;
                }
                else if (!isSky)
                {
                    ++terrainPixels, terrainLit += l, terrainShadowed += s;
                    terrainDarker += s < 0.85f * l;
                }
            }
            ASSERT_GT(treePixels, lit.pixels.size() / 20) << "no trees in view";
            ASSERT_GT(terrainPixels, lit.pixels.size() / 5) << "no terrain in view";
            const double treeFraction = double(treeDarker) / double(treePixels);
            const double terrainFraction = double(terrainDarker) / double(terrainPixels);
            std::cout << "shadows darken " << 100.0 * treeFraction << "% of the tree pixels (mean luminance "
                      << treeLit / double(treePixels) << " -> " << treeShadowed / double(treePixels) << ") and "
                      << 100.0 * terrainFraction << "% of the terrain pixels (" << terrainLit / double(terrainPixels)
                      << " -> " << terrainShadowed / double(terrainPixels) << ")" << std::endl;
            EXPECT_GT(treeFraction, 0.1) << "no shadow on the trees";
            EXPECT_LT(treeShadowed, treeLit);
            EXPECT_GT(terrainFraction, 0.05) << "no shadow on the Terrain";
            EXPECT_LT(terrainShadowed, 0.97 * terrainLit) << "no shadow on the Terrain";
        }
        TreeAssetManager::getSingleton().setBaker(nullptr);
    }
}
