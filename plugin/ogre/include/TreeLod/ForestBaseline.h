// ForestBaseline: a measurement baseline's drawing of a scene's trees without the Forest: the
// speed floors `treelod bench` compares every technique with (what an Ogre user would write by
// hand). A technique registers its baselines (TechniqueRegistry::addBaseline, BaselineInfo) with a
// function making one; ForestScene holds it in place of a Forest.
#pragma once

#include "TreeLod/ForestInstances.h"
#include "TreeLod/TreeAsset.h"

#include <OgreSceneManager.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

namespace TreeLod
{
    class ForestBaseline
    {
    public:
        virtual ~ForestBaseline() = default;
        /// Bytes of GPU memory it holds (textures, vertex and index buffers).
        virtual std::uint64_t getGpuBytes() const = 0;
    };

    /// Draws `instances` (kind = index into `assets`) under `parent` until the baseline is destroyed;
    /// throws Ogre::Exception naming the asset or instance it cannot draw.
    using ForestBaselineFactory = std::function<std::unique_ptr<ForestBaseline>(
        Ogre::SceneManager& sceneManager, Ogre::SceneNode& parent, const std::vector<TreeAssetPtr>& assets,
        const std::vector<ForestInstance>& instances)>;
}
