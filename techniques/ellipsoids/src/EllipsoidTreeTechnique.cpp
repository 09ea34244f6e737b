// Technique "ellipsoids": the leaves as EM/GMM-clustered ellipsoids and the branches as lines, ray
// cast per fragment (the ellipsoids-and-lines paper (001)), drawn by an EllipsoidTree, and as Forest
// levels: each span of screen heights over which EllipsoidTree draws one ellipsoid level and one
// line level (§6) is a level, ForestLevel::techniqueLevel = ellipsoid level + 256 * (line level + 1),
// or the ellipsoid level alone with the reference bark mesh when the package has no lines.
#include "TreeLod/EllipsoidTree.h"
#include "TreeLod/Forest.h"
#include "TreeLod/TechniqueRegistry.h"

#include <OgreException.h>

#include <algorithm>
#include <functional>
#include <limits>

namespace TreeLod
{
    namespace
    {
        std::uint32_t ellipsoidLevelOf(const ForestLevel& level) { return level.techniqueLevel & 0xFFu; }
        /// 0: the bark mesh; else the line level + 1.
        std::uint32_t lineCodeOf(const ForestLevel& level) { return level.techniqueLevel >> 8; }

        class EllipsoidLevels : public ForestLevelProvider
        {
        public:
            std::vector<ForestLevelSpan> getSpans(TreeAsset& asset, const Ogre::String& technique) override
            {
                // The heights where either level changes (levelForHeight: a level's target height
                // and below draws it or a coarser one), tallest first; between two, both are fixed.
                EllipsoidTreeResources& resources = EllipsoidTreeResources::of(asset);
                const EllipsoidTreeData& data = resources.getData();
                const EllipsoidLineData* lines = resources.getLineData();
                std::vector<EllipsoidGpuLevel> ellipsoidLevels, lineLevels;
                std::vector<float> breaks;
                for (std::size_t l = 0; l < data.levels.size(); ++l)
                {
                    ellipsoidLevels.push_back({0, 0, data.levels[l].targetHeightPx});
                    if (l > 0)
                        breaks.push_back(data.levels[l].targetHeightPx);
                }
                if (lines)
                    for (std::size_t l = 0; l < lines->levels.size(); ++l)
                    {
                        lineLevels.push_back({0, 0, lines->levels[l].targetHeightPx});
                        if (l > 0)
                            breaks.push_back(lines->levels[l].targetHeightPx);
                    }
                std::sort(breaks.begin(), breaks.end(), std::greater<float>());
                breaks.erase(std::unique(breaks.begin(), breaks.end()), breaks.end());
                std::vector<ForestLevelSpan> spans;
                Ogre::Real upper = ForestLevelSpan::NO_UPPER;
                float top = std::numeric_limits<float>::max(); // the span's tallest height
                for (std::size_t b = 0; b <= breaks.size(); ++b)
                {
                    const Ogre::Real lower = b < breaks.size() ? Forest::pixelCountForHeight(asset, breaks[b]) : 0.0f;
                    std::uint32_t code = std::uint32_t(levelForHeight(ellipsoidLevels, top));
                    if (lines)
                        code += 256u * std::uint32_t(levelForHeight(lineLevels, top) + 1);
                    if (lower < upper)
                    {
                        spans.push_back({ForestLevel{technique, code, false, lower}, upper});
                        upper = lower;
                    }
                    if (b < breaks.size())
                        top = breaks[b];
                }
                return spans;
            }

            void checkLevel(TreeAsset& asset, const ForestLevel& level, Ogre::AxisAlignedBox& drawnBounds) override
            {
                const char* source = "EllipsoidLevels::checkLevel";
                if (level.lowRes)
                    OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS, "lowRes is for billboard-cloud levels only", source);
                EllipsoidTreeResources& resources = EllipsoidTreeResources::of(asset);
                const EllipsoidTreeData& data = resources.getData();
                const EllipsoidLineData* lines = resources.getLineData();
                const std::uint32_t lineCode = lineCodeOf(level);
                const std::size_t lineLevels = lines ? lines->levels.size() : 0;
                if (ellipsoidLevelOf(level) >= data.levels.size() || lineCode > lineLevels || (lines && lineCode == 0))
                    OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS,
                                "asset '" + asset.getName() + "': level " + std::to_string(level.techniqueLevel) +
                                    " is not a level of its ellipsoids (" + std::to_string(data.levels.size()) +
                                    " ellipsoid levels, " + std::to_string(lineLevels) +
                                    " line levels; techniqueLevel = ellipsoid level + 256 * (line level + 1))",
                                source);
                drawnBounds.merge(ellipsoidBounds(data));
            }

