#include "TreeLodBrowser.h"

#include "ForestSample.h"
#include "SingleTreeView.h"
#include "TechniqueSample.h"
#include "TerrainSample.h"
#include "TreeLod/OffscreenRenderer.h"
#include "TreeLod/LevelSelection.h"
#include "TreeLod/OgreBootstrap.h"
#include "TreeLod/ProcessMemory.h"
#include "TreeLod/TechniqueRegistry.h"
#include "TreeLod/TreeAssetManager.h"
#include "TreeLod/TreeLodPlugin.h"
#include "TreeLod/Wind.h"

#include <OgreAdvancedRenderControls.h>
#include <OgreBorderPanelOverlayElement.h>
#include <OgreCameraMan.h>
#include <OgreFontManager.h>
#include <OgreOverlayManager.h>
#include <OgreOverlaySystem.h>
#include <OgreRTShaderSystem.h>

#include <malloc.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>

namespace TreeLod
{
    namespace
    {
        constexpr int SAMPLE_Z = 0;       ///< the sample's viewports: 0..9
        constexpr int COLUMN_Z = 10;      ///< the trays' column background
        constexpr int UI_Z = 20;          ///< the trays (overlays only)
        constexpr float WIDGET_WIDTH = 250.0f;
        constexpr int THUMBNAIL_WIDTH = 320, THUMBNAIL_HEIGHT = 180; ///< thumbnail textures, pixels
        constexpr int HISTOGRAM_LINES = 7;
        const Ogre::ColourValue COLUMN_COLOUR(0.10f, 0.11f, 0.12f);
        const Ogre::ColourValue MENU_COLOUR(0.16f, 0.19f, 0.22f);

        double secondsSince(std::chrono::steady_clock::time_point start)
        {
            return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        }

        /// The error budget slider's steps: the Forest's budget ladder (FLIP per tree pixel over the
        /// reference's own; 0: the reference itself).
        const std::vector<float>& ERROR_BUDGETS = frameBudgetLadder();

        /// The slider step of `steps` nearest to `value`.
        std::size_t nearestStep(const std::vector<float>& steps, float value)
        {
            std::size_t best = 0;
            for (std::size_t i = 1; i < steps.size(); ++i)
                if (std::abs(steps[i] - value) < std::abs(steps[best] - value))
                    best = i;
            return best;
        }

        /// The transition slider's steps (Forest::setLodTransition; 0: hard switches).
        const std::vector<float> TRANSITIONS = {0.0f, 0.05f, 0.1f, 0.2f, 0.3f, 0.5f, 1.0f};

        /// The wind panel's steps (TreeLod::Wind): strength (0 calm, 1 a fresh breeze, 3 a gale), the
        /// direction it blows to (degrees from +X towards +Z), gustiness.
        const std::vector<float> WIND_STRENGTHS = {0.0f, 0.25f, 0.5f, 1.0f, 2.0f, 3.0f};
        const std::vector<float> WIND_DIRECTIONS = {0.0f, 45.0f, 90.0f, 135.0f, 180.0f, 225.0f, 270.0f, 315.0f};
        const std::vector<float> WIND_GUSTS = {0.0f, 0.25f, 0.5f, 0.75f, 1.0f};

        float windDirectionDegrees(const TreeLod::WindParameters& wind)
        {
            const float degrees = float(std::atan2(wind.direction.y, wind.direction.x) * 180.0 / 3.141592653589793);
            return degrees < 0.0f ? degrees + 360.0f : degrees;
        }

        std::string transitionCaption(float transition)
        {
            return transition > 0.0f ? Ogre::StringConverter::toString(transition) : "hard";
        }

        std::string biasCaption(int exponent)
        {
            char text[16];
            const double bias = std::ldexp(1.0, exponent);
            std::snprintf(text, sizeof text, bias < 1.0 ? "x%.3g" : "x%.0f", bias);
            return text;
        }
    }

    struct TreeLodBrowser::Thumbnail
    {
        Ogre::TexturePtr texture;
        Ogre::MaterialPtr material;
        Ogre::OverlayContainer* picture = nullptr; ///< SdkTrays/Picture: the image and its frame
        std::unique_ptr<OgreBites::Label> caption;
    };

    TreeLodBrowser::TreeLodBrowser(BrowserOptions options, SceneScript script, std::optional<SceneScript> terrainScript)
        : OgreBites::ApplicationContext("TreeLod sample browser"), mOptions(std::move(options)),
          mScript(std::move(script)), mTerrainScript(std::move(terrainScript))
    {
    }

    TreeLodBrowser::~TreeLodBrowser() = default;

    // ---- Ogre setup -------------------------------------------------------------------------

    void TreeLodBrowser::createRoot()
    {
        // Own LogManager first, else Ogre logs to stdout (OGRE-NOTES.md); no config or log files.
        mLogManager = createLogManager("", mOptions.verbose);
        mRoot = OGRE_NEW Ogre::Root("", "", "");
        loadRenderPlugins(*mRoot);
        mPlugin = std::make_unique<TreeLodPlugin>();
        mRoot->installPlugin(mPlugin.get());
        mOverlaySystem = OGRE_NEW Ogre::OverlaySystem();
    }

    bool TreeLodBrowser::oneTimeConfig()
    {
        // No config dialog: the render system loadRenderPlugins chose, windowed, the requested size.
        const Ogre::RenderSystemList& systems = mRoot->getAvailableRenderers();
        if (systems.empty())
            OGRE_EXCEPT(Ogre::Exception::ERR_RENDERINGAPI_ERROR, renderSystemPlugin() + " did not load",
                        "TreeLodBrowser::oneTimeConfig");
        Ogre::RenderSystem* rs = systems.front();
        rs->setConfigOption("Full Screen", "No");
        rs->setConfigOption("VSync", "No");
        rs->setConfigOption("Video Mode",
                            std::to_string(mOptions.width) + " x " + std::to_string(mOptions.height));
        mRoot->setRenderSystem(rs);
        return true;
    }

    OgreBites::NativeWindowPair TreeLodBrowser::createWindow(const Ogre::String& name, uint32_t, uint32_t,
                                                             Ogre::NameValuePairList miscParams)
    {
        if (!mOptions.headless)
            return OgreBites::ApplicationContext::createWindow(name, uint32_t(mOptions.width), uint32_t(mOptions.height),
                                                    miscParams);
        // Headless: a hidden 1x1 window owns the GL context; the screens render into a texture.
        OgreBites::NativeWindowPair pair =
            OgreBites::ApplicationContextBase::createWindow(name, 1, 1, hiddenWindowParams(miscParams));
        pair.render->setAutoUpdated(false);
        return pair;
    }

