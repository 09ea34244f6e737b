// TreeLodBrowser: TreeLod's sample browser, an OgreBites ApplicationContext shaped like Ogre's own
// (Samples/Browser): a menu of samples with thumbnails and descriptions, trays for the controls
// and the stats, CameraMan for keyboard and mouse.
//
// Screen layout: a column of COLUMN_WIDTH pixels on the left holds the trays (menu, controls,
// stats, LoD histogram); the sample draws into the rest. Viewports: the sample's (z-order 0..9),
// the column's background (10), the trays' overlay viewport on top (20, drawing no scene: the
// overlays would otherwise be drawn once per viewport).
//
// Headless (--headless): the same screens render into a texture of --size instead of a window
// (a hidden 1x1 window owns the GL context, as in OffscreenRenderer) and writeScreenshots() saves
// them as PNGs; nothing waits for input.
//
// Ogre setup: RenderSystem_GL3Plus and Codec_STBI from $OGRE_PLUGIN_DIR_OVERRIDE or OGRE's plugin
// folder, the TreeLod plugin installed in-process, TreeLod's materials from
// $TREELOD_MATERIALS_DIR or the source tree (group "TreeLod"), the trays' media from OGRE's
// SdkTrays.zip ("Essential"), RTSS for the trays only (the scene viewports use TreeLod's own
// shaders). Lazy baking through CacheTreeBaker (CacheTreeBaker.h) registered with the
// TreeAssetManager; what it built and reused is printed.
#pragma once

#include "BrowserOptions.h"
#include "BrowserSample.h"
#include "TreeLod/CacheTreeBaker.h"
#include "TreeLod/ForestScene.h"
#include "TreeLod/SceneScript.h"

#include <OgreApplicationContext.h>
#include <OgreInput.h>
#include <OgreTrays.h>

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace OgreBites
{
    class AdvancedRenderControls;
    class CameraMan;
}

namespace TreeLod
{
    class TreeLodPlugin;

