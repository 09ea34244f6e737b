// ImpostorTree: a tree drawn as one camera-facing quad of an impostor technique: the one-quad
// impostor (chunk "impostor", ImpostorData.h, MovableObject type "ImpostorTree") or the
// octahedral impostor (chunk "octahedral-impostor", OctahedralImpostorData.h, type
// "OctahedralImpostorTree"); each type has its own ImpostorTreeFactory.
//
// The quad turns to face the camera in the technique's vertex program, which reads the Forest's
// per-instance data (uv4 = position + scale, uv5 = rotation; Forest.h); a single tree is one such
// instance at its own origin, given as constant per-vertex attributes, so the materials and
// pictures are the Forest's. Bounds: what the turning quad may cover (ImpostorQuad::bounds).
// Materials switch to the shadow-receiving clone under an integrated texture shadow technique.
//
// Level of detail: one quad, one geometric level (setMeshLodBias's indices have nothing to
// clamp; its factor is kept for getLodBias). Material LoD as an Entity's: the material's own
// strategy and lod_values pick its technique, biased and clamped by setMaterialLodBias.
//
// Parameters (createMovableObject params, or the registry): asset (required), group.
#pragma once

#include "TreeLod/ObjectLodBias.h"
#include "TreeLod/TreeAsset.h"

#include <OgreMovableObject.h>
#include <OgreRenderable.h>

#include <functional>
#include <memory>

namespace TreeLod
{
    /// What an ImpostorTree draws: one instanced quad (4 vertices, 6 indices) of the asset's GPU
    /// resources, which outlive the tree (the asset holds them).
    struct ImpostorQuad
    {
        Ogre::VertexData* vertexData = nullptr;
        Ogre::HardwareIndexBufferSharedPtr indexBuffer;
        Ogre::String material;         ///< reads the instance data
        Ogre::String shadowedMaterial; ///< receives integrated texture shadows
        Ogre::AxisAlignedBox bounds;   ///< local: everything the quad may cover, turned any way
    };

    class ImpostorTree : public Ogre::MovableObject, public Ogre::Renderable
    {
    public:
        /// Draws `quad` of `asset` (the technique's resources, built by the caller) as an object of
        /// MovableObject type `movableType`.
        ImpostorTree(const Ogre::String& name, const TreeAssetPtr& asset, const ImpostorQuad& quad,
                     const Ogre::String& movableType);
        ~ImpostorTree() override;

        const TreeAssetPtr& getAsset() const { return mAsset; }

        /// As Entity::setMeshLodBias (the file comment says what it does here).
        void setMeshLodBias(Ogre::Real factor, unsigned short maxDetailIndex = 0, unsigned short minDetailIndex = 99);
        /// As Entity::setMaterialLodBias.
        void setMaterialLodBias(Ogre::Real factor, unsigned short maxDetailIndex = 0,
                                unsigned short minDetailIndex = 99);
        const ObjectLodBias& getLodBias() const { return mLodBias; }
        /// The material LoD index for the last camera.
        unsigned short getMaterialLodIndex() const { return mMaterialLodIndex; }

        // MovableObject
        const Ogre::String& getMovableType() const override;
        const Ogre::AxisAlignedBox& getBoundingBox() const override { return mBounds; }
        Ogre::Real getBoundingRadius() const override { return mRadius; }
        void _notifyCurrentCamera(Ogre::Camera* camera) override;
        void _updateRenderQueue(Ogre::RenderQueue* queue) override;
        void visitRenderables(Ogre::Renderable::Visitor* visitor, bool debugRenderables = false) override;

        // Renderable
        const Ogre::MaterialPtr& getMaterial() const override;
        Ogre::Technique* getTechnique() const override;
        void getRenderOperation(Ogre::RenderOperation& op) override;
        void getWorldTransforms(Ogre::Matrix4* xform) const override;
        Ogre::Real getSquaredViewDepth(const Ogre::Camera* camera) const override;
        const Ogre::LightList& getLights() const override;
        bool getCastsShadows() const override { return getCastShadows(); }

    private:
        TreeAssetPtr mAsset;
        Ogre::String mMovableType;
        std::unique_ptr<Ogre::VertexData> mVertexData; ///< the asset's quad + the instance attributes
        Ogre::IndexData mIndexData;
        Ogre::MaterialPtr mMaterial;
        Ogre::MaterialPtr mShadowedMaterial;
        Ogre::AxisAlignedBox mBounds;
        Ogre::Real mRadius = 0.0f;
        ObjectLodBias mLodBias;
        unsigned short mMaterialLodIndex = 0;
    };

    class ImpostorTreeFactory : public Ogre::MovableObjectFactory
    {
    public:
        /// The one-quad impostor's type.
        static const Ogre::String FACTORY_TYPE_NAME;
        /// The octahedral impostor's type.
        static const Ogre::String OCTAHEDRAL_TYPE_NAME;

        /// Makes ImpostorTrees of `type` drawing quadOf(asset) (which builds the asset's resources
        /// on first use and throws naming the asset when it lacks the technique's chunk).
        ImpostorTreeFactory(const Ogre::String& type, std::function<ImpostorQuad(TreeAsset&)> quadOf)
            : mType(type), mQuadOf(std::move(quadOf))
        {
        }
        const Ogre::String& getType() const override { return mType; }

    protected:
        Ogre::MovableObject* createInstanceImpl(const Ogre::String& name, const Ogre::NameValuePairList* params) override;

    private:
        Ogre::String mType;
        std::function<ImpostorQuad(TreeAsset&)> mQuadOf;
    };
}
