#include "TreeLod/OffscreenRenderer.h"

#include "TreeLod/AtomicFile.h"
#include "TreeLod/Colour.h"
#include "TreeLod/OgreBootstrap.h"
#include "TreeLod/TreeLodPlugin.h"

#include <OgreWorkQueue.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>

namespace TreeLod
{
    namespace
    {
        /// The code OGRE_EXCEPT takes to throw an exception of e's type (Ogre 1.12 keeps no number).
        Ogre::Exception::ExceptionCodes exceptionCode(const Ogre::Exception& e)
        {
            using E = Ogre::Exception;
            if (dynamic_cast<const Ogre::RenderingAPIException*>(&e))
                return E::ERR_RENDERINGAPI_ERROR;
            if (dynamic_cast<const Ogre::FileNotFoundException*>(&e))
                return E::ERR_FILE_NOT_FOUND;
            if (dynamic_cast<const Ogre::IOException*>(&e))
                return E::ERR_CANNOT_WRITE_TO_FILE;
            if (dynamic_cast<const Ogre::InvalidStateException*>(&e))
                return E::ERR_INVALID_STATE;
            if (dynamic_cast<const Ogre::InvalidParametersException*>(&e))
                return E::ERR_INVALIDPARAMS;
            if (dynamic_cast<const Ogre::ItemIdentityException*>(&e))
                return E::ERR_DUPLICATE_ITEM;
            if (dynamic_cast<const Ogre::InvalidCallException*>(&e))
                return E::ERR_INVALID_CALL;
            if (dynamic_cast<const Ogre::UnimplementedException*>(&e))
                return E::ERR_NOT_IMPLEMENTED;
            return E::ERR_INTERNAL_ERROR;
        }
    }

    OffscreenRenderer::OffscreenRenderer(const OffscreenOptions& options)
    {
        // Debian's OGRE is GLX only; fail before Ogre half-starts.
        const char* display = std::getenv("DISPLAY");
        if (!display || !*display)
            OGRE_EXCEPT(Ogre::Exception::ERR_RENDERINGAPI_ERROR,
                        "no X display (DISPLAY is not set): run under xvfb-run -a -s \"-screen 0 1280x1024x24 -noreset\"",
                        "OffscreenRenderer");
        // An exception thrown inside a render system plugin points at the plugin's code and
        // strings (destructor, type name, file), which release() unloads: keep what it says, let
        // it go, then release and throw again from here.
        bool failed = false;
        Ogre::Exception::ExceptionCodes code = Ogre::Exception::ERR_INTERNAL_ERROR;
        std::string description, source;
        try
        {
            start(options);
        }
        catch (const Ogre::Exception& e)
        {
            failed = true;
            code = exceptionCode(e);
            description = e.getDescription();
            source = e.getSource();
        }
        catch (const std::exception& e)
        {
            failed = true;
            description = e.what();
            source = "OffscreenRenderer";
        }
        if (failed)
        {
            release();
            OGRE_EXCEPT(code, "starting Ogre headless on display " + std::string(display) + ": " + description,
                        source);
        }
    }

