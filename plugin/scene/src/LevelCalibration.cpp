#include "TreeLod/LevelCalibration.h"

#include "TreeLod/Forest.h"
#include "TreeLod/OffscreenRenderer.h"
#include "TreeLod/Package.h"
#include "TreeLod/TechniqueRegistry.h"
#include "TreeLod/TreeAssetManager.h"

#include <OgreRenderSystem.h>
#include <OgreRenderSystemCapabilities.h>
#include <OgreRoot.h>
#include <OgreSceneManager.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

namespace TreeLod
{
    namespace
    {
        constexpr float FOV_Y_DEGREES = 45.0f;

        double median(std::vector<double> v)
        {
            std::sort(v.begin(), v.end());
            return v.empty() ? 0.0 : v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
        }

        float boxHeight(const Ogre::AxisAlignedBox& box) { return std::max(box.getMaximum().y - box.getMinimum().y, 1e-6f); }

        /// A grid of `count` trees `distance` metres in front of the camera (looking along -Z from
        /// the origin), each `heightPx` tall, `spacingPx` apart.
        std::vector<ForestInstance> grid(const Ogre::AxisAlignedBox& box, float heightPx, float spacingPx,
                                         float distance, std::uint32_t count)
        {
            const float metresPerPx = boxHeight(box) / heightPx;
            const int columns = std::max(1, int(std::ceil(std::sqrt(double(count)))));
            std::vector<ForestInstance> instances;
            for (std::uint32_t i = 0; i < count; ++i)
            {
                const int cx = int(i) % columns, cy = int(i) / columns;
                ForestInstance instance;
                instance.position = glm::vec3((float(cx) - 0.5f * float(columns - 1)) * spacingPx * metresPerPx,
                                              (float(cy) - 0.5f * float(columns - 1)) * spacingPx * metresPerPx -
                                                  0.5f * (box.getMinimum().y + box.getMaximum().y),
                                              -distance);
                instances.push_back(instance);
            }
            return instances;
        }
    }

    std::string rendererString(Ogre::Root& root)
    {
        Ogre::RenderSystem* system = root.getRenderSystem();
        if (!system)
            return "no render system";
        const Ogre::RenderSystemCapabilities* caps = system->getCapabilities();
        return system->getName() + " | " + (caps ? caps->getDeviceName() : Ogre::String("?")) + " | " +
               (caps ? caps->getDriverVersion().toString() : Ogre::String("?"));
    }

    std::string levelCostKey(TreeAsset& asset)
    {
        std::vector<std::string> chunks;
        for (const ForestLevel& level : Forest::getCandidateLevels(asset, Forest::getAutoTechniques()))
        {
            const TechniqueInfo& info = TechniqueRegistry::getSingleton().get(level.technique);
            if (std::find(chunks.begin(), chunks.end(), info.chunkTechnique) == chunks.end())
                chunks.push_back(info.chunkTechnique);
        }
        if (std::find(chunks.begin(), chunks.end(), REFERENCE_CHUNK) == chunks.end())
            chunks.push_back(REFERENCE_CHUNK); // the bark every level draws
        return assetCostKey(asset.getPackage(), chunks);
    }

    Forest* createLevelForest(Ogre::SceneManager& sceneManager, Ogre::SceneNode& node, TreeAsset& asset,
                              const ForestLevel& level, const std::vector<ForestInstance>& instances,
                              const std::string& name, float heightPx)
    {
        const TreeAssetPtr pointer = TreeAssetManager::getSingleton().getByName(asset.getName(), asset.getGroup());
        if (!pointer)
            OGRE_EXCEPT(Ogre::Exception::ERR_ITEM_NOT_FOUND, "asset '" + asset.getName() + "' is not TreeAssetManager's",
                        "createLevelForest");
        auto* forest = static_cast<Forest*>(sceneManager.createMovableObject(name, ForestFactory::FACTORY_TYPE_NAME));
        try
        {
            ForestLevel only = level;
            only.minPixelCount = 0.0f;
            std::vector<ForestLevel> levels = {only};
            if (heightPx > 0.0f)
            {
                ForestLevel above = level; // built only if a tree is taller than 1.05 heightPx: never here
                above.minPixelCount = Forest::pixelCountForHeight(asset, 1.05f * heightPx);
                levels.insert(levels.begin(), above);
            }
            forest->addSpecies(pointer, levels);
            forest->addInstances(instances);
        }
        catch (...)
        {
            sceneManager.destroyMovableObject(forest);
            throw;
        }
        node.attachObject(forest);
        return forest;
    }

