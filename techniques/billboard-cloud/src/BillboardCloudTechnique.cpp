// The Ogre half of the billboard clouds (García et al. 2007): techniques "billboard-cloud"
// (multi-layered indirect texturing) and "classic-billboard-cloud" drawn by BillboardCloudTree,
// and their Forest levels: each cloud level, a layered level split where its material LoD turns
// to the low-res technique (§5.1), with the bark AO mesh.
#include "TreeLod/BillboardCloudResources.h"
#include "TreeLod/BillboardCloudTree.h"
#include "TreeLod/TechniqueRegistry.h"
#include "TreeLod/TreeAsset.h"

#include <OgreException.h>

#include <algorithm>

namespace TreeLod
{
    namespace
    {
        [[noreturn]] void invalid(const Ogre::String& text)
        {
            OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS, text, "BillboardCloudLevels");
        }

        class BillboardCloudLevels : public ForestLevelProvider
        {
        public:
            explicit BillboardCloudLevels(bool classic) : mClassic(classic) {}

            std::vector<ForestLevelSpan> getSpans(TreeAsset& asset, const Ogre::String& technique) override
            {
                // The switches BillboardCloudTree makes (§6), in the reference sphere's units; a
                // layered level splits where its material LoD turns to the low-res technique (§5.1).
                const BillboardCloudGpu& gpu = BillboardCloudResources::of(asset, mClassic).getLayout();
                const float radius = Ogre::Math::boundingRadiusFromAABB(asset.getBounds());
                const std::vector<Ogre::Real> switches =
                    BillboardCloudTree::switchPixelCounts(gpu, gpu.listFactor, radius);
                std::vector<ForestLevelSpan> spans;
                auto add = [&](std::uint32_t level, bool lowRes, Ogre::Real lower, Ogre::Real upper) {
                    if (lower < upper)
                        spans.push_back({ForestLevel{technique, level, lowRes, lower}, upper});
                };
                if (gpu.levels.empty())
                    add(0, false, 0.0f, ForestLevelSpan::NO_UPPER);
                for (std::uint32_t l = 0; l < gpu.levels.size(); ++l)
                {
                    const Ogre::Real upper = l == 0 ? ForestLevelSpan::NO_UPPER : switches[l - 1];
                    const Ogre::Real lower = l < switches.size() ? switches[l] : 0.0f;
                    if (!gpu.levels[l].layered)
                    {
                        add(l, false, lower, upper);
                        continue;
                    }
                    const Ogre::Real lowRes =
                        billboardCloudPixelCount(1.0f, gpu.levels[l].cellSize, radius, gpu.listFactor);
                    add(l, false, std::max(lowRes, lower), upper);
                    add(l, true, lower, std::min(lowRes, upper));
                }
                return spans;
            }

            Ogre::MeshPtr getBarkMesh(TreeAsset& asset) override
            {
                return BillboardCloudResources::of(asset, mClassic).getBarkAoMesh();
            }

            void checkLevel(TreeAsset& asset, const ForestLevel& level, Ogre::AxisAlignedBox& drawnBounds) override
            {
                const BillboardCloudGpu& layout = BillboardCloudResources::of(asset, mClassic).getLayout();
                if (level.techniqueLevel >= std::max<std::size_t>(layout.levels.size(), 1))
                    invalid("cloud level " + std::to_string(level.techniqueLevel) + " does not exist (" +
                            std::to_string(layout.levels.size()) + " levels)");
                if (level.lowRes &&
                    !(level.techniqueLevel < layout.levels.size() && layout.levels[level.techniqueLevel].layered))
                    invalid("lowRes on a cloud level that is not layered");
                if (level.techniqueLevel < layout.levels.size())
                    drawnBounds.merge(layout.bounds);
            }

            void buildParts(TreeAsset& asset, const ForestLevel& level, ForestPartBuilder& parts) override
            {
                BillboardCloudResources& resources = BillboardCloudResources::of(asset, mClassic);
                const BillboardCloudGpu& gpu = resources.getGpu();
                if (level.techniqueLevel < gpu.levels.size())
                {
                    const BillboardCloudGpu::Level& cloud = gpu.levels[level.techniqueLevel];
                    ForestPartOptions options;
                    options.techniqueLod = level.lowRes ? 1 : 0;
                    options.lengthFactor = gpu.listFactor;
                    parts.addRange(gpu.vertexData.get(), gpu.indexBuffer, cloud.indexStart, cloud.indexCount,
                                   cloud.material, cloud.shadowedMaterial, options);
                }
                if (!asset.getReference().model.barkIndices.empty())
                    parts.addMesh(resources.getBarkAoMesh(), resources.getBarkAoMaterialNames(false),
                                  resources.getBarkAoMaterialNames(true));
            }