    void OffscreenRenderer::start(const OffscreenOptions& options)
    {
        // Own LogManager first, else Ogre logs to stdout (OGRE-NOTES.md).
        mLogManager = createLogManager(options.logFile, options.verbose);
        mRoot = std::make_unique<Ogre::Root>("", "", "");
        // No worker threads in Ogre's work queue: nothing here queues work (bakes run on
        // TreeAssetManager's own threads), and Ogre's workers write the log as they start,
        // beside the render thread, without a lock (Ogre::Log in Debian's build).
        if (auto* queue = dynamic_cast<Ogre::DefaultWorkQueueBase*>(mRoot->getWorkQueue()))
            queue->setWorkerThreadCount(0);

        const std::string pluginDir = loadRenderPlugins(*mRoot);
        if (options.pluginPath.empty())
        {
            mPlugin = std::make_unique<TreeLodPlugin>();
            mRoot->installPlugin(mPlugin.get());
        }
        else
            mRoot->loadPlugin(options.pluginPath);

        const Ogre::RenderSystemList& systems = mRoot->getAvailableRenderers();
        if (systems.empty())
            OGRE_EXCEPT(Ogre::Exception::ERR_RENDERINGAPI_ERROR, renderSystemPlugin() + " did not load from " + pluginDir,
                        "OffscreenRenderer");
        mRoot->setRenderSystem(systems.front());
        mRoot->initialise(false);
        const Ogre::NameValuePairList misc = hiddenWindowParams();
        mWindow = mRoot->createRenderWindow("TreeLodOffscreen", 1, 1, false, &misc);
        mWindow->setAutoUpdated(false);

        Ogre::ResourceGroupManager& rgm = Ogre::ResourceGroupManager::getSingleton();
        addMaterialsLocations(!options.materialsDir.empty() ? options.materialsDir : materialsDirectory());
        rgm.initialiseResourceGroup("TreeLod");
        // Texture shadows need OGRE's ShadowVolume programs (the shadow setup loads them).
        if (addShadowVolumeLocation())
            rgm.initialiseResourceGroup(Ogre::RGN_INTERNAL);

        mSceneManager = mRoot->createSceneManager();
        mCamera = mSceneManager->createCamera("TreeLodOffscreenCamera");
        mCameraNode = mSceneManager->getRootSceneNode()->createChildSceneNode();
        mCameraNode->attachObject(mCamera);
        mSun = mSceneManager->createLight("TreeLodSun");
        mSun->setType(Ogre::Light::LT_DIRECTIONAL);
        mSceneManager->getRootSceneNode()->createChildSceneNode()->attachObject(mSun);
        mContentNode = mSceneManager->getRootSceneNode()->createChildSceneNode("TreeLodContent");
        setLighting(LightingSpec());
    }

    void OffscreenRenderer::clearContent()
    {
        std::vector<Ogre::SceneNode*> stack{mContentNode};
        while (!stack.empty())
        {
            Ogre::SceneNode* node = stack.back();
            stack.pop_back();
            while (node->numAttachedObjects() > 0)
                mSceneManager->destroyMovableObject(node->detachObject((unsigned short)0));
            for (Ogre::Node* child : node->getChildren())
                stack.push_back(static_cast<Ogre::SceneNode*>(child));
        }
        mContentNode->removeAndDestroyAllChildren();
    }

    OffscreenRenderer::~OffscreenRenderer() { release(); }

    void OffscreenRenderer::release()
    {
        if (mTarget)
            Ogre::TextureManager::getSingleton().remove(mTarget);
        mTarget.reset();
        if (mRoot)
        {
            if (mSceneManager)
                mRoot->destroySceneManager(mSceneManager);
            mSceneManager = nullptr;
            mRoot->shutdown();
            // The plugin leaves the Root before either is destroyed (Root's destructor would
            // uninstall it again).
            if (mPlugin && std::find(mRoot->getInstalledPlugins().begin(), mRoot->getInstalledPlugins().end(),
                                     mPlugin.get()) != mRoot->getInstalledPlugins().end())
                mRoot->uninstallPlugin(mPlugin.get());
        }
        mRoot.reset();
        mPlugin.reset();
        mLogManager.reset();
    }

    void applyLighting(Ogre::SceneManager& sceneManager, Ogre::Light& sun, const LightingSpec& lighting)
    {
        const glm::vec3& a = lighting.ambientColour;
        const glm::vec3& c = lighting.sunColour;
        sceneManager.setAmbientLight(Ogre::ColourValue(a.r, a.g, a.b));
        sun.setType(Ogre::Light::LT_DIRECTIONAL);
        sun.setDiffuseColour(Ogre::ColourValue(c.r, c.g, c.b));
        sun.setSpecularColour(Ogre::ColourValue::Black);
        glm::vec3 d = -glm::normalize(lighting.sunDirection); // Ogre: the direction light travels
        sun.getParentSceneNode()->setDirection(Ogre::Vector3(d.x, d.y, d.z), Ogre::Node::TS_WORLD);
    }

    void OffscreenRenderer::setLighting(const LightingSpec& lighting)
    {
        mLighting = lighting;
        applyLighting(*mSceneManager, *mSun, lighting);
    }