    Result<std::vector<LevelCost>> calibrateLevels(OffscreenRenderer& renderer, TreeAsset& asset,
                                                   const CalibrationOptions& options, const ProgressCallback& progress)
    {
        const std::string label = "asset '" + asset.getName() + "'";
        if (options.heightsPx.empty() || options.viewport < 16 || options.frames < 1 || options.maxTrees == 0)
            return fail(label, "calibration", "needs heights, a viewport of 16 px or more, frames and trees");
        std::vector<ForestLevel> levels;
        try
        {
            levels = Forest::getCandidateLevels(asset, Forest::getAutoTechniques());
        }
        catch (const Ogre::Exception& e)
        {
            return fail(label, "calibration", e.getDescription());
        }
        const Ogre::AxisAlignedBox box = asset.getBounds();
        const Ogre::Vector3 size = box.getSize();
        const float aspect = std::max(1.0f, std::max(size.x, size.z) / std::max(size.y, 1e-6f));
        renderer.setShadows(false);
        renderer.setLodBias(1.0f);
        renderer.clearContent();

        // The camera of each height (trees `heightPx` tall in the viewport) and its empty frame's time.
        struct Setup
        {
            float heightPx = 0.0f, spacingPx = 0.0f, distance = 0.0f; ///< distance: of the grid
            std::uint32_t count = 0;
            CameraSpec camera;
            double emptyMs = 0.0;
        };
        std::vector<Setup> setups;
        for (const float heightPx : options.heightsPx)
        {
            Setup setup;
            setup.heightPx = heightPx;
            setup.spacingPx = 1.2f * heightPx * aspect;
            const int columns = std::max(1, int(float(options.viewport) / setup.spacingPx));
            setup.count = std::min(options.maxTrees, std::uint32_t(columns * columns));
            setup.distance = float(distanceForHeight(boxHeight(box), heightPx, options.viewport, FOV_Y_DEGREES));
            setup.camera.position = glm::vec3(0.0f);
            setup.camera.target = glm::vec3(0.0f, 0.0f, -1.0f);
            setup.camera.fovYDegrees = FOV_Y_DEGREES;
            setup.camera.nearClip = std::max(0.01f, 0.25f * setup.distance);
            setup.camera.farClip = 4.0f * setup.distance;
            setup.emptyMs = median(renderer.timeFrames(setup.camera, options.viewport, options.viewport, options.frames));
            setups.push_back(setup);
        }

        std::vector<LevelCost> costs;
        const std::size_t total = levels.size() * setups.size();
        std::size_t done = 0;
        for (const ForestLevel& level : levels)
        {
            LevelCost cost;
            cost.technique = level.technique;
            cost.techniqueLevel = level.techniqueLevel;
            cost.lowRes = level.lowRes;
            for (const Setup& setup : setups)
            {
                report(progress,
                       "calibrate " + Forest::describeLevel(level) + " at " + std::to_string(int(setup.heightPx)) + " px",
                       float(done++) / float(total));
                double perTree = 0.0;
                try
                {
                    auto timeGrid = [&](std::uint32_t count, int frames) {
                        createLevelForest(renderer.getSceneManager(), renderer.getContentNode(), asset, level,
                                          grid(box, setup.heightPx, setup.spacingPx, setup.distance, count),
                                          "TreeLod/Calibration", setup.heightPx);
                        // timeFrames draws one untimed frame first (programs linked, levels built)
                        const double ms = median(renderer.timeFrames(setup.camera, options.viewport, options.viewport,
                                                                     frames));
                        renderer.clearContent();
                        return std::max(0.0, ms - setup.emptyMs);
                    };
                    const std::uint32_t probe = std::min(options.probeTrees, setup.count);
                    const double probeMs = timeGrid(probe, 1) / double(probe);
                    const std::uint32_t count = std::clamp<std::uint32_t>(
                        std::uint32_t(options.targetFrameMs / std::max(probeMs, 1e-4)), 1, setup.count);
                    perTree = timeGrid(count, options.frames) / double(count);
                }
                catch (const Ogre::Exception& e)
                {
                    renderer.clearContent();
                    return fail(label, "level " + Forest::describeLevel(level), e.getDescription());
                }
                cost.heightsPx.push_back(setup.heightPx);
                cost.msPerTree.push_back(float(perTree));
            }
            costs.push_back(std::move(cost));
        }
        report(progress, "calibrate", 1.0f);
        return costs;
    }

    Result<std::vector<LevelCost>> requireLevelCosts(OffscreenRenderer& renderer, TreeAsset& asset,
                                                     const std::string& directory, const CalibrationOptions& options,
                                                     const ProgressCallback& progress, bool* calibrated)
    {
        if (calibrated)
            *calibrated = false;
        const std::string renderString = rendererString(renderer.getRoot());
        const std::string path = costCalibrationPath(directory, renderString);
        const std::string key = levelCostKey(asset);
        CostCalibration calibration;
        calibration.renderer = renderString;
        std::error_code ec;
        if (std::filesystem::exists(path, ec))
        {
            Result<CostCalibration> read = readCostCalibration(path, renderString);
            if (read)
                calibration = std::move(read.value());
            else
                report(progress, "warning: " + read.error().message() + "; calibrating again", 0.0f);
        }
        if (const std::vector<LevelCost>* held = calibration.find(key))
        {
            bool all = true;
            for (const ForestLevel& level : Forest::getCandidateLevels(asset, Forest::getAutoTechniques()))
                all = all && findLevelCost(*held, level.technique, level.techniqueLevel, level.lowRes) >= 0;
            if (all)
                return *held;
        }
        Result<std::vector<LevelCost>> costs = calibrateLevels(renderer, asset, options, progress);
        if (!costs)
            return costs.error();
        calibration.assets[key] = costs.value();
        std::filesystem::create_directories(directory, ec);
        if (Result<void> written = writeCostCalibration(path, calibration); !written)
            return written.error();
        if (calibrated)
            *calibrated = true;
        return costs;
    }
}