            Ogre::String describeLevel(const ForestLevel& level) const override
            {
                return (mClassic ? "classic " : "cloud ") + std::to_string(level.techniqueLevel) +
                       (level.lowRes ? " low" : "");
            }

        private:
            const bool mClassic;
        };

        std::vector<TechniqueStateLine> describeState(Ogre::MovableObject& object)
        {
            auto& cloud = static_cast<BillboardCloudTree&>(object);
            std::vector<TechniqueStateLine> lines;
            for (std::uint32_t level = 0; level < cloud.getLevelCount(); ++level)
            {
                const bool drawn = level == cloud.getLevel();
                const char* material = cloud.isClassic()                  ? ""
                                       : cloud.getMaterialLodIndex() == 0 ? " layered"
                                                                          : " low-res";
                lines.push_back({"cloud " + std::to_string(level) + "  ", drawn ? 1.0 : 0.0, drawn ? material : ""});
            }
            if (cloud.getTransitionShare() > 0.0f)
                lines.push_back({"fading to cloud " + std::to_string(cloud.getLevel() + 1) + "  ",
                                 double(cloud.getTransitionShare()), ""});
            lines.push_back({"bark LoD " + std::to_string(cloud.getBarkLodIndex()), -1.0, ""});
            return lines;
        }

        void setLodTransition(Ogre::MovableObject& object, float length)
        {
            static_cast<BillboardCloudTree&>(object).setLodTransition(length);
        }

        void registerBillboardClouds(TechniqueRegistry& registry)
        {
            auto factory = std::make_shared<BillboardCloudTreeFactory>();
            TechniqueRoles roles;
            roles.autoCandidate = true;
            roles.defaultBandMinHeight = 24.0f;
            roles.benchDefault = true;
            roles.paperBaseline = CLASSIC_BILLBOARD_CLOUD_CHUNK; // García et al. 2007, Fig. 13
            roles.referenceShadingParams = {{"ambientOcclusion", "false"}};
            roles.parameters = {{"level", "level", "draw this cloud (0 finest; 2: low-res only) instead of the LoD strategy's"},
                                {"listFactor", "list-factor",
                                 "shader LoD, list entries walked per pixel of projected hash-cell diagonal (0 = low-res "
                                 "texture only; default from the package)"},
                                {"lodTransition", "lod-transition", "level transition length t in [0, 1]: both levels drawn, screen-door blended, within 1 + t of a switch (0: hard)"}};
            registry.add({BILLBOARD_CLOUD_CHUNK,
                          "billboard clouds with multi-layered indirect texturing and shader LoD (García et al. 2007)",
                          BILLBOARD_CLOUD_CHUNK, BillboardCloudTreeFactory::FACTORY_TYPE_NAME,
                          TechniqueRegistry::byFactory(BillboardCloudTreeFactory::FACTORY_TYPE_NAME,
                                                       {{"classic", "false"}}),
                          factory, std::make_shared<BillboardCloudLevels>(false), &describeState, roles, &setLodTransition});
            TechniqueRoles classicRoles;
            classicRoles.autoCandidate = true;
            classicRoles.referenceShadingParams = roles.referenceShadingParams;
            classicRoles.parameters = {{"level", "level", "draw this cloud (0 finest) instead of the LoD strategy's"},
                                       roles.parameters.back()};
            registry.add({CLASSIC_BILLBOARD_CLOUD_CHUNK,
                          "classic billboard cloud: one RGBA texture per billboard, the baseline of García et al. "
                          "2007 Fig. 13",
                          CLASSIC_BILLBOARD_CLOUD_CHUNK, BillboardCloudTreeFactory::FACTORY_TYPE_NAME,
                          TechniqueRegistry::byFactory(BillboardCloudTreeFactory::FACTORY_TYPE_NAME,
                                                       {{"classic", "true"}}),
                          factory, std::make_shared<BillboardCloudLevels>(true), &describeState, classicRoles,
                          &setLodTransition});
        }

        const TechniqueRegistry::Registration registration(&registerBillboardClouds);
    }
}
