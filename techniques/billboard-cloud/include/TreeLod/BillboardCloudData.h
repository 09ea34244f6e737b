// BillboardCloudData: billboard clouds with multi-layered indirect texturing (García et al. 2007)
// and the classic billboard cloud it is compared with; package chunks "billboard-cloud" and
// "classic-billboard-cloud". The baker is BillboardCloudBaker.h, the Ogre object
// BillboardCloudTree, the shader techniques/billboard-cloud/media/GLSL/TreeLodBillboardCloud.frag, and
// BillboardCloudSampler below evaluates that shader's addressing on the CPU (tests use it as the
// exact reference of what the GPU must fetch).
//
// ---- Geometry -------------------------------------------------------------------------
// A billboard is a planar quad: corner(u, v) = origin + u * axisU + v * axisV, u, v in [0, 1];
// normal = normalize(cross(axisU, axisV)); axisU and axisV are orthogonal. Its "billboard
// coordinates" are (u * hashWidth, v * hashHeight): hash cells are unit squares there.
// Levels (García et al. 2007 §6): level 0 the finest cloud, then coarser ones; a level is `layered`
// when its billboards have hash grids (shader walks lists), else it draws the low-res texture only
// (the coarsest cloud, and every level of a classic cloud).
//
// ---- Hash atlas (§4.2, §6) ---------------------------------------------------------------
// RGBA8, hashAtlasWidth x hashAtlasHeight, rows top to bottom; billboard b's grid occupies
// texels [hashX, hashX + hashWidth) x [hashY, hashY + hashHeight); cell (i, j) of the grid
// (i along u, j along v) is texel (hashX + i, hashY + j). A texel holds
//     start  = R | G << 8 | B << 16   (first entry of its list in the Lists atlas)
//     length = A                      (0: empty cell, transparent; at most 255)
// so the list can be walked from either end (§5). Lookups are integer texel fetches, exact.
//
// ---- Lists atlas (§4.2, Fig. 8) ----------------------------------------------------------
// RGBA16 (u16 x 4 per entry), listsAtlasWidth x listsAtlasHeight; entry e is texel
// (e % listsAtlasWidth, e / listsAtlasWidth). A cell's list holds the leaf fragments that
// overlap the cell, sorted front to back as seen from the +normal side (decreasing signed
// distance of the leaf centre along the normal: what the paper's depth peeling of point
// sprites gives). Entry words:
//     R  centre x: cx = R / 65535 * 64 - 32   leaf tile centre in billboard coordinates,
//     G  centre y: cy = G / 65535 * 64 - 32   relative to the cell's corner (i, j)
//     B  bits 0-14 orientation index k (into the Leaves Texture, below); bit 15 mirror m
//     A  bits 8-15 rotation a: psi = a * 2 pi / 256; bits 0-7 scale code s:
//        side = 2 ^ ((s - 128) / 32) hash cells (the tile square's edge)
// For a point p in billboard coordinates (cell corner subtracted: q = p - (i, j) - (cx, cy)),
// the tile-local position is
//     local = R(-psi) q / side + 0.5,  then local.x = 1 - local.x when m = 1,
// in [0, 1]^2 inside the tile (outside: the entry is transparent there).
//
// ---- AO atlas (§5.2, Fig. 11) -------------------------------------------------------------
// RGBA8 indexed exactly like the Lists atlas: the ambient occlusion of the entry's leaf at
// the tile's corners local (0,0), (1,0), (0,1), (1,1) in R, G, B, A, a least-squares fit of
// the bilinear function to the AO of the leaf's vertices; ao = bilinear(local).
//
// ---- Leaves Texture (§3, §5, §5.2) --------------------------------------------------------
// Tiles of tileSize^2 texels in a grid of tileColumns columns, tile t at column t % columns,
// row t / columns; within a tile, texel (x, y) covers local ((x + 0.5) / tileSize,
// (y + 0.5) / tileSize) (y grows with billboard v, rows top to bottom in the image).
// Tiles are laid out [leaf image][view side][orientation]:
//     t = image * 2 * orientationCount + side * orientationCount + k
// A leaf image is one leaf material's texture on one UV rectangle: a material whose leaves all
// map the same rectangle has one image, an atlas material one per rectangle its leaves use.
// orientation k is the direction d_k of the billboard normal in the leaf's frame (w = texture
// u axis, t = towards the leaf tip (texture v = 0), n = leaf normal), k over a
// orientationGrid x orientationGrid hemi-octahedral grid of the hemisphere d.n >= 0 (the
// stored k already includes the image offset: k = image * 2 * orientationCount + k').
// A tile is the leaf (its image's texture rectangle) projected orthographically
// along d_k, in a square frame whose +y is the projected tip direction, scaled so the leaf
// fits the inner (1 - 2 * TILE_MARGIN) of the tile. side 0 is the leaf as seen from the +d_k
// side (its front), side 1 from the -d_k side (its back, backColour tint), same frame.
// A leaf whose d has d.n < 0 uses d' = -d and mirror m = 1 (the frame is then mirrored).
// The view side the shader reads is
//     side = (camera on the billboard's +normal side ? 0 : 1) XOR m.
// leavesColour: sRGB albedo (material base or back colour x texture) and alpha: the fraction
// of the texel where the material's texture alpha passes its alphaCutoff, so one cutoff,
// LEAVES_COVERAGE_CUTOFF, draws every image as its material's alpha test would;
// leavesNormal: the normal facing that side's viewer in the tile frame (x right, y up,
// z towards the +d_k viewer), encoded n * 0.5 + 0.5 in RGB. Both mip-mapped; level
// leavesMaxLod is the coarsest a tile does not bleed into its neighbours at.
// To the billboard frame: nt.x *= s, nt.z *= s with s = (m ? -1 : 1), then
//     n = (R(psi) nt.xy).x * U + (R(psi) nt.xy).y * V + nt.z * N     (U, V, N unit)
// (R(psi) rotates counter-clockwise in the (U, V) plane; the tile's +y lands on R(psi) (0, 1)).
//
// ---- Low-resolution texture (§5.1, §5.2) --------------------------------------------------
// One atlas for all billboards of all levels; billboard b's image covers texels
// [lowResX, lowResX + lowResWidth) x [lowResY, lowResY + lowResHeight), u to the right,
// v down the rows. RGB = sRGB albedo of the frontmost leaf fragment as seen from the +normal
// side (side 1 of a tile from the other side is not stored: the low-res texture is far
// field), A = 0 where no leaf covers the texel, else 0.5 + 0.5 * ao (the AO term in alpha,
// §5.2); the shader tests A >= LOW_RES_ALPHA_CUTOFF and decodes ao = clamp(2A - 1, 0, 1).
// Its mip chain keeps coverage per level (as buildMipChain) and averages ao over covered texels.
// The classic cloud's textures use the same encoding.
//
// ---- Chunk layout, formatVersion 2 (BILLBOARD_CLOUD_CHUNK_FORMAT_VERSION) ----------------
// Little-endian, "align16" and GpuTexture as in ModelChunk.h:
//   u32 flags (bit 0 classic), f32 listFactor, f32x3 boundsMin, f32x3 boundsMax
//   u32 levelCount, per level: u32 firstBillboard, billboardCount, layered (0/1),
//       f32 cellSize (metres per hash cell, 0 when not layered), f32 lowResTexelSize (metres)
//   u32 billboardCount, align16, billboards of 80 bytes:
//       f32x3 origin, axisU, axisV, normal; u32 hashX, hashY, hashWidth, hashHeight,
//       lowResX, lowResY, lowResWidth, lowResHeight
//   u32 hashAtlasWidth, hashAtlasHeight, align16, width * height * 4 bytes
//   u32 listsAtlasWidth, listsAtlasHeight, u32 entryCount, align16, entryCount * 8 bytes (u16 x 4),
//       then align16, entryCount * 4 bytes (AO atlas); texels past entryCount are zero on upload
//   u32 tileSize, tileColumns, orientationGrid, leafImageCount, leavesMaxLod,
//       per leaf image: u32 model material index, f32 alphaCutoff, f32x2 uvMin, f32x2 uvMax
//   GpuTexture leavesColour, GpuTexture leavesNormal, GpuTexture lowRes  (as ModelChunk.h;
//       a classic chunk and a cloud without leaves store 1x1 placeholders for the ones unused)
//   u32 barkVertexCount, align16, u8 AO per reference bark vertex (0..255 = 0..1): the trunk
//       is drawn from the reference chunk's bark, lit with this AO (§5.2)
//   (end of chunk: trailing bytes are an error)
#pragma once

