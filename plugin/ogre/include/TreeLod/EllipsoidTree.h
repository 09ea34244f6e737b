// EllipsoidTree: a tree whose leaves are a level of EM/GMM-clustered ellipsoids, ray cast per
// fragment (the ellipsoids-and-lines paper (001): hierarchy §3.1, rendering §5, LoD §6).
// MovableObject type "EllipsoidTree", chunk "ellipsoids" (EllipsoidTreeData.h).
//
// Level of detail (§6): a level is made for a tree height on screen at which its mean ellipsoid
// is ELLIPSOID_TARGET_DIAMETER_PX (5) pixels across (EllipsoidLevel::targetHeightPx). The tree
// draws the coarsest level whose target height is at least the tree's height on screen (the
// tree's box height seen at the distance of its centre through the LoD camera, times the LoD
// camera's bias and the object's lodBias), the finest when the tree is taller than every target.
// lodBias is the paper's target-resolution factor: 1/2 or 1/4 draw coarser levels.
//
// Deviations from the paper, for now: the branches are the reference bark mesh with its mesh LoD
// levels (the paper's simplified lines, §3.2, are not built yet), the ellipsoids have no noise
// cube maps (alpha test and normal noise, §3.1) and no AO (§5), and the tree neither casts nor
// receives shadows.
//
// Parameters (createMovableObject params, or the registry): asset (required), group, level
// (force a level: 0 finest), lodBias (> 0, multiplies the LoD camera's bias).
#pragma once

#include "TreeLod/EllipsoidTreeResources.h"
#include "TreeLod/TreeAsset.h"

#include <OgreMovableObject.h>

#include <memory>
#include <vector>

namespace TreeLod
{
    class EllipsoidTree : public Ogre::MovableObject
    {
    public:
        struct Options
        {
            int level = -1;       ///< >= 0: always this level
            float lodBias = 1.0f; ///< > 0
        };

        EllipsoidTree(const Ogre::String& name, const TreeAssetPtr& asset, const Options& options);
        ~EllipsoidTree() override;

        const TreeAssetPtr& getAsset() const { return mAsset; }
        std::size_t getLevelCount() const { return mGpu->levels.size(); }
        /// The level drawn for the last camera.
        std::size_t getLevel() const { return mLevel; }
        /// Ellipsoids of the level drawn.
        std::size_t getEllipsoidCount() const { return mGpu->levels[mLevel].indexCount / 6; }
        /// The level for a tree `heightPx` tall on screen (bias applied), as §6 above.
        static std::size_t levelForHeight(const EllipsoidTreeGpu& gpu, float heightPx);

        // MovableObject
        const Ogre::String& getMovableType() const override;
        const Ogre::AxisAlignedBox& getBoundingBox() const override { return mBounds; }
        Ogre::Real getBoundingRadius() const override { return mRadius; }
        void _notifyCurrentCamera(Ogre::Camera* camera) override;
        void _updateRenderQueue(Ogre::RenderQueue* queue) override;
        void visitRenderables(Ogre::Renderable::Visitor* visitor, bool debugRenderables = false) override;

    private:
        class Part;
        bool useShadowedMaterials() const;

        TreeAssetPtr mAsset;
        const EllipsoidTreeGpu* mGpu;
        Options mOptions;
        std::unique_ptr<Ogre::VertexData> mVertexData; ///< the asset's ellipsoids + one instance at the origin
        std::unique_ptr<Part> mEllipsoids;
        std::vector<std::unique_ptr<Part>> mBarkParts;
        Ogre::MeshPtr mBarkMesh;
        unsigned short mBarkLodIndex = 0;
        std::size_t mLevel = 0;
        float mTreeHeight = 0.0f; ///< the reference's box height, metres
        Ogre::AxisAlignedBox mBounds;
        Ogre::Real mRadius = 0.0f;
    };

    class EllipsoidTreeFactory : public Ogre::MovableObjectFactory
    {
    public:
        static const Ogre::String FACTORY_TYPE_NAME;
        const Ogre::String& getType() const override { return FACTORY_TYPE_NAME; }

    protected:
        Ogre::MovableObject* createInstanceImpl(const Ogre::String& name, const Ogre::NameValuePairList* params) override;
    };
}
