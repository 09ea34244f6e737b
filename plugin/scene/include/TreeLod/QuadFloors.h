// QuadFloors: the two speed floors `treelod bench` measures the Forest against, both
// drawing each tree as the one camera-facing quad of its baked impostor (ImpostorResources::getGpu,
// materials/GLSL/TreeLodImpostor.vert), so all three give the same picture:
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
#pragma once

#include "TreeLod/ForestInstances.h"
#include "TreeLod/TreeAsset.h"

#include <OgreSceneManager.h>

#include <cstdint>
#include <vector>

namespace TreeLod
{
    /// One Entity per tree. kind = index into `assets`. Throws Ogre::Exception naming the asset
    /// when one lacks the impostor chunk, or the instance when its kind has no asset.
    class EntityFloor
    {
    public:
        EntityFloor(Ogre::SceneManager& sceneManager, Ogre::SceneNode& parent, const std::vector<TreeAssetPtr>& assets,
                    const std::vector<ForestInstance>& instances);
        ~EntityFloor();
        EntityFloor(const EntityFloor&) = delete;
        EntityFloor& operator=(const EntityFloor&) = delete;

        std::size_t getEntityCount() const { return mEntities.size(); }
        /// Impostor textures of the species drawn + the quad meshes.
        std::uint64_t getGpuBytes() const { return mGpuBytes; }

    private:
        Ogre::SceneManager& mSceneManager;
        std::vector<Ogre::MeshPtr> mMeshes;
        std::vector<Ogre::Entity*> mEntities;
        std::vector<Ogre::SceneNode*> mNodes;
        std::uint64_t mGpuBytes = 0;
    };

    /// Every tree's quad in static batches of at most BATCH_TREES trees per species.
    class MergedQuadFloor
    {
    public:
        static constexpr std::size_t BATCH_TREES = 4096; ///< 16384 vertices: 16-bit indices

        MergedQuadFloor(Ogre::SceneManager& sceneManager, Ogre::SceneNode& parent,
                        const std::vector<TreeAssetPtr>& assets, const std::vector<ForestInstance>& instances);
        ~MergedQuadFloor();
        MergedQuadFloor(const MergedQuadFloor&) = delete;
        MergedQuadFloor& operator=(const MergedQuadFloor&) = delete;

        std::size_t getBatchCount() const { return mEntities.size(); }
        /// Impostor textures of the species drawn + the batches' buffers.
        std::uint64_t getGpuBytes() const { return mGpuBytes; }

    private:
        Ogre::SceneManager& mSceneManager;
        Ogre::SceneNode* mNode = nullptr;
        std::vector<Ogre::MeshPtr> mMeshes;
        std::vector<Ogre::Entity*> mEntities;
        std::uint64_t mGpuBytes = 0;
    };
}
