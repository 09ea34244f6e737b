// LevelCalibration: what each level of a tree costs on the running machine (LevelCosts.h).
//
// For every level budgeted auto chooses among (Forest::getCandidateLevels of
// Forest::getAutoTechniques()), a grid of trees at
// that one level, spaced so they do not overlap, is drawn through a Forest (instanced, as in a
// scene) at each calibration height; each frame is timed until a one-pixel read-back returns
// (OGRE 1.12's GL3Plus has no timer queries), the median of a few frames taken, the median of an
// empty frame subtracted and the rest divided by the tree count. An untimed probe frame of a few
// trees sizes the timed grid to about targetFrameMs, so a calibration stays short whatever a
// level costs (a few seconds per level on llvmpipe). Results are cached per renderer
// string (costCalibrationPath): a calibration from another renderer is never reused.
//
// The same file holds whether this renderer samples block-compressed textures slower than RGBA8
// (measureTextureSampling, TextureSamplingCost): where it does (llvmpipe decodes every fetch in
// software), requireTextureUpload makes TreeAssetManager decode them at load, before any level
// is calibrated, so that the costs are those of the textures as drawn.
#pragma once

#include "TreeLod/ForestLevelProvider.h"
#include "TreeLod/LevelCosts.h"
#include "TreeLod/Progress.h"
#include "TreeLod/Result.h"

#include <string>
#include <vector>

namespace Ogre
{
    class Root;
    class SceneManager;
    class SceneNode;
}

namespace TreeLod
{
    class Forest;
    class OffscreenRenderer;
    class TreeAsset;
    struct ForestInstance;

    struct CalibrationOptions
    {
        std::vector<float> heightsPx{16.0f, 64.0f, 256.0f};
        int viewport = 512;         ///< square, pixels
        int frames = 3;             ///< timed per measurement (after one warm-up)
        std::uint32_t maxTrees = 1024;
        std::uint32_t probeTrees = 16; ///< the warm-up frame's grid, which sizes the timed one
        double targetFrameMs = 60.0;   ///< the timed grid holds about this many milliseconds of trees
    };

    /// The render system's name, device and driver: the key of a calibration file.
    std::string rendererString(Ogre::Root& root);

    /// The calibration key of `asset` (assetCostKey over the chunks its auto levels draw from, so
    /// that other techniques' chunks added to the package later keep its costs).
    std::string levelCostKey(TreeAsset& asset);

    /// A Forest drawing `asset` at `level` alone (every value), with `instances`, attached to `node`.
    /// Its bark is the bark mesh's LoD level for trees `heightPx` tall, as a Forest whose level
    /// ends there draws it (Forest.h, "Bark"): a copy of the level above it, never drawn, bounds
    /// it; 0 = full detail. Throws Ogre::Exception as Forest::addSpecies / addInstances do.
    Forest* createLevelForest(Ogre::SceneManager& sceneManager, Ogre::SceneNode& node, TreeAsset& asset,
                              const ForestLevel& level, const std::vector<ForestInstance>& instances,
                              const std::string& name, float heightPx = 0.0f);

    /// Time the same draw (a 1024² texture with mips, four trilinear reads a fragment, four
    /// full-viewport layers at min(options.viewport, 256)²) sampling it block-compressed (DXT5) and decoded
    /// to RGBA8 (decodeGpuTexture), median of options.frames frames each, the empty frame
    /// subtracted (GLSL 3.30, or GLSL ES 3.00 where the render system runs only that). Errors
    /// name the step.
    Result<TextureSamplingCost> measureTextureSampling(OffscreenRenderer& renderer,
                                                       const CalibrationOptions& options = {});

    /// The texture sampling cost of this renderer from the calibration file in `directory`, else
    /// measured and added to it; then TreeAssetManager::adoptMeasuredTextureUpload with its
    /// decision (which the user's choice overrides). Errors name the file.
    Result<TextureSamplingCost> requireTextureUpload(OffscreenRenderer& renderer, const std::string& directory,
                                                     const CalibrationOptions& options = {},
                                                     const ProgressCallback& progress = {});

    /// TreeAssetManager::adoptMeasuredTextureUpload with `calibration`'s decision when it holds a
    /// texture sampling cost; false when it holds none.
    bool adoptCalibratedTextureUpload(const CostCalibration& calibration);

    /// Calibrate every auto level of `asset` (loaded). Errors name the asset and the level.
    Result<std::vector<LevelCost>> calibrateLevels(OffscreenRenderer& renderer, TreeAsset& asset,
                                                   const CalibrationOptions& options = {},
                                                   const ProgressCallback& progress = {});

    /// The costs of `asset`'s levels on this renderer: from the calibration file in `directory`
    /// when it holds them all, else calibrated and added to it (atomically); requireTextureUpload
    /// first. `calibrated` tells
    /// which. Errors name the file or the asset.
    Result<std::vector<LevelCost>> requireLevelCosts(OffscreenRenderer& renderer, TreeAsset& asset,
                                                     const std::string& directory,
                                                     const CalibrationOptions& options = {},
                                                     const ProgressCallback& progress = {}, bool* calibrated = nullptr);
}