    void OffscreenRenderer::ensureTarget(int width, int height)
    {
        if (mTarget && int(mTarget->getWidth()) == width && int(mTarget->getHeight()) == height)
            return;
        if (mTarget)
            Ogre::TextureManager::getSingleton().remove(mTarget);
        mTarget = Ogre::TextureManager::getSingleton().createManual(
            "TreeLodOffscreenTarget", Ogre::RGN_INTERNAL, Ogre::TEX_TYPE_2D, Ogre::uint(width), Ogre::uint(height),
            0, Ogre::PF_BYTE_RGBA, Ogre::TU_RENDERTARGET);
        Ogre::RenderTarget* rt = mTarget->getBuffer()->getRenderTarget();
        rt->setAutoUpdated(false);
        Ogre::Viewport* vp = rt->addViewport(mCamera);
        vp->setOverlaysEnabled(false);
        vp->setShadowsEnabled(true);
        vp->setMaterialScheme(mMaterialScheme);
    }

    void OffscreenRenderer::setMaterialScheme(const Ogre::String& scheme)
    {
        mMaterialScheme = scheme;
        if (mTarget)
            mTarget->getBuffer()->getRenderTarget()->getViewport(0)->setMaterialScheme(scheme);
    }

    void OffscreenRenderer::placeCamera(const CameraSpec& spec, int width, int height, int samplesPerAxis)
    {
        if (mSceneManager->isShadowTechniqueTextureBased())
        {
            // The directional shadow camera sits this far from what it focuses on; the
            // default (10 km) would squeeze a tree's depths into the bias.
            mContentNode->_update(true, false);
            const Ogre::AxisAlignedBox& box = mContentNode->_getWorldAABB();
            const Ogre::Real radius = box.isFinite() ? 0.5f * box.getSize().length() : 10.0f;
            Ogre::Real extrusion = 2.0f * radius + 1.0f;
            if (mShadowFarDistance > 0.0f) // casters farther up-sun than this are out of reach anyway
                extrusion = std::min(extrusion, 2.0f * mShadowFarDistance + 50.0f);
            mSceneManager->setShadowDirectionalLightExtrusionDistance(extrusion);
            // Shadows reach past the far side of the content however far the camera stands.
            const Ogre::Vector3 eye(spec.position.x, spec.position.y, spec.position.z);
            const Ogre::Real reach = box.isFinite() ? eye.distance(box.getCenter()) + 2.0f * radius : 0.0f;
            mSceneManager->setShadowFarDistance(mShadowFarDistance > 0.0f ? mShadowFarDistance
                                                                          : std::max(4.0f * radius + 2.0f, reach));
        }
        mCamera->setLodBias(mLodBias / float(samplesPerAxis * samplesPerAxis));
        mCamera->setNearClipDistance(spec.nearClip);
        mCamera->setFarClipDistance(spec.farClip);
        mCamera->setAspectRatio(Ogre::Real(width) / Ogre::Real(height));
        if (spec.orthographic)
        {
            mCamera->setProjectionType(Ogre::PT_ORTHOGRAPHIC);
            mCamera->setOrthoWindowHeight(spec.orthoHeight);
        }
        else
        {
            mCamera->setProjectionType(Ogre::PT_PERSPECTIVE);
            mCamera->setFOVy(Ogre::Degree(spec.fovYDegrees));
        }
        mCameraNode->setPosition(spec.position.x, spec.position.y, spec.position.z);
        mCameraNode->setFixedYawAxis(true, Ogre::Vector3(spec.up.x, spec.up.y, spec.up.z));
        mCameraNode->lookAt(Ogre::Vector3(spec.target.x, spec.target.y, spec.target.z), Ogre::Node::TS_WORLD);
        updateShadowSplits(*mSceneManager, *mCamera);
    }

    void OffscreenRenderer::setShadows(const SunShadowSettings& settings)
    {
        setupSunShadows(*mSceneManager, *mSun, settings, mCamera);
    }

    void OffscreenRenderer::setShadows(bool enabled, unsigned textureSize, ShadowCamera camera)
    {
        SunShadowSettings settings;
        settings.technique = enabled ? Ogre::SHADOWTYPE_TEXTURE_ADDITIVE_INTEGRATED : Ogre::SHADOWTYPE_NONE;
        settings.textureSize = textureSize;
        settings.camera = camera;
        setShadows(settings);
    }

