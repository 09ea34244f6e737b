// VolumeOctreeData: the volumetric octree tree (Linz, Reche-Martinez, Drettakis and Magnor 2006,
// paper 002), package chunk "volume-octree": a tree as an octree of cells, each cell holding one
// small billboard texture per input camera, compressed by vector quantisation (§4). The baker is
// VolumeOctreeBaker.h; the Ogre side VolumeOctreeTree.
//
// ---- Octree ----------------------------------------------------------------------------------
// The root cube [origin, origin + size]^3 (metres, model space). Level l cuts it into 2^l cells a
// side; cell (x, y, z) of level l spans origin + size / 2^l * ([x, x+1] x [y, y+1] x [z, z+1]).
// Every level is stored, intermediate ones included (§3.1): a cell of level l is stored when the
// reconstruction found matter in it; the cells of a level are sorted by Morton code.
//
// ---- Billboards (§2.1, §4) -------------------------------------------------------------------
// Each cell has one slot per input camera: the indices of a colour codeword and an alpha codeword,
// or NO_CODEWORD in both when the billboard is pruned for that camera (§3.2: empty, or hidden
// behind the accumulated alpha of the cells in front). A billboard is a square of the cell's edge
// centred on the cell, facing the viewer, with 4 x 4 texels (texel (s, t) row t from the top).
// The viewer's two input cameras nearest in direction are blended (volumeOctreeCameraPair) with
// premultiplied alpha: rgba = w0 * premultiplied(c0) + w1 * premultiplied(c1); the billboards are
// drawn back to front with the over operator.
//
// ---- Codebook atlas (§4.1, §5) ---------------------------------------------------------------
// One texture of 4 x 4 blocks, row-major (atlas width / 4 blocks a row): colour codeword i is the
// RGB (sRGB) of block i, alpha codeword j the A (linear) of block j, so one DXT5 block holds one
// colour and one alpha codeword independently. RGBA8 or DXT5, one mip level (a mip would mix
// codewords).
//
// ---- Chunk layout, formatVersion 1 (VOLUME_OCTREE_CHUNK_FORMAT_VERSION) ----------------------
// Little-endian:
//   u32 flags (0; others are an error)
//   u32 levelCount L in [1, VOLUME_OCTREE_MAX_LEVELS], u32 cameraCount C in [1, VOLUME_OCTREE_MAX_CAMERAS]
//   f32x3 origin, f32 size (> 0)
//   C x f32x3 camera direction: unit, from the root cube's centre towards the input camera
//   L x u32 cell count of the level (level l at most 8^l)
//   N = sum of the counts, x u32 cell code: x | y << 10 | z << 20, each < 2^l, strictly increasing
//       Morton order within the level
//   N x C x (u16 colour, u16 alpha) slots: codeword indices or NO_CODEWORD (both or neither)
//   u32 colour codeword count Kc, u32 alpha codeword count Ka (each >= 1 when a slot is used)
//   GpuTexture atlas (RGBA8 or DXT5, 1 mip level, width and height multiples of 4 holding
//       max(Kc, Ka) blocks); every used index below its count
//   (end of chunk: trailing bytes are an error)
#pragma once

