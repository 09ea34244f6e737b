#include "ForestSample.h"

#include "TreeLod/AtomicFile.h"
#include "TreeLod/LevelCalibration.h"
#include "TreeLod/OffscreenRenderer.h"
#include "TreeLod/TechniqueRegistry.h"

#include <OgreLogManager.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace TreeLod
{
    const char* const ForestSample::SCRIPT_TECHNIQUE = "scene script";
    /// Bytes of Forest levels built per frame: a level first seen never stalls the browser by more.
    constexpr std::uint64_t UPLOAD_BUDGET = 8000000;

    ForestSample::ForestSample(Ogre::Root& root, SceneScript script) : mRoot(root), mScript(std::move(script))
    {
        mShadows = mScript.shadows.enabled;
        const LightingSpec lighting = sceneLighting(mScript);
        mBackground = Ogre::ColourValue(lighting.background.r, lighting.background.g, lighting.background.b);
    }

    ForestSample::~ForestSample()
    {
        detach();
        mScene.reset();
        if (mSceneManager)
            mRoot.destroySceneManager(mSceneManager);
    }

    std::string ForestSample::getTitle() const { return "Forest: " + mScript.name; }

    std::string ForestSample::getDescription() const
    {
        const std::size_t trees = mScene ? mScene->getPlacements().size() : 0;
        char text[160];
        std::snprintf(text, sizeof text, "\n\n%zu %s of %zu species, a %.0f s camera path. Space plays or pauses it; "
                      "paused, drag to look and move with WASD.",
                      trees, trees == 1 ? "tree" : "trees", mScript.species.size(), pathEnd() - pathStart());
        return mScript.description + text;
    }

    double ForestSample::pathStart() const { return mScript.camera.keyframes.front().time; }
    double ForestSample::pathEnd() const { return mScript.camera.keyframes.back().time; }

    float ForestSample::getCameraSpeed() const { return std::clamp(mScript.ground.size / 60.0f, 2.0f, 100.0f); }

    void ForestSample::build(const ProgressCallback& progress)
    {
        if (mSceneManager)
            return;
        report(progress, "forest: building " + mScript.name, 0.0f);
        mSceneManager = mRoot.createSceneManager();
        ForestSceneOptions options;
        options.uploadBudget = UPLOAD_BUDGET;
        // Budgeted auto with this renderer's costs from the user's cache; none: the fixed bands.
        {
            // Block-compressed textures decoded at load where this renderer's calibration says so.
            const std::string renderer = rendererString(mRoot);
            if (Result<CostCalibration> calibration =
                    readCostCalibration(costCalibrationPath(userCacheDirectory(), renderer), renderer))
                adoptCalibratedTextureUpload(*calibration);
        }
        options.levelCosts = [this](TreeAsset& asset) {
            const std::string renderer = rendererString(mRoot);
            const std::string path = costCalibrationPath(userCacheDirectory(), renderer);
            Result<CostCalibration> calibration = readCostCalibration(path, renderer);
            const std::vector<LevelCost>* costs = calibration ? calibration->find(levelCostKey(asset)) : nullptr;
            if (!costs)
                OGRE_EXCEPT(Ogre::Exception::ERR_ITEM_NOT_FOUND,
                            "no calibration of " + asset.getName() + " on this renderer in " + path +
                                " (treelod calibrate makes one)",
                            "ForestSample");
            return *costs;
        };
        mErrorBudget = mScript.lod.maxError;
        mLodTransition = mScript.lod.transition;
        prepareSceneOptions(options);
        // The camera first: PSSM shadows split the view of the scene manager's camera.
        mCamera = mSceneManager->createCamera("TreeLod/Browser/ForestCamera");
        mCameraNode = mSceneManager->getRootSceneNode()->createChildSceneNode();
        mCameraNode->attachObject(mCamera);
        mPathTime = pathStart();
        applyCameraSpec(*mCamera, *mCameraNode, cameraAt(mScript, mPathTime));
        mScene = std::make_unique<ForestScene>(*mSceneManager, *mSceneManager->getRootSceneNode(), mScript, options);
        setShadows(mShadows);
        report(progress, "forest: building " + mScript.name, 1.0f);
    }

    void ForestSample::renderThumbnail(Ogre::RenderTarget& target)
    {
        // The middle of the camera path: the first keyframe may stand inside a crown.
        Ogre::Viewport* vp = addViewport(target, mCamera, 0, {0, 0, int(target.getWidth()), int(target.getHeight())});
        vp->setBackgroundColour(mBackground);
        vp->setOverlaysEnabled(false);
        applyCameraSpec(*mCamera, *mCameraNode, cameraAt(mScript, 0.5 * (pathStart() + pathEnd())));
        target.update();
        target.removeViewport(vp->getZOrder());
        applyCameraSpec(*mCamera, *mCameraNode, cameraAt(mScript, mPathTime));
    }

    void ForestSample::attach(Ogre::RenderTarget& target, const PixelRect& area, int firstZOrder)
    {
        detach();
        mTarget = &target;
        mViewport = addViewport(target, mCamera, firstZOrder, area);
        mViewport->setBackgroundColour(mBackground);
        mViewport->setOverlaysEnabled(false);
        mViewport->setShadowsEnabled(true);
    }

    void ForestSample::detach()
    {
        if (mTarget && mViewport)
            mTarget->removeViewport(mViewport->getZOrder());
        mViewport = nullptr;
        mTarget = nullptr;
    }

    void ForestSample::frame(double seconds)
    {
        // A technique switch bakes on worker threads; the Forest keeps drawing the current one.
        try
        {
            const bool frozen = isLodFrozen();
            if (mScene->update())
            {
                mScene->getForest().setLodFrozen(frozen);
                mScene->getForest().setLodTransition(mLodTransition);
            }
        }
        catch (const Ogre::Exception& e)
        {
            mBakeError = e.getDescription();
            Ogre::LogManager::getSingleton().logError(mBakeError);
        }
        if (!mPlaying)
            return;
        const double length = pathEnd() - pathStart();
        mPathTime += seconds;
        if (mPathTime > pathEnd())
            mPathTime = length > 0.0 ? pathStart() + std::fmod(mPathTime - pathStart(), length) : pathStart();
        applyCameraSpec(*mCamera, *mCameraNode, cameraAt(mScript, mPathTime));
    }

    void ForestSample::frameTimed(double seconds)
    {
        // Under a frame budget (the script's lod.frameBudgetMs), the controller scales its model by it.
        mScene->getForest().notifyFrameTime(float(seconds * 1000.0));
    }

    void ForestSample::setScreenshotView(unsigned index, unsigned count)
    {
        mPlaying = false;
        mPathTime = frameTime(mScript, index, count);
        applyCameraSpec(*mCamera, *mCameraNode, cameraAt(mScript, mPathTime));
    }

    std::vector<std::string> ForestSample::getTechniques() const
    {
        std::vector<std::string> names{SCRIPT_TECHNIQUE};
        for (const TechniqueInfo& info : TechniqueRegistry::getSingleton().getTechniques())
            if (info.forestLevels)
                names.push_back(info.name);
        return names;
    }

    std::string ForestSample::menuLabel(const LodPolicy& policy)
    {
        return policy.mode == LodPolicy::Mode::Script ? std::string(SCRIPT_TECHNIQUE) : policy.toString();
    }

    std::string ForestSample::getTechnique() const
    {
        // The one asked for while its bakes run (the menu keeps showing the choice).
        return menuLabel(mScene->isPolicyPending() ? mScene->getPendingPolicy() : mScene->getPolicy());
    }

    void ForestSample::setTechnique(const std::string& technique)
    {
        requestPolicy(technique == SCRIPT_TECHNIQUE ? LodPolicy::scriptChoice() : LodPolicy::fixed(technique));
    }

    void ForestSample::requestPolicy(const LodPolicy& policy)
    {
        mBakeError.clear();
        mScene->requestPolicy(policy);
    }

    void ForestSample::setErrorBudget(float budget)
    {
        mErrorBudget = budget;
        // Budgeted species re-plan in place; otherwise the scene is rebuilt under budgeted auto.
        if (!mScene->isPolicyPending() && mScene->setErrorBudget(budget))
            return;
        requestPolicy(LodPolicy::automatic(budget));
    }

    void ForestSample::setLodTransition(float transition)
    {
        mLodTransition = transition;
        mScene->getForest().setLodTransition(transition);
    }

    void ForestSample::setLodBias(float bias)
    {
        mLodBias = bias;
        mCamera->setLodBias(bias);
    }

    void ForestSample::setShadows(bool enabled)
    {
        mShadows = enabled;
        mScene->setShadows(enabled);
    }

    void ForestSample::setWireframe(bool enabled)
    {
        mWireframe = enabled;
        mCamera->setPolygonMode(enabled ? Ogre::PM_WIREFRAME : Ogre::PM_SOLID);
    }

    bool ForestSample::isSettled() const
    {
        return !mScene->isPolicyPending() && mScene->getForest().getStats().pendingLevels == 0;
    }

    bool ForestSample::isLodFrozen() const { return mScene->getForest().isLodFrozen(); }

    void ForestSample::setLodFrozen(bool frozen) { mScene->getForest().setLodFrozen(frozen); }

    std::vector<std::pair<std::string, std::string>> ForestSample::getStats()
    {
        const ForestStats& s = mScene->getForest().getStats();
        char cull[32];
        std::snprintf(cull, sizeof cull, "%.2f ms", s.cullMilliseconds);
        std::vector<std::pair<std::string, std::string>> stats;
        stats.emplace_back("Trees shown", formatCount(s.visibleInstances) + " of " + formatCount(s.instances));
        if (s.occludedInstances > 0)
            stats.emplace_back("Hidden by trees", formatCount(s.occludedInstances));
        if (mLodTransition > 0.0f)
            stats.emplace_back("In a transition", formatCount(s.transitionInstances));
        stats.emplace_back("Batches (frame)", std::to_string(mCamera->_getNumRenderedBatches()));
        stats.emplace_back("Triangles (frame)", formatCount(mCamera->_getNumRenderedFaces()));
        stats.emplace_back("Forest draws", std::to_string(s.batches));
        stats.emplace_back("GPU memory", formatBytes(mScene->getGpuBytes()));
        stats.emplace_back("Cull + LoD", cull);
        if (s.pendingLevels > 0 || s.fallbackInstances > 0)
            stats.emplace_back("Levels uploading", std::to_string(s.pendingLevels) + " (" +
                                                       formatCount(s.fallbackInstances) + " trees at a fallback)");
        if (mScene->isPolicyPending())
            stats.emplace_back("Baking", getTechnique() + " (drawing " + menuLabel(mScene->getPolicy()) + " meanwhile)");
        if (!mBakeError.empty())
            stats.emplace_back("Bake failed", mBakeError);
        // "oak: budget 0.04: <technique> 3000 >= 117 px, ...": how, here; which levels, in the level box.
        for (const std::string& note : mScene->getLevelNotes())
        {
            const std::size_t colon = note.find(": ");
            const std::string how = note.substr(colon + 2);
            stats.emplace_back("Auto " + note.substr(0, colon), how.substr(0, how.find(':')));
        }
        return stats;
    }

    std::vector<std::string> ForestSample::getLevelHistogram()
    {
        constexpr int CELLS = 8;
        const Forest& forest = mScene->getForest();
        const ForestStats& s = forest.getStats();
        std::uint32_t most = 1; // bars relative to the fullest level
        for (const std::vector<std::uint32_t>& counts : s.levelCounts)
            for (std::uint32_t count : counts)
                most = std::max(most, count);
        std::vector<std::string> lines = mScene->getLevelNotes();
        for (std::size_t species = 0; species < s.levelCounts.size(); ++species)
        {
            const std::vector<ForestLevel>& levels = forest.getLevels(std::uint32_t(species));
            for (std::size_t level = 0; level < s.levelCounts[species].size() && level < levels.size(); ++level)
            {
                const std::uint32_t count = s.levelCounts[species][level];
                if (count == 0)
                    continue;
                // "oak L2 cloud 1 low": species, Forest level, what it draws (Forest.h).
                const ForestLevel& l = levels[level];
                const TechniqueInfo* info = TechniqueRegistry::getSingleton().find(l.technique);
                const std::string what = info && info->forestLevels ? info->forestLevels->describeLevel(l) : l.technique;
                lines.push_back(mScript.species[species].name + " L" + std::to_string(level) + " " + what + " " +
                                textBar(double(count) / double(most), CELLS) + " " +
                                std::to_string(count));
            }
        }
        if (lines.size() == mScene->getLevelNotes().size())
            lines.push_back("(no tree in view)");
        return lines;
    }
}