    void TreeLodBrowser::locateResources()
    {
        Ogre::ResourceGroupManager& rgm = Ogre::ResourceGroupManager::getSingleton();
        const std::string media = ogreMediaDirectory();
        rgm.addResourceLocation(media + "/packs/SdkTrays.zip", "Zip", "Essential");
        rgm.addResourceLocation(media + "/RTShaderLib/materials", "FileSystem", Ogre::RGN_INTERNAL);
        rgm.addResourceLocation(media + "/RTShaderLib/GLSL", "FileSystem", Ogre::RGN_INTERNAL);
        rgm.addResourceLocation(media + "/Terrain", "FileSystem", Ogre::RGN_INTERNAL); // the Terrain's GLSL includes
        addShadowVolumeLocation();
        addMaterialsLocations(materialsDirectory(), TREELOD_GROUP);
    }

    void TreeLodBrowser::setup()
    {
        OgreBites::ApplicationContext::setup(); // window, resources, RTSS, frame listener
        createTarget();
        createUi();
        if (!mOptions.headless)
        {
            addInputListener(this);
            if (mOptions.grabInput)
                setWindowGrab(true);
        }
        mBaker = std::make_unique<CacheTreeBaker>(
            mOptions.cacheDirectory.empty() ? defaultBakeCacheDirectory() : mOptions.cacheDirectory,
            [this](const std::string& step, float fraction) { showProgress(step, fraction); });
        TreeAssetManager::getSingleton().setBaker(mBaker.get());
        buildSamples();
        for (const BakeCacheEntry& entry : mBaker->getEntries())
            std::cout << "bake cache: " << entry.describe() << std::endl;
        createThumbnails();
        showMenu();
    }

    void TreeLodBrowser::createTarget()
    {
        if (!mOptions.headless)
        {
            mTarget = getRenderWindow();
            return;
        }
        mHeadlessTexture = Ogre::TextureManager::getSingleton().createManual(
            "TreeLod/Browser/Screen", Ogre::RGN_INTERNAL, Ogre::TEX_TYPE_2D, Ogre::uint(mOptions.width),
            Ogre::uint(mOptions.height), 0, Ogre::PF_BYTE_RGBA, Ogre::TU_RENDERTARGET);
        mTarget = mHeadlessTexture->getBuffer()->getRenderTarget();
        mTarget->setAutoUpdated(true);
    }

    void TreeLodBrowser::createUi()
    {
        // The trays' own scene: nothing but a camera; its viewport draws the overlays on top.
        mUiSceneManager = mRoot->createSceneManager(Ogre::DefaultSceneManagerFactory::FACTORY_TYPE_NAME,
                                                    "TreeLod/Browser/Ui");
        mUiSceneManager->addRenderQueueListener(mOverlaySystem);
        mUiCamera = mUiSceneManager->createCamera("TreeLod/Browser/UiCamera");
        mUiSceneManager->getRootSceneNode()->attachObject(mUiCamera);
        // The trays' materials have no shaders: GL3Plus draws them through RTSS.
        Ogre::RTShader::ShaderGenerator* shaderGenerator = Ogre::RTShader::ShaderGenerator::getSingletonPtr();
        if (!shaderGenerator)
            OGRE_EXCEPT(Ogre::Exception::ERR_FILE_NOT_FOUND,
                        "the RT shader system did not start (RTShaderLib not found under " +
                            ogreMediaDirectory() + ")",
                        "TreeLodBrowser::createUi");
        shaderGenerator->addSceneManager(mUiSceneManager);

        // The trays measure captions with the fonts' glyphs: load them first (unloaded, every
        // glyph measures as wide as it is tall and captions are cut and wrapped at half width).
        for (const char* font : {"SdkTrays/Caption", "SdkTrays/Value"})
            Ogre::FontManager::getSingleton().getByName(font, "Essential")->load();
        mTrays = std::make_unique<OgreBites::TrayManager>("TreeLod/Browser/Trays", getRenderWindow(), this);
        mTrays->setWidgetPadding(6.0f);
        if (mOptions.headless || !mOptions.grabInput)
            mTrays->hideCursor();
        else
            mTrays->showCursor();
        mCameraMan = std::make_unique<OgreBites::CameraMan>(mUiSceneManager->getRootSceneNode());
        mCameraMan->setStyle(OgreBites::CS_MANUAL);
        layoutScreen();
    }

    void TreeLodBrowser::shutdown()
    {
        TreeAssetManager* assets = TreeAssetManager::getSingletonPtr();
        if (assets)
            assets->setBaker(nullptr);
        if (mCurrent >= 0)
            mSamples[std::size_t(mCurrent)]->detach();
        mRenderControls.reset();
        for (auto& thumbnail : mThumbnails)
        {
            thumbnail->caption->cleanup();
            OgreBites::Widget::nukeOverlayElement(thumbnail->picture);
            Ogre::MaterialManager::getSingleton().remove(thumbnail->material);
            Ogre::TextureManager::getSingleton().remove(thumbnail->texture);
        }
        mThumbnails.clear();
        if (mMenuOverlay)
            Ogre::OverlayManager::getSingleton().destroy(mMenuOverlay);
        mMenuOverlay = nullptr;
        mSamples.clear();
        mCameraMan.reset();
        mTrays.reset();
        if (mTarget)
            mTarget->removeAllViewports();
        if (mHeadlessTexture)
            Ogre::TextureManager::getSingleton().remove(mHeadlessTexture);
        mHeadlessTexture.reset();
        mTarget = nullptr;
        if (mUiSceneManager)
        {
            Ogre::RTShader::ShaderGenerator::getSingleton().removeSceneManager(mUiSceneManager);
            mUiSceneManager->removeRenderQueueListener(mOverlaySystem);
            mRoot->destroySceneManager(mUiSceneManager);
            mUiSceneManager = nullptr;
        }
        OgreBites::ApplicationContext::shutdown();
        // The in-process plugin goes while the render system is still there (as OffscreenRenderer).
        if (mRoot && mPlugin)
        {
            mRoot->shutdown();
            mRoot->uninstallPlugin(mPlugin.get());
        }
    }

    // ---- samples ------------------------------------------------------------------------------

