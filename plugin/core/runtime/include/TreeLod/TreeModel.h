// TreeModel: a polygonal tree as every TreeLod baker sees it.
//
// Units are metres, +Y is up, the tree stands with its base near the origin.
// Bark is a plain triangle soup with a material per triangle. Leaves are individual
// records: each owns a contiguous range of `leafVertices` and of `leafIndices`
// (indices are absolute into `leafVertices`), so a technique can move, drop or merge
// single leaves. Textures are decoded RGBA8 (sRGB colour, straight alpha).
// Any part may be empty: a bare trunk (no leaves) and loose foliage (no bark) are trees.
#pragma once

#include "TreeLod/Result.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace TreeLod
{
    struct Vertex
    {
        glm::vec3 position{0.0f};
        glm::vec3 normal{0.0f, 1.0f, 0.0f};
        glm::vec2 uv{0.0f};
    };

    /// Decoded image, RGBA8, rows top to bottom (glTF/PNG convention).
    struct TextureImage
    {
        std::string name; ///< file name or "image N" for embedded images
        int width = 0;
        int height = 0;
        std::vector<std::uint8_t> rgba; ///< width * height * 4 bytes
    };

    struct Material
    {
        std::string name;
        glm::vec4 baseColour{1.0f};           ///< linear factor (glTF baseColorFactor)
        glm::vec3 backColour{0.0f};           ///< leaves: tint of the back side (linear); 0 = same as front
        std::int32_t texture = -1;            ///< index into TreeModel::textures, -1 = none
        float alphaCutoff = 0.5f;             ///< alpha test threshold for leaves
        bool isLeaf = false;
        bool doubleSided = false;
    };

    /// One leaf: a connected component of the leaf triangles.
    struct Leaf
    {
        std::uint32_t firstVertex = 0; ///< into TreeModel::leafVertices
        std::uint32_t vertexCount = 0;
        std::uint32_t firstIndex = 0;  ///< into TreeModel::leafIndices (absolute vertex indices)
        std::uint32_t indexCount = 0;  ///< multiple of 3
        std::uint32_t material = 0;    ///< into TreeModel::materials
        glm::vec3 centre{0.0f};        ///< area-weighted centroid of its triangles
        glm::vec3 normal{0.0f, 1.0f, 0.0f}; ///< area-weighted mean face normal, unit (or +Y if area is 0)
        float area = 0.0f;             ///< m^2, sum of its triangles (one side)
        glm::vec2 uvMin{0.0f};         ///< UV rectangle covering its texture image
        glm::vec2 uvMax{0.0f};
    };

    struct SkeletonNode
    {
        glm::vec3 position{0.0f};
        float radius = 0.0f;
        std::int32_t parent = -1; ///< -1 for the root
    };

    struct TreeModel
    {
        std::string name;
        std::vector<Material> materials;
        std::vector<TextureImage> textures;

        std::vector<Vertex> barkVertices;
        std::vector<std::uint32_t> barkIndices;       ///< triangles
        std::vector<std::uint32_t> barkTriangleMaterial; ///< one per triangle

        std::vector<Vertex> leafVertices;
        std::vector<std::uint32_t> leafIndices;
        std::vector<Leaf> leaves;

        std::vector<SkeletonNode> skeleton; ///< optional

        glm::vec3 boundsMin{0.0f};
        glm::vec3 boundsMax{0.0f};

        std::size_t barkTriangleCount() const { return barkIndices.size() / 3; }
        std::size_t leafTriangleCount() const { return leafIndices.size() / 3; }

        /// Recompute boundsMin/boundsMax from bark and leaf vertices (0,0 when empty).
        void updateBounds();

        /// Recompute centre, normal, area and UV rectangle of leaf `i` from its triangles.
        void updateLeafRecord(std::size_t i);

        /// The triangles of leaf `i` by plane, as index triples into leafVertices, the largest
        /// plane first: the largest triangles seed planes, a triangle joins the most parallel
        /// seed within `parallel` (|n_a . n_b|), planes under `minShare` of the leaf's area join
        /// the most parallel larger one, degenerate triangles the first. One plane for a flat
        /// leaf; several for one mesh in several planes (a folded leaf, a sprig in one piece).
        std::vector<std::vector<std::uint32_t>> leafPlanes(std::size_t i, float parallel = 0.9f,
                                                           float minShare = 0.1f) const;

        /// Check internal consistency: ranges, indices, materials, finite values.
        /// `file` only labels the error.
        Result<void> validate(const std::string& file = "") const;
    };

    /// `model` with each leaf in several planes (TreeModel::leafPlanes) made one leaf per plane,
    /// on its own copies of the vertices, in the leaf's place; nullopt when every leaf is flat.
    std::optional<TreeModel> leafPlanesAsLeaves(const TreeModel& model);
}
