// The Ogre half of LoDF (Rebollo et al. 2006): technique "lodf" drawn by FoliageLodTree, and its
// Forest levels (quantised leaf counts, each the asset's shared level + the bark mesh).
#include "TreeLod/FoliageLodResources.h"
#include "TreeLod/FoliageLodTree.h"
#include "TreeLod/TechniqueRegistry.h"
#include "TreeLod/TreeAsset.h"

#include <OgreException.h>

#include <algorithm>

namespace TreeLod
{
    namespace
    {
        class FoliageLodLevels : public ForestLevelProvider
        {
        public:
            std::vector<ForestLevelSpan> getSpans(TreeAsset& asset, const Ogre::String& technique) override
            {
                // Leaf counts halving from all leaves; the level drawing N leaves keeps them while
                // FoliageLodTree's curve asks for more than N / 2, so it never draws fewer leaves
                // than the curve (the same rule as FoliageLodState::quantise, which rounds up).
                const FoliageLodData& data = FoliageLodResources::of(asset).getFoliageLod();
                const float perLeaf = FoliageLodTree::DEFAULT_PIXELS_PER_LEAF;
                std::vector<ForestLevelSpan> spans;
                auto add = [&](std::uint32_t count, Ogre::Real lower, Ogre::Real upper) {
                    if (lower < upper)
                        spans.push_back({ForestLevel{technique, count, false, lower}, upper});
                };
                std::uint32_t count = data.maxLeafCount();
                Ogre::Real upper = ForestLevelSpan::NO_UPPER;
                while (true)
                {
                    const std::uint32_t next = std::max((count + 1) / 2, data.minLeafCount());
                    if (data.clusters.empty() || next >= count)
                    {
                        add(count, 0.0f, upper);
                        break;
                    }
                    const Ogre::Real lower = FoliageLodTree::pixelCountForLeaves(next, perLeaf);
                    add(count, lower, upper);
                    upper = lower;
                    count = next;
                }
                return spans;
            }

            void checkLevel(TreeAsset& asset, const ForestLevel& level, Ogre::AxisAlignedBox&) override
            {
                if (level.lowRes)
                    OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS, "lowRes is for billboard-cloud levels only",
                                "FoliageLodLevels::checkLevel");
                FoliageLodResources::of(asset).getFoliageLod(); // decoded and checked against the reference
            }

            void buildParts(TreeAsset& asset, const ForestLevel& level, ForestPartBuilder& parts) override
            {
                FoliageLodResources& resources = FoliageLodResources::of(asset);
                const FoliageLodData& data = resources.getFoliageLod();
                const std::vector<Ogre::String>& materials = asset.getMaterialNames();
                const std::vector<Ogre::String>& shadowed = asset.getShadowedMaterialNames();
                if (!data.clusters.empty())
                {
                    const FoliageLodLevel& shared = resources.getFoliageLodLevel(
                        level.techniqueLevel == 0 ? data.maxLeafCount() : level.techniqueLevel);
                    // One range per run of same-material clusters (FoliageLodResources::getFoliageLodLevel).
                    std::size_t run = 0;
                    for (std::size_t c = 0; c < data.clusters.size(); ++run)
                    {
                        const std::uint32_t material = data.clusters[c].material;
                        while (c < data.clusters.size() && data.clusters[c].material == material)
                            ++c;
                        parts.addRange(resources.getLeafVertexData(), shared.buffer, shared.ranges[run].first,
                                       shared.ranges[run].second, materials[material], shadowed[material]);
                    }
                }
                if (!asset.getReference().model.barkIndices.empty())
                    parts.addMesh(asset.getBarkMesh(), materials, shadowed);
            }

            Ogre::String describeLevel(const ForestLevel& level) const override
            {
                return level.technique + " " + (level.techniqueLevel ? std::to_string(level.techniqueLevel) : "all");
            }
        };

        void registerFoliageLod(TechniqueRegistry& registry)
        {
            TechniqueRoles roles;
            roles.autoCandidate = true;
            roles.defaultBandMinHeight = 160.0f; // every leaf geometric while the tree is large on screen
            roles.benchDefault = true;
            roles.parameters = {{"leaves", "leaves", "draw exactly this many leaves (default: from screen size)"},
                                {"pixelsPerLeaf", "pixels-per-leaf", "projected pixels per leaf (default 4)"}};
            registry.add({FOLIAGE_LOD_CHUNK,
                          "LoDF: every leaf geometric, leaf count continuous with screen size (Rebollo et al. 2006)",
                          FOLIAGE_LOD_CHUNK, FoliageLodTreeFactory::FACTORY_TYPE_NAME,
                          TechniqueRegistry::byFactory(FoliageLodTreeFactory::FACTORY_TYPE_NAME),
                          std::make_shared<FoliageLodTreeFactory>(), std::make_shared<FoliageLodLevels>(),
                          [](Ogre::MovableObject& object) -> std::vector<TechniqueStateLine> {
                              auto& tree = static_cast<FoliageLodTree&>(object);
                              const double fraction =
                                  double(tree.getLeafCount()) / double(std::max(1u, tree.getMaxLeafCount()));
                              return {{"leaves ", fraction,
                                       " " + std::to_string(tree.getLeafCount()) + "/" +
                                           std::to_string(tree.getMaxLeafCount())},
                                      {"bark LoD " + std::to_string(tree.getBarkLodIndex()), -1.0, ""}};
                          }, roles, nullptr}); // a continuous collapse
        }

        const TechniqueRegistry::Registration registration(&registerFoliageLod);
    }
}