#include "TreeLod/ModelChunk.h"
#include "TreeLod/Result.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace TreeLod
{
    constexpr const char* VOLUME_OCTREE_CHUNK = "volume-octree";
    constexpr std::uint32_t VOLUME_OCTREE_CHUNK_FORMAT_VERSION = 1;
    constexpr std::uint32_t VOLUME_OCTREE_MAX_LEVELS = 10;  ///< 512 cells a side at the finest
    constexpr std::uint32_t VOLUME_OCTREE_MAX_CAMERAS = 64;
    constexpr std::uint16_t NO_CODEWORD = 0xFFFF;
    /// Texels a side of a billboard (§4: 4 x 4, down from 8 x 8 in Reche-Martinez et al. 2004).
    constexpr std::uint32_t VOLUME_BILLBOARD_TEXELS = 4;

    struct VolumeOctreeSlot
    {
        std::uint16_t colour = NO_CODEWORD, alpha = NO_CODEWORD;
        bool pruned() const { return colour == NO_CODEWORD; }
    };

    struct VolumeOctreeData
    {
        std::uint32_t levelCount = 0;
        glm::vec3 origin{0.0f};
        float size = 0.0f;
        std::vector<glm::vec3> cameraDirections;      ///< C unit vectors
        std::vector<std::uint32_t> levelCellCounts;   ///< L
        std::vector<std::uint32_t> cells;             ///< codes, level after level
        std::vector<VolumeOctreeSlot> slots;          ///< cells.size() x C, cell-major
        std::uint32_t colourCodewords = 0, alphaCodewords = 0;
        GpuTexture atlas;

        std::uint32_t cameraCount() const { return std::uint32_t(cameraDirections.size()); }
        /// Index of level `level`'s first cell in `cells`.
        std::uint32_t firstCell(std::uint32_t level) const;
        const VolumeOctreeSlot& slot(std::size_t cell, std::uint32_t camera) const
        {
            return slots[cell * cameraDirections.size() + camera];
        }
        /// Edge of a cell of `level`, metres.
        float cellEdge(std::uint32_t level) const { return size / float(1u << level); }
        /// Centre of the cell with `code` at `level`.
        glm::vec3 cellCentre(std::uint32_t code, std::uint32_t level) const;
        /// Slots of `level` that hold a billboard (not pruned).
        std::uint64_t billboardCount(std::uint32_t level) const;
        /// Bytes on the GPU: the atlas, plus the slots as a texture of 4 bytes a slot.
        std::uint64_t gpuBytes() const { return atlas.data.size() + std::uint64_t(slots.size()) * 4; }

        /// Levels, cameras, codes (range, order), slots (both or neither NO_CODEWORD, indices below
        /// the codeword counts), atlas format, size and capacity. `label` names the source.
        Result<void> validate(const std::string& label) const;
    };

    /// x | y << 10 | z << 20.
    inline std::uint32_t volumeCellCode(std::uint32_t x, std::uint32_t y, std::uint32_t z)
    {
        return x | (y << 10) | (z << 20);
    }
    inline glm::uvec3 volumeCellCoords(std::uint32_t code)
    {
        return {code & 1023u, (code >> 10) & 1023u, (code >> 20) & 1023u};
    }
    /// The Morton key that orders a level's cells (bits of x, y, z interleaved, x lowest).
    std::uint32_t volumeMortonKey(std::uint32_t code);

    /// The two input cameras to blend for a view from `towards` (unit, model space, from the tree
    /// towards the viewer) and their weights (w0 + w1 = 1): the two cameras with the largest
    /// dot(direction, towards) (ties: lower index first), weighted by the angle to the other one,
    /// w0 = a1 / (a0 + a1) with a = the angle between the camera and `towards` (w0 = 1 when
    /// a0 + a1 = 0 or there is one camera).
    struct VolumeCameraPair
    {
        std::uint32_t first = 0, second = 0;
        float firstWeight = 1.0f;
    };
    VolumeCameraPair volumeOctreeCameraPair(const std::vector<glm::vec3>& cameraDirections, const glm::vec3& towards);

    // ---- Level of detail (§3.1): distance planes orthogonal to the view --------------------
    // The plane of level l lies at the view depth where a cell of level l covers lodPixels pixels:
    // planeDepth(l) = cellEdge(l) * focalPixels / lodPixels (focalPixels = viewport height /
    // (2 tan(fovY / 2))). The active level L is the finest level whose plane lies beyond the
    // tree's nearest point. Cells of level L whose parent's centre lies in front of L's plane
    // are drawn; the descent stops one level up for the others (cells of level L - 1 whose
    // centre lies behind the plane). Level 0 alone when L = 0.

    inline float volumeOctreePlaneDepth(float cellEdge, float focalPixels, float lodPixels)
    {
        return cellEdge * focalPixels / lodPixels;
    }
    /// L for a tree whose nearest point is `nearestDepth` metres in front of the camera.
    std::uint32_t volumeOctreeActiveLevel(const VolumeOctreeData& data, float nearestDepth, float focalPixels,
                                          float lodPixels);
    /// Whether a cell of `level` is drawn; depths are view depths of the cell's and its parent's
    /// centres, planeDepth the active level's plane.
    inline bool volumeOctreeDrawsCell(std::uint32_t level, float centreDepth, float parentCentreDepth,
                                      std::uint32_t activeLevel, float planeDepth)
    {
        if (activeLevel == 0)
            return level == 0;
        if (level == activeLevel)
            return parentCentreDepth < planeDepth;
        return level + 1 == activeLevel && centreDepth >= planeDepth;
    }

    /// Level `level`'s cells (indices from its first cell) back to front for a view direction
    /// (from the camera towards the tree) whose sign along axis a is negative where bit a of
    /// `octant` is set: slices along z, rows along y, cells along x, each axis run from its far side,
    /// a visibility order of a grid's cells for any view direction in the octant.
    std::vector<std::uint32_t> volumeOctreeOctantOrder(const VolumeOctreeData& data, std::uint32_t level,
                                                       std::uint32_t octant);
    /// The octant of a view direction (from the camera towards the tree) for volumeOctreeOctantOrder.
    inline std::uint32_t volumeOctreeOctant(const glm::vec3& view)
    {
        return (view.x < 0.0f ? 1u : 0u) | (view.y < 0.0f ? 2u : 0u) | (view.z < 0.0f ? 4u : 0u);
    }

    /// Serialise in the layout above. Deterministic; does not validate (decode does).
    std::vector<std::uint8_t> encodeVolumeOctreeChunk(const VolumeOctreeData& data);
    /// Parse and validate(); errors name `label`, "chunk 'volume-octree' level 0" and the element.
    Result<VolumeOctreeData> decodeVolumeOctreeChunk(const std::vector<std::uint8_t>& bytes, const std::string& label);
}
