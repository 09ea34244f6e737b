// SingleTreeView: the split view of the technique samples (one tree, every technique of the
// TechniqueRegistry): three panels side by side, the polygonal reference | the technique | the
// FLIP difference of the two as a heatmap with its mean and maximum.
//
// One scene manager holds the reference (an Entity, REFERENCE_VISIBILITY) and one object per
// technique (TECHNIQUE_VISIBILITY, only the shown one visible) on one node; both panels render
// through one camera, so they line up pixel for pixel. The difference is recomputed on the CPU
// (ImageMetrics.h flip / flipHeatmap) from offscreen renders of both panels once the view has
// been still for RECOMPUTE_DELAY seconds, not every frame; the heatmap is a texture shown by an
// overlay panel over the third viewport. The view state (camera, LoD bias, shadows, wireframe,
// frozen LoD) is shared by all technique samples.
#pragma once

#include "BrowserSupport.h"
#include "TreeLod/Progress.h"
#include "TreeLod/TreeAsset.h"

#include <Ogre.h>
#include <OgreOverlay.h>
#include <OgrePanelOverlayElement.h>

#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace OgreBites
{
    class Label;
}

namespace TreeLod
{
    class SingleTreeView
    {
    public:
        /// Seconds the view must stay unchanged before the difference is recomputed.
        static constexpr double RECOMPUTE_DELAY = 0.3;

        /// `source`: a tree file or a generator source (TreeBaker.h); `shadowSize`: the shadow
        /// map's side in texels.
        SingleTreeView(Ogre::Root& root, std::string source, unsigned shadowSize = 2048);
        ~SingleTreeView();

        /// Bake (through TreeAssetManager::require and the registered baker) the chunks of every
        /// registered technique (so a forest of the same tree finds the package complete), load
        /// the asset and create the objects. Throws Ogre::Exception.
        void build(const ProgressCallback& progress);
        const TreeAssetPtr& getAsset() const { return mAsset; }
        const std::string& getSource() const { return mSource; }

        /// Technique shown in the middle panel (a registry name).
        void showTechnique(const std::string& technique);
        const std::string& getTechnique() const { return mTechnique; }

        void attach(Ogre::RenderTarget& target, const PixelRect& area, int firstZOrder);
        void detach();
        void frame(double seconds);
        /// Render `technique` alone from the start view into `target`.
        void renderThumbnail(const std::string& technique, Ogre::RenderTarget& target);

        Ogre::Camera& getCamera() { return *mCamera; }
        Ogre::SceneNode& getCameraNode() { return *mCameraNode; }
        Ogre::SceneNode& getOrbitTarget() { return *mOrbitTarget; }
        float getRadius() const { return mRadius; }
        /// Back to the start view (the tree framed whole in a panel); the next frame() recomputes
        /// the difference at once.
        void resetView();

        float getLodBias() const { return mLodBias; }
        void setLodBias(float bias);
        bool getShadows() const { return mShadows; }
        void setShadows(bool enabled);
        bool getWireframe() const { return mWireframe; }
        void setWireframe(bool enabled);
        /// Level transitions of the objects that have them (TechniqueInfo::setLodTransition; 0: hard).
        float getLodTransition() const { return mLodTransition; }
        void setLodTransition(float length);
        bool isLodFrozen() const { return mLodFrozen; }
        void setLodFrozen(bool frozen);

        std::vector<std::pair<std::string, std::string>> getStats();
        std::vector<std::string> getLevelHistogram();

    private:
        struct Signature; ///< what the difference depends on
        Signature signature() const;
        void layoutPanels();
        void updateShadowRange();
        void recomputeDifference();
        void uploadHeatmap(const std::vector<std::uint8_t>& rgba, int width, int height);
        Ogre::MovableObject* techniqueObject() const;
        /// Render `camera`'s view with `mask` into the offscreen target `texture` (made on first use).
        std::vector<std::uint8_t> renderPanel(Ogre::TexturePtr& texture, const char* name, Ogre::uint32 mask,
                                              int width, int height);

        Ogre::Root& mRoot;
        std::string mSource;
        unsigned mShadowSize;
        TreeAssetPtr mAsset;
        Ogre::SceneManager* mSceneManager = nullptr;
        Ogre::Camera* mCamera = nullptr;
        Ogre::SceneNode* mCameraNode = nullptr;
        Ogre::Camera* mBlankCamera = nullptr; ///< clears the difference viewport, draws nothing
        Ogre::Camera* mLodCamera = nullptr; ///< frozen LoD: a copy of the camera left behind
        Ogre::SceneNode* mLodCameraNode = nullptr;
        Ogre::SceneNode* mOrbitTarget = nullptr;
        Ogre::SceneNode* mTreeNode = nullptr;
        Ogre::Light* mSun = nullptr;
        Ogre::Entity* mReference = nullptr;
        std::map<std::string, Ogre::MovableObject*> mTechniques; ///< by registry name
        std::string mTechnique;
        Ogre::AxisAlignedBox mBounds;
        float mRadius = 1.0f;
        Ogre::ColourValue mBackground;

        // The split view on the browser's target.
        Ogre::RenderTarget* mTarget = nullptr;
        PixelRect mArea;
        int mFirstZOrder = 0;
        Ogre::Viewport* mReferenceViewport = nullptr;
        Ogre::Viewport* mTechniqueViewport = nullptr;
        Ogre::Viewport* mDifferenceViewport = nullptr;
        Ogre::Overlay* mOverlay = nullptr;
        Ogre::OverlayContainer* mOverlayRoot = nullptr;
        Ogre::PanelOverlayElement* mHeatmapPanel = nullptr;
        std::unique_ptr<OgreBites::Label> mCaptions[3];

        // The difference.
        Ogre::TexturePtr mReferenceTexture, mTechniqueTexture, mHeatmapTexture;
        Ogre::MaterialPtr mHeatmapMaterial;
        std::unique_ptr<Signature> mComputed; ///< the view the heatmap shows; null: none yet
        std::unique_ptr<Signature> mPending;  ///< the view seen last frame
        double mStillSeconds = 0.0;
        bool mRecomputeNow = false;
        bool mViewPlaced = false; ///< resetView() ran for a panel (the first attach)
        double mFlipMean = 0.0, mFlipMax = 0.0;
        double mFlipMilliseconds = 0.0, mRenderMilliseconds = 0.0; ///< last recompute: FLIP, and the two offscreen renders

        float mLodBias = 1.0f;
        float mLodTransition = 0.0f;
        bool mShadows = false;
        bool mWireframe = false;
        bool mLodFrozen = false;
    };
}
