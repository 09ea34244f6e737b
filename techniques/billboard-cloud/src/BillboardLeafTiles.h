// BillboardLeafTiles: the Leaves Texture of García et al. 2007 (§3, §5, §5.2) and the one place
// that maps a leaf onto a billboard plane (orientation, mirror, rotation, tile edge, centre, AO).
// Everything here follows the "Leaves Texture" and "Lists atlas" sections of BillboardCloudData.h;
// the baker (BillboardCloudBaker.cpp) and the tests use only this API.
//
// Leaf frame (per leaf, from its triangles): w = direction of increasing texture u, t = towards
// the tip (decreasing texture v), both least-squares fits of dP/du and -dP/dv over the leaf's
// vertices, orthonormalised around n = Leaf::normal (t first; w = cross(t, n) if the fit of
// w fails; any unit vector orthogonal to n if both fail, e.g. a leaf with all UVs equal).
// Leaf images: a material's leaves are grouped by the UV rectangle they map (an atlas texture
// holds several leaf images; BillboardCloudData.h, "Leaves Texture"), one tile block per image.
// Canonical leaf of an image: its UV rectangle [uvMin, uvMax] (the union over its leaves) on a
// flat rectangle in the (w, t) plane with the image's median aspect (leaf width / length,
// from the leaves' fitted |dP/du| and |dP/dv| extents).
// Deviation (techniques/billboard-cloud/README.md): every leaf of an image is drawn with the canonical
// leaf's shape and texture rectangle; non-planar leaves are drawn flat (the paper also stores
// one image per orientation). A leaf whose texture is mirrored on it (fitted (w, t, n) left-handed) uses
// the frame (w, t, -n): its image is right, but its front and back tints are swapped.
#pragma once

#include "TreeLod/BillboardCloudData.h"
#include "TreeLod/TreeModel.h"

#include <glm/glm.hpp>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace TreeLod
{
    /// Where a leaf lands on a billboard plane (unit axes U, V, normal N = cross(U, V)).
    struct LeafPlacement
    {
        glm::vec2 centre{0.0f};       ///< tile centre in plane coordinates (metres along U, V from the plane origin)
        float depth = 0.0f;           ///< signed distance of the leaf centre along N from the plane origin
        std::uint32_t orientation = 0; ///< tile index of side 0 (material offset included)
        bool mirrored = false;
        float rotation = 0.0f;        ///< psi, radians in [0, 2 pi)
        float side = 0.0f;            ///< tile square edge, metres
    };

    class BillboardLeafTiles
    {
    public:
        /// Build the tiles of every leaf image that `model`'s leaves use (materials without leaves
        /// get none). tileSize: power of two >= 8; grid >= 1. maxTexels > 0: the tile edge halves
        /// (not below 16) while the tiles would take more texels (tileSize() tells what was used).
        BillboardLeafTiles(const TreeModel& model, std::uint32_t tileSize, std::uint32_t grid,
                           std::uint64_t maxTexels = 0);

        std::uint32_t tileSize() const { return mTileSize; }
        std::uint32_t grid() const { return mGrid; }
        std::uint32_t tileColumns() const { return mColumns; }
        std::uint32_t tileCount() const;
        /// The leaf images in tile-block order (material, cutoff, UV rectangle).
        const std::vector<BillboardLeafImage>& images() const { return mImages; }
        /// The leaf image of leaf `leaf`, -1 for none (its material index is out of range).
        std::int32_t imageOf(std::uint32_t leaf) const { return leaf < mLeafBlock.size() ? mLeafBlock[leaf] : -1; }
        /// What the grouping could not keep apart (a material mapping more rectangles than it may
        /// have images), for the baker to report.
        const std::vector<std::string>& warnings() const { return mWarnings; }
        /// The smallest and largest tile edge of leaf `leaf` over the orientations, metres.
        glm::vec2 sideRange(std::uint32_t leaf) const;

        /// Leaf `leaf` on the plane (origin, U, V, N).
        LeafPlacement place(std::uint32_t leaf, const glm::vec3& origin, const glm::vec3& U, const glm::vec3& V,
                            const glm::vec3& N) const;

        /// The entry for `placement` in a hash grid of `cellSize` metres, relative to the corner
        /// of cell (i, j) (the cell grid starts at the plane origin).
        BillboardListEntry entryFor(const LeafPlacement& placement, float cellSize, std::uint32_t i,
                                    std::uint32_t j) const;

        /// García et al. 2007 §5.2, Fig. 11: AO at the tile corners local (0,0), (1,0), (0,1),
        /// (1,1) by least squares of the bilinear function to the leaf's vertex AO values at their
        /// tile-local positions (clamped to [0, 1]; ao must hold one value per leaf vertex of the
        /// model). A leaf with one distinct position gives its mean everywhere.
        std::array<std::uint8_t, 4> fitAo(std::uint32_t leaf, const LeafPlacement& placement, const glm::vec3& origin,
                                          const glm::vec3& U, const glm::vec3& V,
                                          const std::vector<float>& leafVertexAo) const;

        /// Level-0 images of the Leaves Texture (RGBA8, tileColumns * tileSize wide):
        /// colour (sRGB albedo, coverage alpha) and normal (n * 0.5 + 0.5, alpha 255).
        const TextureImage& colour() const { return mColour; }
        const TextureImage& normal() const { return mNormal; }

        /// Bilinear lookup of tile `tile` at tile-local `local` (outside [0,1]^2: transparent):
        /// linear-light albedo in rgb, coverage in a.
        glm::vec4 sample(std::uint32_t tile, const glm::vec2& local) const;
        /// Normal facing the tile's viewer, in the tile frame, at `local` (nearest texel).
        glm::vec3 sampleNormal(std::uint32_t tile, const glm::vec2& local) const;

        /// Coarsest mip level at which no tile bleeds into its neighbours (TILE_MARGIN).
        std::uint32_t maxLod() const;

    private:
        std::uint32_t mTileSize = 0, mGrid = 0, mColumns = 0;
        std::vector<BillboardLeafImage> mImages;
        std::vector<std::int32_t> mLeafBlock; ///< leaf -> image (tile block), -1 none
        std::vector<std::string> mWarnings;
        struct LeafFrame
        {
            glm::vec3 w{1, 0, 0}, t{0, 1, 0}, n{0, 0, 1}; ///< right-handed; n = -Leaf::normal if the texture is mirrored
            float length = 0.0f;   ///< metres along t of the canonical UV rectangle
            glm::vec3 centre{0.0f}; ///< the canonical rectangle's centre on the leaf, world
        };
        std::vector<LeafFrame> mFrames; ///< per leaf
        std::vector<float> mTileExtent; ///< per tile: tile edge / leaf length
        std::vector<glm::mat3> mTileAxes; ///< per orientation k': tile x, y, z (= d_k) in the leaf frame
        const TreeModel& mModel;
        TextureImage mColour, mNormal;
    };
}
