// FoliageLodTree: a tree drawn with LoDF, continuous foliage level of detail by leaf collapse
// (Rebollo et al. 2006). MovableObject type "FoliageLodTree".
//
// Every leaf vertex lives on the GPU once per asset (FoliageLodResources::getLeafVertexData); each
// instance owns one index buffer holding every cluster's region (FoliageLodData). When the
// leaf count changes, FoliageLodState walks Changed_group (§3.3) and only the regions of the
// clusters that changed are rewritten, with partial buffer writes (§4); one draw per leaf
// material covers all regions (unused slots hold degenerate triangles).
//
// Leaf count: from ScreenSizeLodStrategy ("treelod_screen_size", the LoD camera's bias in it),
// a continuous curve
//     leaves = clamp(pixels * mesh LoD factor / pixelsPerLeaf, minLeaves, maxLeaves)
// where pixels is the projected area of the bounding sphere, pi r_px^2 (the value's quarter,
// Ogre's pixel_count units); leaves grow as they collapse (FoliageLodBaker.h), keeping the
// crown's covered area. The LoD camera drives it, so shadow cameras see the level the viewer
// sees. Bark: the asset's bark mesh with its MeshLodGenerator levels, chosen by the mesh's own
// strategy and values, as an Entity chooses them. setMeshLodBias: the factor multiplies the
// curve's pixels; the detail indices limit the bark mesh's LoD index (the leaf count has no
// index: `leaves` fixes it). No material LoD of its own: setMaterialLodBias biases the LoD
// index of each material (Material::getLodIndex by its strategy). Materials are the
// reference's (leaf material shared), switched to their shadow-receiving clones when the
// scene uses an integrated texture shadow technique.
//
// Parameters (createMovableObject params, or the registry): asset (required with the
// factory), group, leaves (a fixed leaf count instead of the curve), pixelsPerLeaf (default 4),
// quantise (N: snap to N geometric levels, see FoliageLodState::quantise; 0 = continuous),
// lodStrategy (treelod_screen_size, the default, or another: ObjectLodBias.h).
// A quantised instance owns no index buffer: it draws the asset's shared level
// (FoliageLodResources::getFoliageLodLevel), so changing level uploads nothing and instances at one
// level draw identical geometry (what a Forest instances).
#pragma once

#include "TreeLod/FoliageLodState.h"
#include "TreeLod/ObjectLodBias.h"
#include "TreeLod/TreeAsset.h"

#include <OgreMovableObject.h>
#include <OgreRenderable.h>

#include <memory>
#include <vector>

namespace TreeLod
{
    /// What the last LoD change cost (and totals since creation).
    struct FoliageLodUpdateStats
    {
        std::uint32_t leafCount = 0;       ///< leaves drawn now
        std::uint32_t clustersWritten = 0; ///< by the last change
        std::uint64_t bytesUploaded = 0;   ///< by the last change
        std::uint32_t writeCalls = 0;      ///< buffer writes of the last change (adjacent regions merged)
        std::uint64_t totalBytesUploaded = 0;
        std::uint32_t changes = 0;         ///< LoD changes since creation
    };

    class FoliageLodTree : public Ogre::MovableObject
    {
    public:
        /// Projected pixels per leaf of the default curve.
        static constexpr float DEFAULT_PIXELS_PER_LEAF = 4.0f;

        struct Options
        {
            std::uint32_t fixedLeafCount = 0; ///< 0 = from the LoD strategy
            float pixelsPerLeaf = DEFAULT_PIXELS_PER_LEAF; ///< projected pixels per leaf at full curve
            std::uint32_t quantiseLevels = 0; ///< 0 = continuous
            const Ogre::LodStrategy* lodStrategy = nullptr; ///< null: treelod_screen_size (ObjectLodBias::strategy)
        };

        FoliageLodTree(const Ogre::String& name, const TreeAssetPtr& asset, const Options& options);
        ~FoliageLodTree() override;

        const TreeAssetPtr& getAsset() const { return mAsset; }

