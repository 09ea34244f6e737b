// TerrainSample: a scene script's forest on Ogre's Terrain component, under PSSM shadows. The
// script's heightfield ground becomes one Ogre::Terrain whose vertices take their heights from
// groundHeight(), so every tree ForestScene places stands on it; ForestScene draws the trees and
// no ground mesh. Shadows: setupSunShadows (the script's shadow camera, PSSM in terrain-pssm.json)
// and the Terrain's material (TerrainMaterialGeneratorA::SM2Profile) receiving the trees' depth
// shadows, as OGRE's Terrain sample sets it up; docs/browser.md, "The terrain sample".
#pragma once

#include "ForestSample.h"

#include <memory>

namespace Ogre
{
    class Terrain;
    class TerrainGlobalOptions;
}

namespace TreeLod
{
    class TerrainSample : public ForestSample
    {
    public:
        /// Vertices per side of the Terrain (2^n + 1): one per pixel of a 129 x 129 heightmap.
        static constexpr Ogre::uint16 TERRAIN_SIZE = 129;

        /// `script` needs a heightfield ground; build() throws Ogre::Exception otherwise.
        TerrainSample(Ogre::Root& root, SceneScript script);
        ~TerrainSample() override;

        std::string getTitle() const override;
        std::string getDescription() const override;
        void build(const ProgressCallback& progress) override;
        void frame(double seconds) override;
        void setShadows(bool enabled) override;
        bool isSettled() const override;
        std::string getScreenshotPrefix() const override { return "terrain"; }

        Ogre::Terrain& getTerrain() { return *mTerrain; }
        ForestScene& getForestScene() { return *mScene; }
        Ogre::SceneManager& getSceneManager() { return *mSceneManager; }

    protected:
        void prepareSceneOptions(ForestSceneOptions& options) override { options.ground = false; }

    private:
        void createTerrain();
        /// The Terrain's material receives the shadows Ogre draws now: PSSM with depth textures
        /// from the scene manager's PSSMShadowCameraSetup, or none.
        void configureTerrainShadows();

        std::unique_ptr<Ogre::TerrainGlobalOptions> mTerrainGlobals;
        std::unique_ptr<Ogre::Terrain> mTerrain;
        /// What the PSSM split points were computed from (updateShadowSplits).
        Ogre::Real mSplitNearClip = 0;
        Ogre::Real mSplitFarDistance = 0;
    };
}
