// Technique "ellipsoids": the leaves as EM/GMM-clustered ellipsoids ray cast per fragment (the
// ellipsoids-and-lines paper (001)), drawn by an EllipsoidTree. Not yet a Forest level.
#include "TreeLod/EllipsoidTree.h"
#include "TreeLod/TechniqueRegistry.h"

namespace TreeLod
{
    namespace
    {
        void registerEllipsoids(TechniqueRegistry& registry)
        {
            const Ogre::String& type = EllipsoidTreeFactory::FACTORY_TYPE_NAME;
            registry.add({ELLIPSOID_TREE_CHUNK, "leaves as EM/GMM-clustered ellipsoids, ray cast per pixel",
                          ELLIPSOID_TREE_CHUNK, type, TechniqueRegistry::byFactory(type),
                          std::make_shared<EllipsoidTreeFactory>(), nullptr,
                          [](Ogre::MovableObject& object) -> std::vector<TechniqueStateLine> {
                              auto& tree = static_cast<EllipsoidTree&>(object);
                              const std::size_t levels = tree.getLevelCount();
                              return {{"level ",
                                       levels > 1 ? 1.0 - double(tree.getLevel()) / double(levels - 1) : 1.0,
                                       " " + std::to_string(tree.getLevel()) + " of " + std::to_string(levels) + ", " +
                                           std::to_string(tree.getEllipsoidCount()) + " ellipsoids"}};
                          }});
        }

        const TechniqueRegistry::Registration registration(&registerEllipsoids);
    }
}
