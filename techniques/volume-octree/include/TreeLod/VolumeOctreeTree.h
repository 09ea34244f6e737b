// VolumeOctreeTree: a tree drawn as the volumetric octree of Linz, Reche-Martinez, Drettakis and
// Magnor 2006 (paper 002): per cell a billboard facing the viewer, textured by the two input
// cameras nearest the view, blended back to front with the over operator (§2.1).
// MovableObject type "VolumeOctreeTree", chunk "volume-octree" (VolumeOctreeData.h).
//
// Level of detail (§3.1): the distance planes of volumeOctreeDrawsCell. The active level is the
// finest whose plane lies beyond the tree's nearest point; a cell of level l's plane is where it
// covers lodPixels (default 4: one texel a pixel) on screen. The vertex program
// (techniques/volume-octree/media/GLSL/TreeLodVolumeOctree.vert) decides per cell between the active level and the
// level above. Pixels per metre come from ScreenSizeLodStrategy ("treelod_screen_size"): the
// projected radius r_px of the bounding sphere over its radius, the LoD camera's bias and the
// mesh LoD factor (setMeshLodBias; the `lodBias` parameter sets it) in the value, a screen area:
// a factor of 1/4 halves the pixels, one level coarser.
// setMeshLodBias's detail indices count levels from the finest (index 0 = level levelCount - 1,
// index levelCount - 1 = the root) and clamp the active level; setMaterialLodBias the material
// LoD index of its material (by the material's strategy).
//
// Order (§6: the paper traverses the octree on the CPU every frame, its stated bottleneck): each
// level's cells are sorted once per view octant at load (VolumeOctreeResources::getCellOrders); the index
// buffer is rewritten only when the octant of the view direction or the active level changes, the
// level above first (its cells lie behind the plane), then the active level.
//
// Camera pair: chosen on the CPU once per object and frame (as the paper does per frame).
// Shadows (the paper has none): it receives none (the photographs carry their light) and casts the
// same billboards facing the light, textured by the input cameras nearest the light, each texel
// kept by a hashed alpha test, so a light ray is blocked with the probability the reconstruction
// gives (techniques/volume-octree/media/GLSL/TreeLodVolumeOctree.frag, CASTER). Shadow cameras keep the viewer's levels.
//
// Transitions (ObjectTransition.h; setLodTransition, the `lodTransition` parameter, default 0:
// hard), per cell as the switches are: a cell of the level above whose centre is in front of the
// plane by less than 1 + t in screen size draws with its children, complementary screen-door masks
// sharing its pixels (a cell's own range, plane to half the plane's depth, caps the band at
// sqrt(2)). The active level's own change (cells beyond twice the nearest point's depth) stays hard,
// as do shadow casters (the active level everywhere).
//
// Parameters (createMovableObject params, or the registry): asset (required), group, level (force
// the active level), lodBias (> 0), lodPixels (> 0), lodStrategy (treelod_screen_size, the
// default, or another: ObjectLodBias.h), lodTransition (in [0, 1]).
#pragma once

#include "TreeLod/ObjectLodBias.h"
#include "TreeLod/ObjectTransition.h"
#include "TreeLod/TreeAsset.h"
#include "TreeLod/VolumeOctreeResources.h"

#include <OgreHardwareIndexBuffer.h>
#include <OgreMovableObject.h>

#include <memory>

namespace TreeLod
{
    class VolumeOctreeTree : public Ogre::MovableObject
    {
    public:
        struct Options
        {
            int level = -1;          ///< >= 0: always this active level
            float lodBias = 1.0f;    ///< > 0, the initial setMeshLodBias factor
            const Ogre::LodStrategy* lodStrategy = nullptr; ///< null: treelod_screen_size (ObjectLodBias::strategy)
            float lodPixels = 4.0f;  ///< > 0
            float lodTransition = ForestInstances::DEFAULT_TRANSITION; ///< ObjectTransition::length
        };

        VolumeOctreeTree(const Ogre::String& name, const TreeAssetPtr& asset, const Options& options);
        ~VolumeOctreeTree() override;

        const TreeAssetPtr& getAsset() const { return mAsset; }
        std::uint32_t getLevelCount() const { return mData->levelCount; }
        /// The active level for the last camera.
        std::uint32_t getActiveLevel() const { return mActive; }
        /// Its distance plane's view depth for the last camera (metres; FLT_MAX: none, as for an
        /// orthographic camera).
        float getPlaneDepth() const { return mPlaneDepth; }
        /// Billboards the last camera's draw may show (cells of both drawn levels).
        std::size_t getDrawnCellCount() const;
        /// The two input cameras blended for the last camera.
        const VolumeCameraPair& getCameraPair() const { return mPair; }

        /// As Entity::setMeshLodBias (the file comment says what it biases and clamps).
        void setMeshLodBias(Ogre::Real factor, unsigned short maxDetailIndex = 0, unsigned short minDetailIndex = 99);
        /// As Entity::setMaterialLodBias.
        void setMaterialLodBias(Ogre::Real factor, unsigned short maxDetailIndex = 0,
                                unsigned short minDetailIndex = 99);
        const ObjectLodBias& getLodBias() const { return mLodBias; }
        /// Transition length t (ObjectTransition.h) in [0, 1]; throws naming the object otherwise.
        void setLodTransition(Ogre::Real length);
        Ogre::Real getLodTransition() const { return mTransition.length; }

        // MovableObject
        const Ogre::String& getMovableType() const override;
        const Ogre::AxisAlignedBox& getBoundingBox() const override { return mGpu->bounds; }
        Ogre::Real getBoundingRadius() const override { return mRadius; }
        void _notifyCurrentCamera(Ogre::Camera* camera) override;
        void _updateRenderQueue(Ogre::RenderQueue* queue) override;
        void visitRenderables(Ogre::Renderable::Visitor* visitor, bool debugRenderables = false) override;

    private:
        class Part;
        /// Rewrite the index buffer for `octant` and active level `active` (if they changed).
        void order(std::uint32_t octant, std::uint32_t active);

        TreeAssetPtr mAsset;
        const VolumeOctreeData* mData;
        const VolumeOctreeGpu* mGpu;
        const VolumeOctreeCellOrders* mCellOrders;
        Options mOptions;
        std::unique_ptr<Part> mPart;
        Ogre::HardwareIndexBufferSharedPtr mIndexBuffer;
        std::uint32_t mOctant = 8, mActive = 0, mOrderedActive = ~0u;
        VolumeCameraPair mPair;
        float mPlaneDepth = 0.0f;
        Ogre::Real mRadius = 0.0f;
        ObjectLodBias mLodBias;
        ObjectTransition mTransition;
    };

    class VolumeOctreeTreeFactory : public Ogre::MovableObjectFactory
    {
    public:
        static const Ogre::String FACTORY_TYPE_NAME;
        const Ogre::String& getType() const override { return FACTORY_TYPE_NAME; }

    protected:
        Ogre::MovableObject* createInstanceImpl(const Ogre::String& name, const Ogre::NameValuePairList* params) override;
    };
}