    void TreeLodBrowser::showProgress(const std::string& step, float fraction)
    {
        const std::string stage = step.substr(0, step.find(':'));
        if (stage != mProgressStep)
        {
            std::cout << step << std::endl;
            mProgressStep = stage;
        }
        if (!mProgressBar || mOptions.headless)
            return;
        static const auto start = std::chrono::steady_clock::now();
        const double now = secondsSince(start);
        if (now - mProgressShownAt < 0.1 && fraction < 1.0f)
            return;
        mProgressShownAt = now;
        mProgressBar->setComment(step);
        mProgressBar->setProgress(fraction);
        mTarget->update(); // as TrayManager's loading bar: draw the trays now
    }

    void TreeLodBrowser::buildSamples()
    {
        mProgressBar = mTrays->createProgressBar(OgreBites::TL_CENTER, "Progress", "Preparing the samples", 480, 320);
        SceneScript script = mScript;
        if (mOptions.shadowSize > 0)
            script.shadows.textureSize = int(mOptions.shadowSize);
        mSamples.push_back(std::make_unique<ForestSample>(*mRoot, script));
        if (mTerrainScript)
        {
            SceneScript terrain = *mTerrainScript;
            if (mOptions.shadowSize > 0)
                terrain.shadows.textureSize = int(mOptions.shadowSize);
            mSamples.push_back(std::make_unique<TerrainSample>(*mRoot, terrain));
        }
        auto view = std::make_shared<SingleTreeView>(*mRoot, mOptions.tree, mOptions.shadowSize > 0 ? mOptions.shadowSize : 2048);
        for (const TechniqueInfo& info : TechniqueRegistry::getSingleton().getTechniques())
            mSamples.push_back(std::make_unique<TechniqueSample>(view, info.name));
        auto progress = [this](const std::string& step, float fraction) { showProgress(step, fraction); };
        // The single tree first: it asks for every chunk of its tree at once (SingleTreeView::build).
        for (std::size_t i = mSamples.size(); i-- > 0;)
            mSamples[i]->build(progress);
        mTrays->destroyWidget(mProgressBar);
        mProgressBar = nullptr;
    }

    void TreeLodBrowser::createThumbnails()
    {
        Ogre::OverlayManager& overlays = Ogre::OverlayManager::getSingleton();
        mMenuOverlay = overlays.create("TreeLod/Browser/Menu");
        mMenuOverlay->setZOrder(150); // above the trays' backdrop, below the trays
        Ogre::TextureManager& textures = Ogre::TextureManager::getSingleton();
        for (std::size_t i = 0; i < mSamples.size(); ++i)
        {
            auto thumbnail = std::make_unique<Thumbnail>();
            const Ogre::String name = "TreeLod/Browser/Thumbnail/" + std::to_string(i);
            thumbnail->texture = textures.createManual(name, Ogre::RGN_INTERNAL, Ogre::TEX_TYPE_2D, THUMBNAIL_WIDTH,
                                                       THUMBNAIL_HEIGHT, 0, Ogre::PF_BYTE_RGBA, Ogre::TU_RENDERTARGET);
            Ogre::RenderTarget* rt = thumbnail->texture->getBuffer()->getRenderTarget();
            rt->setAutoUpdated(false);
            mSamples[i]->renderThumbnail(*rt);

            thumbnail->material = Ogre::MaterialManager::getSingleton().create(name, Ogre::RGN_INTERNAL);
            Ogre::Pass* pass = thumbnail->material->getTechnique(0)->getPass(0);
            pass->setLightingEnabled(false);
            pass->setDepthCheckEnabled(false);
            pass->createTextureUnitState(name)->setTextureAddressingMode(Ogre::TextureUnitState::TAM_CLAMP);

            thumbnail->picture = static_cast<Ogre::OverlayContainer*>(
                overlays.createOverlayElementFromTemplate("SdkTrays/Picture", "Panel", name));
            thumbnail->picture->setMaterialName(name, Ogre::RGN_INTERNAL);
            thumbnail->picture->setHorizontalAlignment(Ogre::GHA_LEFT);
            thumbnail->picture->setVerticalAlignment(Ogre::GVA_TOP);
            mMenuOverlay->add2D(thumbnail->picture);
            thumbnail->caption = std::make_unique<OgreBites::Label>(name + "/Caption", mSamples[i]->getTitle(), 100.0f);
            thumbnail->caption->getOverlayElement()->setHorizontalAlignment(Ogre::GHA_LEFT);
            mMenuOverlay->add2D(static_cast<Ogre::OverlayContainer*>(thumbnail->caption->getOverlayElement()));
            mThumbnails.push_back(std::move(thumbnail));
        }
    }

    void TreeLodBrowser::layoutThumbnails()
    {
        if (mThumbnails.empty() || !mTarget)
            return;
        const int areaLeft = COLUMN_WIDTH, areaWidth = int(mTarget->getWidth()) - COLUMN_WIDTH;
        const int areaHeight = int(mTarget->getHeight());
        const int count = int(mThumbnails.size());
        const int columns = std::min(3, count), rows = (count + columns - 1) / columns;
        const int gap = 24, captionHeight = 40;
        int width = (areaWidth - (columns + 1) * gap) / columns;
        int height = width * THUMBNAIL_HEIGHT / THUMBNAIL_WIDTH;
        const int maxHeight = (areaHeight - (rows + 1) * gap) / rows - captionHeight;
        if (height > maxHeight)
        {
            height = std::max(40, maxHeight);
            width = height * THUMBNAIL_WIDTH / THUMBNAIL_HEIGHT;
        }
        const int left0 = areaLeft + (areaWidth - columns * width - (columns - 1) * gap) / 2;
        const int top0 = (areaHeight - rows * (height + captionHeight) - (rows - 1) * gap) / 2;
        for (int i = 0; i < count; ++i)
        {
            Thumbnail& t = *mThumbnails[std::size_t(i)];
            const int x = left0 + (i % columns) * (width + gap), y = top0 + (i / columns) * (height + captionHeight + gap);
            t.picture->setPosition(Ogre::Real(x), Ogre::Real(y));
            t.picture->setDimensions(Ogre::Real(width), Ogre::Real(height));
            auto* frame = static_cast<Ogre::BorderPanelOverlayElement*>(
                t.picture->getChild(t.picture->getName() + "/PictureFrame"));
            frame->setDimensions(Ogre::Real(width + 16), Ogre::Real(height + 16));
            const bool selected = i == mSelected;
            frame->setMaterialName(selected ? "SdkTrays/Frame/Over" : "SdkTrays/Frame");
            frame->setBorderMaterialName(selected ? "SdkTrays/Frame/Over" : "SdkTrays/Frame");
            t.caption->getOverlayElement()->setPosition(Ogre::Real(x), Ogre::Real(y + height + 8));
            t.caption->getOverlayElement()->setWidth(Ogre::Real(width));
        }
    }

