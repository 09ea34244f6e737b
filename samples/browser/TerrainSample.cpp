#include "TerrainSample.h"

#include "TreeLod/ShadowSetup.h"

#include <OgreImage.h>
#include <OgreMaterialManager.h>
#include <OgreShadowCameraSetupPSSM.h>
#include <OgreTerrain.h>
#include <OgreTerrainMaterialGeneratorA.h>
#include <OgreTextureManager.h>
#include <OgreWorkQueue.h>

#include <chrono>
#include <cstdio>
#include <thread>
#include <vector>

namespace TreeLod
{
    namespace
    {
        const char* const DIFFUSE_TEXTURE = "TreeLod/Terrain/Grass_diffusespecular";
        const char* const NORMAL_TEXTURE = "TreeLod/Terrain/Flat_normalheight";
        /// Metres one repeat of the grass texture covers.
        constexpr Ogre::Real LAYER_WORLD_SIZE = 6;
        /// The grass in sRGB: the Terrain's shader writes its lit colour as it is, where TreeLod's
        /// shaders light in linear space and convert (ForestScene's ground is linear (0.10, 0.16, 0.05)).
        constexpr float GRASS[3] = {0.35f, 0.44f, 0.25f};

        /// The one layer TerrainMaterialGeneratorA draws: "diffuse_specular" (grass with a little
        /// noise, no specular) and "normal_height" (flat), made in memory once.
        void createLayerTextures(const Ogre::String& group)
        {
            Ogre::TextureManager& textures = Ogre::TextureManager::getSingleton();
            if (textures.resourceExists(DIFFUSE_TEXTURE, group))
                return;
            constexpr Ogre::uint32 SIZE = 64;
            Ogre::Image diffuse(Ogre::PF_BYTE_RGBA, SIZE, SIZE);
            Ogre::Image normal(Ogre::PF_BYTE_RGBA, SIZE, SIZE);
            Ogre::uint32 hash = 2166136261u;
            for (Ogre::uint32 y = 0; y < SIZE; ++y)
                for (Ogre::uint32 x = 0; x < SIZE; ++x)
                {
                    hash = (hash ^ (x * 73856093u ^ y * 19349663u)) * 16777619u;
                    const float shade = 0.85f + 0.3f * float(hash >> 24) / 255.0f;
                    diffuse.setColourAt(Ogre::ColourValue(GRASS[0] * shade, GRASS[1] * shade, GRASS[2] * shade, 0.0f), x, y, 0);
                    normal.setColourAt(Ogre::ColourValue(0.5f, 0.5f, 1.0f, 0.5f), x, y, 0);
                }
            textures.loadImage(DIFFUSE_TEXTURE, group, diffuse);
            textures.loadImage(NORMAL_TEXTURE, group, normal);
        }
    }

    TerrainSample::TerrainSample(Ogre::Root& root, SceneScript script) : ForestSample(root, std::move(script)) {}

    TerrainSample::~TerrainSample()
    {
        detach();
        mTerrain.reset(); // before the scene manager and the global options
        mScene.reset();
        if (mSceneManager)
            mRoot.destroySceneManager(mSceneManager);
        mSceneManager = nullptr;
        mTerrainGlobals.reset();
    }

    std::string TerrainSample::getTitle() const { return "Terrain: " + mScript.name; }

    std::string TerrainSample::getDescription() const
    {
        char text[200];
        std::snprintf(text, sizeof text,
                      "\n\nThe ground is Ogre's Terrain (%u x %u vertices over %.0f m), receiving the trees' "
                      "%s depth shadows in its own material.",
                      unsigned(TERRAIN_SIZE), unsigned(TERRAIN_SIZE), double(mScript.ground.size),
                      mScript.shadows.camera.c_str());
        return ForestSample::getDescription() + text;
    }

