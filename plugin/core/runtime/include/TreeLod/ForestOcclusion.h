// ForestOcclusion: how much of each tree a camera sees through the trees in front of it, estimated
// on the CPU while the Forest culls (ForestInstances::cull, docs/forest.md "Occlusion").
//
// Each kind of tree has an OcclusionMask: the share of each cell of a 16 x 16 grid over its
// bounding sphere's square, seen from the side, that the tree covers (makeOcclusionMask: leaves and
// bark rasterised along x and along z on 256 x 256 samples, each leaf's opacity the share of its
// texture rectangle the alpha test keeps, a triangle under two samples put at its centroid as its
// area, overlaps multiplying transmittance; the two views averaged), and per cell its `solid`
// coverage, the least over the cell's 4 x 4 blocks.
// A camera's OcclusionGrid holds two transmittances T over a grid of OCCLUSION_GRID_COLUMNS
// columns on the screen, 1 where nothing is in front. Trees are added near first; the share of a
// tree that is visible is the mask-weighted mean of T over the cells its square covers, then the
// tree occludes:
//   - estimated: each cell's T times 1 - a m (a: the share of the cell its square covers, m: its
//     mask's mean there). The trees in front as independent random occluders within a cell, as
//     the canopy-gap models of forestry take them (Beer-Lambert through the crowns). This share
//     weighs the error a level adds where a tree is partly hidden (LevelSelection.h,
//     occlusionHeightScale).
//   - conservative: only the cells inside its square, each times 1 - the least `solid` of its
//     mask there. Edges line up from tree to tree (the lower edges of a stand's crowns on flat
//     ground seen from the trunks' height all fall on the horizon), where independence closes the
//     gap below them; a cell an edge crosses hides nothing here. A tree of which this share is
//     below OCCLUSION_HIDDEN is not drawn.
// A statistical estimate, not a depth test. A tree whose sphere reaches the camera's plane is taken
// as visible and occludes nothing (its square is unbounded); so does a tree whose square is under
// OCCLUSION_MIN_OCCLUDER_PX tall: a few pixels of alpha-tested leaves draw far less than their area
// (an alpha test on mipmapped alpha drops most of them), and behind a thousand such trees the
// estimate hid trees that showed through.
#pragma once

#include "TreeLod/ModelChunk.h"

#include <glm/glm.hpp>

#include <array>
#include <cstddef>
#include <vector>

namespace TreeLod
{
    /// Visibility classes of occlusionHeightScale: class c for a visible share of 2^-c.
    constexpr std::size_t OCCLUSION_CLASSES = 6;
    /// A tree of which less is visible is not drawn.
    constexpr float OCCLUSION_HIDDEN = 1.0f / 64.0f;
    /// Columns of a camera's OcclusionGrid (rows by its aspect ratio).
    constexpr int OCCLUSION_GRID_COLUMNS = 128;
    /// The smallest tree that hides others: its bounding sphere's square this many pixels tall.
    constexpr float OCCLUSION_MIN_OCCLUDER_PX = 16.0f;

    /// A tree's silhouette seen from the side: coverage in [0, 1] of each cell of its bounding
    /// sphere's square (x across, y up; cell (0, 0) at the bottom left).
    struct OcclusionMask
    {
        static constexpr int SIZE = 16;
        std::array<float, SIZE * SIZE> coverage{};
        /// What the tree is trusted to hide behind each cell: the least coverage of the cell's 4 x 4
        /// blocks (makeOcclusionMask), so that a cell an edge crosses hides little.
        std::array<float, SIZE * SIZE> solid{};
        /// Summed-area table of `coverage`, (SIZE + 1)^2, made by finish().
        std::array<float, (SIZE + 1) * (SIZE + 1)> sums{};
        /// Mean coverage of the square.
        float mean = 0.0f;
        /// Make `sums` and `mean` from `coverage`.
        void finish();
        /// Mean coverage over [u0, u1] x [v0, v1] (mask cells, 0..SIZE; empty: 0).
        float meanOver(float u0, float v0, float u1, float v1) const;
        /// The least `solid` of the cells [u0, u1] x [v0, v1] touches (at least one cell).
        float minOver(float u0, float v0, float u1, float v1) const;
    };

    /// The mask of `reference`'s tree in the square of the sphere (`centre`, `radius`), as above
    /// (its leaf textures' alpha read from `reference.textures`). A tree without triangles gives an
    /// empty mask (occludes nothing).
    OcclusionMask makeOcclusionMask(const ReferenceChunk& reference, const glm::vec3& centre, float radius);

    /// The share of a tree that the trees in front leave visible (OcclusionGrid::addTree).
    struct OcclusionShare
    {
        float estimate = 1.0f;     ///< independent occluders by their mean coverage: the plan's weight
        float conservative = 1.0f; ///< conservative occluders: below OCCLUSION_HIDDEN the tree is not drawn
    };

    /// A camera's transmittance over its screen, as above, twice: estimated and conservative.
    class OcclusionGrid
    {
    public:
        /// Every cell clear (T = 1); `columns` x `rows` cells (at least 1 each).
        void clear(int columns, int rows);
        int getColumns() const { return mColumns; }
        int getRows() const { return mRows; }
        /// The share of a tree whose square spans [x0, x1] x [y0, y1] (normalised device
        /// coordinates, -1..1, y up) that is visible, both ways, in [0, 1]; then the tree occludes,
        /// where `occludes` (a null mask: weighed evenly, occludes nothing). A square outside the
        /// screen: 1.
        OcclusionShare addTree(const OcclusionMask* mask, float x0, float y0, float x1, float y1, bool occludes = true);
        /// Estimated and conservative transmittance of cell (column, row), row 0 at the bottom.
        float getTransmittance(int column, int row) const { return mCells[std::size_t(row * mColumns + column)]; }
        float getConservativeTransmittance(int column, int row) const
        {
            return mSolidCells[std::size_t(row * mColumns + column)];
        }

    private:
        int mColumns = 0, mRows = 0;
        std::vector<float> mCells, mSolidCells;
    };
}