    int TreeLodBrowser::thumbnailAt(const Ogre::Vector2& cursor) const
    {
        for (std::size_t i = 0; i < mThumbnails.size(); ++i)
            if (OgreBites::Widget::isCursorOver(mThumbnails[i]->picture, cursor, 0))
                return int(i);
        return -1;
    }

    Ogre::Vector2 TreeLodBrowser::cursorPosition() const
    {
        return Ogre::Vector2(mTrays->getCursorContainer()->getLeft(), mTrays->getCursorContainer()->getTop());
    }

    // ---- screens -----------------------------------------------------------------------------

    void TreeLodBrowser::layoutScreen()
    {
        if (!mTarget)
            return;
        if (mCurrent >= 0)
            mSamples[std::size_t(mCurrent)]->detach();
        mTarget->removeAllViewports();
        const int width = int(mTarget->getWidth()), height = int(mTarget->getHeight());
        const PixelRect area{COLUMN_WIDTH, 0, width - COLUMN_WIDTH, height};
        // Background viewports render the trays' empty scene with nothing visible: a viewport
        // without a camera is not even cleared.
        auto background = [&](int zOrder, const PixelRect& rect, const Ogre::ColourValue& colour) {
            Ogre::Viewport* vp = addViewport(*mTarget, mUiCamera, zOrder, rect);
            vp->setBackgroundColour(colour);
            vp->setOverlaysEnabled(false);
            vp->setShadowsEnabled(false);
            vp->setVisibilityMask(0);
        };
        if (mCurrent >= 0)
            mSamples[std::size_t(mCurrent)]->attach(*mTarget, area, SAMPLE_Z);
        else
            background(SAMPLE_Z, area, MENU_COLOUR);
        background(COLUMN_Z, {0, 0, COLUMN_WIDTH, height}, COLUMN_COLOUR);
        Ogre::Viewport* ui = addViewport(*mTarget, mUiCamera, UI_Z, {0, 0, width, height});
        ui->setClearEveryFrame(true, Ogre::FBT_DEPTH);
        ui->setOverlaysEnabled(true);
        ui->setShadowsEnabled(false);
        ui->setSkiesEnabled(false);
        ui->setVisibilityMask(0);
        ui->setMaterialScheme(Ogre::RTShader::ShaderGenerator::DEFAULT_SCHEME_NAME);
        layoutThumbnails();
    }

    void TreeLodBrowser::showMenu()
    {
        if (mCurrent >= 0)
            mSamples[std::size_t(mCurrent)]->detach();
        mCurrent = -1;
        mRenderControls.reset();
        mCameraMan->setStyle(OgreBites::CS_MANUAL);
        mCameraMan->setCamera(mUiSceneManager->getRootSceneNode());
        mTrays->destroyAllWidgets();
        mTechniqueMenu = nullptr;
        mLodBiasSlider = nullptr;
        mErrorBudgetSlider = nullptr;
        mTransitionSlider = nullptr;
        mWindSlider = mWindDirectionSlider = mGustSlider = nullptr;
        mShadowsBox = mWireframeBox = mFreezeBox = nullptr;
        mPlayButton = nullptr;
        mStatsPanel = nullptr;
        mHistogramBox = nullptr;

        mTrays->createLabel(OgreBites::TL_TOPLEFT, "Title", "TreeLod samples", WIDGET_WIDTH);
        Ogre::StringVector titles;
        for (const auto& sample : mSamples)
            titles.push_back(sample->getTitle());
        mSampleMenu = mTrays->createThickSelectMenu(OgreBites::TL_TOPLEFT, "Samples", "Sample", WIDGET_WIDTH, 8, titles);
        mTrays->createButton(OgreBites::TL_TOPLEFT, "Start", "Start sample", WIDGET_WIDTH);
        mDescription = mTrays->createTextBox(OgreBites::TL_TOPLEFT, "Description", "About this sample", WIDGET_WIDTH,
                                             std::max(160.0f, float(mTarget->getHeight()) - 330.0f));
        if (!mOptions.headless)
            mTrays->createButton(OgreBites::TL_BOTTOMLEFT, "Quit", "Quit", WIDGET_WIDTH);
        mTrays->showBackdrop("SdkTrays/Bands");
        mMenuOverlay->show();
        layoutScreen();
        selectSample(mSelected);
    }

    void TreeLodBrowser::selectSample(int index)
    {
        if (mSamples.empty())
            return;
        mSelected = (index % int(mSamples.size()) + int(mSamples.size())) % int(mSamples.size());
        if (mSampleMenu && mSampleMenu->getSelectionIndex() != mSelected)
            mSampleMenu->selectItem(std::size_t(mSelected), false);
        if (mDescription)
        {
            mDescription->setCaption(mSamples[std::size_t(mSelected)]->getTitle());
            mDescription->setText(mSamples[std::size_t(mSelected)]->getDescription());
        }
        layoutThumbnails();
    }

    void TreeLodBrowser::runSample(int index)
    {
        if (mCurrent >= 0)
            mSamples[std::size_t(mCurrent)]->detach();
        mSelected = mCurrent = index;
        BrowserSample& sample = *mSamples[std::size_t(index)];
        mMenuOverlay->hide();
        mTrays->hideBackdrop();
        mRenderControls.reset(); // its details panel is a tray widget: destroy it first
        mTrays->destroyAllWidgets();
        mSampleMenu = nullptr;
        mDescription = nullptr;
        createSampleControls();
        layoutScreen();
        syncControls();

        mCameraMan->setStyle(OgreBites::CS_MANUAL);
        mCameraMan->setCamera(&sample.getCameraNode());
        mCameraMan->setTopSpeed(sample.getCameraSpeed());
        if (Ogre::SceneNode* target = sample.getOrbitTarget())
        {
            mCameraMan->setTarget(target);
            mCameraMan->setStyle(OgreBites::CS_ORBIT);
        }
        else
            mCameraMan->setStyle(OgreBites::CS_FREELOOK);
        if (!mOptions.headless)
            mRenderControls = std::make_unique<OgreBites::AdvancedRenderControls>(mTrays.get(), &sample.getCamera());
    }

