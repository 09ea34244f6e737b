#include "TreeLod/ImpostorTree.h"

#include "TreeLod/ObjectParams.h"
#include "TreeLod/ShadowSetup.h"
#include "TreeLod/TechniqueSupport.h"
#include "TreeLod/Wind.h"

#include <OgreException.h>
#include <OgreMaterialManager.h>
#include <OgreNode.h>
#include <OgreRenderQueue.h>
#include <OgreSceneManager.h>
#include <OgreTechnique.h>

namespace TreeLod
{
    const Ogre::String ImpostorTreeFactory::FACTORY_TYPE_NAME = "ImpostorTree";
    const Ogre::String ImpostorTreeFactory::OCTAHEDRAL_TYPE_NAME = "OctahedralImpostorTree";

    ImpostorTree::ImpostorTree(const Ogre::String& name, const TreeAssetPtr& asset, const ImpostorQuad& quad,
                               const Ogre::String& movableType)
        : Ogre::MovableObject(name), mAsset(asset), mMovableType(movableType)
    {
        const Ogre::String& group = asset->getGroup();
        mMaterial = Ogre::MaterialManager::getSingleton().getByName(quad.material, group);
        mShadowedMaterial = Ogre::MaterialManager::getSingleton().getByName(quad.shadowedMaterial, group);
        if (!mMaterial || !mShadowedMaterial)
            OGRE_EXCEPT(Ogre::Exception::ERR_ITEM_NOT_FOUND,
                        "impostor material '" + quad.material + "' or its shadowed variant not found",
                        movableType + " '" + name + "'");
        mMaterial->load();
        mShadowedMaterial->load();

        // The asset's quad, plus one instance at the origin.
        mVertexData.reset(quad.vertexData->clone(false));
        OgreAssert(mVertexData->vertexCount == 4, "the impostor is one quad");
        addOriginInstance(*mVertexData);
        mIndexData.indexBuffer = quad.indexBuffer;
        mIndexData.indexStart = 0;
        mIndexData.indexCount = 6;

        mBounds = quad.bounds;
        mRadius = Ogre::Math::boundingRadiusFromAABB(mBounds);
        Wind::setTreeHeight(*this, Wind::treeHeight(asset->getBounds()));
    }

    ImpostorTree::~ImpostorTree() = default;

    const Ogre::String& ImpostorTree::getMovableType() const { return mMovableType; }

    void ImpostorTree::setMeshLodBias(Ogre::Real factor, unsigned short maxDetailIndex, unsigned short minDetailIndex)
    {
        mLodBias.setMesh(factor, maxDetailIndex, minDetailIndex, mMovableType + " '" + mName + "'");
    }

    void ImpostorTree::setMaterialLodBias(Ogre::Real factor, unsigned short maxDetailIndex,
                                          unsigned short minDetailIndex)
    {
        mLodBias.setMaterial(factor, maxDetailIndex, minDetailIndex, mMovableType + " '" + mName + "'");
    }

    void ImpostorTree::_notifyCurrentCamera(Ogre::Camera* camera)
    {
        Ogre::MovableObject::_notifyCurrentCamera(camera);
        if (mParentNode)
            mMaterialLodIndex = mLodBias.materialLodIndex(*getMaterial(), *this, camera);
    }

    Ogre::Technique* ImpostorTree::getTechnique() const
    {
        return getMaterial()->getBestTechnique(mMaterialLodIndex, this);
    }

    void ImpostorTree::_updateRenderQueue(Ogre::RenderQueue* queue)
    {
        if (mManager)
            notifyShadowTechnique(*mManager);
        queue->addRenderable(this, mRenderQueueID, mRenderQueuePriority);
    }

    void ImpostorTree::visitRenderables(Ogre::Renderable::Visitor* visitor, bool)
    {
        visitor->visit(this, 0, false);
    }

    const Ogre::MaterialPtr& ImpostorTree::getMaterial() const
    {
        const bool shadowed =
            receivesDepthShadows(mManager);
        return shadowed ? mShadowedMaterial : mMaterial;
    }

    void ImpostorTree::getRenderOperation(Ogre::RenderOperation& op)
    {
        op.operationType = Ogre::RenderOperation::OT_TRIANGLE_LIST;
        op.useIndexes = true;
        op.vertexData = mVertexData.get();
        op.indexData = &mIndexData;
        op.srcRenderable = this;
    }

    void ImpostorTree::getWorldTransforms(Ogre::Matrix4* xform) const { *xform = _getParentNodeFullTransform(); }

    Ogre::Real ImpostorTree::getSquaredViewDepth(const Ogre::Camera* camera) const
    {
        return getParentNode() ? getParentNode()->getSquaredViewDepth(camera) : 0.0f;
    }

    const Ogre::LightList& ImpostorTree::getLights() const { return queryLights(); }

    Ogre::MovableObject* ImpostorTreeFactory::createInstanceImpl(const Ogre::String& name,
                                                                 const Ogre::NameValuePairList* params)
    {
        const ObjectParams p(params, "ImpostorTreeFactory::createInstanceImpl");
        const TreeAssetPtr asset = p.loadAsset(name, mType.c_str());
        return new ImpostorTree(name, asset, mQuadOf(*asset), mType);
    }
}
