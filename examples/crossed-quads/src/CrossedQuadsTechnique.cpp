// Technique "crossed-quads", the Ogre half: CrossedQuadsTree for single trees, one Forest level
// (the quads' plain materials; the Forest makes their instanced variants), and the registration.
#include "TreeLod/CrossedQuadsData.h"
#include "TreeLod/CrossedQuadsResources.h"
#include "TreeLod/CrossedQuadsTree.h"
#include "TreeLod/TechniqueRegistry.h"
#include "TreeLod/TreeAsset.h"

#include <OgreException.h>

namespace TreeLod
{
    namespace
    {
        class CrossedQuadsLevels : public ForestLevelProvider
        {
        public:
            std::vector<ForestLevelSpan> getSpans(TreeAsset& asset, const Ogre::String& technique) override
            {
                CrossedQuadsResources::of(asset).getData(); // decoded, nothing uploaded
                return {{ForestLevel{technique, 0, false, 0.0f}, ForestLevelSpan::NO_UPPER}};
            }

            bool drawsBarkMesh() const override { return false; } // the bark is in the textures

            void checkLevel(TreeAsset& asset, const ForestLevel& level, Ogre::AxisAlignedBox& drawnBounds) override
            {
                if (level.lowRes || level.techniqueLevel != 0)
                    OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS,
                                "crossed-quads has one level (techniqueLevel 0, lowRes false)",
                                "CrossedQuadsLevels::checkLevel");
                // The quads reach past the reference's box by their texel margins.
                drawnBounds.merge(CrossedQuadsResources::of(asset).getBounds());
            }

            void buildParts(TreeAsset& asset, const ForestLevel&, ForestPartBuilder& parts) override
            {
                const CrossedQuadsGpu& gpu = CrossedQuadsResources::of(asset).getGpu();
                for (const CrossedQuadsPart& part : gpu.parts)
                    parts.addRange(gpu.vertexData.get(), gpu.indexBuffer, part.indexStart, 6, part.material,
                                   part.shadowedMaterial);
            }
        };

        void registerCrossedQuads(TechniqueRegistry& registry)
        {
            registry.add({CROSSED_QUADS_CHUNK,
                          "two or three textured vertical quads crossing on the trunk axis (an example technique)",
                          CROSSED_QUADS_CHUNK, CrossedQuadsTreeFactory::FACTORY_TYPE_NAME,
                          TechniqueRegistry::byFactory(CrossedQuadsTreeFactory::FACTORY_TYPE_NAME),
                          std::make_shared<CrossedQuadsTreeFactory>(), std::make_shared<CrossedQuadsLevels>(),
                          [](Ogre::MovableObject& object) -> std::vector<TechniqueStateLine> {
                              const auto& tree = static_cast<CrossedQuadsTree&>(object);
                              return {{"quads " + std::to_string(tree.getQuadCount()), -1.0, ""}};
                          }, TechniqueRoles{}, nullptr}); // one level
        }

        const TechniqueRegistry::Registration registration(&registerCrossedQuads);
    }
}
