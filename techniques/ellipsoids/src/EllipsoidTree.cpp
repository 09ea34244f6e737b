// EllipsoidTree: the leaves as ray-cast ellipsoids of one level (the ellipsoids-and-lines paper
// (001) §5, §6), the branches as the reference bark. See EllipsoidTree.h for the LoD rule.
#include "TreeLod/EllipsoidTree.h"

#include "TreeLod/ObjectParams.h"
#include "TreeLod/ScreenSizeLodStrategy.h"
#include "TreeLod/ShadowSetup.h"
#include "TreeLod/TechniqueSupport.h"
#include "TreeLod/TreePart.h"
#include "TreeLod/Wind.h"

#include <OgreCamera.h>
#include <OgreLodStrategy.h>
#include <OgreMaterialManager.h>
#include <OgreMesh.h>
#include <OgreNode.h>
#include <OgreRenderQueue.h>
#include <OgreSceneManager.h>
#include <OgreSubMesh.h>
#include <OgreViewport.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace TreeLod
{
    /// One draw of an EllipsoidTree: the ellipsoids of the level drawn, or a bark submesh.
    class EllipsoidTree::Part : public TreePart
    {
    public:
        Part(EllipsoidTree& parent, const Ogre::String& group, Ogre::VertexData* vertexData,
             const Ogre::String& material, const Ogre::String& shadowedMaterial)
            : TreePart(parent, group, vertexData, material, shadowedMaterial, "EllipsoidTree"),
              mParent(parent)
        {
            Wind::setTreeHeight(*this, Wind::treeHeight(parent.mAsset->getBounds()));
        }

    protected:
        bool useShadowedMaterials() const override { return mParent.useShadowedMaterials(); }
        unsigned short barkLodIndex() const override { return mParent.mBarkLodIndex; }

    private:
        EllipsoidTree& mParent;
    };

    const Ogre::String EllipsoidTreeFactory::FACTORY_TYPE_NAME = "EllipsoidTree";

    EllipsoidTree::EllipsoidTree(const Ogre::String& name, const TreeAssetPtr& asset, const Options& options)
        : Ogre::MovableObject(name), mAsset(asset), mGpu(&EllipsoidTreeResources::of(*asset).getGpu()),
          mOptions(options)
    {
        mLodBias.setMesh(mOptions.lodBias, 0, 99, "EllipsoidTree '" + name + "'");
        mLodBias.strategy = mOptions.lodStrategy;
        mTransition.set(mOptions.lodTransition, "EllipsoidTree '" + name + "'");
        if (mOptions.level >= 0 && std::size_t(mOptions.level) >= mGpu->levels.size())
            OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS,
                        "parameter 'level': " + std::to_string(mOptions.level) + " is not a level of the ellipsoids (" +
                            std::to_string(mGpu->levels.size()) + " levels)",
                        "EllipsoidTree '" + name + "'");

        // The asset's ellipsoids plus one instance at the origin, as a Forest instance reads them.
        mVertexData.reset(mGpu->vertexData->clone(false));
        addOriginInstance(*mVertexData);
        // TreeLod's own material, in whichever group holds TreeLod's materials/.
        const Ogre::MaterialPtr material =
            Ogre::MaterialManager::getSingleton().getByName(ELLIPSOID_MATERIAL, Ogre::RGN_AUTODETECT);
        if (!material)
            OGRE_EXCEPT(Ogre::Exception::ERR_ITEM_NOT_FOUND,
                        Ogre::String("material '") + ELLIPSOID_MATERIAL +
                            "' not found: add TreeLod's materials/ to a resource group",
                        "EllipsoidTree '" + name + "'");
        for (std::unique_ptr<Part>* part : {&mEllipsoids.fine, &mEllipsoids.coarse})
        {
            *part = std::make_unique<Part>(*this, material->getGroup(), mVertexData.get(), ELLIPSOID_MATERIAL,
                                           ELLIPSOID_SHADOWED_MATERIAL);
            (*part)->mIndexData.indexBuffer = mGpu->indexBuffer;
        }

        const TreeModel& model = mAsset->getReference().model;
        mTreeHeight = model.boundsMax.y - model.boundsMin.y;
        mBounds = mGpu->bounds;
        mBounds.merge(Ogre::AxisAlignedBox(model.boundsMin.x, model.boundsMin.y, model.boundsMin.z, model.boundsMax.x,
                                           model.boundsMax.y, model.boundsMax.z));
        mLines = mOptions.lines ? EllipsoidTreeResources::of(*mAsset).getLineGpu() : nullptr;
        if (mLines)
        {
            mLineVertexData.reset(mLines->vertexData->clone(false));
            addOriginInstance(*mLineVertexData);
            for (std::unique_ptr<Part>* part : {&mLineParts.fine, &mLineParts.coarse})
            {
                *part = std::make_unique<Part>(*this, material->getGroup(), mLineVertexData.get(),
                                               ELLIPSOID_LINE_MATERIAL, ELLIPSOID_LINE_SHADOWED_MATERIAL);
                (*part)->mIndexData.indexBuffer = mLines->indexBuffer;
            }
        }
        else if (!model.barkIndices.empty())
        {
            // The reference's bark, lit like the polygonal tree.
            mBarkMesh = mAsset->getBarkMesh();
            const std::vector<Ogre::String>& plain = mAsset->getMaterialNames();
            const std::vector<Ogre::String>& shadowed = mAsset->getShadowedMaterialNames();
            for (Ogre::SubMesh* sub : mBarkMesh->getSubMeshes())
            {
                const auto it = std::find(plain.begin(), plain.end(), sub->getMaterialName());
                const Ogre::String receiver = it == plain.end() ? "" : shadowed[std::size_t(it - plain.begin())];
                auto part =
                    std::make_unique<Part>(*this, mAsset->getGroup(), sub->vertexData, sub->getMaterialName(), receiver);
                part->mLevels.push_back(sub->indexData);
                for (Ogre::IndexData* level : sub->mLodFaceList)
                    part->mLevels.push_back(level);
                mBarkParts.push_back(std::move(part));
            }
        }
        mRadius = Ogre::Math::boundingRadiusFromAABB(mBounds);
        setLevels(mOptions.level >= 0 ? mGpu->levels[std::size_t(mOptions.level)].targetHeightPx
                                      : std::numeric_limits<float>::max());
    }

    void EllipsoidTree::setLevels(float heightPx)
    {
        mHeightPx = heightPx;
        // Forced or clamped: heightPx is not what the tree shows, so nothing fades.
        bool held = mOptions.level >= 0;
        if (held) // the lines made for its target height
        {
            mLevel = std::size_t(mOptions.level);
            heightPx = mGpu->levels[mLevel].targetHeightPx;
        }
        else
        {
            mLevel = TreeLod::levelForHeight(mGpu->levels, heightPx);
            const std::size_t clamped = std::min<std::size_t>(
                mLodBias.clampMesh(Ogre::ushort(std::min<std::size_t>(mLevel, 0xffff))), mGpu->levels.size() - 1);
            held = clamped != mLevel;
            if (held) // the lines made for its target height
                heightPx = mGpu->levels[clamped].targetHeightPx;
            mLevel = clamped;
        }
        const bool nextAllowed = mLodBias.clampMesh(Ogre::ushort(std::min<std::size_t>(mLevel + 1, 0xffff))) == mLevel + 1;
        setLevelDraw(mEllipsoids, mGpu->levels, mLevel,
                     !held && nextAllowed ? transitionShare(mGpu->levels, mLevel, heightPx) : 0.0f);
        if (mLines)
        {
            mLineLevel = TreeLod::levelForHeight(mLines->levels, heightPx);
            setLevelDraw(mLineParts, mLines->levels, mLineLevel,
                         held ? 0.0f : transitionShare(mLines->levels, mLineLevel, heightPx));
        }
    }

    float EllipsoidTree::transitionShare(const std::vector<EllipsoidGpuLevel>& levels, std::size_t level, float heightPx) const
    {
        // Level l is drawn down to the next one's target height, from its own (level 0: any height).
        if (level + 1 >= levels.size() || !(levels[level + 1].targetHeightPx > 0.0f) ||
            levels[level + 1].indexCount == 0)
            return 0.0f;
        const float next = levels[level + 1].targetHeightPx;
        const float range = level == 0 ? std::numeric_limits<float>::infinity() : levels[level].targetHeightPx / next;
        return mTransition.coarseShare(heightPx / next, range);
    }

    void EllipsoidTree::setLevelDraw(LevelDraw& draw, const std::vector<EllipsoidGpuLevel>& levels, std::size_t level, float share)
    {
        draw.share = share;
        draw.fine->mIndexData.indexStart = levels[level].indexStart;
        draw.fine->mIndexData.indexCount = levels[level].indexCount;
        const Ogre::Vector3 position = mParentNode ? mParentNode->_getDerivedPosition() : Ogre::Vector3::ZERO;
        ObjectTransition::apply(*draw.fine, share > 0.0f ? -share : 0.0f, position);
        if (share > 0.0f)
        {
            draw.coarse->mIndexData.indexStart = levels[level + 1].indexStart;
            draw.coarse->mIndexData.indexCount = levels[level + 1].indexCount;
            ObjectTransition::apply(*draw.coarse, share, position);
        }
    }

    EllipsoidTree::~EllipsoidTree() = default;

    const Ogre::String& EllipsoidTree::getMovableType() const { return EllipsoidTreeFactory::FACTORY_TYPE_NAME; }

    std::size_t EllipsoidTree::levelForHeight(const EllipsoidTreeGpu& gpu, float heightPx)
    {
        return TreeLod::levelForHeight(gpu.levels, heightPx);
    }

    void EllipsoidTree::_notifyCurrentCamera(Ogre::Camera* camera)
    {
        Ogre::MovableObject::_notifyCurrentCamera(camera);
        if (!mParentNode)
            return;
        // The tree's height on screen from treelod_screen_size's value (the LoD camera's, the
        // viewer's for shadow cameras, with its bias) and the mesh factor: r_px scaled by the
        // tree's height over its bounding radius.
        const Ogre::Real radiusPx = ScreenSizeLodStrategy::radiusInPixels(mLodBias.screenSize(*this, camera));
        const Ogre::Real radius = getBoundingRadiusScaled();
        Ogre::Real heightPx = std::numeric_limits<Ogre::Real>::max();
        if (radiusPx < heightPx && radius > 0.0f)
            heightPx = mTreeHeight * std::abs(mParentNode->_getDerivedScale().y) * radiusPx / radius;
        setLevels(float(heightPx));
        if (mBarkMesh)
            mBarkLodIndex = mLodBias.meshLodIndex(*mBarkMesh, *this, camera);
        for (Part* part : {mEllipsoids.fine.get(), mEllipsoids.coarse.get(), mLineParts.fine.get(), mLineParts.coarse.get()})
            if (part)
                part->updateMaterialLod(mLodBias, camera);
        for (const std::unique_ptr<Part>& part : mBarkParts)
            part->updateMaterialLod(mLodBias, camera);
    }

    void EllipsoidTree::setLodTransition(Ogre::Real length)
    {
        mTransition.set(length, "EllipsoidTree '" + mName + "'");
    }

    void EllipsoidTree::setMeshLodBias(Ogre::Real factor, unsigned short maxDetailIndex, unsigned short minDetailIndex)
    {
        mLodBias.setMesh(factor, maxDetailIndex, minDetailIndex, "EllipsoidTree '" + mName + "'");
    }

    void EllipsoidTree::setMaterialLodBias(Ogre::Real factor, unsigned short maxDetailIndex,
                                           unsigned short minDetailIndex)
    {
        mLodBias.setMaterial(factor, maxDetailIndex, minDetailIndex, "EllipsoidTree '" + mName + "'");
    }

    bool EllipsoidTree::useShadowedMaterials() const
    {
        return receivesDepthShadows(mManager);
    }

    void EllipsoidTree::_updateRenderQueue(Ogre::RenderQueue* queue)
    {
        if (mManager)
            notifyShadowTechnique(*mManager);
        for (const LevelDraw* draw : {&mEllipsoids, &mLineParts})
            if (draw->fine)
            {
                queue->addRenderable(draw->fine.get(), mRenderQueueID, mRenderQueuePriority);
                if (draw->share > 0.0f)
                    queue->addRenderable(draw->coarse.get(), mRenderQueueID, mRenderQueuePriority);
            }
        for (const std::unique_ptr<Part>& part : mBarkParts)
            queue->addRenderable(part.get(), mRenderQueueID, mRenderQueuePriority);
    }

    void EllipsoidTree::visitRenderables(Ogre::Renderable::Visitor* visitor, bool)
    {
        for (const LevelDraw* draw : {&mEllipsoids, &mLineParts})
            if (draw->fine)
            {
                visitor->visit(draw->fine.get(), 0, false);
                visitor->visit(draw->coarse.get(), 1, false);
            }
        for (const std::unique_ptr<Part>& part : mBarkParts)
            visitor->visit(part.get(), 0, false);
    }

    Ogre::MovableObject* EllipsoidTreeFactory::createInstanceImpl(const Ogre::String& name,
                                                                  const Ogre::NameValuePairList* params)
    {
        const ObjectParams p(params, "EllipsoidTreeFactory::createInstanceImpl");
        EllipsoidTree::Options options;
        double value = 0.0;
        if (p.number("level", 0.0, 1e6, value))
        {
            if (value != std::floor(value))
                p.bad("level", *p.find("level"), "a whole number");
            options.level = int(value);
        }
        if (p.number("lodBias", 1e-6, 1e6, value))
            options.lodBias = float(value);
        p.flag("lines", options.lines);
        options.lodStrategy = ObjectLodBias::strategyParam(p);
        ObjectTransition::param(p, options.lodTransition);
        return new EllipsoidTree(name, p.loadAsset(name, "EllipsoidTree"), options);
    }
}