    void TreeLodBrowser::createSampleControls()
    {
        BrowserSample& sample = *mSamples[std::size_t(mCurrent)];
        using namespace OgreBites;
        mPlayButton = nullptr;
        mTrays->createButton(TL_TOPLEFT, "Back", "< Samples (Esc)", WIDGET_WIDTH);
        mTrays->createLabel(TL_TOPLEFT, "SampleTitle", sample.getTitle(), WIDGET_WIDTH);
        mTechniqueMenu = mTrays->createLongSelectMenu(TL_TOPLEFT, "Technique", "Technique", WIDGET_WIDTH, 150.0f,
                                                      10, sample.getTechniques());
        mLodBiasSlider = mTrays->createLongSlider(TL_TOPLEFT, "LodBias", "LoD bias ([ ])", WIDGET_WIDTH, 60.0f, 54.0f,
                                                  -4.0f, 4.0f, 9);
        mErrorBudgetSlider = nullptr;
        if (sample.hasErrorBudget())
            mErrorBudgetSlider = mTrays->createLongSlider(TL_TOPLEFT, "ErrorBudget", "Error budget", WIDGET_WIDTH,
                                                          60.0f, 54.0f, 0.0f, float(ERROR_BUDGETS.size() - 1),
                                                          unsigned(ERROR_BUDGETS.size()));
        mTransitionSlider = nullptr;
        if (sample.hasLodTransition())
            mTransitionSlider = mTrays->createLongSlider(TL_TOPLEFT, "Transition", "Transitions (X)", WIDGET_WIDTH,
                                                         60.0f, 54.0f, 0.0f, float(TRANSITIONS.size() - 1),
                                                         unsigned(TRANSITIONS.size()));
        mShadowsBox = mTrays->createCheckBox(TL_TOPLEFT, "Shadows", "Shadows (H)", WIDGET_WIDTH);
        mWireframeBox = mTrays->createCheckBox(TL_TOPLEFT, "Wireframe", "Wireframe (R)", WIDGET_WIDTH);
        mFreezeBox = mTrays->createCheckBox(TL_TOPLEFT, "FreezeLod", "Freeze LoD (L)", WIDGET_WIDTH);
        if (sample.hasCameraPath())
            mPlayButton = mTrays->createButton(TL_TOPLEFT, "Play", "Pause path (Space)", WIDGET_WIDTH);

        if (mWindPanelShown)
            showWindPanel(true);

        mStatsPanel = mTrays->createParamsPanel(TL_BOTTOMLEFT, "Stats", WIDGET_WIDTH, 8);
        mHistogramBox = mTrays->createTextBox(TL_BOTTOMLEFT, "Levels", "LoD levels in use", WIDGET_WIDTH,
                                              float(52 + 19 * HISTOGRAM_LINES));
    }

    void TreeLodBrowser::syncControls()
    {
        if (mCurrent < 0)
            return;
        BrowserSample& sample = *mSamples[std::size_t(mCurrent)];
        const std::vector<std::string> techniques = sample.getTechniques();
        const auto at = std::find(techniques.begin(), techniques.end(), sample.getTechnique());
        if (at != techniques.end())
            mTechniqueMenu->selectItem(std::size_t(at - techniques.begin()), false);
        const int exponent = int(std::lround(std::log2(std::max(1e-3f, sample.getLodBias()))));
        mLodBiasSlider->setValue(Ogre::Real(exponent), false);
        mLodBiasSlider->setValueCaption(biasCaption(exponent));
        if (mErrorBudgetSlider)
        {
            const std::size_t step = nearestStep(ERROR_BUDGETS, sample.getErrorBudget());
            mErrorBudgetSlider->setValue(Ogre::Real(step), false);
            mErrorBudgetSlider->setValueCaption(Ogre::StringConverter::toString(ERROR_BUDGETS[step]));
        }
        if (mTransitionSlider)
        {
            const std::size_t step = nearestStep(TRANSITIONS, sample.getLodTransition());
            mTransitionSlider->setValue(Ogre::Real(step), false);
            mTransitionSlider->setValueCaption(transitionCaption(TRANSITIONS[step]));
        }
        syncWindControls();
        mShadowsBox->setChecked(sample.getShadows(), false);
        mWireframeBox->setChecked(sample.getWireframe(), false);
        mFreezeBox->setChecked(sample.isLodFrozen(), false);
        if (mPlayButton)
            mPlayButton->setCaption(sample.isPlaying() ? "Pause path (Space)" : "Play path (Space)");
    }

    void TreeLodBrowser::showWindPanel(bool shown)
    {
        using namespace OgreBites;
        mWindPanelShown = shown;
        if (!shown)
        {
            for (Slider** slider : {&mWindSlider, &mWindDirectionSlider, &mGustSlider})
                if (*slider)
                {
                    mTrays->destroyWidget(*slider);
                    *slider = nullptr;
                }
            return;
        }
        if (mWindSlider)
            return;
        // On the right, over the picture (a split view's heat map too): shown on request only.
        mWindSlider = mTrays->createLongSlider(TL_TOPRIGHT, "Wind", "Wind strength", WIDGET_WIDTH, 60.0f, 54.0f, 0.0f,
                                               float(WIND_STRENGTHS.size() - 1), unsigned(WIND_STRENGTHS.size()));
        mWindDirectionSlider = mTrays->createLongSlider(TL_TOPRIGHT, "WindDirection", "Blowing to", WIDGET_WIDTH, 60.0f,
                                                        54.0f, 0.0f, float(WIND_DIRECTIONS.size() - 1),
                                                        unsigned(WIND_DIRECTIONS.size()));
        mGustSlider = mTrays->createLongSlider(TL_TOPRIGHT, "Gusts", "Gusts", WIDGET_WIDTH, 60.0f, 54.0f, 0.0f,
                                               float(WIND_GUSTS.size() - 1), unsigned(WIND_GUSTS.size()));
        syncWindControls();
    }

    void TreeLodBrowser::syncWindControls()
    {
        if (!mWindSlider)
            return;
        const TreeLod::WindParameters& wind = TreeLod::Wind::getParameters();
        const std::size_t strength = nearestStep(WIND_STRENGTHS, wind.strength);
        mWindSlider->setValue(Ogre::Real(strength), false);
        mWindSlider->setValueCaption(wind.calm() ? "calm" : Ogre::StringConverter::toString(wind.strength));
        const std::size_t direction = nearestStep(WIND_DIRECTIONS, windDirectionDegrees(wind));
        mWindDirectionSlider->setValue(Ogre::Real(direction), false);
        mWindDirectionSlider->setValueCaption(Ogre::StringConverter::toString(WIND_DIRECTIONS[direction]) + " deg");
        const std::size_t gusts = nearestStep(WIND_GUSTS, wind.gustiness);
        mGustSlider->setValue(Ogre::Real(gusts), false);
        mGustSlider->setValueCaption(Ogre::StringConverter::toString(wind.gustiness));
    }

