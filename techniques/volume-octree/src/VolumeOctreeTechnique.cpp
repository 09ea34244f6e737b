// Technique "volume-octree": the volumetric octree tree (VolumeOctreeData.h) drawn by a
// VolumeOctreeTree, and as Forest levels, one per active level (VolumeOctreeForestGpu).
#include "TreeLod/Forest.h"
#include "TreeLod/TechniqueRegistry.h"
#include "TreeLod/VolumeOctreeData.h"
#include "TreeLod/VolumeOctreeResources.h"
#include "TreeLod/VolumeOctreeTree.h"

#include <OgreException.h>

namespace TreeLod
{
    namespace
    {
        /// The octree's Forest levels: level L draws the trees whose active level is L.
        /// A VolumeOctreeTree takes the finest level whose distance plane lies beyond the tree's
        /// nearest point; a Forest switches by the LoD value of the tree's sphere, that is by its
        /// centre: L while a cell of level L covers lodPixels pixels at the tree's centre
        /// (height on screen >= lodPixels * tree height / cellEdge(L)). Inside a level the
        /// distance planes refine as for one tree. Billboards blend, so the draws list their trees
        /// far to near (ForestPartOptions::backToFront).
        class VolumeOctreeLevels : public ForestLevelProvider
        {
        public:
            std::vector<ForestLevelSpan> getSpans(TreeAsset& asset, const Ogre::String& technique) override
            {
                const VolumeOctreeData& data = VolumeOctreeResources::of(asset).getData();
                const Ogre::AxisAlignedBox bounds = asset.getBounds();
                const Ogre::Real height = bounds.getMaximum().y - bounds.getMinimum().y;
                std::vector<ForestLevelSpan> spans;
                Ogre::Real upper = ForestLevelSpan::NO_UPPER;
                for (std::uint32_t level = data.levelCount; level-- > 0;)
                {
                    const Ogre::Real value =
                        level == 0 ? 0.0f
                                   : Forest::pixelCountForHeight(asset, LOD_PIXELS * height / data.cellEdge(level));
                    if (!(value < upper))
                        continue; // finer than the values can tell apart
                    spans.push_back({ForestLevel{technique, level, false, value}, upper});
                    upper = value;
                }
                return spans;
            }

            bool drawsBarkMesh() const override { return false; }

            void checkLevel(TreeAsset& asset, const ForestLevel& level, Ogre::AxisAlignedBox& drawnBounds) override
            {
                const char* source = "VolumeOctreeLevels::checkLevel";
                if (level.lowRes)
                    OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS, "lowRes is for billboard-cloud levels only", source);
                const VolumeOctreeData& data = VolumeOctreeResources::of(asset).getData();
                if (level.techniqueLevel >= data.levelCount)
                    OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS,
                                "level " + std::to_string(level.techniqueLevel) + " is not a level of the octree (" +
                                    std::to_string(data.levelCount) + " levels)",
                                source);
                drawnBounds.merge(volumeOctreeDrawnBounds(data));
            }

            void buildParts(TreeAsset& asset, const ForestLevel& level, ForestPartBuilder& parts) override
            {
                VolumeOctreeResources& resources = VolumeOctreeResources::of(asset);
                const VolumeOctreeForestGpu& gpu = resources.getForestGpu();
                const std::uint32_t active = level.techniqueLevel;
                ForestPartOptions options;
                options.instancedMaterial = true;
                options.backToFront = true;
                options.lengthFactor = 1.0f / LOD_PIXELS;
                options.customParameters[1] =
                    Ogre::Vector4(float(active), float(gpu.orderStart[active]), float(gpu.quadCount[active]),
                                  resources.getData().cellEdge(active));
                parts.addRange(gpu.vertexData.get(), gpu.indexBuffer, 0, 6 * std::size_t(gpu.quadCount[active]),
                               gpu.material, "", options);
            }

            Ogre::String describeLevel(const ForestLevel& level) const override
            {
                return level.technique + " " + std::to_string(level.techniqueLevel);
            }

        private:
            /// A cell covers this many pixels at its level's plane (VolumeOctreeTree's default).
            static constexpr float LOD_PIXELS = VolumeOctreeTree::Options{}.lodPixels;
        };

        void registerVolumeOctree(TechniqueRegistry& registry)
        {
            const Ogre::String& type = VolumeOctreeTreeFactory::FACTORY_TYPE_NAME;
            TechniqueRoles roles;
            roles.parameters = {{"lodTransition", "lod-transition", "level transition length t in [0, 1]: cells fade into their children within 1 + t of the plane (0: hard)"}};
            registry.add({VOLUME_OCTREE_CHUNK,
                          "an octree of per-camera billboards from matted images, VQ-compressed (Linz et al. 2006)",
                          VOLUME_OCTREE_CHUNK, type, TechniqueRegistry::byFactory(type),
                          std::make_shared<VolumeOctreeTreeFactory>(), std::make_shared<VolumeOctreeLevels>(),
                          [](Ogre::MovableObject& object) -> std::vector<TechniqueStateLine> {
                              auto& tree = static_cast<VolumeOctreeTree&>(object);
                              const std::uint32_t levels = tree.getLevelCount();
                              const VolumeCameraPair& pair = tree.getCameraPair();
                              return {{"level ", levels > 1 ? double(tree.getActiveLevel()) / double(levels - 1) : 1.0,
                                       " " + std::to_string(tree.getActiveLevel()) + " of " + std::to_string(levels) +
                                           ", " + std::to_string(tree.getDrawnCellCount()) + " cells"},
                                      {"cameras " + std::to_string(pair.first) + " and " + std::to_string(pair.second) +
                                           " blended",
                                       -1.0, ""}};
                          },
                          roles, [](Ogre::MovableObject& object, float length) {
                              static_cast<VolumeOctreeTree&>(object).setLodTransition(length);
                          }});
        }

        const TechniqueRegistry::Registration registration(&registerVolumeOctree);
    }
}
