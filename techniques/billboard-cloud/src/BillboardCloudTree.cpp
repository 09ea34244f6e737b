// BillboardCloudTree: billboard clouds with multi-layered indirect texturing (García et al. 2007
// §5, §6). See BillboardCloudTree.h for the LoD rules.
#include "TreeLod/BillboardCloudTree.h"

#include "TreeLod/ObjectParams.h"
#include "TreeLod/ScreenSizeLodStrategy.h"
#include "TreeLod/ShadowSetup.h"
#include "TreeLod/TreePart.h"

#include "TreeLod/TreeAssetManager.h"
#include "TreeLod/Wind.h"

#include <OgreCamera.h>
#include <OgreException.h>
#include <OgreMaterialManager.h>
#include <OgreNode.h>
#include <OgreRenderQueue.h>
#include <OgreSceneManager.h>
#include <OgreSubMesh.h>
#include <OgreTechnique.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace TreeLod
{
    /// One draw of a BillboardCloudTree: a cloud level's index range, or a bark submesh.
    class BillboardCloudTree::Part : public TreePart
    {
    public:
        Part(BillboardCloudTree& parent, Ogre::VertexData* vertexData, const Ogre::String& material,
             const Ogre::String& shadowedMaterial, bool cloud)
            : TreePart(parent, parent.mAsset->getGroup(), vertexData, material, shadowedMaterial,
                       "BillboardCloudTree"),
              mParent(parent), mCloud(cloud)
        {
            Wind::setTreeHeight(*this, Wind::treeHeight(parent.mAsset->getBounds()));
        }

        /// Custom Renderables pick the material LoD technique themselves (§5.1: layers close
        /// up, the low-res texture alone far away).
        Ogre::Technique* getTechnique() const override
        {
            return mCloud ? getMaterial()->getBestTechnique(mParent.mMaterialLodIndex, this) : TreePart::getTechnique();
        }

    protected:
        bool useShadowedMaterials() const override { return mParent.useShadowedMaterials(); }
        unsigned short barkLodIndex() const override { return mParent.mBarkLodIndex; }

    private:
        BillboardCloudTree& mParent;
        bool mCloud;
    };

    const Ogre::String BillboardCloudTreeFactory::FACTORY_TYPE_NAME = "BillboardCloudTree";

    BillboardCloudTree::BillboardCloudTree(const Ogre::String& name, const TreeAssetPtr& asset, const Options& options)
        : Ogre::MovableObject(name), mAsset(asset), mGpu(&BillboardCloudResources::of(*asset, options.classic).getGpu()),
          mOptions(options)
    {
        const std::uint32_t levels = getLevelCount();
        if (mOptions.level >= 0 && std::uint32_t(mOptions.level) >= std::max<std::uint32_t>(levels, 1))
            OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS,
                        "parameter 'level': " + std::to_string(mOptions.level) +
                            " is not a level of the cloud (it has " + std::to_string(levels) + ")",
                        "BillboardCloudTree '" + name + "'");
        mLodBias.setMesh(mOptions.lodBias, 0, 99, "BillboardCloudTree '" + name + "'");
        mLodBias.strategy = mOptions.lodStrategy;
        mTransition.set(mOptions.lodTransition, "BillboardCloudTree '" + name + "'");
        mListFactor = mOptions.listFactor >= 0.0f ? mOptions.listFactor : mGpu->listFactor;
        updateSwitchValues();

        if (mGpu->vertexData)
            for (const BillboardCloudGpu::Level& level : mGpu->levels)
            {
                auto part = std::make_unique<Part>(*this, mGpu->vertexData.get(), level.material,
                                                   level.shadowedMaterial, true);
                part->mIndexData.indexBuffer = mGpu->indexBuffer;
                part->mIndexData.indexStart = level.indexStart;
                part->mIndexData.indexCount = level.indexCount;
                mLevelParts.push_back(std::move(part));
            }

        if (!mAsset->getReference().model.barkIndices.empty())
        {
            // ambientOcclusion=false: the reference's own bark (no AO), lit like the polygonal tree.
            const bool ao = mOptions.ambientOcclusion;
            BillboardCloudResources& cloud = BillboardCloudResources::of(*mAsset, mOptions.classic);
            mBarkMesh = ao ? cloud.getBarkAoMesh() : mAsset->getBarkMesh();
            const std::vector<Ogre::String>& plain = ao ? cloud.getBarkAoMaterialNames(false)
                                                        : mAsset->getMaterialNames();
            const std::vector<Ogre::String>& shadowed = ao ? cloud.getBarkAoMaterialNames(true)
                                                           : mAsset->getShadowedMaterialNames();
            for (Ogre::SubMesh* sub : mBarkMesh->getSubMeshes())
            {
                const auto it = std::find(plain.begin(), plain.end(), sub->getMaterialName());
                const Ogre::String receiver = it == plain.end() ? "" : shadowed[std::size_t(it - plain.begin())];
                auto part = std::make_unique<Part>(*this, sub->vertexData, sub->getMaterialName(), receiver, false);
                part->mLevels.push_back(sub->indexData);
                for (Ogre::IndexData* level : sub->mLodFaceList)
                    part->mLevels.push_back(level);
                mBarkParts.push_back(std::move(part));
            }
        }
        mLevel = mOptions.level >= 0 ? std::uint32_t(mOptions.level) : 0;
        applyLevel();
    }

    BillboardCloudTree::~BillboardCloudTree() = default;

    const Ogre::String& BillboardCloudTree::getMovableType() const
    {
        return BillboardCloudTreeFactory::FACTORY_TYPE_NAME;
    }

    std::vector<Ogre::Real> BillboardCloudTree::switchPixelCounts(const BillboardCloudGpu& gpu, float listFactor,
                                                                  float radius)
    {
        // §6: switches consistent with the shader LoD (BillboardCloudTree.h).
        std::vector<Ogre::Real> switches(gpu.levels.size() > 1 ? gpu.levels.size() - 1 : 0, 0.0f);
        for (std::size_t l = 0; l < switches.size(); ++l)
        {
            const BillboardCloudGpu::Level& level = gpu.levels[l];
            const BillboardCloudGpu::Level& next = gpu.levels[l + 1];
            if (level.layered)
                switches[l] = billboardCloudPixelCount(next.layered ? SWITCH_ENTRIES : 1.0f, level.cellSize, radius,
                                                       listFactor);
            else // a low-res level before another: keep the finer one as long as the one before
                switches[l] = l > 0 ? switches[l - 1] : 0.0f;
            // listFactor 0: the layered levels walk nothing at any size.
            if (switches[l] == std::numeric_limits<Ogre::Real>::max() && l > 0)
                switches[l] = switches[l - 1];
        }
        return switches;
    }

    void BillboardCloudTree::updateSwitchValues()
    {
        mSwitchPixelCounts = switchPixelCounts(*mGpu, mListFactor, float(mGpu->radius));
    }

    void BillboardCloudTree::setListFactor(float listFactor)
    {
        if (!(listFactor >= 0.0f) || !std::isfinite(listFactor))
            OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS,
                        "listFactor must be a finite number >= 0, got " + std::to_string(listFactor),
                        "BillboardCloudTree '" + mName + "'");
        mListFactor = listFactor;
        updateSwitchValues();
        applyLevel();
    }

    void BillboardCloudTree::setLodTransition(Ogre::Real length)
    {
        mTransition.set(length, "BillboardCloudTree '" + mName + "'");
    }

    void BillboardCloudTree::setForcedLevel(int level)
    {
        mOptions.level = level < 0 ? -1 : std::min(level, int(std::max<std::uint32_t>(getLevelCount(), 1)) - 1);
        if (mOptions.level >= 0)
            mLevel = std::uint32_t(mOptions.level);
        applyLevel();
    }

    std::uint32_t BillboardCloudTree::levelForPixelCount(Ogre::Real value) const
    {
        for (std::uint32_t l = 0; l < mSwitchPixelCounts.size(); ++l)
            if (value >= mSwitchPixelCounts[l])
                return l;
        return std::uint32_t(mSwitchPixelCounts.size());
    }

    std::uint32_t BillboardCloudTree::levelForValue(Ogre::Real value) const
    {
        return levelForPixelCount(mLastCamera ? mLodBias.screenSizeOf(value, *this, mLastCamera) : value);
    }

    unsigned short BillboardCloudTree::materialLodIndexForPixelCount(Ogre::Real value) const
    {
        if (mLevel >= mGpu->levels.size() || !mGpu->levels[mLevel].layered || mLevelParts.empty())
            return 0;
        // The clone's lod_values are for the chunk's list factor; the switch (one entry walked)
        // moves with value * (listFactor / chunk's)^2.
        const float ratio = mGpu->listFactor > 0.0f ? mListFactor / mGpu->listFactor : 0.0f;
        const Ogre::MaterialPtr& material = mLevelParts[mLevel]->getMaterial();
        return mLodBias.clampMaterial(material->getLodIndex(value * ratio * ratio));
    }

    void BillboardCloudTree::setMeshLodBias(Ogre::Real factor, unsigned short maxDetailIndex,
                                            unsigned short minDetailIndex)
    {
        mLodBias.setMesh(factor, maxDetailIndex, minDetailIndex, "BillboardCloudTree '" + mName + "'");
    }

    void BillboardCloudTree::setMaterialLodBias(Ogre::Real factor, unsigned short maxDetailIndex,
                                                unsigned short minDetailIndex)
    {
        mLodBias.setMaterial(factor, maxDetailIndex, minDetailIndex, "BillboardCloudTree '" + mName + "'");
    }

    void BillboardCloudTree::applyLevel()
    {
        // The shader's list factor: bias multiplies pixel areas, so lengths scale by its root.
        // y: weight of the ambient occlusion term (0 = none, as the polygonal reference draws).
        const Ogre::Vector4 lodParams(mListFactor * std::sqrt(mBias), mOptions.ambientOcclusion ? 1.0f : 0.0f, 0.0f,
                                      0.0f);
        for (const std::unique_ptr<Part>& part : mLevelParts)
            part->setCustomParameter(0, lodParams);
        // Entity's material value: the unbiased one times the material factor.
        const Ogre::Real maxValue = std::numeric_limits<Ogre::Real>::max();
        mMaterialLodIndex = materialLodIndexForPixelCount(
            mPixelCountValue == maxValue ? maxValue
                                         : mPixelCountValue / mLodBias.meshFactor * mLodBias.materialFactor);
    }

    void BillboardCloudTree::_notifyCurrentCamera(Ogre::Camera* camera)
    {
        Ogre::MovableObject::_notifyCurrentCamera(camera);
        if (!mParentNode)
            return;
        // The LoD camera (the viewer's, for shadow cameras) and its bias decide, through Ogre's
        // strategies: TreeLod's screen size, or the distance to the bounding box.
        const Ogre::Camera* lod = camera->getLodCamera();
        mBias = lod->getLodBias() * mLodBias.meshFactor;
        mLastCamera = camera;
        mLodValue = mLodBias.value(*this, camera);
        mPixelCountValue = mLodBias.screenSizeOf(mLodValue, *this, camera);

        const std::uint32_t strategyLevel = levelForPixelCount(mPixelCountValue);
        if (mOptions.level < 0)
            mLevel = mLodBias.clampMesh(Ogre::ushort(std::min<std::uint32_t>(strategyLevel, 0xffff)));
        mLevel = std::min(mLevel, std::max<std::uint32_t>(getLevelCount(), 1) - 1);
        // A transition to the next level (ObjectTransition.h), where the strategy chose this one and
        // the next is allowed: screen sizes are square roots of pixel counts.
        mTransitionShare = 0.0f;
        if (mOptions.level < 0 && mLevel + 1 < mLevelParts.size() && mLevel < mSwitchPixelCounts.size() &&
            strategyLevel == mLevel && mLodBias.clampMesh(Ogre::ushort(mLevel + 1)) == mLevel + 1 &&
            mSwitchPixelCounts[mLevel] > 0.0f && mLevelParts[mLevel + 1]->mIndexData.indexCount > 0)
        {
            const Ogre::Real threshold = mSwitchPixelCounts[mLevel];
            const float range = mLevel == 0 ? std::numeric_limits<float>::infinity()
                                            : std::sqrt(float(mSwitchPixelCounts[mLevel - 1] / threshold));
            mTransitionShare = mTransition.coarseShare(std::sqrt(float(mPixelCountValue / threshold)), range);
        }
        if (mLevel < mLevelParts.size())
        {
            const Ogre::Vector3& position = mParentNode->_getDerivedPosition();
            ObjectTransition::apply(*mLevelParts[mLevel], mTransitionShare > 0.0f ? -mTransitionShare : 0.0f, position);
            if (mTransitionShare > 0.0f)
                ObjectTransition::apply(*mLevelParts[mLevel + 1], mTransitionShare, position);
        }
        if (mBarkMesh)
            mBarkLodIndex = mLodBias.meshLodIndex(*mBarkMesh, *this, camera);
        for (const std::unique_ptr<Part>& part : mBarkParts)
            part->updateMaterialLod(mLodBias, camera);
        applyLevel();
    }

    bool BillboardCloudTree::useShadowedMaterials() const
    {
        return receivesDepthShadows(mManager);
    }

    void BillboardCloudTree::_updateRenderQueue(Ogre::RenderQueue* queue)
    {
        if (mManager)
            notifyShadowTechnique(*mManager);
        for (const std::unique_ptr<Part>& part : mBarkParts)
            queue->addRenderable(part.get(), mRenderQueueID, mRenderQueuePriority);
        if (mLevel < mLevelParts.size() && mLevelParts[mLevel]->mIndexData.indexCount > 0)
            queue->addRenderable(mLevelParts[mLevel].get(), mRenderQueueID, mRenderQueuePriority);
        if (mTransitionShare > 0.0f)
            queue->addRenderable(mLevelParts[mLevel + 1].get(), mRenderQueueID, mRenderQueuePriority);
    }

    void BillboardCloudTree::visitRenderables(Ogre::Renderable::Visitor* visitor, bool)
    {
        for (const std::unique_ptr<Part>& part : mBarkParts)
            visitor->visit(part.get(), 0, false);
        for (std::size_t l = 0; l < mLevelParts.size(); ++l)
            visitor->visit(mLevelParts[l].get(), Ogre::ushort(l), false);
    }

    BillboardCloudTree::Options BillboardCloudTreeFactory::parseOptions(const Ogre::NameValuePairList* params)
    {
        BillboardCloudTree::Options options;
        const ObjectParams p(params, "BillboardCloudTreeFactory");
        double v = 0.0;
        p.flag("classic", options.classic);
        if (p.number("level", 0.0, 255.0, v))
        {
            if (v != std::floor(v))
                p.bad("level", *p.find("level"), "a whole number");
            options.level = int(v);
        }
        options.lodStrategy = ObjectLodBias::strategyParam(p);
        p.flag("ambientOcclusion", options.ambientOcclusion);
        ObjectTransition::param(p, options.lodTransition);
        if (p.number("listFactor", 0.0, 1e6, v))
            options.listFactor = float(v);
        if (p.number("lodBias", 1e-6, 1e6, v))
            options.lodBias = float(v);
        return options;
    }

    Ogre::MovableObject* BillboardCloudTreeFactory::createInstanceImpl(const Ogre::String& name,
                                                                       const Ogre::NameValuePairList* params)
    {
        const ObjectParams p(params, "BillboardCloudTreeFactory::createInstanceImpl");
        const BillboardCloudTree::Options options = parseOptions(params); // bad parameters before loading
        return new BillboardCloudTree(name, p.loadAsset(name, "BillboardCloudTree"), options);
    }
}
