// ImpostorTree: a tree drawn as its one-quad impostor (chunk "impostor", ImpostorData.h): the
// cheapest representation, the Forest's far level. MovableObject type "ImpostorTree".
//
// The quad turns about the tree's local +Y axis to face the camera (a cylindrical billboard) in
// the impostor's vertex program, which reads the Forest's per-instance data (uv4 = position +
// scale, uv5 = rotation; Forest.h); a single tree is one such instance at its own origin, given
// as constant per-vertex attributes, so the materials and pictures are the Forest's.
// Bounds: the box swept by the quad turning about +Y. Materials switch to the shadow-receiving
// clone under an integrated texture shadow technique.
//
// Parameters (createMovableObject params, or the registry): asset (required), group.
#pragma once

#include "TreeLod/TreeAsset.h"

#include <OgreMovableObject.h>
#include <OgreRenderable.h>

#include <memory>

namespace TreeLod
{
    struct ImpostorGpu;

    class ImpostorTree : public Ogre::MovableObject, public Ogre::Renderable
    {
    public:
        /// Builds the asset's impostor on first use; throws naming the asset when it has none.
        ImpostorTree(const Ogre::String& name, const TreeAssetPtr& asset);
        ~ImpostorTree() override;

        const TreeAssetPtr& getAsset() const { return mAsset; }

        // MovableObject
        const Ogre::String& getMovableType() const override;
        const Ogre::AxisAlignedBox& getBoundingBox() const override { return mBounds; }
        Ogre::Real getBoundingRadius() const override { return mRadius; }
        void _updateRenderQueue(Ogre::RenderQueue* queue) override;
        void visitRenderables(Ogre::Renderable::Visitor* visitor, bool debugRenderables = false) override;

        // Renderable
        const Ogre::MaterialPtr& getMaterial() const override;
        void getRenderOperation(Ogre::RenderOperation& op) override;
        void getWorldTransforms(Ogre::Matrix4* xform) const override;
        Ogre::Real getSquaredViewDepth(const Ogre::Camera* camera) const override;
        const Ogre::LightList& getLights() const override;

    private:
        TreeAssetPtr mAsset;
        const ImpostorGpu* mGpu;
        std::unique_ptr<Ogre::VertexData> mVertexData; ///< the asset's quad + the instance attributes
        Ogre::IndexData mIndexData;
        Ogre::MaterialPtr mMaterial;
        Ogre::MaterialPtr mShadowedMaterial;
        Ogre::AxisAlignedBox mBounds;
        Ogre::Real mRadius = 0.0f;
    };

    class ImpostorTreeFactory : public Ogre::MovableObjectFactory
    {
    public:
        static const Ogre::String FACTORY_TYPE_NAME;
        const Ogre::String& getType() const override { return FACTORY_TYPE_NAME; }

    protected:
        Ogre::MovableObject* createInstanceImpl(const Ogre::String& name, const Ogre::NameValuePairList* params) override;
    };
}
