// ForestSample: the scene script's forest (ForestScene: ground, sun, shadows, one Forest of every
// placed tree) seen from the script's camera path, played back in real time or paused for free
// look; the technique choice is the script's (per distance band or "auto") or one technique
// for every tree.
#pragma once

#include "BrowserSample.h"
#include "TreeLod/ForestScene.h"

#include <memory>

namespace TreeLod
{
    class ForestSample : public BrowserSample
    {
    public:
        /// Technique menu entry for the script's own choice.
        static const char* const SCRIPT_TECHNIQUE;

        ForestSample(Ogre::Root& root, SceneScript script);
        ~ForestSample() override;

        std::string getTitle() const override;
        std::string getDescription() const override;
        void build(const ProgressCallback& progress) override;
        void renderThumbnail(Ogre::RenderTarget& target) override;
        void attach(Ogre::RenderTarget& target, const PixelRect& area, int firstZOrder) override;
        void detach() override;
        void frame(double seconds) override;
        void frameTimed(double seconds) override;

        Ogre::Camera& getCamera() override { return *mCamera; }
        Ogre::SceneNode& getCameraNode() override { return *mCameraNode; }
        Ogre::SceneNode* getOrbitTarget() override { return nullptr; }
        float getCameraSpeed() const override;

        bool isSplitView() const override { return false; }
        std::vector<std::string> getTechniques() const override;
        std::string getTechnique() const override;
        void setTechnique(const std::string& technique) override;
        /// setTechnique's and the budget slider's way to the scene: bakes run, then it switches.
        void requestPolicy(const LodPolicy& policy);
        /// The menu's name for `policy`: SCRIPT_TECHNIQUE, a technique, or "auto@E".
        static std::string menuLabel(const LodPolicy& policy);
        float getLodBias() const override { return mLodBias; }
        void setLodBias(float bias) override;
        bool getShadows() const override { return mShadows; }
        void setShadows(bool enabled) override;
        bool getWireframe() const override { return mWireframe; }
        void setWireframe(bool enabled) override;
        bool isLodFrozen() const override;
        void setLodFrozen(bool frozen) override;
        bool hasCameraPath() const override { return true; }
        bool isSettled() const override;
        /// Auto at another budget: the technique "auto@E" (ForestScene.h). Levels come from the
        /// packages' error curves and this renderer's calibration in the user's cache (`treelod
        /// bench` or `treelod calibrate` made them); without them auto keeps its fixed bands.
        bool hasErrorBudget() const override { return true; }
        float getErrorBudget() const override { return mErrorBudget; }
        void setErrorBudget(float budget) override;
        /// The Forest's transitions (the script's lod.transition at first), kept across technique switches.
        bool hasLodTransition() const override { return true; }
        float getLodTransition() const override { return mLodTransition; }
        void setLodTransition(float transition) override;
        bool isPlaying() const override { return mPlaying; }
        void setPlaying(bool playing) override { mPlaying = playing; }
        void setScreenshotView(unsigned index, unsigned count) override;

        std::vector<std::pair<std::string, std::string>> getStats() override;
        std::vector<std::string> getLevelHistogram() override;

    protected:
        /// Before the ForestScene is made (TerrainSample: no ground mesh).
        virtual void prepareSceneOptions(ForestSceneOptions&) {}

        /// Seconds of the script's camera path: its first and last keyframe times.
        double pathStart() const;
        double pathEnd() const;

        Ogre::Root& mRoot;
        SceneScript mScript;
        std::unique_ptr<ForestScene> mScene;
        Ogre::SceneManager* mSceneManager = nullptr;
        Ogre::Camera* mCamera = nullptr;
        Ogre::SceneNode* mCameraNode = nullptr;
        Ogre::RenderTarget* mTarget = nullptr;
        Ogre::Viewport* mViewport = nullptr;
        Ogre::ColourValue mBackground;
        double mPathTime = 0.0; ///< seconds along the camera path
        bool mPlaying = true;
        std::string mBakeError; ///< the last technique switch's failed bake, shown in the stats
        float mLodBias = 1.0f;
        float mErrorBudget = 0.0f; ///< set from the script's lod.maxError when built
        float mLodTransition = 0.0f; ///< set from the script's lod.transition when built
        bool mShadows = false;
        bool mWireframe = false;
    };
}
