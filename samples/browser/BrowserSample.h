// BrowserSample: one entry of the sample browser's menu (the role of OgreBites' Sample in Ogre's
// own browser). A sample owns a scene manager, builds its scene once (lazily baking what it
// draws), shows itself in a rectangle of the browser's render target and answers the browser's
// controls and stats panel.
#pragma once

#include "BrowserSupport.h"
#include "TreeLod/Progress.h"

#include <Ogre.h>

#include <string>
#include <utility>
#include <vector>

namespace TreeLod
{
    class BrowserSample
    {
    public:
        virtual ~BrowserSample() = default;

        virtual std::string getTitle() const = 0;
        virtual std::string getDescription() const = 0;

        /// Bake what is missing, load and create the scene. Throws Ogre::Exception naming the
        /// input on failure. Called once, before anything else below.
        virtual void build(const ProgressCallback& progress) = 0;

        /// Render the menu thumbnail into `target` (a texture of the thumbnail's size).
        virtual void renderThumbnail(Ogre::RenderTarget& target) = 0;

        /// Show the sample in `area` of `target` with viewports from z-order `firstZOrder` on
        /// (at most 10); detach() removes them again.
        virtual void attach(Ogre::RenderTarget& target, const PixelRect& area, int firstZOrder) = 0;
        virtual void detach() = 0;

        /// Per frame, before rendering: `seconds` since the last frame.
        virtual void frame(double seconds) = 0;
        /// Per frame, after rendering: the wall time the frame took to render (the stats' "FPS
        /// (render)"), for a frame budget to close its loop on.
        virtual void frameTimed(double) {}

        /// The camera the user moves (CameraMan), its node, and how: orbit around
        /// getOrbitTarget() (a single tree) or free look (the forest).
        virtual Ogre::Camera& getCamera() = 0;
        virtual Ogre::SceneNode& getCameraNode() = 0;
        virtual Ogre::SceneNode* getOrbitTarget() = 0; ///< nullptr: free look
        /// Free-look speed in metres per second.
        virtual float getCameraSpeed() const = 0;

        // ---- controls ---------------------------------------------------------------------
        /// A split view shows one technique; choosing another technique selects that
        /// technique's sample (the view state is shared). Otherwise setTechnique() changes the
        /// technique in place.
        virtual bool isSplitView() const = 0;
        virtual std::vector<std::string> getTechniques() const = 0;
        virtual std::string getTechnique() const = 0;
        virtual void setTechnique(const std::string& technique) = 0;

        virtual float getLodBias() const = 0;
        virtual void setLodBias(float bias) = 0; ///< > 0, the camera's LoD bias
        virtual bool getShadows() const = 0;
        virtual void setShadows(bool enabled) = 0;
        virtual bool getWireframe() const = 0;
        virtual void setWireframe(bool enabled) = 0;
        virtual bool isLodFrozen() const = 0;
        virtual void setLodFrozen(bool frozen) = 0;
        /// A camera path to play (the forest's scene script); false: play/pause is hidden.
        /// Nothing is still arriving (a technique's bakes, Forest levels within the upload
        /// budget): what the next frame shows is complete. Screenshots wait for it.
        virtual bool isSettled() const { return true; }
        /// Budgeted auto's error budget (Forest::levelsForErrorBudget), where the sample has one.
        virtual bool hasErrorBudget() const { return false; }
        virtual float getErrorBudget() const { return 0.0f; }
        virtual void setErrorBudget(float) {}
        /// Level transitions (Forest::setLodTransition, the tree objects' setLodTransition: 0 hard
        /// switches), where the sample has them.
        virtual bool hasLodTransition() const { return false; }
        virtual float getLodTransition() const { return 0.0f; }
        virtual void setLodTransition(float) {}
        virtual bool hasCameraPath() const { return false; }
        virtual bool isPlaying() const { return false; }
        virtual void setPlaying(bool) {}
        /// Headless: the screenshots' names, PREFIX-NNN.png (samples that are not split views).
        virtual std::string getScreenshotPrefix() const { return "forest"; }
        /// Headless: put the camera where screenshot `index` of `count` is taken.
        virtual void setScreenshotView(unsigned index, unsigned count) = 0;

        // ---- stats ------------------------------------------------------------------------
        /// Name / value lines for the stats panel (after FPS, which the browser adds).
        virtual std::vector<std::pair<std::string, std::string>> getStats() = 0;
        /// Lines of the LoD histogram: one per level in use, a text bar and a count.
        virtual std::vector<std::string> getLevelHistogram() = 0;
    };
}
