// Technique "volume-octree": the volumetric octree tree (VolumeOctreeData.h) drawn by a
// VolumeOctreeTree. Not a Forest level yet: its back-to-front order and camera pair are per object.
#include "TreeLod/TechniqueRegistry.h"
#include "TreeLod/VolumeOctreeData.h"
#include "TreeLod/VolumeOctreeTree.h"

namespace TreeLod
{
    namespace
    {
        void registerVolumeOctree(TechniqueRegistry& registry)
        {
            const Ogre::String& type = VolumeOctreeTreeFactory::FACTORY_TYPE_NAME;
            registry.add({VOLUME_OCTREE_CHUNK,
                          "an octree of per-camera billboards from matted images, VQ-compressed (Linz et al. 2006)",
                          VOLUME_OCTREE_CHUNK, type, TechniqueRegistry::byFactory(type),
                          std::make_shared<VolumeOctreeTreeFactory>(), nullptr,
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
                          }});
        }

        const TechniqueRegistry::Registration registration(&registerVolumeOctree);
    }
}