        /// Draw exactly `count` leaves (clamped), or 0 to follow the LoD strategy again.
        void setFixedLeafCount(std::uint32_t count);
        void setPixelsPerLeaf(float pixelsPerLeaf);
        /// Quantised instances draw shared levels (set at creation by the `quantise` parameter).
        bool isQuantised() const { return mOptions.quantiseLevels > 1; }
        /// Leaves the curve gives for `pixels` (projected bounding-sphere area) and `bias`.
        std::uint32_t leafCountForPixels(Ogre::Real pixels, Ogre::Real bias = 1.0f) const;
        /// The curve (the file comment) for `data`: leaves at LoD value `pixels` (bias applied).
        static std::uint32_t leafCountOnCurve(const FoliageLodData& data, Ogre::Real pixels, float pixelsPerLeaf);
        /// The largest LoD value (bias applied) at which the curve asks for at most `leaves`
        /// leaves (before clamping): levels that draw a fixed count switch there (the Forest).
        static Ogre::Real pixelCountForLeaves(std::uint32_t leaves, float pixelsPerLeaf);

        /// Move to `count` leaves now (what a camera change does); returns the clusters rewritten.
        std::uint32_t updateLeafCount(std::uint32_t count);
        std::uint32_t getLeafCount() const { return mState.leafCount(); }
        std::uint32_t getMinLeafCount() const { return mData->minLeafCount(); }
        std::uint32_t getMaxLeafCount() const { return mData->maxLeafCount(); }
        const FoliageLodUpdateStats& getUpdateStats() const { return mStats; }
        const FoliageLodState& getState() const { return mState; }
        /// Bark mesh LoD level in use (0 = full).
        unsigned short getBarkLodIndex() const { return mBarkLodIndex; }

        /// As Entity::setMeshLodBias (the file comment says what it biases and clamps).
        void setMeshLodBias(Ogre::Real factor, unsigned short maxDetailIndex = 0, unsigned short minDetailIndex = 99);
        /// As Entity::setMaterialLodBias, for the material LoD of the leaf and bark materials.
        void setMaterialLodBias(Ogre::Real factor, unsigned short maxDetailIndex = 0,
                                unsigned short minDetailIndex = 99);
        const ObjectLodBias& getLodBias() const { return mLodBias; }

        // MovableObject
        const Ogre::String& getMovableType() const override;
        const Ogre::AxisAlignedBox& getBoundingBox() const override { return mBounds; }
        Ogre::Real getBoundingRadius() const override { return mRadius; }
        void _notifyCurrentCamera(Ogre::Camera* camera) override;
        void _updateRenderQueue(Ogre::RenderQueue* queue) override;
        void visitRenderables(Ogre::Renderable::Visitor* visitor, bool debugRenderables = false) override;

        /// Renderables: one per leaf material over its clusters' regions, one per bark submesh.
        class Part;

    private:
        void writeAllClusters();
        /// Cluster `cluster`'s region as the index buffer's index type, at `at`.
        void writeRegion(std::uint32_t cluster, std::uint8_t* at) const;
        void useSharedLevel();
        bool useShadowedMaterials();

        TreeAssetPtr mAsset;
        const FoliageLodData* mData;
        FoliageLodState mState;
        Options mOptions;
        Ogre::HardwareIndexBufferSharedPtr mIndexBuffer;
        std::vector<std::uint8_t> mScratch; ///< the regions of one write
        std::vector<std::uint32_t> mChanged; ///< changed clusters, sorted
        std::vector<std::unique_ptr<Part>> mLeafParts;
        std::vector<std::unique_ptr<Part>> mBarkParts;
        Ogre::MeshPtr mBarkMesh;
        unsigned short mBarkLodIndex = 0;
        Ogre::AxisAlignedBox mBounds;
        Ogre::Real mRadius = 0.0f;
        FoliageLodUpdateStats mStats;
        ObjectLodBias mLodBias;
    };

    class FoliageLodTreeFactory : public Ogre::MovableObjectFactory
    {
    public:
        static const Ogre::String FACTORY_TYPE_NAME;
        const Ogre::String& getType() const override { return FACTORY_TYPE_NAME; }
        /// Parse `params` (see FoliageLodTree) into options; throws naming the bad parameter.
        static FoliageLodTree::Options parseOptions(const Ogre::NameValuePairList* params);

    protected:
        Ogre::MovableObject* createInstanceImpl(const Ogre::String& name, const Ogre::NameValuePairList* params) override;
    };
}
