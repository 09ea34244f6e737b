// Technique "octahedral-impostor": the octahedral impostor (OctahedralImpostorData.h) drawn by an
// ImpostorTree of type "OctahedralImpostorTree", and as a Forest level (one quad a tree, three
// baked views blended per fragment).
#include "TreeLod/OctahedralImpostorData.h"
#include "TreeLod/OctahedralImpostorResources.h"
#include "TreeLod/TechniqueRegistry.h"
#include "TreeLod/TreeAsset.h"

#include <OgreException.h>

namespace TreeLod
{
    namespace
    {
        class OctahedralImpostorLevels : public ForestLevelProvider
        {
        public:
            std::vector<ForestLevelSpan> getSpans(TreeAsset& asset, const Ogre::String& technique) override
            {
                OctahedralImpostorResources::of(asset).getData();
                return {{ForestLevel{technique, 0, false, 0.0f}, ForestLevelSpan::NO_UPPER}};
            }

            bool drawsBarkMesh() const override { return false; }

            void checkLevel(TreeAsset& asset, const ForestLevel& level, Ogre::AxisAlignedBox& drawnBounds) override
            {
                if (level.lowRes)
                    OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS, "lowRes is for billboard-cloud levels only",
                                "OctahedralImpostorLevels::checkLevel");
                drawnBounds.merge(OctahedralImpostorResources::of(asset).getDrawnBounds());
            }

            void buildParts(TreeAsset& asset, const ForestLevel&, ForestPartBuilder& parts) override
            {
                const OctahedralImpostorGpu& gpu = OctahedralImpostorResources::of(asset).getGpu();
                ForestPartOptions options;
                options.instancedMaterial = true; // TreeLodOctahedralImpostor.vert reads the instance data
                parts.addRange(gpu.vertexData.get(), gpu.indexBuffer, 0, 6, gpu.material, gpu.shadowedMaterial,
                               options);
            }
        };

        void registerOctahedralImpostor(TechniqueRegistry& registry)
        {
            const Ogre::String type = ImpostorTreeFactory::OCTAHEDRAL_TYPE_NAME;
            TechniqueRoles roles;
            roles.autoCandidate = true;
            registry.add({OCTAHEDRAL_IMPOSTOR_CHUNK,
                          "many baked views over the upper hemisphere, the three nearest blended on one quad",
                          OCTAHEDRAL_IMPOSTOR_CHUNK, type, TechniqueRegistry::byFactory(type),
                          std::make_shared<ImpostorTreeFactory>(
                              type, [](TreeAsset& asset) { return OctahedralImpostorResources::of(asset).getGpu().quad(); }),
                          std::make_shared<OctahedralImpostorLevels>(),
                          [](Ogre::MovableObject&) -> std::vector<TechniqueStateLine> {
                              return {{"one quad, 3 of the baked views blended", -1.0, ""}};
                          }, roles, nullptr}); // one level
        }

        const TechniqueRegistry::Registration registration(&registerOctahedralImpostor);
    }
}
