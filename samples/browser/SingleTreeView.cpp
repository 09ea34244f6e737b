#include "SingleTreeView.h"

#include "TreeLod/ImageMetrics.h"
#include "TreeLod/OffscreenRenderer.h"
#include "TreeLod/ShadowSetup.h"
#include "TreeLod/RgbaImageConversion.h"
#include "TreeLod/TechniqueRegistry.h"
#include "TreeLod/TreeAssetManager.h"

#include <OgreOverlayManager.h>
#include <OgreTrays.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <set>

namespace TreeLod
{
    namespace
    {
        /// Start view: azimuth and elevation of the orbit, degrees (as `treelod render --camera orbit:30,10,1`).
        constexpr float START_YAW_DEGREES = 30.0f;
        constexpr float START_PITCH_DEGREES = 10.0f;
        /// Caption labels: margin to the panel's edges, pixels.
        constexpr int CAPTION_MARGIN = 6;
        const Ogre::ColourValue DIFFERENCE_BACKGROUND(0.08f, 0.08f, 0.08f);

        std::string fixed(double value, int decimals)
        {
            char text[32];
            std::snprintf(text, sizeof text, "%.*f", decimals, value);
            return text;
        }

        /// The reference Entity's materials, or their shadow-receiving clones (TreeAsset.h).
        void useShadowedMaterials(Ogre::Entity& entity, TreeAsset& asset, bool shadowed)
        {
            const std::vector<Ogre::String>& plain = asset.getMaterialNames();
            const std::vector<Ogre::String>& receiving = asset.getShadowedMaterialNames();
            for (Ogre::SubEntity* sub : entity.getSubEntities())
            {
                const Ogre::String& name = sub->getMaterialName();
                for (std::size_t i = 0; i < plain.size() && i < receiving.size(); ++i)
                    if (name == plain[i] || name == receiving[i])
                    {
                        sub->setMaterialName(shadowed ? receiving[i] : plain[i], asset.getGroup());
                        break;
                    }
            }
        }
    }

    struct SingleTreeView::Signature
    {
        Ogre::Vector3 position;
        Ogre::Quaternion orientation;
        std::string technique;
        float lodBias = 1.0f;
        bool shadows = false, wireframe = false, lodFrozen = false;
        int width = 0, height = 0;

        bool operator==(const Signature& o) const
        {
            return position == o.position && orientation == o.orientation && technique == o.technique &&
                   lodBias == o.lodBias && shadows == o.shadows && wireframe == o.wireframe &&
                   lodFrozen == o.lodFrozen && width == o.width && height == o.height;
        }
        bool operator!=(const Signature& o) const { return !(*this == o); }
    };

    SingleTreeView::SingleTreeView(Ogre::Root& root, std::string source, unsigned shadowSize)
        : mRoot(root), mSource(std::move(source)), mShadowSize(shadowSize)
    {
        const LightingSpec lighting;
        mBackground = Ogre::ColourValue(lighting.background.r, lighting.background.g, lighting.background.b);
    }

    SingleTreeView::~SingleTreeView()
    {
        detach();
        for (auto& caption : mCaptions)
            if (caption)
                caption->cleanup();
        if (mOverlayRoot)
            OgreBites::Widget::nukeOverlayElement(mOverlayRoot);
        if (mOverlay)
            Ogre::OverlayManager::getSingleton().destroy(mOverlay);
        Ogre::TextureManager& textures = Ogre::TextureManager::getSingleton();
        for (Ogre::TexturePtr* texture : {&mReferenceTexture, &mTechniqueTexture, &mHeatmapTexture})
            if (*texture)
                textures.remove(*texture);
        if (mHeatmapMaterial)
            Ogre::MaterialManager::getSingleton().remove(mHeatmapMaterial);
        if (mSceneManager)
            mRoot.destroySceneManager(mSceneManager);
    }