    FrameTiming OffscreenRenderer::renderTimedFrame(const CameraSpec& spec, int width, int height)
    {
        ensureTarget(width, height);
        placeCamera(spec, width, height, 1);
        Ogre::RenderTarget* rt = mTarget->getBuffer()->getRenderTarget();
        const glm::vec3& bg = mLighting.background;
        rt->getViewport(0)->setBackgroundColour(Ogre::ColourValue(bg.r, bg.g, bg.b, 1.0f));
        std::uint8_t pixel[4];
        Ogre::PixelBox one(1, 1, 1, Ogre::PF_BYTE_RGBA, pixel);
        FrameTiming timing;
        const auto start = std::chrono::steady_clock::now();
        mRoot->renderOneFrame();
        rt->update();
        timing.cpuMilliseconds = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        rt->copyContentsToMemory(Ogre::Box(0, 0, 1, 1), one, Ogre::RenderTarget::FB_AUTO);
        timing.frameMilliseconds = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        const Ogre::RenderTarget::FrameStats& stats = rt->getStatistics();
        timing.batches = stats.batchCount;
        timing.triangles = stats.triangleCount;
        return timing;
    }

    std::vector<double> OffscreenRenderer::timeFrames(const CameraSpec& spec, int width, int height, int frames)
    {
        std::vector<double> ms;
        for (int f = -1; f < frames; ++f)
        {
            const double t = renderTimedFrame(spec, width, height).frameMilliseconds;
            if (f >= 0)
                ms.push_back(t);
        }
        return ms;
    }

    RgbaImage OffscreenRenderer::render(const CameraSpec& spec, int width, int height, int samplesPerAxis)
    {
        OgreAssert(width > 0 && height > 0 && samplesPerAxis > 0, "render size must be positive");
        const int s = samplesPerAxis, w = width * s, h = height * s;
        ensureTarget(w, h);
        placeCamera(spec, width, height, s);

        Ogre::RenderTarget* rt = mTarget->getBuffer()->getRenderTarget();
        const glm::vec3& bg = mLighting.background;
        rt->getViewport(0)->setBackgroundColour(Ogre::ColourValue(bg.r, bg.g, bg.b, 1.0f));
        mRoot->renderOneFrame(); // frame listeners, controllers
        rt->update();

        RgbaImage out;
        out.width = width;
        out.height = height;
        out.pixels.resize(std::size_t(width) * height * 4);
        std::vector<std::uint8_t> big;
        // One sample: averaging one sRGB byte in linear light gives the byte back (a tested
        // identity), so the pixels are read straight into the output.
        std::uint8_t* read = out.pixels.data();
        if (s > 1)
        {
            big.resize(std::size_t(w) * h * 4);
            read = big.data();
        }
        Ogre::PixelBox box(Ogre::uint32(w), Ogre::uint32(h), 1, Ogre::PF_BYTE_RGBA, read);
        rt->copyContentsToMemory(Ogre::Box(0, 0, Ogre::uint32(w), Ogre::uint32(h)), box,
                                 Ogre::RenderTarget::FB_AUTO);
        if (s == 1)
        {
            for (std::size_t i = 3; i < out.pixels.size(); i += 4)
                out.pixels[i] = 255;
            return out;
        }
        const float norm = 1.0f / float(s * s);
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x)
            {
                float sum[3] = {0.0f, 0.0f, 0.0f};
                for (int sy = 0; sy < s; ++sy)
                    for (int sx = 0; sx < s; ++sx)
                    {
                        const std::uint8_t* p = &big[(std::size_t(y * s + sy) * w + (x * s + sx)) * 4];
                        for (int c = 0; c < 3; ++c)
                            sum[c] += srgbByteToLinear(p[c]);
                    }
                std::uint8_t* o = &out.pixels[(std::size_t(y) * width + x) * 4];
                for (int c = 0; c < 3; ++c)
                    o[c] = linearToSrgbByte(sum[c] * norm);
                o[3] = 255;
            }
        return out;
    }

    void OffscreenRenderer::savePng(const RgbaImage& image, const std::string& path)
    {
        Result<void> r = writeFileAtomicVia(path, [&](const std::string& temp) -> Result<void> {
            Ogre::Image img;
            img.loadDynamicImage(const_cast<std::uint8_t*>(image.pixels.data()), Ogre::uint32(image.width),
                                 Ogre::uint32(image.height), Ogre::PF_BYTE_RGBA);
            try
            {
                img.save(temp);
            }
            catch (const Ogre::Exception& e)
            {
                return fail(path, "", e.getDescription());
            }
            return {};
        });
        if (!r)
            OGRE_EXCEPT(Ogre::Exception::ERR_CANNOT_WRITE_TO_FILE, r.error().message(), "OffscreenRenderer::savePng");
    }
}
