// VolumeOctreeResources: the volumetric octree tree (chunk "volume-octree", VolumeOctreeData.h) of
// one TreeAsset on the GPU, shared by every VolumeOctreeTree drawing it.
#pragma once

#include "TreeLod/TechniqueResources.h"
#include "TreeLod/VolumeOctreeData.h"

#include <OgreAxisAlignedBox.h>
#include <OgreVertexIndexData.h>

#include <array>
#include <memory>
#include <vector>

namespace TreeLod
{
    class TreeAsset;

    /// The material every volume octree clone comes from (materials/TreeLodVolumeOctree.material).
    constexpr const char* VOLUME_OCTREE_MATERIAL = "TreeLod/VolumeOctree";
    /// Its shadow caster (a hashed alpha test of the same billboards).
    constexpr const char* VOLUME_OCTREE_CASTER_MATERIAL = "TreeLod/VolumeOctreeCaster";

    /// The octree on the GPU (materials/GLSL/TreeLodVolumeOctree.vert):
    ///   - vertices, 4 a cell: position = the cell's centre; uv0 = (corner x, corner y in {-1, 1},
    ///     level, cell index); uv1 = (the parent's centre, half the cell's edge), model metres;
    ///   - texture Codebook: the chunk's atlas; texture Slots: RGBA8, slot i = cell * cameras + camera
    ///     at (i % slotsWidth, i / slotsWidth), bytes (colour low, colour high, alpha low, alpha high);
    ///   - per level and view octant the level's cells in back-to-front order (cellOrders).
    struct VolumeOctreeGpu
    {
        std::unique_ptr<Ogre::VertexData> vertexData;
        Ogre::String material;       ///< clone of TreeLod/VolumeOctree with the textures and constants
        Ogre::String casterMaterial; ///< clone of TreeLod/VolumeOctreeCaster, the clone's shadow caster
        Ogre::String codebookTexture, slotsTexture;
        std::uint32_t slotsWidth = 0;
        /// [level][octant]: volumeOctreeOctantOrder of every level and octant.
        std::vector<std::array<std::vector<std::uint32_t>, 8>> cellOrders;
        Ogre::AxisAlignedBox bounds; ///< local: the root cube grown by half a finest cell (billboards turn)
        std::uint64_t gpuBytes = 0;
    };

    class VolumeOctreeResources : public TechniqueResources
    {
    public:
        /// The asset's (made on first call).
        static VolumeOctreeResources& of(TreeAsset& asset);

        explicit VolumeOctreeResources(TreeAsset& asset) : mAsset(asset) {}
        ~VolumeOctreeResources() override;

        /// The decoded chunk (on first call); throws naming the asset when the package lacks the
        /// chunk or has a broken one.
        const VolumeOctreeData& getData();
        /// Built on first call (nothing left behind when it throws).
        const VolumeOctreeGpu& getGpu();

        std::uint64_t getGpuBytes() const override { return mGpu ? mGpu->gpuBytes : 0; }

    private:
        TreeAsset& mAsset;
        std::unique_ptr<VolumeOctreeData> mData;
        std::unique_ptr<VolumeOctreeGpu> mGpu;
    };
}
