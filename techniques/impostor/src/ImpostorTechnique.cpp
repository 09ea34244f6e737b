// Technique "impostor": the one-quad impostor drawn by ImpostorTree, and as a Forest level (the
// cheapest one: two triangles a tree, the fallback of every other level).
#include "TreeLod/ImpostorData.h"
#include "TreeLod/ImpostorResources.h"
#include "TreeLod/ImpostorTree.h"
#include "TreeLod/QuadFloors.h"
#include "TreeLod/TechniqueRegistry.h"
#include "TreeLod/TreeAsset.h"

#include <OgreException.h>

namespace TreeLod
{
    namespace
    {
        class ImpostorLevels : public ForestLevelProvider
        {
        public:
            std::vector<ForestLevelSpan> getSpans(TreeAsset& asset, const Ogre::String& technique) override
            {
                ImpostorResources::of(asset).getData();
                return {{ForestLevel{technique, 0, false, 0.0f}, ForestLevelSpan::NO_UPPER}};
            }

            bool drawsBarkMesh() const override { return false; }

            void checkLevel(TreeAsset& asset, const ForestLevel& level, Ogre::AxisAlignedBox&) override
            {
                if (level.lowRes)
                    OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS, "lowRes is for billboard-cloud levels only",
                                "ImpostorLevels::checkLevel");
                ImpostorResources::of(asset).getData(); // decoded and checked
            }

            void buildParts(TreeAsset& asset, const ForestLevel&, ForestPartBuilder& parts) override
            {
                // Instanced already (TreeLodImpostor.vert): its materials as they are.
                const ImpostorGpu& gpu = ImpostorResources::of(asset).getGpu();
                ForestPartOptions options;
                options.instancedMaterial = true;
                parts.addRange(gpu.vertexData.get(), gpu.indexBuffer, 0, 6, gpu.material, gpu.shadowedMaterial,
                               options);
            }
        };

        /// A ForestBaselineFactory: a `Floor` of QuadFloors.h.
        template <class Floor>
        std::unique_ptr<ForestBaseline> makeFloor(Ogre::SceneManager& sceneManager, Ogre::SceneNode& parent,
                                                  const std::vector<TreeAssetPtr>& assets,
                                                  const std::vector<ForestInstance>& instances)
        {
            return std::make_unique<Floor>(sceneManager, parent, assets, instances);
        }

        void registerImpostor(TechniqueRegistry& registry)
        {
            TechniqueRoles roles;
            roles.floor = true;
            roles.autoCandidate = true;
            roles.comparisonLabel = "floor: the Forest's one-quad level";
            roles.plotMarker = 's';
            registry.add({IMPOSTOR_CHUNK,
                          "one camera-facing quad with baked colour and normal textures: the cheapest level",
                          IMPOSTOR_CHUNK, ImpostorTreeFactory::FACTORY_TYPE_NAME,
                          TechniqueRegistry::byFactory(ImpostorTreeFactory::FACTORY_TYPE_NAME),
                          std::make_shared<ImpostorTreeFactory>(
                              ImpostorTreeFactory::FACTORY_TYPE_NAME,
                              [](TreeAsset& asset) { return ImpostorResources::of(asset).getGpu().quad(); }), std::make_shared<ImpostorLevels>(),
                          [](Ogre::MovableObject&) -> std::vector<TechniqueStateLine> {
                              return {{"one quad, 2 triangles", -1.0, ""}};
                          }, roles, nullptr}); // one level

            // The speed floors: the impostor's quad drawn as plain Ogre objects (QuadFloors.h).
            registry.addBaseline({"entities", "floor: one Ogre entity per tree (a quad)", '^', IMPOSTOR_CHUNK,
                                  &makeFloor<EntityFloor>, true});
            registry.addBaseline({"merged-quads", "floor: quads merged into a few batches", 'x', IMPOSTOR_CHUNK,
                                  &makeFloor<MergedQuadFloor>});
            registry.addBaseline({"billboard-set", "floor: a plain Ogre BillboardSet (unlit)", 'D', IMPOSTOR_CHUNK,
                                  &makeFloor<BillboardSetFloor>});
        }

        const TechniqueRegistry::Registration registration(&registerImpostor);
    }
}