    void SingleTreeView::build(const ProgressCallback& progress)
    {
        if (mSceneManager)
            return;
        // Every technique's chunk in one request: a later request for fewer chunks (a forest of
        // the same tree) then finds the package complete instead of rewriting it under our objects.
        std::vector<Ogre::String> chunks{REFERENCE_CHUNK};
        for (const TechniqueInfo& info : TechniqueRegistry::getSingleton().getTechniques())
            if (std::find(chunks.begin(), chunks.end(), info.chunkTechnique) == chunks.end())
                chunks.push_back(info.chunkTechnique);
        mAsset = TreeAssetManager::getSingleton().require(mSource, chunks, TREELOD_GROUP);
        report(progress, "single tree: creating the objects", 0.0f);

        mSceneManager = mRoot.createSceneManager();
        mSun = mSceneManager->createLight("TreeLodSun");
        mSceneManager->getRootSceneNode()->createChildSceneNode()->attachObject(mSun);
        applyLighting(*mSceneManager, *mSun, LightingSpec());

        mTreeNode = mSceneManager->getRootSceneNode()->createChildSceneNode();
        const TechniqueRegistry& registry = TechniqueRegistry::getSingleton();
        mReference = static_cast<Ogre::Entity*>(
            registry.createInstance(REFERENCE_TECHNIQUE, *mSceneManager, "TreeLod/Browser/Reference", *mAsset));
        mReference->setVisibilityFlags(REFERENCE_VISIBILITY);
        mTreeNode->attachObject(mReference);
        for (const TechniqueInfo& info : registry.getTechniques())
        {
            Ogre::MovableObject* object =
                registry.createInstance(info.name, *mSceneManager, "TreeLod/Browser/" + info.name, *mAsset);
            object->setVisibilityFlags(TECHNIQUE_VISIBILITY);
            object->setVisible(false);
            mTreeNode->attachObject(object);
            mTechniques[info.name] = object;
        }

        mBounds = mAsset->getBounds();
        mRadius = std::max(0.01f, 0.5f * float(mBounds.getSize().length()));
        mOrbitTarget = mSceneManager->getRootSceneNode()->createChildSceneNode(mBounds.getCenter());
        // Two cameras on one node: identical views, separate statistics per panel.
        mCameraNode = mSceneManager->getRootSceneNode()->createChildSceneNode();
        mCamera = mSceneManager->createCamera("TreeLod/Browser/Camera");
        mCameraNode->attachObject(mCamera);
        Ogre::Camera* referenceCamera = mSceneManager->createCamera("TreeLod/Browser/ReferenceCamera");
        mCameraNode->attachObject(referenceCamera);
        for (Ogre::Camera* camera : {mCamera, referenceCamera})
        {
            camera->setNearClipDistance(0.01f * mRadius);
            camera->setFarClipDistance(200.0f * mRadius);
            camera->setFOVy(Ogre::Degree(45.0f));
        }
        mBlankCamera = mSceneManager->createCamera("TreeLod/Browser/BlankCamera");
        mSceneManager->getRootSceneNode()->attachObject(mBlankCamera);
        mLodCameraNode = mSceneManager->getRootSceneNode()->createChildSceneNode();
        mLodCamera = mSceneManager->createCamera("TreeLod/Browser/LodCamera");
        mLodCameraNode->attachObject(mLodCamera);
        setShadows(true);
        showTechnique(registry.getTechniques().front().name);
        resetView();
        report(progress, "single tree: creating the objects", 1.0f);
    }

    Ogre::MovableObject* SingleTreeView::techniqueObject() const
    {
        auto it = mTechniques.find(mTechnique);
        return it == mTechniques.end() ? nullptr : it->second;
    }

