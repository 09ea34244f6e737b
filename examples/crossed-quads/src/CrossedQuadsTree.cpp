// CrossedQuadsTree: one Renderable per quad over the asset's shared buffers (CrossedQuadsTree.h).
#include "TreeLod/CrossedQuadsTree.h"

#include "TreeLod/CrossedQuadsResources.h"
#include "TreeLod/ObjectParams.h"
#include "TreeLod/TreeAssetManager.h"

#include <OgreException.h>
#include <OgreMaterialManager.h>
#include <OgreNode.h>
#include <OgreRenderQueue.h>
#include <OgreRenderable.h>
#include <OgreSceneManager.h>

namespace TreeLod
{
    const Ogre::String CrossedQuadsTreeFactory::FACTORY_TYPE_NAME = "CrossedQuadsTree";

    /// One quad: 6 indices of the asset's buffers with that quad's materials.
    class CrossedQuadsTree::Part : public Ogre::Renderable
    {
    public:
        Part(CrossedQuadsTree& tree, const CrossedQuadsGpu& gpu, const CrossedQuadsPart& part, const Ogre::String& group)
            : mTree(tree), mVertexData(gpu.vertexData.get())
        {
            mMaterial = Ogre::MaterialManager::getSingleton().getByName(part.material, group);
            mShadowedMaterial = Ogre::MaterialManager::getSingleton().getByName(part.shadowedMaterial, group);
            if (!mMaterial || !mShadowedMaterial)
                OGRE_EXCEPT(Ogre::Exception::ERR_ITEM_NOT_FOUND,
                            "material '" + part.material + "' or its shadowed variant not found",
                            "CrossedQuadsTree '" + tree.getName() + "'");
            mMaterial->load();
            mShadowedMaterial->load();
            mIndexData.indexBuffer = gpu.indexBuffer;
            mIndexData.indexStart = part.indexStart;
            mIndexData.indexCount = 6;
        }

        const Ogre::MaterialPtr& getMaterial() const override
        {
            Ogre::SceneManager* sm = mTree._getManager();
            const bool shadowed = sm && sm->isShadowTechniqueTextureBased() && sm->isShadowTechniqueIntegrated();
            return shadowed ? mShadowedMaterial : mMaterial;
        }

        void getRenderOperation(Ogre::RenderOperation& op) override
        {
            op.operationType = Ogre::RenderOperation::OT_TRIANGLE_LIST;
            op.useIndexes = true;
            op.vertexData = mVertexData;
            op.indexData = &mIndexData;
            op.srcRenderable = this;
        }

        void getWorldTransforms(Ogre::Matrix4* xform) const override { *xform = mTree._getParentNodeFullTransform(); }

        Ogre::Real getSquaredViewDepth(const Ogre::Camera* camera) const override
        {
            return mTree.getParentNode() ? mTree.getParentNode()->getSquaredViewDepth(camera) : 0.0f;
        }

        const Ogre::LightList& getLights() const override { return mTree.queryLights(); }

    private:
        CrossedQuadsTree& mTree;
        Ogre::VertexData* mVertexData; ///< the asset's, alive as long as mTree holds the asset
        Ogre::IndexData mIndexData;
        Ogre::MaterialPtr mMaterial;
        Ogre::MaterialPtr mShadowedMaterial;
    };

    CrossedQuadsTree::CrossedQuadsTree(const Ogre::String& name, const TreeAssetPtr& asset)
        : Ogre::MovableObject(name), mAsset(asset)
    {
        const CrossedQuadsGpu& gpu = CrossedQuadsResources::of(*asset).getGpu();
        for (const CrossedQuadsPart& part : gpu.parts)
            mParts.push_back(std::make_unique<Part>(*this, gpu, part, asset->getGroup()));
        mBounds = gpu.bounds;
        mRadius = Ogre::Math::boundingRadiusFromAABB(mBounds);
    }

    CrossedQuadsTree::~CrossedQuadsTree() = default;

    const Ogre::String& CrossedQuadsTree::getMovableType() const { return CrossedQuadsTreeFactory::FACTORY_TYPE_NAME; }

    void CrossedQuadsTree::_updateRenderQueue(Ogre::RenderQueue* queue)
    {
        for (const std::unique_ptr<Part>& part : mParts)
            queue->addRenderable(part.get(), mRenderQueueID, mRenderQueuePriority);
    }

    void CrossedQuadsTree::visitRenderables(Ogre::Renderable::Visitor* visitor, bool)
    {
        for (std::size_t i = 0; i < mParts.size(); ++i)
            visitor->visit(mParts[i].get(), 0, false);
    }

    Ogre::MovableObject* CrossedQuadsTreeFactory::createInstanceImpl(const Ogre::String& name,
                                                                     const Ogre::NameValuePairList* params)
    {
        const ObjectParams p(params, "CrossedQuadsTreeFactory::createInstanceImpl");
        return new CrossedQuadsTree(name, p.loadAsset(name, "CrossedQuadsTree"));
    }
}