    void TerrainSample::build(const ProgressCallback& progress)
    {
        if (mSceneManager)
            return;
        if (mScript.ground.kind != SceneGround::Kind::Heightfield)
            OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS,
                        mScript.file + ": the terrain sample needs a heightfield ground", "TerrainSample::build");
        ForestSample::build(progress);
        report(progress, "terrain: building the Terrain", 0.0f);
        createTerrain();
        configureTerrainShadows();
        report(progress, "terrain: building the Terrain", 1.0f);
    }

    void TerrainSample::createTerrain()
    {
        const SceneGround& ground = mScript.ground;
        mTerrainGlobals = std::make_unique<Ogre::TerrainGlobalOptions>();
        mTerrainGlobals->setDefaultResourceGroup(TREELOD_GROUP);
        mTerrainGlobals->setMaxPixelError(2);
        // The high-LoD material everywhere the camera sees: the composite map (a baked colour for
        // far terrain) would drop the shadows and the layer texture.
        mTerrainGlobals->setCompositeMapDistance(mScript.camera.farClip);
        mTerrainGlobals->setUseVertexCompressionWhenAvailable(false);
        const Ogre::Light& sun = mScene->getSun();
        mTerrainGlobals->setLightMapDirection(sun.getDerivedDirection());
        mTerrainGlobals->setCompositeMapAmbient(mSceneManager->getAmbientLight());
        mTerrainGlobals->setCompositeMapDiffuse(sun.getDiffuseColour());
        auto* profile = static_cast<Ogre::TerrainMaterialGeneratorA::SM2Profile*>(
            mTerrainGlobals->getDefaultMaterialGenerator()->getActiveProfile());
        // The sun's shadows come from the shadow textures only; the Terrain does not cast (its
        // default), so its lightmap, the hills' own shadows, is left out too.
        profile->setLightmapEnabled(false);
        // Layer normal mapping stays on (with a flat normal map): OGRE 1.12's GLSL generator
        // numbers a normal-map sampler per layer either way, and with it off, the shadow
        // textures' inverseShadowmapSize constants read the sizes of the wrong texture units
        // (1 / 1: the PCF taps land far off and the shadows vanish or turn into patches).
        profile->setLayerNormalMappingEnabled(true);
        profile->setLayerParallaxMappingEnabled(false);
        profile->setLayerSpecularMappingEnabled(false);
        createLayerTextures(TREELOD_GROUP);

        // Heights at the vertices from the script's heightfield. ALIGN_X_Z puts vertex (x, y) at
        // world (x * step - size/2, h, size/2 - y * step): row y runs towards -Z.
        const int n = TERRAIN_SIZE;
        const float step = ground.size / float(n - 1), half = 0.5f * ground.size;
        std::vector<float> heights(std::size_t(n) * n);
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x)
                heights[std::size_t(y) * n + x] = groundHeight(ground, float(x) * step - half, half - float(y) * step);

        Ogre::Terrain::ImportData data;
        data.terrainAlign = Ogre::Terrain::ALIGN_X_Z;
        data.terrainSize = TERRAIN_SIZE;
        data.worldSize = ground.size;
        data.pos = Ogre::Vector3::ZERO;
        data.inputFloat = heights.data();
        data.deleteInputData = false; // prepare() copies the heights
        data.inputScale = 1;
        data.inputBias = 0;
        data.minBatchSize = 17;
        data.maxBatchSize = 65;
        data.layerList.resize(1);
        data.layerList[0].worldSize = LAYER_WORLD_SIZE;
        data.layerList[0].textureNames = {DIFFUSE_TEXTURE, NORMAL_TEXTURE};

        mTerrain = std::make_unique<Ogre::Terrain>(mSceneManager);
        mTerrain->setResourceGroup(TREELOD_GROUP);
        if (!mTerrain->prepare(data))
            OGRE_EXCEPT(Ogre::Exception::ERR_INTERNAL_ERROR, mScript.file + ": Ogre::Terrain::prepare failed",
                        "TerrainSample::createTerrain");
        mTerrain->load();
        // The normal map (and composite map) come from Ogre's work queue: wait for them, so the
        // first frame is lit right (a queue without worker threads is run here).
        Ogre::WorkQueue* queue = mRoot.getWorkQueue();
        auto* defaultQueue = dynamic_cast<Ogre::DefaultWorkQueueBase*>(queue);
        const auto start = std::chrono::steady_clock::now();
        while (mTerrain->isDerivedDataUpdateInProgress() &&
               std::chrono::steady_clock::now() - start < std::chrono::seconds(60))
        {
            if (defaultQueue && defaultQueue->getWorkerThreadCount() == 0)
                defaultQueue->_processNextRequest();
            queue->processResponses();
            std::this_thread::sleep_for(std::chrono::milliseconds(2));
        }
        mTerrain->freeTemporaryResources();
    }

    void TerrainSample::configureTerrainShadows()
    {
        if (!mTerrainGlobals)
            return;
        auto* profile = static_cast<Ogre::TerrainMaterialGeneratorA::SM2Profile*>(
            mTerrainGlobals->getDefaultMaterialGenerator()->getActiveProfile());
        auto* pssm = dynamic_cast<Ogre::PSSMShadowCameraSetup*>(mSceneManager->getShadowCameraSetup().get());
        const bool depth = receivesDepthShadows(mSceneManager);
        // Ogre's Terrain sample with depth shadows. The Terrain's fragment program compares as
        // OGRE's RTSS integrated PSSM does (SGX_ComputeShadowFactor_PSSM3: window depth
        // 0.5 z/w + 0.5 <= texel, 2x2 PCF, no bias), which is what TreeLod's casters write into
        // their PF_FLOAT32_R textures; the Terrain casts no shadow, so needs no bias.
        // Anything that casts without a caster of its own writes the trees' depth too (Ogre's
        // default caster has no shaders outside the RTSS).
        if (depth)
            mSceneManager->setShadowTextureCasterMaterial(
                Ogre::MaterialManager::getSingleton().getByName("TreeLod/BarkCaster", TREELOD_GROUP));
        profile->setReceiveDynamicShadowsEnabled(depth && pssm);
        profile->setReceiveDynamicShadowsPSSM(depth ? pssm : nullptr);
        profile->setReceiveDynamicShadowsDepth(depth);
        profile->setReceiveDynamicShadowsLowLod(true);
        // The split points are constants of the generated program: generate it again.
        mTerrainGlobals->getDefaultMaterialGenerator()->_markChanged();
        mSplitNearClip = mCamera->getNearClipDistance();
        mSplitFarDistance = mSceneManager->getShadowFarDistance();
    }

    void TerrainSample::setShadows(bool enabled)
    {
        ForestSample::setShadows(enabled); // setupSunShadows: a new PSSM camera setup
        configureTerrainShadows();
    }

    void TerrainSample::frame(double seconds)
    {
        ForestSample::frame(seconds);
        if (mCamera->getNearClipDistance() != mSplitNearClip ||
            mSceneManager->getShadowFarDistance() != mSplitFarDistance)
        {
            updateShadowSplits(*mSceneManager, *mCamera);
            configureTerrainShadows();
        }
    }

    bool TerrainSample::isSettled() const
    {
        return ForestSample::isSettled() && !mTerrain->isDerivedDataUpdateInProgress();
    }
}