    void TreeLodBrowser::setWindFromControls()
    {
        auto step = [](const std::vector<float>& steps, OgreBites::Slider* slider) {
            return steps[std::min(steps.size() - 1, std::size_t(std::lround(slider->getValue())))];
        };
        TreeLod::WindParameters wind = TreeLod::Wind::getParameters();
        wind.strength = step(WIND_STRENGTHS, mWindSlider);
        const double radians = double(step(WIND_DIRECTIONS, mWindDirectionSlider)) * 3.141592653589793 / 180.0;
        wind.direction = {float(std::cos(radians)), float(std::sin(radians))};
        wind.gustiness = step(WIND_GUSTS, mGustSlider);
        TreeLod::Wind::setParameters(wind);
        syncWindControls();
    }

    void TreeLodBrowser::setLodBiasExponent(int exponent)
    {
        exponent = std::clamp(exponent, -4, 4);
        mSamples[std::size_t(mCurrent)]->setLodBias(float(std::ldexp(1.0, exponent)));
        mLodBiasSlider->setValue(Ogre::Real(exponent), false);
        mLodBiasSlider->setValueCaption(biasCaption(exponent));
    }

    void TreeLodBrowser::updateStats()
    {
        if (mCurrent < 0 || !mStatsPanel)
            return;
        BrowserSample& sample = *mSamples[std::size_t(mCurrent)];
        std::vector<std::pair<std::string, std::string>> stats = sample.getStats();
        char fps[48];
        std::snprintf(fps, sizeof fps, "%.1f (%.1f ms)", mFrameSeconds > 0.0 ? 1.0 / mFrameSeconds : 0.0,
                      mFrameSeconds * 1000.0);
        stats.insert(stats.begin(), {"FPS (render)", fps});
        const ResidentMemory memory = residentMemory();
        char resident[48];
        std::snprintf(resident, sizeof resident, "%.0f MiB, peak %.0f", memory.currentMiB, memory.peakMiB);
        stats.push_back({"Resident", resident});
        Ogre::StringVector names, values;
        for (const auto& [name, value] : stats)
        {
            names.push_back(name);
            values.push_back(value);
        }
        if (mStatsPanel->getAllParamNames() != names)
            mStatsPanel->setAllParamNames(names);
        mStatsPanel->setAllParamValues(values);
        std::string text;
        const std::vector<std::string> lines = sample.getLevelHistogram();
        for (std::size_t i = 0; i < lines.size() && i < std::size_t(HISTOGRAM_LINES); ++i)
            text += (i ? "\n" : "") + lines[i];
        if (lines.size() > std::size_t(HISTOGRAM_LINES))
            text += "\n(+" + std::to_string(lines.size() - HISTOGRAM_LINES) + " more)";
        if (mHistogramBox->getText() != text)
            mHistogramBox->setText(text);
    }

    // ---- frames --------------------------------------------------------------------------------

    bool TreeLodBrowser::frameStarted(const Ogre::FrameEvent& evt)
    {
        OgreBites::ApplicationContext::frameStarted(evt); // input events
        // Screen changes wait for the next frame: a tray callback must not destroy its own widget.
        if (mPendingScreen == MENU_SCREEN)
            showMenu();
        else if (mPendingScreen >= 0)
            runSample(mPendingScreen);
        mPendingScreen = NO_SCREEN;
        if (mCurrent >= 0)
        {
            const double seconds = mFixedFrameSeconds.value_or(double(evt.timeSinceLastFrame));
            TreeLod::Wind::setTime(TreeLod::Wind::getTime() + seconds);
            mSamples[std::size_t(mCurrent)]->frame(seconds);
            updateStats();
        }
        mFrameStart = std::chrono::steady_clock::now();
        return true;
    }

    bool TreeLodBrowser::frameEnded(const Ogre::FrameEvent&)
    {
        const double seconds = secondsSince(mFrameStart);
        mFrameSeconds = mFrameSeconds > 0.0 && !mOptions.headless ? 0.9 * mFrameSeconds + 0.1 * seconds : seconds;
        if (mCurrent >= 0)
            mSamples[std::size_t(mCurrent)]->frameTimed(seconds);
        return true;
    }

    void TreeLodBrowser::frameRendered(const Ogre::FrameEvent& evt)
    {
        mTrays->frameRendered(evt);
        if (mCurrent >= 0)
            mCameraMan->frameRendered(evt);
    }

    void TreeLodBrowser::windowResized(Ogre::RenderWindow*) { layoutScreen(); }

    std::vector<std::string> TreeLodBrowser::writeScreenshots()
    {
        namespace fs = std::filesystem;
        fs::create_directories(mOptions.screenshots);
        std::vector<std::string> written;
        auto shoot = [&](const std::string& name) {
            // Until nothing is arriving (bakes, levels within the upload budget), then two frames:
            // the stats panel shows what the frame before measured.
            for (int f = 0; f < 200 && mCurrent >= 0 && !mSamples[std::size_t(mCurrent)]->isSettled(); ++f)
                mRoot->renderOneFrame();
            mRoot->renderOneFrame();
            mRoot->renderOneFrame();
            const std::string path = (fs::path(mOptions.screenshots) / name).string();
            savePng(path);
            written.push_back(path);
            std::cout << "wrote " << path << std::endl;
        };
        showMenu();
        selectSample(0);
        shoot("menu.png");
        for (std::size_t i = 0; i < mSamples.size(); ++i)
        {
            BrowserSample& sample = *mSamples[i];
            runSample(int(i));
            if (sample.isSplitView())
            {
                sample.setScreenshotView(0, 1);
                shoot("split-" + sample.getTechnique() + ".png");
                continue;
            }
            for (unsigned f = 0; f < mOptions.frames; ++f)
            {
                sample.setScreenshotView(f, mOptions.frames);
                syncControls();
                char number[16];
                std::snprintf(number, sizeof number, "-%03u.png", f);
                shoot(sample.getScreenshotPrefix() + number);
            }
        }
        return written;
    }

    TreeLodBrowser::SoakMemory TreeLodBrowser::measureMemory()
    {
        // Free memory the allocator holds (glibc keeps freed blocks, and each thread's arena, resident)
        // is returned first: what stays is what the process holds.
        malloc_trim(0);
        const struct mallinfo2 heap = mallinfo2();
        return {residentMemory().currentMiB, double(heap.uordblks + heap.hblkhd) / (1024.0 * 1024.0)};
    }