    class TreeLodBrowser : public OgreBites::ApplicationContext,
                           public OgreBites::InputListener,
                           public OgreBites::TrayListener
    {
    public:
        /// Width of the trays' column, pixels.
        static constexpr int COLUMN_WIDTH = 270;

        /// `terrainScript`: the terrain sample's scene (a heightfield ground); none: no terrain sample.
        TreeLodBrowser(BrowserOptions options, SceneScript script, std::optional<SceneScript> terrainScript = {});
        ~TreeLodBrowser() override;

        /// Headless: write the screenshots (see --help) into options.screenshots; returns their paths.
        std::vector<std::string> writeScreenshots();

        /// Memory at one point of a soak run (MiB), after returning the allocator's free memory.
        struct SoakMemory
        {
            double residentMiB = 0.0; ///< VmRSS
            double heapMiB = 0.0;     ///< malloc'd and not freed (mallinfo2), the GL driver's included
        };
        struct SoakReport
        {
            unsigned switches = 0;       ///< made in all
            unsigned warmUpSwitches = 0; ///< the first SOAK_WARM_UP_PASSES passes over every sample and technique
            SoakMemory afterWarmUp;      ///< after them
            SoakMemory end;              ///< at the end
            double peakMiB = 0.0;        ///< the process's peak resident memory
        };
        /// Passes over every sample and technique before the soak's baseline: the first bakes,
        /// builds levels and compiles shaders; in the second the GL driver still compiles
        /// variants for states it first meets there (docs/browser.md, "Memory").
        static constexpr unsigned SOAK_WARM_UP_PASSES = 2;
        /// Headless: `switches` changes of screen as a user makes them (the menu and a sample in
        /// turn, then each entry of its technique menu), each drawn until it has settled; prints
        /// memory after each pass, and returns it after the warm-up passes and at the end.
        SoakReport soak(unsigned switches);

        // ApplicationContext
        void createRoot() override;
        bool oneTimeConfig() override;
        void locateResources() override;
        void setup() override;
        void shutdown() override;
        OgreBites::NativeWindowPair createWindow(const Ogre::String& name, uint32_t w = 0, uint32_t h = 0,
                                                 Ogre::NameValuePairList miscParams = Ogre::NameValuePairList()) override;
        bool frameStarted(const Ogre::FrameEvent& evt) override;
        bool frameEnded(const Ogre::FrameEvent& evt) override;
        void windowResized(Ogre::RenderWindow* window) override;

        // InputListener
        void frameRendered(const Ogre::FrameEvent& evt) override;
        bool keyPressed(const OgreBites::KeyboardEvent& evt) override;
        bool keyReleased(const OgreBites::KeyboardEvent& evt) override;
        bool mouseMoved(const OgreBites::MouseMotionEvent& evt) override;
        bool mousePressed(const OgreBites::MouseButtonEvent& evt) override;
        bool mouseReleased(const OgreBites::MouseButtonEvent& evt) override;
        bool mouseWheelRolled(const OgreBites::MouseWheelEvent& evt) override;

        // TrayListener
        void buttonHit(OgreBites::Button* button) override;
        void itemSelected(OgreBites::SelectMenu* menu) override;
        void sliderMoved(OgreBites::Slider* slider) override;
        /// The wind panel from TreeLod::Wind, and TreeLod::Wind from the panel.
        void syncWindControls();
        void showWindPanel(bool shown);
        void setWindFromControls();
        void checkBoxToggled(OgreBites::CheckBox* box) override;

    private:
        struct Thumbnail;

        void createTarget();
        void createUi();
        void buildSamples();
        void createThumbnails();
        void showProgress(const std::string& step, float fraction);
        /// Viewports of the current screen on the target (menu or sample).
        void layoutScreen();
        void showMenu();
        void selectSample(int index);
        void runSample(int index);
        void createSampleControls();
        void syncControls();
        void updateStats();
        void layoutThumbnails();
        int thumbnailAt(const Ogre::Vector2& cursor) const;
        Ogre::Vector2 cursorPosition() const;
        void setLodBiasExponent(int exponent);
        void savePng(const std::string& path);
        static SoakMemory measureMemory();

        BrowserOptions mOptions;
        SceneScript mScript;
        std::optional<SceneScript> mTerrainScript; ///< the terrain sample's scene, if any
        std::unique_ptr<Ogre::LogManager> mLogManager;
        std::unique_ptr<TreeLodPlugin> mPlugin;
        std::unique_ptr<CacheTreeBaker> mBaker;

        Ogre::RenderTarget* mTarget = nullptr; ///< the window, or the headless texture's target
        Ogre::TexturePtr mHeadlessTexture;
        Ogre::SceneManager* mUiSceneManager = nullptr;
        Ogre::Camera* mUiCamera = nullptr;

        std::unique_ptr<OgreBites::TrayManager> mTrays;
        std::unique_ptr<OgreBites::CameraMan> mCameraMan;
        std::unique_ptr<OgreBites::AdvancedRenderControls> mRenderControls;
        OgreBites::SelectMenu* mSampleMenu = nullptr;
        OgreBites::TextBox* mDescription = nullptr;
        OgreBites::SelectMenu* mTechniqueMenu = nullptr;
        OgreBites::Slider* mLodBiasSlider = nullptr;
        OgreBites::Slider* mErrorBudgetSlider = nullptr; ///< samples with budgeted auto only
        OgreBites::Slider* mTransitionSlider = nullptr;  ///< samples with level transitions only
        float mLastTransition = 0.2f; ///< what the X key turns transitions back on to
        OgreBites::Slider* mWindSlider = nullptr; ///< the wind panel (TreeLod::Wind), every sample; B shows it
        OgreBites::Slider* mWindDirectionSlider = nullptr;
        OgreBites::Slider* mGustSlider = nullptr;
        bool mWindPanelShown = false;
        OgreBites::CheckBox* mShadowsBox = nullptr;
        OgreBites::CheckBox* mWireframeBox = nullptr;
        OgreBites::CheckBox* mFreezeBox = nullptr;
        OgreBites::Button* mPlayButton = nullptr;
        OgreBites::ParamsPanel* mStatsPanel = nullptr;
        OgreBites::TextBox* mHistogramBox = nullptr;
        OgreBites::ProgressBar* mProgressBar = nullptr;

        std::vector<std::unique_ptr<BrowserSample>> mSamples;
        std::vector<std::unique_ptr<Thumbnail>> mThumbnails;
        Ogre::Overlay* mMenuOverlay = nullptr;
        int mSelected = 0;
        int mCurrent = -1; ///< running sample, -1 in the menu
        static constexpr int NO_SCREEN = -2, MENU_SCREEN = -1;
        int mPendingScreen = NO_SCREEN; ///< the screen to show at the next frame: a sample, the menu, or none
        bool mDragLook = false;
        double mFrameSeconds = 0.0;  ///< smoothed time of the last frames (rendering only)
        std::chrono::steady_clock::time_point mFrameStart;
        /// Seconds each frame advances the samples (camera paths, delays); none: the real frame
        /// time. The soak sets it so that what it draws does not depend on the machine's speed.
        std::optional<double> mFixedFrameSeconds;
        double mProgressShownAt = -1.0;
        std::string mProgressStep;
    };
}
