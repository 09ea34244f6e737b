// QuadFloors: the speed floors `treelod bench` measures the Forest against (ForestBaselines the
// impostor registers as "entities", "merged-quads" and "billboard-set"), each drawing a tree
// as one camera-facing quad of its baked impostor (ImpostorResources::getGpu). The first two use
// the impostor's own materials (techniques/impostor/media/GLSL/TreeLodImpostor.vert), so they and the Forest's
// quad level give the same picture:
// - EntityFloor: one Ogre Entity on its own SceneNode per tree, one draw each: what Ogre users
//   pay today (measured with a minimal Ogre program: 10,000 one-quad entities cost 16 ms on an
//   H100, all of it Ogre's per-object CPU cost).
// - MergedQuadFloor: every tree's quad merged into static batches of at most BATCH_TREES trees
//   (one Entity of a built Mesh per batch, culled by its own bounds): the cheapest drawing.
// The impostor's vertex program reads uv4 (position + uniform scale) and uv5 (cos, sin) that the
// Forest feeds per instance; here they are ordinary per-vertex attributes: (0, 0, 0, 1) for an
// entity (its node places it), the tree's own for a merged quad. Materials: the impostor's, its
// shadow-receiving variant when the scene manager has integrated texture shadows at construction
// (as the Forest picks), casting with the impostor's light-facing caster.
// - BillboardSetFloor: one plain Ogre BillboardSet per species, the impostor's colour texture
//   unlit and alpha tested (TreeLod/BillboardSetFloor): what an Ogre user writes by hand in twenty
//   lines, the honest floor. It neither casts nor receives shadows and is not lit, so its picture
//   differs from the others in shading only (same pixels covered).
#pragma once

#include "TreeLod/ForestBaseline.h"

#include <OgreBillboardSet.h>
#include <OgreSceneManager.h>

#include <cstdint>
#include <vector>

namespace TreeLod
{
    /// One Entity per tree. kind = index into `assets`. Throws Ogre::Exception naming the asset
    /// when one lacks the impostor chunk, or the instance when its kind has no asset.
    class EntityFloor : public ForestBaseline
    {
    public:
        EntityFloor(Ogre::SceneManager& sceneManager, Ogre::SceneNode& parent, const std::vector<TreeAssetPtr>& assets,
                    const std::vector<ForestInstance>& instances);
        ~EntityFloor() override;
        EntityFloor(const EntityFloor&) = delete;
        EntityFloor& operator=(const EntityFloor&) = delete;

        std::size_t getEntityCount() const { return mEntities.size(); }
        /// Impostor textures of the species drawn + the quad meshes.
        std::uint64_t getGpuBytes() const override { return mGpuBytes; }

    private:
        Ogre::SceneManager& mSceneManager;
        std::vector<Ogre::MeshPtr> mMeshes;
        std::vector<Ogre::Entity*> mEntities;
        std::vector<Ogre::SceneNode*> mNodes;
        std::uint64_t mGpuBytes = 0;
    };

    /// Every tree's quad in static batches of at most BATCH_TREES trees per species.
    class MergedQuadFloor : public ForestBaseline
    {
    public:
        static constexpr std::size_t BATCH_TREES = 4096; ///< 16384 vertices: 16-bit indices

        MergedQuadFloor(Ogre::SceneManager& sceneManager, Ogre::SceneNode& parent,
                        const std::vector<TreeAssetPtr>& assets, const std::vector<ForestInstance>& instances);
        ~MergedQuadFloor() override;
        MergedQuadFloor(const MergedQuadFloor&) = delete;
        MergedQuadFloor& operator=(const MergedQuadFloor&) = delete;

        std::size_t getBatchCount() const { return mEntities.size(); }
        /// Impostor textures of the species drawn + the batches' buffers.
        std::uint64_t getGpuBytes() const override { return mGpuBytes; }

    private:
        Ogre::SceneManager& mSceneManager;
        Ogre::SceneNode* mNode = nullptr;
        std::vector<Ogre::MeshPtr> mMeshes;
        std::vector<Ogre::Entity*> mEntities;
        std::uint64_t mGpuBytes = 0;
    };

    /// One Ogre BillboardSet per species (per MAX_SET_TREES trees): quads turned about +Y towards the camera
    /// (BBT_ORIENTED_COMMON), sized and placed as the impostor's quad, the material a clone of
    /// TreeLod/BillboardSetFloor with the impostor's colour texture and alpha cutoff.
    class BillboardSetFloor : public ForestBaseline
    {
    public:
        /// Billboards per set: Ogre 1.12's BillboardSet indexes its vertices with 16 bits. A
        /// species with more trees gets several sets, each a compact patch (culled by its bounds).
        static constexpr std::size_t MAX_SET_TREES = 16384;

        BillboardSetFloor(Ogre::SceneManager& sceneManager, Ogre::SceneNode& parent,
                          const std::vector<TreeAssetPtr>& assets, const std::vector<ForestInstance>& instances);
        ~BillboardSetFloor() override;
        BillboardSetFloor(const BillboardSetFloor&) = delete;
        BillboardSetFloor& operator=(const BillboardSetFloor&) = delete;

        std::size_t getSetCount() const { return mSets.size(); }
        const Ogre::BillboardSet& getSet(std::size_t i) const { return *mSets[i]; }
        /// The floor's colour textures (one per species) + the sets' vertex buffers (4 vertices per billboard).
        std::uint64_t getGpuBytes() const override { return mGpuBytes; }

    private:
        void release();

        Ogre::SceneManager& mSceneManager;
        Ogre::SceneNode* mNode = nullptr;
        std::vector<Ogre::BillboardSet*> mSets;
        std::vector<Ogre::MaterialPtr> mMaterials;
        std::vector<Ogre::TexturePtr> mTextures; ///< per species: the impostor's colour, plain RGBA (not sRGB)
        std::uint64_t mGpuBytes = 0;
    };
}