    TreeLodBrowser::SoakReport TreeLodBrowser::soak(unsigned switches)
    {
        SoakReport report;
        const auto start = std::chrono::steady_clock::now();
        // Every pass draws the same frames on any machine: each switch is drawn with the sample's
        // time stopped until the sample has settled (bakes and level builds on worker threads
        // take as long as they take: no frame count limits the wait, so no load carries over
        // into the next switch), then three frames of 0.2 s each, as a user who stops to look
        // sees it (a split view computes its difference image after
        // SingleTreeView::RECOMPUTE_DELAY, 0.3 s, still).
        constexpr double SETTLE_LIMIT_SECONDS = 600.0;
        unsigned passes = 0;
        auto settle = [&] {
            int frames = 0;
            mFixedFrameSeconds = 0.0;
            const auto switched = std::chrono::steady_clock::now();
            for (; mCurrent >= 0 && !mSamples[std::size_t(mCurrent)]->isSettled(); ++frames)
            {
                if (secondsSince(switched) > SETTLE_LIMIT_SECONDS)
                    OGRE_EXCEPT(Ogre::Exception::ERR_INVALID_STATE,
                                "soak: '" + mSamples[std::size_t(mCurrent)]->getTitle() + "' did not settle in " +
                                    std::to_string(int(SETTLE_LIMIT_SECONDS)) + " s",
                                "TreeLodBrowser::soak");
                mRoot->renderOneFrame();
            }
            mFixedFrameSeconds = 0.2;
            for (int still = 0; still < 3; ++still, ++frames)
                mRoot->renderOneFrame();
            if (++report.switches % 25 == 0)
                std::fprintf(stderr, "soak: %u of %u switches, %.1f s (%s: %d frames)\n", report.switches, switches,
                             secondsSince(start), mSamples[std::size_t(mCurrent)]->getTitle().c_str(), frames);
        };
        while (report.switches < switches)
        {
            for (std::size_t i = 0; i < mSamples.size() && report.switches < switches; ++i)
            {
                mPendingScreen = MENU_SCREEN;
                mRoot->renderOneFrame();
                mPendingScreen = int(i);
                settle();
                // Through the technique menu, as the N key does: a split view moves to that
                // technique's sample, the forest switches in place.
                const std::size_t techniques = mTechniqueMenu ? mTechniqueMenu->getNumItems() : 0;
                for (std::size_t t = 1; t < techniques && report.switches < switches; ++t)
                {
                    mTechniqueMenu->selectItem((std::size_t(mTechniqueMenu->getSelectionIndex()) + 1) % techniques);
                    settle();
                }
                // Level transitions on and off, as the X key does.
                if (mTransitionSlider && report.switches < switches)
                {
                    const std::size_t now = std::size_t(std::lround(mTransitionSlider->getValue()));
                    mTransitionSlider->setValue(Ogre::Real(now == 0 ? nearestStep(TRANSITIONS, mLastTransition) : 0));
                    settle();
                }
            }
            const SoakMemory pass = measureMemory();
            std::fprintf(stderr, "soak: after %u switches %.1f MiB resident, %.1f MiB heap in use\n", report.switches,
                         pass.residentMiB, pass.heapMiB);
            if (++passes == SOAK_WARM_UP_PASSES)
            {
                report.warmUpSwitches = report.switches;
                report.afterWarmUp = pass;
            }
        }
        report.end = measureMemory();
        report.peakMiB = residentMemory().peakMiB;
        mFixedFrameSeconds.reset();
        if (passes < SOAK_WARM_UP_PASSES)
        {
            std::fprintf(stderr, "soak: %u switches end within the warm-up (%u passes): growth is from the end\n",
                         report.switches, SOAK_WARM_UP_PASSES);
            report.warmUpSwitches = report.switches;
            report.afterWarmUp = report.end;
        }
        std::printf("soak: %u switches; after the warm-up (%u switches) %.1f MiB resident, %.1f MiB heap in use; "
                    "at the end %.1f MiB resident (%+.1f), %.1f MiB heap in use (%+.1f); peak %.1f MiB resident\n",
                    report.switches, report.warmUpSwitches, report.afterWarmUp.residentMiB,
                    report.afterWarmUp.heapMiB, report.end.residentMiB,
                    report.end.residentMiB - report.afterWarmUp.residentMiB, report.end.heapMiB,
                    report.end.heapMiB - report.afterWarmUp.heapMiB, report.peakMiB);
        std::fflush(stdout);
        return report;
    }

    void TreeLodBrowser::savePng(const std::string& path)
    {
        RgbaImage image;
        image.width = int(mTarget->getWidth());
        image.height = int(mTarget->getHeight());
        image.pixels.resize(std::size_t(image.width) * image.height * 4);
        Ogre::PixelBox box(Ogre::uint32(image.width), Ogre::uint32(image.height), 1, Ogre::PF_BYTE_RGBA,
                           image.pixels.data());
        mTarget->copyContentsToMemory(Ogre::Box(0, 0, Ogre::uint32(image.width), Ogre::uint32(image.height)), box,
                                      Ogre::RenderTarget::FB_AUTO);
        for (std::size_t i = 3; i < image.pixels.size(); i += 4)
            image.pixels[i] = 255; // overlays blend into alpha too; the screen is opaque
        OffscreenRenderer::savePng(image, path);
    }

    // ---- input ---------------------------------------------------------------------------------