#include "TreeLod/ModelChunk.h"
#include "TreeLod/Result.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace TreeLod
{
    constexpr const char* BILLBOARD_CLOUD_CHUNK = "billboard-cloud";
    constexpr const char* CLASSIC_BILLBOARD_CLOUD_CHUNK = "classic-billboard-cloud";
    constexpr std::uint32_t BILLBOARD_CLOUD_CHUNK_FORMAT_VERSION = 2;

    constexpr std::uint32_t BILLBOARD_MAX_LIST_LENGTH = 255;        ///< hash A channel
    constexpr std::uint32_t BILLBOARD_MAX_ENTRIES = 1u << 24;       ///< hash RGB start
    constexpr float BILLBOARD_CENTRE_RANGE = 32.0f;                 ///< |cx|, |cy| < 32 cells
    constexpr float TILE_MARGIN = 0.0625f;                          ///< empty border of a tile
    constexpr float LOW_RES_ALPHA_CUTOFF = 0.25f;
    constexpr float LEAVES_COVERAGE_CUTOFF = 0.5f; ///< Leaves Texture alpha drawn, every leaf image

    struct BillboardCloudLevel
    {
        std::uint32_t firstBillboard = 0;
        std::uint32_t billboardCount = 0;
        bool layered = false;
        float cellSize = 0.0f;        ///< metres per hash cell (layered levels)
        float lowResTexelSize = 0.0f; ///< metres per low-res texel
    };

    struct Billboard
    {
        glm::vec3 origin{0.0f};
        glm::vec3 axisU{1.0f, 0.0f, 0.0f};
        glm::vec3 axisV{0.0f, 1.0f, 0.0f};
        glm::vec3 normal{0.0f, 0.0f, 1.0f};
        std::uint32_t hashX = 0, hashY = 0, hashWidth = 0, hashHeight = 0;
        std::uint32_t lowResX = 0, lowResY = 0, lowResWidth = 0, lowResHeight = 0;
    };

    /// One list entry, decoded (the u16 words are its exact storage).
    struct BillboardListEntry
    {
        std::uint16_t words[4] = {0, 0, 0, 0};

        float centreX() const { return float(words[0]) / 65535.0f * 2.0f * BILLBOARD_CENTRE_RANGE - BILLBOARD_CENTRE_RANGE; }
        float centreY() const { return float(words[1]) / 65535.0f * 2.0f * BILLBOARD_CENTRE_RANGE - BILLBOARD_CENTRE_RANGE; }
        std::uint32_t orientation() const { return words[2] & 0x7fffu; }
        bool mirrored() const { return (words[2] & 0x8000u) != 0; }
        float rotation() const { return float(words[3] >> 8) * 6.28318530718f / 256.0f; }
        float side() const; ///< tile edge in hash cells

        /// Quantise (values are clamped to what the encoding holds).
        static BillboardListEntry encode(float centreX, float centreY, std::uint32_t orientation, bool mirrored,
                                         float rotation, float side);
    };

    /// One leaf image of the Leaves Texture (a block of tiles): a leaf material, or one image of
    /// a material whose texture is an atlas of several (leaves map different UV rectangles).
    struct BillboardLeafImage
    {
        std::uint32_t material = 0; ///< index into the model's materials
        float alphaCutoff = 0.5f;   ///< the material's, applied when the tiles were drawn
        glm::vec2 uvMin{0.0f}, uvMax{0.0f}; ///< the image's rectangle in the material's texture
    };

    struct BillboardCloudData
    {
        bool classic = false;
        float listFactor = 1.0f; ///< shader LoD: entries walked = listFactor * projected cell diagonal in pixels
        glm::vec3 boundsMin{0.0f}, boundsMax{0.0f};
        std::vector<BillboardCloudLevel> levels;
        std::vector<Billboard> billboards;

        std::uint32_t hashAtlasWidth = 0, hashAtlasHeight = 0;
        std::vector<std::uint8_t> hashAtlas; ///< RGBA8

        std::uint32_t listsAtlasWidth = 0, listsAtlasHeight = 0;
        std::vector<BillboardListEntry> entries; ///< at most BILLBOARD_MAX_ENTRIES (24-bit starts)
        std::vector<std::uint8_t> entryAo; ///< 4 per entry

        std::uint32_t tileSize = 0, tileColumns = 0, orientationGrid = 0, leavesMaxLod = 0;
        std::vector<BillboardLeafImage> leafImages;
        GpuTexture leavesColour, leavesNormal, lowRes;
        std::vector<std::uint8_t> barkAo; ///< one per reference bark vertex

        std::uint32_t orientationCount() const { return orientationGrid * orientationGrid; }
        std::uint32_t tileCount() const { return std::uint32_t(leafImages.size()) * 2 * orientationCount(); }

        /// Hash texel of cell (i, j) of billboard b: (start, length).
        std::pair<std::uint32_t, std::uint32_t> cell(std::uint32_t billboard, std::uint32_t i, std::uint32_t j) const;

        /// Bytes on the GPU as Table 1 counts them (atlases + textures as stored, all mips).
        std::uint64_t gpuBytes() const;

        /// Every invariant the shader relies on: level ranges, billboard rects inside their
        /// atlases and disjoint, list ranges inside the entries, lengths <= 255, orientation
        /// indices < tileCount, texture sizes, finite geometry. `label` names the source.
        Result<void> validate(const std::string& label) const;
    };

    /// Grid cell of billboard coordinate g = u * size, clamped to [0, size - 1] (NaN -> 0).
    /// GLSL: cell = clamp(floor(g), 0.0, float(size) - 1.0), exact for sizes <= 2^24.
    std::uint32_t billboardGridCell(float g, std::uint32_t size);

    /// The entry's tile-local position (contract above): local = R(-psi) q / side + 0.5, then
    /// local.x = 1 - local.x when mirrored. q: the point relative to the tile centre, in hash cells.
    inline glm::vec2 billboardTileLocal(glm::vec2 q, float cosPsi, float sinPsi, float invSide, bool mirrored)
    {
        glm::vec2 local((cosPsi * q.x + sinPsi * q.y) * invSide + 0.5f,
                        (-sinPsi * q.x + cosPsi * q.y) * invSide + 0.5f);
        if (mirrored)
            local.x = 1.0f - local.x;
        return local;
    }

    /// Unit direction d_k of orientation k' (0 <= k' < grid^2) on the hemisphere d.z >= 0
    /// (hemi-octahedral map: cell centre (x, y) in [-1, 1]^2 rotated 45 degrees onto the
    /// octahedron's upper half).
    glm::vec3 billboardOrientationDirection(std::uint32_t k, std::uint32_t grid);
    /// The orientation whose cell holds unit direction d (d.z >= 0).
    std::uint32_t billboardOrientationIndex(const glm::vec3& d, std::uint32_t grid);

    std::vector<std::uint8_t> encodeBillboardCloudChunk(const BillboardCloudData& data);
    /// Parse and validate(); errors name `label` and the element.
    Result<BillboardCloudData> decodeBillboardCloudChunk(const std::vector<std::uint8_t>& bytes,
                                                         const std::string& label);

    /// The shader's addressing on the CPU (TreeLodBillboardCloud.frag does the same steps).
    class BillboardCloudSampler
    {
    public:
        explicit BillboardCloudSampler(const BillboardCloudData& data) : mData(data) {}

        struct Fragment
        {
            std::uint32_t entry = 0; ///< index into entries
            std::uint32_t tile = 0;  ///< Leaves Texture tile read (side applied)
            glm::vec2 local{0.0f};   ///< tile-local position in [0, 1]^2
        };

        /// walk()'s hash fetch: cell (i, j) of billboard b that holds (u, v) (clamped to the grid)
        /// and its texel's list; length 0 when b is out of range or has no grid.
        struct Cell
        {
            std::uint32_t i = 0, j = 0, start = 0, length = 0;
        };
        Cell lookup(std::uint32_t billboard, float u, float v) const;

        /// The list entries that cover billboard coordinate (u, v) in [0,1]^2 of billboard b,
        /// in walk order for a camera on the +normal side (frontSide) or the other, at most
        /// maxEntries: the hash fetch, then per entry the tile-local position; entries whose
        /// local position falls outside the tile are skipped. Alpha is not tested here.
        std::vector<Fragment> walk(std::uint32_t billboard, float u, float v, bool frontSide,
                                   std::uint32_t maxEntries = BILLBOARD_MAX_LIST_LENGTH) const;

    private:
        const BillboardCloudData& mData;
    };
}
