// LeafExtraction: split a soup of leaf triangles into leaves (shared by the glTF and .mesh importers).
//
// A leaf is one connected component of the soup's triangles, two triangles being connected
// when they share a vertex index or a vertex position (bitwise-equal floats, -0 == +0).
// Exact equality is enough for what exporters write: vertices split for UV or normal seams
// keep the very same float position, and the importer has applied one transform per node.
//
// Duplicates: an index-connected piece whose triangles repeat an earlier piece exactly
// (same corner positions in the same order) is a copy, not a part of the original: copies
// are welded only with pieces of the same copy number, so a leaf written twice gives two
// leaves, the second counted as a duplicate.
#pragma once

#include "TreeLod/Progress.h"
#include "TreeLod/TreeModel.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace TreeLod
{
    namespace detail
    {
        /// Leaf triangles in file order. `indices` index `vertices`; one material per triangle.
        struct LeafSoup
        {
            std::vector<Vertex> vertices;
            std::vector<std::uint32_t> indices;
            std::vector<std::uint32_t> triangleMaterial;
        };

        struct LeafExtractionStats
        {
            std::size_t degenerate = 0; ///< leaves of (nearly) zero area, dropped
            std::size_t duplicates = 0; ///< kept leaves that copy an earlier piece exactly
        };

        /// Append the soup's leaves to `model` (leafVertices, leafIndices, leaves, each leaf
        /// record updated), ordered by their first triangle in the soup. A leaf's vertices are
        /// those its triangles use, in order of first use; its material is its first
        /// triangle's. A leaf whose area is at most kDegenerateAreaRatio times the square of
        /// its bounding box's longest side (a point, a line, up to float rounding) is dropped.
        /// Vertices used by no triangle are dropped. The soup's indices must be in range.
        LeafExtractionStats extractLeaves(const LeafSoup& soup, TreeModel& model,
                                          const ProgressCallback& progress = {});

        constexpr double kDegenerateAreaRatio = 1e-6;
    }
}
