// Technique "mesh": the polygonal reference (bark with MeshLodGenerator levels, every leaf) as an
// Ogre Entity of TreeAsset::getReferenceMesh, and as a Forest level. Every comparison in this
// project is made against it.
#include "TreeLod/ModelChunk.h"
#include "TreeLod/Package.h"
#include "TreeLod/TechniqueRegistry.h"
#include "TreeLod/TreeAsset.h"
#include "TreeLod/Wind.h"

#include <OgreEntity.h>
#include <OgreSubEntity.h>
#include <OgreException.h>
#include <OgreSceneManager.h>

namespace TreeLod
{
    namespace
    {
        class ReferenceLevels : public ForestLevelProvider
        {
        public:
            std::vector<ForestLevelSpan> getSpans(TreeAsset& asset, const Ogre::String& technique) override
            {
                if (!hasPolygons(asset.getReference().model))
                    return {}; // baked from photographs: nothing to draw as a mesh
                return {{ForestLevel{technique, 0, false, 0.0f}, ForestLevelSpan::NO_UPPER}};
            }

            void checkLevel(TreeAsset& asset, const ForestLevel& level, Ogre::AxisAlignedBox&) override
            {
                if (level.lowRes)
                    OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS, "lowRes: the mesh has no low-res level",
                                "ReferenceLevels::checkLevel");
                if (Result<void> polygons = requirePolygons(asset.getReference().model, asset.getName(), "technique 'mesh'");
                    !polygons)
                    asset.raise(polygons.error());
            }

            void buildParts(TreeAsset& asset, const ForestLevel&, ForestPartBuilder& parts) override
            {
                parts.addMesh(asset.getReferenceMesh(), asset.getMaterialNames(), asset.getShadowedMaterialNames());
            }
        };

        void registerReference(TechniqueRegistry& registry)
        {
            TechniqueRoles roles;
            roles.autoCandidate = true;
            roles.comparisonLabel = "polygonal reference (mesh, 1 spp)";
            roles.plotMarker = 'o';
            registry.add({REFERENCE_TECHNIQUE, "polygonal reference: bark with MeshLodGenerator levels, every leaf", REFERENCE_CHUNK,
                          Ogre::EntityFactory::FACTORY_TYPE_NAME,
                          [](Ogre::SceneManager& sm, const Ogre::String& name, TreeAsset& asset,
                             const Ogre::NameValuePairList&) {
                              Ogre::Entity* entity = sm.createEntity(name, asset.getReferenceMesh());
                              const Ogre::Real height = Wind::treeHeight(asset.getBounds());
                              for (Ogre::SubEntity* sub : entity->getSubEntities())
                                  Wind::setTreeHeight(*sub, height);
                              return static_cast<Ogre::MovableObject*>(entity);
                          },
                          nullptr, std::make_shared<ReferenceLevels>(),
                          [](Ogre::MovableObject& object) {
                              auto& entity = static_cast<Ogre::Entity&>(object);
                              std::vector<TechniqueStateLine> lines;
                              const unsigned levels = entity.getMesh()->getNumLodLevels();
                              for (unsigned level = 0; level < levels; ++level)
                              {
                                  const bool drawn = level == entity.getCurrentLodIndex();
                                  lines.push_back({"bark LoD " + std::to_string(level) + "  ", drawn ? 1.0 : 0.0, ""});
                              }
                              return lines;
                          }, roles, nullptr}); // the mesh LoD of an Entity
        }

        const TechniqueRegistry::Registration registration(&registerReference);
    }
}
