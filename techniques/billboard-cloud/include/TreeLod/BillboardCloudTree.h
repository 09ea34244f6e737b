// BillboardCloudTree: a tree drawn as a billboard cloud with multi-layered indirect texturing
// (García et al. 2007), or as the classic billboard cloud it is compared with. MovableObject type
// "BillboardCloudTree".
//
// Foliage: the asset's billboard cloud chunk (BillboardCloudResources::getGpu): the quads of
// all levels in one vertex buffer, one draw of one level's index range (§6). The fragment
// shader (techniques/billboard-cloud/media/GLSL/TreeLodBillboardCloud.frag) walks the hash/lists atlases (§5) with
// shader LoD (§5.1); far away the material's LoD switches to the low-res technique.
// Bark: the reference bark with its MeshLodGenerator levels, lit with the chunk's bark AO
// (§5.2, §6 [Hop96]).
//
// Level of detail. Geometric (§6): the clouds are switched by an LoD value read through Ogre's
// LodStrategy interface: ScreenSizeLodStrategy's ("treelod_screen_size": 4 pi r_px^2 of the
// bounding sphere scaled by the node, the LoD camera's bias in it), times the mesh LoD factor
// (setMeshLodBias; the `lodBias` parameter sets it), or the one the lodStrategy parameter names
// (ObjectLodBias.h: e.g. distance, DistanceLodBoxStrategy's squared distance to the world
// bounding box over the camera's bias, divided by that factor, compared with the screen-size
// thresholds seen through the LoD camera's projection). Thresholds follow the shader LoD so that a switch changes little
// (§6: "consistent with the corresponding shader LoD at the time of the switch"):
//   - a layered level gives way to the next layered level where its shader walks
//     SWITCH_ENTRIES list entries (listFactor * projected cell diagonal = 4), the leaves the
//     walk drops then come from the low-res texture in both;
//   - the last layered level gives way to the low-res-only level exactly where its shader
//     walks less than one entry, the value at which its material LoD (lod_values set by
//     TreeAsset) selects the low-res technique: both draw the low-res texture alone there.
// With a perspective camera the tree's projected radius is r_px = sqrt(value / (4 pi)) and a
// hash cell's diagonal sqrt(2) * cellSize * r_px / radius pixels (billboardCloudPixelCount).
// The shader's list factor is listFactor * sqrt(bias): supersampling by s with bias 1 / s^2
// (OffscreenRenderer) walks the entries of the output image's pixels.
//
// Transitions (ObjectTransition.h; setLodTransition, the `lodTransition` parameter, default 0:
// hard): within 1 + t of a switch in screen size (the square root of the pixel-count value) both
// clouds are drawn with complementary screen-door masks, the coarser one keeping the share
// getTransitionShare of the pixels. Not past a clamped or forced level.
//
// Parameters (createMovableObject params, or the registry): asset (required with the factory),
// group, classic (true | false: draw chunk "classic-billboard-cloud"), level (force level 0,
// 1, 2...), lodStrategy (treelod_screen_size, the default, or another: ObjectLodBias.h), listFactor (overrides the
// chunk's shader LoD factor; 0 = low-res texture only), lodBias (> 0, setMeshLodBias's factor),
// ambientOcclusion (true, the default | false: light like the polygonal reference, which has
// no AO; the image-error study compares that way), lodTransition (in [0, 1]).
#pragma once

#include "TreeLod/BillboardCloudResources.h"
#include "TreeLod/ObjectLodBias.h"
#include "TreeLod/ObjectTransition.h"
#include "TreeLod/TreeAsset.h"

#include <OgreMovableObject.h>
#include <OgreRenderable.h>

#include <memory>
#include <vector>

namespace TreeLod
{
    class BillboardCloudTree : public Ogre::MovableObject
    {
    public:
        struct Options
        {
            bool classic = false;
            int level = -1;          ///< >= 0: always this level
            const Ogre::LodStrategy* lodStrategy = nullptr; ///< null: treelod_screen_size (ObjectLodBias::strategy)
            float listFactor = -1.0f; ///< < 0: the chunk's
            float lodBias = 1.0f;     ///< the initial setMeshLodBias factor
            bool ambientOcclusion = true; ///< false: no AO on leaves or bark (the polygonal reference's lighting)
            float lodTransition = ForestInstances::DEFAULT_TRANSITION; ///< ObjectTransition::length
        };

        /// List entries a layered level's shader walks where the next layered level takes over.
        static constexpr float SWITCH_ENTRIES = 4.0f;

        BillboardCloudTree(const Ogre::String& name, const TreeAssetPtr& asset, const Options& options);
        ~BillboardCloudTree() override;

        const TreeAssetPtr& getAsset() const { return mAsset; }
        bool isClassic() const { return mOptions.classic; }
        const Options& getOptions() const { return mOptions; }

        /// Level drawn now (0 = finest cloud) and how many there are.
        std::uint32_t getLevel() const { return mLevel; }
        std::uint32_t getLevelCount() const { return std::uint32_t(mGpu->levels.size()); }
        /// Force `level` (clamped), or follow the LoD strategy again with -1.
        void setForcedLevel(int level);
        /// Material LoD index of the drawn level's material: 0 layers, 1 low-res only.
        unsigned short getMaterialLodIndex() const { return mMaterialLodIndex; }
        /// Bark mesh LoD level in use (0 = full).
        unsigned short getBarkLodIndex() const { return mBarkLodIndex; }

