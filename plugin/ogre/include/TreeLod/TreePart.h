// TreePart: one draw of a tree MovableObject (FoliageLodTree, BillboardCloudTree): a range of
// an index buffer over shared vertices, or a bark submesh with its MeshLodGenerator levels,
// drawn with its material or, under integrated texture shadows, the shadow-receiving clone.
// The owning object says which (useShadowedMaterials) and which bark level (barkLodIndex), and
// gives its tree's height to the wind (Wind::setTreeHeight).
#pragma once

#include "TreeLod/ObjectLodBias.h"
#include "TreeLod/ObjectTransition.h"
#include "TreeLod/Wind.h"

#include <OgreMaterialManager.h>
#include <OgreTechnique.h>
#include <OgreMovableObject.h>
#include <OgreRenderable.h>
#include <OgreSceneNode.h>

#include <algorithm>
#include <vector>

namespace TreeLod
{
    class TreePart : public Ogre::Renderable
    {
    public:
        /// Throws Ogre::Exception (ERR_ITEM_NOT_FOUND, naming `ownerType`) if `material` is missing.
        TreePart(Ogre::MovableObject& owner, const Ogre::String& group, Ogre::VertexData* vertexData,
                 const Ogre::String& material, const Ogre::String& shadowedMaterial, const char* ownerType)
            : mOwner(owner), mVertexData(vertexData)
        {
            mMaterial = Ogre::MaterialManager::getSingleton().getByName(material, group);
            if (!shadowedMaterial.empty())
                mShadowedMaterial = Ogre::MaterialManager::getSingleton().getByName(shadowedMaterial, group);
            if (!mMaterial)
                OGRE_EXCEPT(Ogre::Exception::ERR_ITEM_NOT_FOUND, "material '" + material + "' not found", ownerType);
            for (Ogre::MaterialPtr* m : {&mMaterial, &mShadowedMaterial})
                if (*m)
                    (*m)->load();
            ObjectTransition::apply(*this, 0.0f, Ogre::Vector3::ZERO); // the whole tree
            Wind::setTreeHeight(*this, 0.0f); // still until the owner gives its tree's height
        }

        Ogre::IndexData mIndexData;            ///< ranged parts: start and count in a shared buffer
        std::vector<Ogre::IndexData*> mLevels; ///< bark parts: index data per mesh LoD level

        unsigned short mMaterialLodIndex = 0;  ///< set by updateMaterialLod

        const Ogre::MaterialPtr& getMaterial() const override
        {
            return mShadowedMaterial && useShadowedMaterials() ? mShadowedMaterial : mMaterial;
        }
        /// The material's LoD index for `camera` by its own strategy, biased and clamped by `bias`
        /// (what an Entity does per SubEntity).
        void updateMaterialLod(const ObjectLodBias& bias, const Ogre::Camera* camera)
        {
            mMaterialLodIndex = bias.materialLodIndex(*getMaterial(), mOwner, camera);
        }
        Ogre::Technique* getTechnique() const override
        {
            return getMaterial()->getBestTechnique(mMaterialLodIndex, this);
        }
        void getRenderOperation(Ogre::RenderOperation& op) override
        {
            op.operationType = Ogre::RenderOperation::OT_TRIANGLE_LIST;
            op.useIndexes = true;
            op.vertexData = mVertexData;
            op.indexData =
                mLevels.empty() ? &mIndexData : mLevels[std::min<std::size_t>(barkLodIndex(), mLevels.size() - 1)];
        }
        void getWorldTransforms(Ogre::Matrix4* xform) const override { *xform = mOwner._getParentNodeFullTransform(); }
        Ogre::Real getSquaredViewDepth(const Ogre::Camera* camera) const override
        {
            return mOwner.getParentNode() ? mOwner.getParentNode()->getSquaredViewDepth(camera) : 0.0f;
        }
        const Ogre::LightList& getLights() const override { return mOwner.queryLights(); }
        bool getCastsShadows() const override { return mOwner.getCastShadows(); }

    protected:
        virtual bool useShadowedMaterials() const = 0;
        virtual unsigned short barkLodIndex() const = 0;

    private:
        Ogre::MovableObject& mOwner;
        Ogre::VertexData* mVertexData;
        Ogre::MaterialPtr mMaterial;
        Ogre::MaterialPtr mShadowedMaterial;
    };
}