    void SingleTreeView::showTechnique(const std::string& technique)
    {
        if (!mTechniques.count(technique))
            OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS,
                        "unknown technique '" + technique + "' (known: " + TechniqueRegistry::getSingleton().describe() + ")",
                        "SingleTreeView::showTechnique");
        for (auto& [name, object] : mTechniques)
            object->setVisible(name == technique);
        mTechnique = technique;
        if (mCaptions[1])
            mCaptions[1]->setCaption(mTechnique);
    }

    void SingleTreeView::resetView()
    {
        // Frame the bounding box: back off along the view direction until every corner is inside
        // both fields of view (with a small margin).
        Ogre::Quaternion orientation = Ogre::Quaternion(Ogre::Degree(START_YAW_DEGREES), Ogre::Vector3::UNIT_Y) *
                                       Ogre::Quaternion(Ogre::Degree(-START_PITCH_DEGREES), Ogre::Vector3::UNIT_X);
        const Ogre::Vector3 centre = mBounds.getCenter();
        const float tanY = std::tan(0.5f * mCamera->getFOVy().valueRadians());
        const float tanX = std::max(0.05f, float(mCamera->getAspectRatio())) * tanY;
        float distance = 0.0f;
        for (const Ogre::Vector3& corner : mBounds.getAllCorners())
        {
            const Ogre::Vector3 local = orientation.Inverse() * (corner - centre); // camera axes, +z towards the camera
            distance = std::max(distance, local.z + std::max(std::abs(local.x) / tanX, std::abs(local.y) / tanY));
        }
        distance *= 1.05f;
        mCameraNode->setFixedYawAxis(true);
        mCameraNode->setOrientation(orientation);
        mCameraNode->setPosition(centre + orientation * Ogre::Vector3(0.0f, 0.0f, distance));
        mRecomputeNow = true;
    }

    void SingleTreeView::attach(Ogre::RenderTarget& target, const PixelRect& area, int firstZOrder)
    {
        detach();
        mTarget = &target;
        mArea = area;
        mFirstZOrder = firstZOrder;
        Ogre::OverlayManager& overlays = Ogre::OverlayManager::getSingleton();
        if (!mOverlay)
        {
            mOverlay = overlays.create("TreeLod/Browser/SplitView");
            mOverlay->setZOrder(150); // above the trays' backdrop (100), below the trays (200)
            mOverlayRoot = static_cast<Ogre::OverlayContainer*>(
                overlays.createOverlayElement("Panel", "TreeLod/Browser/SplitView/Root"));
            mOverlayRoot->setMetricsMode(Ogre::GMM_PIXELS);
            static_cast<Ogre::PanelOverlayElement*>(mOverlayRoot)->setTransparent(true);
            mOverlay->add2D(mOverlayRoot);
            mHeatmapPanel = static_cast<Ogre::PanelOverlayElement*>(
                overlays.createOverlayElement("Panel", "TreeLod/Browser/SplitView/Heatmap"));
            mHeatmapPanel->setMetricsMode(Ogre::GMM_PIXELS);
            mHeatmapPanel->hide();
            mOverlayRoot->addChild(mHeatmapPanel);
            const char* captions[3] = {"polygonal reference", "", "FLIP difference"};
            for (int i = 0; i < 3; ++i)
            {
                mCaptions[i] = std::make_unique<OgreBites::Label>("TreeLod/Browser/SplitView/Caption" + std::to_string(i),
                                                                  captions[i], 100.0f);
                mCaptions[i]->getOverlayElement()->setHorizontalAlignment(Ogre::GHA_LEFT);
                mOverlayRoot->addChild(static_cast<Ogre::OverlayContainer*>(mCaptions[i]->getOverlayElement()));
            }
            mCaptions[1]->setCaption(mTechnique);
        }
        layoutPanels();
        if (!mViewPlaced) // the start view fits the panel's aspect ratio
            resetView();
        mViewPlaced = true;
        mOverlay->show();
        mRecomputeNow = true;
    }

    void SingleTreeView::layoutPanels()
    {
        const int third = mArea.width / 3;
        const PixelRect rects[3] = {{mArea.left, mArea.top, third, mArea.height},
                                    {mArea.left + third, mArea.top, third, mArea.height},
                                    {mArea.left + 2 * third, mArea.top, mArea.width - 2 * third, mArea.height}};
        Ogre::Camera* referenceCamera = mSceneManager->getCamera("TreeLod/Browser/ReferenceCamera");
        mReferenceViewport = addViewport(*mTarget, referenceCamera, mFirstZOrder, rects[0]);
        mTechniqueViewport = addViewport(*mTarget, mCamera, mFirstZOrder + 1, rects[1]);
        mDifferenceViewport = addViewport(*mTarget, mBlankCamera, mFirstZOrder + 2, rects[2]);
        mDifferenceViewport->setVisibilityMask(0); // cleared, nothing drawn: the heatmap overlay covers it
        mDifferenceViewport->setShadowsEnabled(false);
        for (Ogre::Viewport* vp : {mReferenceViewport, mTechniqueViewport})
        {
            vp->setBackgroundColour(mBackground);
            vp->setOverlaysEnabled(false);
            vp->setShadowsEnabled(true);
        }
        mReferenceViewport->setVisibilityMask(REFERENCE_VISIBILITY);
        mTechniqueViewport->setVisibilityMask(TECHNIQUE_VISIBILITY);
        mDifferenceViewport->setBackgroundColour(DIFFERENCE_BACKGROUND);
        mDifferenceViewport->setOverlaysEnabled(false);
        if (mLodFrozen)
            mLodCamera->_notifyViewport(mTechniqueViewport);

        mOverlayRoot->setDimensions(Ogre::Real(mTarget->getWidth()), Ogre::Real(mTarget->getHeight()));
        for (int i = 0; i < 3; ++i)
        {
            Ogre::OverlayElement* caption = mCaptions[i]->getOverlayElement();
            caption->setPosition(Ogre::Real(rects[i].left + CAPTION_MARGIN), Ogre::Real(rects[i].top + CAPTION_MARGIN));
            caption->setWidth(Ogre::Real(std::max(40, rects[i].width - 2 * CAPTION_MARGIN)));
        }
        mHeatmapPanel->setPosition(Ogre::Real(rects[2].left), Ogre::Real(rects[2].top));
        mHeatmapPanel->setDimensions(Ogre::Real(rects[2].width), Ogre::Real(rects[2].height));
    }

    void SingleTreeView::detach()
    {
        if (!mTarget)
            return;
        for (int z = mFirstZOrder; z < mFirstZOrder + 3; ++z)
            if (mTarget->hasViewportWithZOrder(z))
                mTarget->removeViewport(z);
        mReferenceViewport = mTechniqueViewport = mDifferenceViewport = nullptr;
        if (mOverlay)
            mOverlay->hide();
        mTarget = nullptr;
    }

    void SingleTreeView::updateShadowRange()
    {
        if (!mShadows)
            return;
        // As OffscreenRenderer::placeCamera: the directional shadow camera close to the tree, the
        // shadows reaching past its far side wherever the camera stands.
        const Ogre::Vector3 centre = mBounds.getCenter();
        mSceneManager->setShadowDirectionalLightExtrusionDistance(2.0f * mRadius + 1.0f);
        const Ogre::Real reach = mCameraNode->_getDerivedPosition().distance(centre) + 2.0f * mRadius;
        mSceneManager->setShadowFarDistance(std::max(4.0f * mRadius + 2.0f, reach));
    }

    SingleTreeView::Signature SingleTreeView::signature() const
    {
        Signature s;
        s.position = mCameraNode->_getDerivedPosition();
        s.orientation = mCameraNode->_getDerivedOrientation();
        s.technique = mTechnique;
        s.lodBias = mLodBias;
        s.shadows = mShadows;
        s.wireframe = mWireframe;
        s.lodFrozen = mLodFrozen;
        if (mTechniqueViewport)
        {
            s.width = mTechniqueViewport->getActualWidth();
            s.height = mTechniqueViewport->getActualHeight();
        }
        return s;
    }

    void SingleTreeView::frame(double seconds)
    {
        updateShadowRange();
        if (!mTarget)
            return;
        const Signature now = signature();
        if (!mPending || *mPending != now)
        {
            mPending = std::make_unique<Signature>(now);
            mStillSeconds = 0.0;
        }
        else
            mStillSeconds += seconds;
        const bool stale = !mComputed || *mComputed != now;
        if (mRecomputeNow || (stale && mStillSeconds >= RECOMPUTE_DELAY))
        {
            recomputeDifference();
            mComputed = std::make_unique<Signature>(now);
            mRecomputeNow = false;
        }
        if (!mComputed || *mComputed != now)
            mCaptions[2]->setCaption("FLIP: updating");
        else
            mCaptions[2]->setCaption("FLIP " + fixed(mFlipMean, 3) + " (max " + fixed(mFlipMax, 2) + ")");
    }

    std::vector<std::uint8_t> SingleTreeView::renderPanel(Ogre::TexturePtr& texture, const char* name,
                                                          Ogre::uint32 mask, int width, int height)
    {
        Ogre::Camera* camera =
            mask == REFERENCE_VISIBILITY ? mSceneManager->getCamera("TreeLod/Browser/ReferenceCamera") : mCamera;
        if (!texture || int(texture->getWidth()) != width || int(texture->getHeight()) != height)
        {
            if (texture)
                Ogre::TextureManager::getSingleton().remove(texture);
            texture = Ogre::TextureManager::getSingleton().createManual(
                name, Ogre::RGN_INTERNAL, Ogre::TEX_TYPE_2D, Ogre::uint(width), Ogre::uint(height), 0,
                Ogre::PF_BYTE_RGBA, Ogre::TU_RENDERTARGET);
            Ogre::RenderTarget* rt = texture->getBuffer()->getRenderTarget();
            rt->setAutoUpdated(false);
            Ogre::Viewport* vp = rt->addViewport(camera);
            vp->setOverlaysEnabled(false);
            vp->setShadowsEnabled(true);
            vp->setBackgroundColour(mBackground);
            vp->setVisibilityMask(mask);
        }
        Ogre::RenderTarget* rt = texture->getBuffer()->getRenderTarget();
        // Twice: the focused shadow camera frames what the camera saw in its previous render
        // (SceneManager::getVisibleObjectsBoundsInfo), so a first render after a change differs.
        rt->update();
        rt->update();
        std::vector<std::uint8_t> pixels(std::size_t(width) * height * 4);
        Ogre::PixelBox box(Ogre::uint32(width), Ogre::uint32(height), 1, Ogre::PF_BYTE_RGBA, pixels.data());
        rt->copyContentsToMemory(Ogre::Box(0, 0, Ogre::uint32(width), Ogre::uint32(height)), box,
                                 Ogre::RenderTarget::FB_AUTO);
        return pixels;
    }

    void SingleTreeView::recomputeDifference()
    {
        const auto start = std::chrono::steady_clock::now();
        const int width = mTechniqueViewport->getActualWidth(), height = mTechniqueViewport->getActualHeight();
        if (width <= 0 || height <= 0)
            return;
        RgbaImage reference{width, height, renderPanel(mReferenceTexture, "TreeLod/Browser/FlipReference",
                                                       REFERENCE_VISIBILITY, width, height)};
        RgbaImage test{width, height, renderPanel(mTechniqueTexture, "TreeLod/Browser/FlipTechnique",
                                                  TECHNIQUE_VISIBILITY, width, height)};
        const auto rendered = std::chrono::steady_clock::now();
        mRenderMilliseconds = std::chrono::duration<double, std::milli>(rendered - start).count();
        FlipOptions options;
        options.keepErrorMap = true;
        Result<FlipResult> result = flip(toImage(reference), toImage(test), options);
        if (!result)
            OGRE_EXCEPT(Ogre::Exception::ERR_INTERNAL_ERROR, "FLIP: " + result.error().message(),
                        "SingleTreeView::recomputeDifference");
        mFlipMean = result->mean;
        mFlipMax = result->max;
        const Image heatmap = flipHeatmap(*result);
        std::vector<std::uint8_t> rgba(heatmap.pixels.size() * 4);
        for (std::size_t i = 0; i < heatmap.pixels.size(); ++i)
            for (int c = 0; c < 4; ++c)
                rgba[4 * i + c] = c == 3 ? 255 : unitToByte(heatmap.pixels[i][c]);
        uploadHeatmap(rgba, heatmap.width, heatmap.height);
        mFlipMilliseconds = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - rendered).count();
    }

    void SingleTreeView::uploadHeatmap(const std::vector<std::uint8_t>& rgba, int width, int height)
    {
        if (!mHeatmapTexture || int(mHeatmapTexture->getWidth()) != width || int(mHeatmapTexture->getHeight()) != height)
        {
            // A new material name with each texture: RTSS keeps shader techniques per material.
            static int counter = 0;
            const Ogre::String suffix = std::to_string(counter++);
            if (mHeatmapMaterial)
                Ogre::MaterialManager::getSingleton().remove(mHeatmapMaterial);
            if (mHeatmapTexture)
                Ogre::TextureManager::getSingleton().remove(mHeatmapTexture);
            mHeatmapTexture = Ogre::TextureManager::getSingleton().createManual(
                "TreeLod/Browser/Heatmap/" + suffix, Ogre::RGN_INTERNAL, Ogre::TEX_TYPE_2D, Ogre::uint(width),
                Ogre::uint(height), 0, Ogre::PF_BYTE_RGBA, Ogre::TU_DYNAMIC_WRITE_ONLY);
            mHeatmapMaterial = Ogre::MaterialManager::getSingleton().create("TreeLod/Browser/Heatmap/" + suffix,
                                                                            Ogre::RGN_INTERNAL);
            Ogre::Pass* pass = mHeatmapMaterial->getTechnique(0)->getPass(0);
            pass->setLightingEnabled(false);
            pass->setDepthCheckEnabled(false);
            Ogre::TextureUnitState* unit = pass->createTextureUnitState(mHeatmapTexture->getName());
            unit->setTextureAddressingMode(Ogre::TextureUnitState::TAM_CLAMP);
            unit->setTextureFiltering(Ogre::TFO_NONE);
            mHeatmapPanel->setMaterialName(mHeatmapMaterial->getName(), Ogre::RGN_INTERNAL);
        }
        Ogre::PixelBox box(Ogre::uint32(width), Ogre::uint32(height), 1, Ogre::PF_BYTE_RGBA,
                           const_cast<std::uint8_t*>(rgba.data()));
        mHeatmapTexture->getBuffer()->blitFromMemory(box);
        mHeatmapPanel->show();
    }

    void SingleTreeView::renderThumbnail(const std::string& technique, Ogre::RenderTarget& target)
    {
        const std::string shown = mTechnique;
        showTechnique(technique);
        const Ogre::Vector3 position = mCameraNode->getPosition();
        const Ogre::Quaternion orientation = mCameraNode->getOrientation();
        const Ogre::Real aspect = mCamera->getAspectRatio();
        Ogre::Viewport* vp = target.addViewport(mCamera);
        mCamera->setAspectRatio(Ogre::Real(vp->getActualWidth()) / Ogre::Real(vp->getActualHeight()));
        vp->setBackgroundColour(mBackground);
        vp->setOverlaysEnabled(false);
        vp->setVisibilityMask(TECHNIQUE_VISIBILITY);
        resetView();
        updateShadowRange();
        target.update();
        target.removeViewport(vp->getZOrder());
        mCamera->setAspectRatio(aspect);
        mCameraNode->setPosition(position);
        mCameraNode->setOrientation(orientation);
        showTechnique(shown);
    }

    void SingleTreeView::setLodBias(float bias)
    {
        mLodBias = bias;
        for (Ogre::Camera* camera : {mCamera, mSceneManager->getCamera("TreeLod/Browser/ReferenceCamera")})
            camera->setLodBias(bias);
        if (!mLodFrozen)
            mLodCamera->setLodBias(bias);
    }

    void SingleTreeView::setLodTransition(float length)
    {
        mLodTransition = length;
        for (const auto& [name, object] : mTechniques)
            if (const TechniqueInfo* info = TechniqueRegistry::getSingleton().find(name); info && info->setLodTransition)
                info->setLodTransition(*object, length);
    }

    void SingleTreeView::setShadows(bool enabled)
    {
        mShadows = enabled;
        SunShadowSettings settings;
        settings.technique = enabled ? Ogre::SHADOWTYPE_TEXTURE_ADDITIVE_INTEGRATED : Ogre::SHADOWTYPE_NONE;
        settings.textureSize = mShadowSize;
        setupSunShadows(*mSceneManager, *mSun, settings);
        useShadowedMaterials(*mReference, *mAsset, enabled);
        if (auto* mesh = dynamic_cast<Ogre::Entity*>(mTechniques[REFERENCE_TECHNIQUE]))
            useShadowedMaterials(*mesh, *mAsset, enabled);
        updateShadowRange();
    }

    void SingleTreeView::setWireframe(bool enabled)
    {
        mWireframe = enabled;
        for (Ogre::Camera* camera : {mCamera, mSceneManager->getCamera("TreeLod/Browser/ReferenceCamera")})
            camera->setPolygonMode(enabled ? Ogre::PM_WIREFRAME : Ogre::PM_SOLID);
    }

    void SingleTreeView::setLodFrozen(bool frozen)
    {
        // The technique's levels freeze; the reference keeps drawing what it draws from here.
        mLodFrozen = frozen;
        if (!frozen)
        {
            mCamera->setLodCamera(nullptr);
            return;
        }
        // A copy of the camera stays behind: the objects pick their levels from it (Camera::getLodCamera).
        mLodCamera->setFOVy(mCamera->getFOVy());
        mLodCamera->setAspectRatio(mCamera->getAspectRatio());
        mLodCamera->setNearClipDistance(mCamera->getNearClipDistance());
        mLodCamera->setFarClipDistance(mCamera->getFarClipDistance());
        mLodCamera->setLodBias(mLodBias);
        mLodCameraNode->setPosition(mCameraNode->_getDerivedPosition());
        mLodCameraNode->setOrientation(mCameraNode->_getDerivedOrientation());
        // Pixel-count LoD strategies read the LoD camera's viewport size.
        mLodCamera->_notifyViewport(mTechniqueViewport ? mTechniqueViewport : mCamera->getViewport());
        mCamera->setLodCamera(mLodCamera);
    }

    std::vector<std::pair<std::string, std::string>> SingleTreeView::getStats()
    {
        Ogre::Camera* referenceCamera = mSceneManager->getCamera("TreeLod/Browser/ReferenceCamera");
        Ogre::MovableObject* object = techniqueObject();
        std::vector<std::pair<std::string, std::string>> stats;
        stats.emplace_back("Panels", "ref | tech");
        stats.emplace_back("Batches", std::to_string(referenceCamera->_getNumRenderedBatches()) + " | " +
                                          std::to_string(mCamera->_getNumRenderedBatches()));
        stats.emplace_back("Triangles", formatCount(referenceCamera->_getNumRenderedFaces()) + " | " +
                                            formatCount(mCamera->_getNumRenderedFaces()));
        stats.emplace_back("GPU memory", formatBytes(gpuBytesOf(*mReference)) + " | " +
                                             (object ? formatBytes(gpuBytesOf(*object)) : std::string("-")));
        const bool current = mComputed && mPending && *mComputed == *mPending;
        stats.emplace_back("FLIP mean", current ? fixed(mFlipMean, 4) : std::string("(view moving)"));
        stats.emplace_back("FLIP max", current ? fixed(mFlipMax, 3) : std::string("-"));
        stats.emplace_back("FLIP | render", fixed(mFlipMilliseconds, 0) + " | " + fixed(mRenderMilliseconds, 0) + " ms");
        return stats;
    }

    std::vector<std::string> SingleTreeView::getLevelHistogram()
    {
        constexpr int CELLS = 16;
        std::vector<std::string> lines;
        Ogre::MovableObject* object = techniqueObject();
        const TechniqueInfo* info = object ? TechniqueRegistry::getSingleton().find(mTechnique) : nullptr;
        if (info && info->describeState)
            for (const TechniqueStateLine& line : info->describeState(*object))
                lines.push_back(line.label + (line.fraction >= 0.0 ? textBar(line.fraction, CELLS) : "") + line.suffix);
        return lines;
    }
}