            void buildParts(TreeAsset& asset, const ForestLevel& level, ForestPartBuilder& parts) override
            {
                EllipsoidTreeResources& resources = EllipsoidTreeResources::of(asset);
                const EllipsoidTreeGpu& gpu = resources.getGpu();
                const EllipsoidGpuLevel& drawn = gpu.levels[ellipsoidLevelOf(level)];
                ForestPartOptions options;
                options.instancedMaterial = true; // TreeLodEllipsoid*.vert read the instance data
                parts.addRange(gpu.vertexData.get(), gpu.indexBuffer, drawn.indexStart, drawn.indexCount,
                               ELLIPSOID_MATERIAL, ELLIPSOID_SHADOWED_MATERIAL, options);
                if (const std::uint32_t lineCode = lineCodeOf(level))
                {
                    const EllipsoidLineGpu& lines = *resources.getLineGpu();
                    const EllipsoidGpuLevel& drawnLines = lines.levels[lineCode - 1];
                    parts.addRange(lines.vertexData.get(), lines.indexBuffer, drawnLines.indexStart,
                                   drawnLines.indexCount, ELLIPSOID_LINE_MATERIAL, ELLIPSOID_LINE_SHADOWED_MATERIAL,
                                   options);
                }
                else if (!asset.getReference().model.barkIndices.empty())
                    parts.addMesh(asset.getBarkMesh(), asset.getMaterialNames(), asset.getShadowedMaterialNames());
            }

            Ogre::String describeLevel(const ForestLevel& level) const override
            {
                const std::uint32_t lineCode = lineCodeOf(level);
                return level.technique + " " + std::to_string(ellipsoidLevelOf(level)) +
                       (lineCode ? ", lines " + std::to_string(lineCode - 1) : "");
            }
        };

        void registerEllipsoids(TechniqueRegistry& registry)
        {
            const Ogre::String& type = EllipsoidTreeFactory::FACTORY_TYPE_NAME;
            TechniqueRoles roles;
            roles.autoCandidate = true;
            roles.parameters = {{"level", "level", "draw this level (0 finest) instead of the LoD strategy's"},
                                {"lodTransition", "lod-transition", "level transition length t in [0, 1]: both levels drawn, screen-door blended, within 1 + t of a switch (0: hard)"}};
            registry.add({ELLIPSOID_TREE_CHUNK, "leaves as EM/GMM-clustered ellipsoids, ray cast per pixel",
                          ELLIPSOID_TREE_CHUNK, type, TechniqueRegistry::byFactory(type),
                          std::make_shared<EllipsoidTreeFactory>(), std::make_shared<EllipsoidLevels>(),
                          [](Ogre::MovableObject& object) -> std::vector<TechniqueStateLine> {
                              auto& tree = static_cast<EllipsoidTree&>(object);
                              const std::size_t levels = tree.getLevelCount();
                              std::vector<TechniqueStateLine> state = {
                                  {"level ", levels > 1 ? 1.0 - double(tree.getLevel()) / double(levels - 1) : 1.0,
                                   " " + std::to_string(tree.getLevel()) + " of " + std::to_string(levels) + ", " +
                                       std::to_string(tree.getEllipsoidCount()) + " ellipsoids"}};
                              if (tree.getTransitionShare() > 0.0f)
                                  state.push_back({"fading to level " + std::to_string(tree.getLevel() + 1) + " ",
                                                   double(tree.getTransitionShare()), ""});
                              if (tree.drawsLines())
                                  state.push_back({"lines: level " + std::to_string(tree.getLineLevel()) + ", " +
                                                       std::to_string(tree.getLineCount()) + " lines",
                                                   -1.0, ""});
                              return state;
                          }, roles,
                          [](Ogre::MovableObject& object, float length) {
                              static_cast<EllipsoidTree&>(object).setLodTransition(length);
                          }});
        }

        const TechniqueRegistry::Registration registration(&registerEllipsoids);
    }
}