        /// As Entity::setMeshLodBias: `factor` (> 0) biases the LoD value as its strategy does
        /// (> 1 keeps finer levels longer); the cloud level (0 = finest cloud) and the bark mesh's
        /// LoD index (by the bark mesh's own strategy) are kept within [maxDetailIndex,
        /// minDetailIndex]. A forced level is not clamped.
        void setMeshLodBias(Ogre::Real factor, unsigned short maxDetailIndex = 0, unsigned short minDetailIndex = 99);
        /// As Entity::setMaterialLodBias, for the material LoD of the drawn cloud level (0 = the
        /// layered technique, 1 = the low-res texture alone).
        void setMaterialLodBias(Ogre::Real factor, unsigned short maxDetailIndex = 0,
                                unsigned short minDetailIndex = 99);
        const ObjectLodBias& getLodBias() const { return mLodBias; }

        /// Transition length t (ObjectTransition.h) in [0, 1]; throws naming the object otherwise.
        void setLodTransition(Ogre::Real length);
        Ogre::Real getLodTransition() const { return mTransition.length; }
        /// The share of the pixels level getLevel() + 1 draws now (0: getLevel() alone).
        Ogre::Real getTransitionShare() const { return mTransitionShare; }

        /// Shader LoD factor in use (the chunk's unless overridden); >= 0.
        float getListFactor() const { return mListFactor; }
        void setListFactor(float listFactor);

        /// The last LoD value, in the strategy's units (bias applied), and its pixel-count
        /// equivalent (what the thresholds and the material LoD compare).
        Ogre::Real getLodValue() const { return mLodValue; }
        Ogre::Real getPixelCountValue() const { return mPixelCountValue; }
        /// Pixel-count value (bias applied) below which level `level` + 1 is drawn instead of
        /// `level`; for level < getLevelCount() - 1.
        Ogre::Real getSwitchPixelCount(std::uint32_t level) const { return mSwitchPixelCounts[level]; }
        /// Pixel-count values (bias applied) below which level l + 1 of `gpu` replaces level l,
        /// for shader LoD factor `listFactor` and a bounding radius of `radius` metres (the LoD
        /// value's units: 4 pi r_px^2 of that radius); the rules of the file comment.
        static std::vector<Ogre::Real> switchPixelCounts(const BillboardCloudGpu& gpu, float listFactor, float radius);
        /// The level the strategy value `value` (its units, bias applied) selects; distance
        /// values are converted with the projection of the last camera seen (still alive).
        std::uint32_t levelForValue(Ogre::Real value) const;
        /// The material LoD index for a pixel-count value (material bias applied, clamped by
        /// setMaterialLodBias) at this list factor.
        unsigned short materialLodIndexForPixelCount(Ogre::Real value) const;

        // MovableObject
        const Ogre::String& getMovableType() const override;
        const Ogre::AxisAlignedBox& getBoundingBox() const override { return mGpu->bounds; }
        Ogre::Real getBoundingRadius() const override { return mGpu->radius; }
        void _notifyCurrentCamera(Ogre::Camera* camera) override;
        void _updateRenderQueue(Ogre::RenderQueue* queue) override;
        void visitRenderables(Ogre::Renderable::Visitor* visitor, bool debugRenderables = false) override;

        /// Renderables: one per cloud level (its index range), one per bark submesh.
        class Part;

    private:
        std::uint32_t levelForPixelCount(Ogre::Real value) const;
        void updateSwitchValues();
        void applyLevel();
        bool useShadowedMaterials() const;

        TreeAssetPtr mAsset;
        const BillboardCloudGpu* mGpu;
        Options mOptions;
        float mListFactor = 1.0f;
        std::vector<Ogre::Real> mSwitchPixelCounts;
        std::vector<std::unique_ptr<Part>> mLevelParts;
        std::vector<std::unique_ptr<Part>> mBarkParts;
        Ogre::MeshPtr mBarkMesh;
        std::uint32_t mLevel = 0;
        unsigned short mMaterialLodIndex = 0;
        unsigned short mBarkLodIndex = 0;
        Ogre::Real mLodValue = 0.0f;
        Ogre::Real mPixelCountValue = 0.0f;
        Ogre::Real mBias = 1.0f; ///< the camera's LoD bias times the mesh factor
        ObjectLodBias mLodBias;
        ObjectTransition mTransition;
        Ogre::Real mTransitionShare = 0.0f;
        const Ogre::Camera* mLastCamera = nullptr; ///< the last camera seen, for levelForValue
    };

    class BillboardCloudTreeFactory : public Ogre::MovableObjectFactory
    {
    public:
        static const Ogre::String FACTORY_TYPE_NAME;
        const Ogre::String& getType() const override { return FACTORY_TYPE_NAME; }
        /// Parse `params` (see BillboardCloudTree) into options; throws naming the bad parameter.
        static BillboardCloudTree::Options parseOptions(const Ogre::NameValuePairList* params);

    protected:
        Ogre::MovableObject* createInstanceImpl(const Ogre::String& name,
                                                const Ogre::NameValuePairList* params) override;
    };
}
