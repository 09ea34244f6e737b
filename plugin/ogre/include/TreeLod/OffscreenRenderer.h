// OffscreenRenderer: a headless Ogre Root that renders into a texture (OGRE-NOTES.md,
// "Headless"): RenderSystem_GL3Plus under an X server (Xvfb), a hidden 1x1 window owning
// the context, TreeLod's materials in the resource group "TreeLod", and the TreeLod
// plugin installed (in-process, or loaded from a .so path for tests of the plugin itself).
// Used by the CLI, the tests and the benchmarks; not part of Plugin_TreeLod.
#pragma once

#include "TreeLod/Camera.h"
#include "TreeLod/ShadowSetup.h"

#include <Ogre.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace TreeLod
{
    class TreeLodPlugin;

    struct OffscreenOptions
    {
        std::string logFile = "";      ///< "" = no log file (messages dropped unless verbose)
        bool verbose = false;          ///< also echo Ogre's log to stdout
        std::string pluginPath = "";   ///< "" = install TreeLodPlugin in-process; else loadPlugin(path)
        std::string materialsDir = ""; ///< "" = materialsDirectory() (OgreBootstrap.h)
    };

    /// An RGBA8 picture, rows top to bottom (PNG order).
    struct RgbaImage
    {
        int width = 0;
        int height = 0;
        std::vector<std::uint8_t> pixels;
    };

    /// Sun (a directional light) and ambient light as `lighting` says (its background is the
    /// viewport's business). Shared by OffscreenRenderer and the scene builder (ForestScene).
    void applyLighting(Ogre::SceneManager& sceneManager, Ogre::Light& sun, const LightingSpec& lighting);

    /// One timed frame (OffscreenRenderer::renderTimedFrame).
    struct FrameTiming
    {
        double cpuMilliseconds = 0.0;   ///< renderOneFrame + the target's update: until the commands are submitted
        double frameMilliseconds = 0.0; ///< until a one-pixel read-back returns: the GPU has finished the frame
        std::size_t batches = 0;        ///< draws (RenderTarget statistics)
        std::size_t triangles = 0;      ///< triangles submitted (RenderTarget statistics)
    };

    class OffscreenRenderer
    {
    public:
        /// Throws Ogre::Exception with the reason when no GL context can be had
        /// (e.g. no X server: run under xvfb-run).
        explicit OffscreenRenderer(const OffscreenOptions& options = {});
        ~OffscreenRenderer();

        Ogre::Root& getRoot() { return *mRoot; }
        Ogre::SceneManager& getSceneManager() { return *mSceneManager; }

        /// Parent node for what is drawn (the camera and sun live elsewhere).
        Ogre::SceneNode& getContentNode() { return *mContentNode; }
        /// Destroy every object under the content node and its child nodes.
        void clearContent();

        /// Sun (directional light) and ambient as LightingSpec says; background colour too.
        void setLighting(const LightingSpec& lighting);

        /// The sun's shadows as `settings` say (setupSunShadows, ShadowSetup.h). Unless
        /// setShadowFarDistance says otherwise, the shadow far distance reaches past the content
        /// from wherever the camera stands (render()): a shorter one clipped the shadows of
        /// distant trees away; PSSM's splits follow it.
        void setShadows(const SunShadowSettings& settings);
        /// Integrated additive texture shadows framed by `camera`, or none.
        void setShadows(bool enabled, unsigned textureSize = 2048, ShadowCamera camera = ShadowCamera::Focused);

        /// Shadow far distance in metres from the camera; 0 (default) = past the content's far
        /// side from wherever the camera stands (right for one tree, too far for a forest).
        void setShadowFarDistance(float metres) { mShadowFarDistance = metres; }

        /// Camera LoD bias (> 1 = more detail). render() divides it by the supersampling
        /// factor's pixel count, so pixel-count LoD sees the output image's size.
        void setLodBias(float bias) { mLodBias = bias; }

        /// The viewport's material scheme (Ogre::Viewport::setMaterialScheme), e.g. the RTSS's
        /// for an application whose materials the RTSS draws; default Ogre's.
        void setMaterialScheme(const Ogre::String& scheme);

        /// Render the scene from `camera` at width x height, supersampled with
        /// samplesPerAxis^2 samples per pixel (box filter in linear space, like the CPU
        /// reference renderer). Returns opaque RGBA8.
        RgbaImage render(const CameraSpec& camera, int width, int height, int samplesPerAxis = 1);

        /// Milliseconds of each of `frames` frames from `camera` at width x height (one sample
        /// per pixel), each ended by reading one pixel back so the GPU has finished it; after
        /// one untimed warm-up frame. For benchmarks.
        std::vector<double> timeFrames(const CameraSpec& camera, int width, int height, int frames);

        /// One frame from `camera` at width x height (one sample per pixel), timed; no warm-up.
        FrameTiming renderTimedFrame(const CameraSpec& camera, int width, int height);

        /// Save as PNG through Ogre's codec, atomically. Throws on failure.
        static void savePng(const RgbaImage& image, const std::string& path);

    private:
        void start(const OffscreenOptions& options);
        /// Destroys what start() made, in order; safe on a half-started renderer.
        void release();
        void ensureTarget(int width, int height);
        void placeCamera(const CameraSpec& camera, int width, int height, int samplesPerAxis);

        std::unique_ptr<Ogre::LogManager> mLogManager;
        std::unique_ptr<Ogre::Root> mRoot;
        std::unique_ptr<TreeLodPlugin> mPlugin; ///< when installed in-process
        Ogre::RenderWindow* mWindow = nullptr;
        Ogre::SceneManager* mSceneManager = nullptr;
        Ogre::Camera* mCamera = nullptr;
        Ogre::SceneNode* mCameraNode = nullptr;
        Ogre::Light* mSun = nullptr;
        Ogre::SceneNode* mContentNode = nullptr;
        Ogre::TexturePtr mTarget;
        LightingSpec mLighting;
        float mLodBias = 1.0f;
        Ogre::String mMaterialScheme = Ogre::MaterialManager::DEFAULT_SCHEME_NAME;
        float mShadowFarDistance = 0.0f;
    };
}
