// VolumeOctreeResources: the volumetric octree tree (chunk "volume-octree", VolumeOctreeData.h) of
// one TreeAsset on the GPU, shared by every VolumeOctreeTree drawing it.
#pragma once

#include "TreeLod/TechniqueResources.h"
#include "TreeLod/VolumeOctreeData.h"

#include <OgreAxisAlignedBox.h>
#include <OgreHardwareIndexBuffer.h>
#include <OgreVertexIndexData.h>

#include <array>
#include <memory>
#include <vector>

namespace TreeLod
{
    class TreeAsset;

    /// The material every volume octree clone comes from (techniques/volume-octree/media/TreeLodVolumeOctree.material).
    constexpr const char* VOLUME_OCTREE_MATERIAL = "TreeLod/VolumeOctree";
    /// Its shadow caster (a hashed alpha test of the same billboards).
    constexpr const char* VOLUME_OCTREE_CASTER_MATERIAL = "TreeLod/VolumeOctreeCaster";

    /// What every draw of the octree samples: texture `codebook`, the chunk's atlas; texture
    /// `slots`, RGBA8, slot i = cell * cameras + camera at (i % slotsWidth, i / slotsWidth), bytes
    /// (colour low, colour high, alpha low, alpha high).
    struct VolumeOctreeTextures
    {
        Ogre::String codebook, slots;
        std::uint32_t slotsWidth = 0;
        std::uint64_t bytes = 0;
    };

    /// Per level and view octant the level's cells in back-to-front order (volumeOctreeOctantOrder).
    using VolumeOctreeCellOrders = std::vector<std::array<std::vector<std::uint32_t>, 8>>;

    /// The octree for VolumeOctreeTree (techniques/volume-octree/media/GLSL/TreeLodVolumeOctree.vert): vertices, 4 a
    /// cell: position = the cell's centre; uv0 = (corner x, corner y in {-1, 1}, level, cell index);
    /// uv1 = (the parent's centre, half the cell's edge), model metres.
    struct VolumeOctreeGpu
    {
        std::unique_ptr<Ogre::VertexData> vertexData;
        Ogre::String material;       ///< clone of TreeLod/VolumeOctree with the textures and constants
        Ogre::String casterMaterial; ///< clone of TreeLod/VolumeOctreeCaster, the clone's shadow caster
        Ogre::AxisAlignedBox bounds; ///< local: the root cube grown by half a finest cell (billboards turn)
        std::uint64_t gpuBytes = 0;  ///< the vertex buffer
    };

    /// The material of the octree as a Forest level (TreeLodVolumeOctree.vert, INSTANCED).
    constexpr const char* VOLUME_OCTREE_FOREST_MATERIAL = "TreeLod/VolumeOctreeForest";
    /// Its shadow caster.
    constexpr const char* VOLUME_OCTREE_FOREST_CASTER_MATERIAL = "TreeLod/VolumeOctreeForestCaster";

    /// The octree as a Forest level: one instanced draw per active level L whose vertex program
    /// fetches each quad's cell, so every tree has its own view octant's order and camera pair
    /// (techniques/volume-octree/media/GLSL/TreeLodVolumeOctree.vert, INSTANCED):
    ///   - vertices, 4 a quad: position = 4 quad + corner (0 to 3 counter-clockwise from (-1, -1)),
    ///     as many quads as the largest level pair; indices 6 a quad, each level draws its first
    ///     6 n(L);
    ///   - texture Cells: cell c at (c % width, c / width), RGBA8 holding the 32 bits (little-endian)
    ///     x | y << 9 | z << 18 | level << 27 of its coordinates (volumeCellCoords) and level;
    ///   - texture Orders: RGBA8 holding 32-bit cell indices: the cells of level L - 1 then of L (L
    ///     alone for L = 0) back to front for each of the 8 view octants, entry
    ///     orderStart[L] + octant * n(L) + quad;
    ///   - the materials' cameraDirections: the input cameras (VolumeOctreeData::cameraDirections).
    struct VolumeOctreeForestGpu
    {
        std::unique_ptr<Ogre::VertexData> vertexData;
        Ogre::HardwareIndexBufferSharedPtr indexBuffer;
        Ogre::String material;       ///< clone of TreeLod/VolumeOctreeForest
        Ogre::String casterMaterial; ///< clone of TreeLod/VolumeOctreeForestCaster, the clone's caster
        Ogre::String cellsTexture, ordersTexture;
        std::vector<std::uint32_t> orderStart; ///< per active level
        std::vector<std::uint32_t> quadCount;  ///< per active level: n(L)
        std::uint64_t gpuBytes = 0;            ///< beyond VolumeOctreeTextures
    };

    /// What an octree draws outside its root cube: billboards turn, so up to half a finest cell's
    /// diagonal beyond it (local metres).
    Ogre::AxisAlignedBox volumeOctreeDrawnBounds(const VolumeOctreeData& data);

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
        /// Each built on first call (nothing left behind when it throws): the textures, the cells'
        /// orders (CPU), what VolumeOctreeTrees draw, and the Forest levels' resources. A forest of
        /// octrees builds no VolumeOctreeGpu, and a VolumeOctreeTree no VolumeOctreeForestGpu.
        const VolumeOctreeTextures& getTextures();
        const VolumeOctreeCellOrders& getCellOrders();
        const VolumeOctreeGpu& getGpu();
        const VolumeOctreeForestGpu& getForestGpu();

        std::uint64_t getGpuBytes() const override
        {
            return (mTextures ? mTextures->bytes : 0) + (mGpu ? mGpu->gpuBytes : 0) +
                   (mForestGpu ? mForestGpu->gpuBytes : 0);
        }

    private:
        TreeAsset& mAsset;
        std::unique_ptr<VolumeOctreeData> mData;
        std::unique_ptr<VolumeOctreeTextures> mTextures;
        VolumeOctreeCellOrders mCellOrders;
        std::unique_ptr<VolumeOctreeGpu> mGpu;
        std::unique_ptr<VolumeOctreeForestGpu> mForestGpu;
    };
}
