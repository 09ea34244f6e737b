// EllipsoidTree: a tree whose leaves are a level of EM/GMM-clustered ellipsoids, ray cast per
// fragment (the ellipsoids-and-lines paper (001): hierarchy §3.1, rendering §5, LoD §6).
// MovableObject type "EllipsoidTree", chunk "ellipsoids" (EllipsoidTreeData.h).
//
// Level of detail (§6): a level is made for a tree height on screen at which its mean ellipsoid
// is ELLIPSOID_TARGET_DIAMETER_PX (5) pixels across (EllipsoidLevel::targetHeightPx). The tree
// draws the coarsest level whose target height is at least the tree's height on screen, the
// finest when the tree is taller than every target. The height is read through
// ScreenSizeLodStrategy ("treelod_screen_size"): the projected radius r_px of the bounding
// sphere seen by the LoD camera, scaled by the tree's box height over that radius. The LoD
// camera's bias and the mesh LoD factor (setMeshLodBias; the `lodBias` parameter sets it)
// multiply the value, a screen area: a factor of 1/4 halves the height (the paper's
// target-resolution factor 1/2).
// setMeshLodBias's detail indices are ellipsoid levels (0 finest; the lines then follow the
// clamped level's target height) and the bark mesh's LoD index (by its own strategy).
// setMaterialLodBias: the material LoD index of each part's material (by its strategy).
//
// Branches (§3.2): the lines of chunk "ellipsoid-lines" (capsules ray cast per fragment, at least a
// pixel wide, TreeLodEllipsoidLine.vert) at the level the same rule gives for the lines' own
// targets (a mean line 1 px wide, §6); without that chunk, or with lines=false, the reference bark
// mesh with its mesh LoD.
//
// Shadows (§5 uses shadow mapping): the ellipsoids and lines cast their ray-cast surfaces into
// the sun's texture shadow and receive it at the hit point (integrated texture shadows; any shadow
// camera projection: focused, LiSPSM).
//
// Noise (§3.1, Fig. 6; §5): one pair of white-noise cube maps for every tree (EllipsoidNoise.h,
// bound by EllipsoidTreeResources): the alpha test opens holes in each ellipsoid at its level's
// calibrated threshold (the far side shows through, in shadows too), the normal is blended with
// the normal noise; the lod is the cluster's (from its leaf weight) or the pixel footprint's at
// its centre if coarser (the paper takes fwidth per fragment).
//
// AO (§5): the ambient term is scaled by each primitive's baked AO (none unless baked with
// ellipsoids.aoRays).
//
// Transitions (ObjectTransition.h; setLodTransition, the `lodTransition` parameter, default 0:
// hard): within 1 + t of a switch in height on screen (a level's target height) the ellipsoids, and
// the lines at their own switches, are drawn at both levels with complementary screen-door masks.
// Not past a clamped or forced level.
//
// Parameters (createMovableObject params, or the registry): asset (required), group, level
// (force an ellipsoid level: 0 finest; the lines follow its target height), lodBias (> 0,
// setMeshLodBias's factor), lines (true: the baked lines when the package has them), lodStrategy
// (treelod_screen_size, the default, or another: ObjectLodBias.h), lodTransition (in [0, 1]).
#pragma once

#include "TreeLod/EllipsoidTreeResources.h"
#include "TreeLod/ObjectLodBias.h"
#include "TreeLod/ObjectTransition.h"
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
            float lodBias = 1.0f; ///< > 0, the initial setMeshLodBias factor
            const Ogre::LodStrategy* lodStrategy = nullptr; ///< null: treelod_screen_size (ObjectLodBias::strategy)
            bool lines = true;    ///< the baked lines when the package has them, else the bark mesh
            float lodTransition = ForestInstances::DEFAULT_TRANSITION; ///< ObjectTransition::length
        };

        EllipsoidTree(const Ogre::String& name, const TreeAssetPtr& asset, const Options& options);
        ~EllipsoidTree() override;

        const TreeAssetPtr& getAsset() const { return mAsset; }
        std::size_t getLevelCount() const { return mGpu->levels.size(); }
        /// The level drawn for the last camera.
        std::size_t getLevel() const { return mLevel; }
        /// The tree's height on screen for the last camera (bias applied), what the levels follow.
        float getHeightOnScreen() const { return mHeightPx; }
        /// Ellipsoids of the level drawn.
        std::size_t getEllipsoidCount() const { return mGpu->levels[mLevel].indexCount / 6; }
        /// Whether the branches are lines (else the bark mesh).
        bool drawsLines() const { return mLines != nullptr; }
        /// The line level drawn for the last camera, and its line count (0 without lines).
        std::size_t getLineLevel() const { return mLineLevel; }
        std::size_t getLineCount() const { return mLines ? mLines->levels[mLineLevel].indexCount / 6 : 0; }
        /// As Entity::setMeshLodBias (the file comment says what it biases and clamps).
        void setMeshLodBias(Ogre::Real factor, unsigned short maxDetailIndex = 0, unsigned short minDetailIndex = 99);
        /// As Entity::setMaterialLodBias.
        void setMaterialLodBias(Ogre::Real factor, unsigned short maxDetailIndex = 0,
                                unsigned short minDetailIndex = 99);
        const ObjectLodBias& getLodBias() const { return mLodBias; }
        /// Transition length t (ObjectTransition.h) in [0, 1]; throws naming the object otherwise.
        void setLodTransition(Ogre::Real length);
        Ogre::Real getLodTransition() const { return mTransition.length; }
        /// The share of the pixels level getLevel() + 1 (getLineLevel() + 1) draws now (0: one level).
        Ogre::Real getTransitionShare() const { return mEllipsoids.share; }
        Ogre::Real getLineTransitionShare() const { return mLineParts.share; }
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
        /// A level's draw and, in a transition, the next coarser level's (its share of the pixels).
        struct LevelDraw
        {
            std::unique_ptr<Part> fine, coarse;
            float share = 0.0f;
        };
        /// Point `draw` at `level` of `levels` and, with `share` > 0, at the next one in a transition.
        void setLevelDraw(LevelDraw& draw, const std::vector<EllipsoidGpuLevel>& levels, std::size_t level, float share);
        /// The next coarser level's share at `heightPx` for `level` of `levels` (ObjectTransition.h).
        float transitionShare(const std::vector<EllipsoidGpuLevel>& levels, std::size_t level, float heightPx) const;
        bool useShadowedMaterials() const;
        /// The ellipsoid and line levels for a tree `heightPx` tall on screen (or the forced level).
        void setLevels(float heightPx);

        TreeAssetPtr mAsset;
        const EllipsoidTreeGpu* mGpu;
        Options mOptions;
        std::unique_ptr<Ogre::VertexData> mVertexData; ///< the asset's ellipsoids + one instance at the origin
        LevelDraw mEllipsoids;
        const EllipsoidLineGpu* mLines = nullptr;
        std::unique_ptr<Ogre::VertexData> mLineVertexData; ///< the asset's lines + one instance at the origin
        LevelDraw mLineParts; ///< no parts without lines
        std::size_t mLineLevel = 0;
        std::vector<std::unique_ptr<Part>> mBarkParts;
        Ogre::MeshPtr mBarkMesh;
        unsigned short mBarkLodIndex = 0;
        std::size_t mLevel = 0;
        float mTreeHeight = 0.0f; ///< the reference's box height, metres
        float mHeightPx = 0.0f;
        Ogre::AxisAlignedBox mBounds;
        Ogre::Real mRadius = 0.0f;
        ObjectLodBias mLodBias;
        ObjectTransition mTransition;
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
