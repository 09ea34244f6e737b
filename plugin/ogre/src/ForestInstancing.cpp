// The Forest's instancing: a level's parts built through its provider (PartBuilder), and the
// instanced variants of their materials (per-instance uv4/uv5, Forest.h "Materials").
#include "ForestDetail.h"
#include "TreeLod/Wind.h"

namespace TreeLod
{
    Ogre::MaterialPtr Forest::instancedMaterial(const Ogre::String& name, const Ogre::String& group)
    {
        auto found = mInstancedMaterials.find(name);
        if (found != mInstancedMaterials.end())
            return found->second;
        Ogre::MaterialPtr material = Ogre::MaterialManager::getSingleton().getByName(name, group);
        if (!material)
            OGRE_EXCEPT(Ogre::Exception::ERR_ITEM_NOT_FOUND, "material '" + name + "' not found",
                        "Forest '" + mName + "'");
        material->load();
        Ogre::MaterialPtr clone = material->clone(mMaterialPrefix + name, true, material->getGroup());
        for (Ogre::Technique* technique : clone->getTechniques())
        {
            for (Ogre::Pass* pass : technique->getPasses())
            {
                if (!pass->hasVertexProgram())
                    OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS,
                                "material '" + name + "' technique '" + technique->getName() + "' pass '" +
                                    pass->getName() + "' has no vertex program to draw instanced",
                                "Forest '" + mName + "'");
                const Ogre::GpuProgramParametersSharedPtr plain = pass->getVertexProgramParameters();
                pass->setVertexProgram(instancedProgram(pass->getVertexProgram()), true);
                pass->getVertexProgramParameters()->copyMatchingNamedConstantsFrom(*plain);
            }
            if (Ogre::MaterialPtr caster = technique->getShadowCasterMaterial())
                technique->setShadowCasterMaterial(instancedMaterial(caster->getName(), caster->getGroup()));
        }
        clone->compile();
        clone->load();
        mInstancedMaterials.emplace(name, clone);
        return clone;
    }

    /// The ForestPartBuilder a level's provider adds its parts through.
    class Forest::PartBuilder : public ForestPartBuilder
    {
    public:
        PartBuilder(Forest& forest, TreeAsset& asset, Ogre::Real upperPixelCount)
            : mForest(forest), mAsset(asset), mUpperPixelCount(upperPixelCount)
        {
        }

        void addRange(Ogre::VertexData* vertices, const Ogre::HardwareIndexBufferSharedPtr& buffer, std::size_t start,
                      std::size_t count, const Ogre::String& material, const Ogre::String& shadowed,
                      const ForestPartOptions& options) override
        {
            if (count == 0 || !vertices)
                return;
            Part& part = add(vertices, material, shadowed, options);
            part.ownIndexData.indexBuffer = buffer;
            part.ownIndexData.indexStart = start;
            part.ownIndexData.indexCount = count;
            part.indexData = &part.ownIndexData;
        }

        void addMesh(const Ogre::MeshPtr& mesh, const std::vector<Ogre::String>& plain,
                     const std::vector<Ogre::String>& shadowed) override
        {
            // The submeshes at the LoD level the mesh's strategy gives for the level's largest value.
            const unsigned short lod = mUpperPixelCount == NO_UPPER ? 0 : mesh->getLodIndex(mUpperPixelCount);
            for (Ogre::SubMesh* sub : mesh->getSubMeshes())
            {
                Ogre::IndexData* indices =
                    lod == 0 || sub->mLodFaceList.empty()
                        ? sub->indexData
                        : sub->mLodFaceList[std::min<std::size_t>(lod, sub->mLodFaceList.size()) - 1];
                if (indices->indexCount == 0)
                    continue;
                const auto it = std::find(plain.begin(), plain.end(), sub->getMaterialName());
                const Ogre::String receiver = it == plain.end() ? "" : shadowed[std::size_t(it - plain.begin())];
                Part& part = add(sub->vertexData, sub->getMaterialName(), receiver, {});
                part.indexData = indices;
                part.mesh = mesh;
            }
        }

        std::vector<std::unique_ptr<Part>> mParts;

    private:
        Part& add(Ogre::VertexData* vertices, const Ogre::String& material, const Ogre::String& shadowed,
                  const ForestPartOptions& options)
        {
            const Ogre::String& group = mAsset.getGroup();
            auto part = std::make_unique<Part>();
            part->vertexData = vertices;
            part->techniqueLod = options.techniqueLod;
            part->lengthFactor = options.lengthFactor;
            part->customParameters = options.customParameters;
            part->customParameters.emplace(WIND_CUSTOM_PARAMETER,
                                           Ogre::Vector4(Wind::treeHeight(mAsset.getBounds()), 0.0f, 0.0f, 0.0f));
            part->backToFront = options.backToFront;
            if (options.instancedMaterial)
            {
                for (auto [name, slot] : {std::make_pair(&material, &part->material),
                                          std::make_pair(&shadowed, &part->shadowedMaterial)})
                {
                    if (name->empty())
                        continue;
                    // The asset's own (cloned per asset), else a shared one wherever it is.
                    *slot = Ogre::MaterialManager::getSingleton().getByName(*name, group);
                    if (!*slot)
                        *slot = Ogre::MaterialManager::getSingleton().getByName(*name, Ogre::RGN_AUTODETECT);
                    if (!*slot)
                        OGRE_EXCEPT(Ogre::Exception::ERR_ITEM_NOT_FOUND, "material '" + *name + "' not found",
                                    "Forest '" + mForest.mName + "'");
                    (*slot)->load();
                }
            }
            else
            {
                part->material = mForest.instancedMaterial(material, group);
                if (!shadowed.empty())
                    part->shadowedMaterial = mForest.instancedMaterial(shadowed, group);
            }
            mParts.push_back(std::move(part));
            return *mParts.back();
        }

        Forest& mForest;
        TreeAsset& mAsset;
        const Ogre::Real mUpperPixelCount;
    };

    std::vector<std::unique_ptr<Forest::Part>> Forest::buildParts(TreeAsset& asset, const ForestLevel& level,
                                                                  Ogre::Real upperPixelCount)
    {
        PartBuilder builder(*this, asset, upperPixelCount);
        levelProvider(level.technique, "", "Forest").buildParts(asset, level, builder);
        return std::move(builder.mParts);
    }
}