    bool TreeLodBrowser::keyPressed(const OgreBites::KeyboardEvent& evt)
    {
        const OgreBites::Keycode key = evt.keysym.sym;
        if (mTrays->isDialogVisible())
            return true;
        if (mCurrent < 0)
        {
            if (key == OgreBites::SDLK_ESCAPE)
                mRoot->queueEndRendering();
            else if (key == OgreBites::SDLK_UP || key == OgreBites::SDLK_LEFT)
                selectSample(mSelected - 1);
            else if (key == OgreBites::SDLK_DOWN || key == OgreBites::SDLK_RIGHT)
                selectSample(mSelected + 1);
            else if (key == OgreBites::SDLK_RETURN || key == OgreBites::SDLK_KP_ENTER)
                mPendingScreen = mSelected;
            return true;
        }
        BrowserSample& sample = *mSamples[std::size_t(mCurrent)];
        if (key == OgreBites::SDLK_ESCAPE)
            mPendingScreen = MENU_SCREEN;
        else if (key == 'n')
            mTechniqueMenu->selectItem((std::size_t(mTechniqueMenu->getSelectionIndex()) + 1) % mTechniqueMenu->getNumItems());
        else if (key == '[' || key == ']')
            setLodBiasExponent(int(std::lround(mLodBiasSlider->getValue())) + (key == ']' ? 1 : -1));
        else if (key == 'h')
            mShadowsBox->toggle();
        else if (key == 'r')
            mWireframeBox->toggle();
        else if (key == 'l')
            mFreezeBox->toggle();
        else if (key == 'b')
            showWindPanel(!mWindPanelShown);
        else if (key == 'x' && mTransitionSlider)
        {
            // Hard switches and back to the last transition length.
            const float now = sample.getLodTransition();
            if (now > 0.0f)
                mLastTransition = now;
            mTransitionSlider->setValue(Ogre::Real(nearestStep(TRANSITIONS, now > 0.0f ? 0.0f : mLastTransition)));
        }
        else if (key == OgreBites::SDLK_SPACE && sample.hasCameraPath())
            buttonHit(mPlayButton);
        else
        {
            if (mRenderControls)
                mRenderControls->keyPressed(evt);
            mCameraMan->keyPressed(evt);
        }
        return true;
    }

    bool TreeLodBrowser::keyReleased(const OgreBites::KeyboardEvent& evt)
    {
        if (mCurrent >= 0)
            mCameraMan->keyReleased(evt);
        return true;
    }

    bool TreeLodBrowser::mouseMoved(const OgreBites::MouseMotionEvent& evt)
    {
        if (mTrays->mouseMoved(evt))
            return true;
        if (mCurrent >= 0 && (mCameraMan->getStyle() == OgreBites::CS_ORBIT || mDragLook))
            mCameraMan->mouseMoved(evt);
        return true;
    }

    bool TreeLodBrowser::mousePressed(const OgreBites::MouseButtonEvent& evt)
    {
        if (mTrays->mousePressed(evt))
            return true;
        if (mCurrent < 0)
        {
            const int hit = evt.button == OgreBites::BUTTON_LEFT ? thumbnailAt(cursorPosition()) : -1;
            if (hit >= 0 && hit == mSelected)
                mPendingScreen = hit;
            else if (hit >= 0)
                selectSample(hit);
            return true;
        }
        if (mCameraMan->getStyle() == OgreBites::CS_FREELOOK && evt.button == OgreBites::BUTTON_LEFT)
        {
            mDragLook = true; // as SdkSample's drag look
            mTrays->hideCursor();
        }
        mCameraMan->mousePressed(evt);
        return true;
    }

    bool TreeLodBrowser::mouseReleased(const OgreBites::MouseButtonEvent& evt)
    {
        if (mTrays->mouseReleased(evt))
            return true;
        if (mDragLook && evt.button == OgreBites::BUTTON_LEFT)
        {
            mDragLook = false;
            if (mOptions.grabInput)
                mTrays->showCursor();
        }
        if (mCurrent >= 0)
            mCameraMan->mouseReleased(evt);
        return true;
    }

    bool TreeLodBrowser::mouseWheelRolled(const OgreBites::MouseWheelEvent& evt)
    {
        if (mTrays->mouseWheelRolled(evt))
            return true;
        if (mCurrent >= 0)
            mCameraMan->mouseWheelRolled(evt);
        return true;
    }

    // ---- trays ---------------------------------------------------------------------------------

    void TreeLodBrowser::buttonHit(OgreBites::Button* button)
    {
        const Ogre::String& name = button->getName();
        if (name == "Start")
            mPendingScreen = mSelected;
        else if (name == "Quit")
            mRoot->queueEndRendering();
        else if (name == "Back")
            mPendingScreen = MENU_SCREEN;
        else if (name == "Play" && mCurrent >= 0)
        {
            BrowserSample& sample = *mSamples[std::size_t(mCurrent)];
            sample.setPlaying(!sample.isPlaying());
            syncControls();
        }
    }

    void TreeLodBrowser::itemSelected(OgreBites::SelectMenu* menu)
    {
        if (menu == mSampleMenu)
            selectSample(menu->getSelectionIndex());
        else if (menu == mTechniqueMenu && mCurrent >= 0)
        {
            BrowserSample& sample = *mSamples[std::size_t(mCurrent)];
            const std::string technique = menu->getSelectedItem();
            if (technique == sample.getTechnique())
                return;
            if (!sample.isSplitView())
            {
                sample.setTechnique(technique);
                return;
            }
            // Split views: the technique's own sample (same view state).
            for (std::size_t i = 0; i < mSamples.size(); ++i)
                if (mSamples[i]->isSplitView() && mSamples[i]->getTechnique() == technique)
                {
                    mPendingScreen = int(i);
                    return;
                }
        }
    }

    void TreeLodBrowser::sliderMoved(OgreBites::Slider* slider)
    {
        if (slider == mLodBiasSlider && mCurrent >= 0)
            setLodBiasExponent(int(std::lround(slider->getValue())));
        if (slider == mTransitionSlider && mCurrent >= 0)
        {
            const float transition = TRANSITIONS[std::min(TRANSITIONS.size() - 1, std::size_t(std::lround(slider->getValue())))];
            mSamples[std::size_t(mCurrent)]->setLodTransition(transition);
            slider->setValueCaption(transitionCaption(transition));
        }
        if ((slider == mWindSlider || slider == mWindDirectionSlider || slider == mGustSlider) && mCurrent >= 0)
            setWindFromControls();
        if (slider == mErrorBudgetSlider && mCurrent >= 0)
        {
            const std::size_t step = std::min(ERROR_BUDGETS.size() - 1, std::size_t(std::lround(slider->getValue())));
            mSamples[std::size_t(mCurrent)]->setErrorBudget(ERROR_BUDGETS[step]);
            slider->setValueCaption(Ogre::StringConverter::toString(ERROR_BUDGETS[step]));
        }
    }

    void TreeLodBrowser::checkBoxToggled(OgreBites::CheckBox* box)
    {
        if (mCurrent < 0)
            return;
        BrowserSample& sample = *mSamples[std::size_t(mCurrent)];
        if (box == mShadowsBox)
            sample.setShadows(box->isChecked());
        else if (box == mWireframeBox)
            sample.setWireframe(box->isChecked());
        else if (box == mFreezeBox)
            sample.setLodFrozen(box->isChecked());
    }
}
