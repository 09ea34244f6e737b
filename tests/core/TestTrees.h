// Test trees built in code, shared by the core tests and the core bench: the generated oak
// (cached per leaf count and height) and leaves as the generator builds them.
#pragma once

#include "TreeLod/TreeGenerator.h"
#include "TreeLod/TreeModel.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>

namespace TreeLod
{
    namespace test
    {
        /// The generated oak (seed 1, 64-texel texture) with `leaves` leaves, `height` metres tall
        /// (0: the preset's height), `images` leaf images in its texture (above 1 an atlas) and
        /// `materials` leaf materials (GeneratorOptions), built once per combination; throws
        /// std::runtime_error with the generator's message when it fails (gtest reports it as the
        /// test's failure).
        inline const TreeModel& generatedOak(std::uint32_t leaves, float height = 0.0f, std::uint32_t images = 1,
                                             std::uint32_t materials = 1)
        {
            using Key = std::tuple<std::uint32_t, float, std::uint32_t, std::uint32_t>;
            static std::map<Key, TreeModel> cache;
            const Key key{leaves, height, images, materials};
            auto it = cache.find(key);
            if (it == cache.end())
            {
                GeneratorOptions options;
                options.preset = TreePreset::Oak;
                options.leafCount = leaves;
                options.height = height;
                options.textureSize = 64;
                options.leafImages = images;
                options.leafMaterials = materials;
                Result<TreeModel> m = generateTree(options);
                if (!m)
                    throw std::runtime_error(m.error().message());
                it = cache.emplace(key, std::move(m).value()).first;
            }
            return it->second;
        }

        /// A double-sided, untextured leaf material named `name` (base colour and back colour
        /// left for the caller).
        inline Material leafMaterial(const std::string& name)
        {
            Material leaf;
            leaf.name = name;
            leaf.isLeaf = true;
            leaf.doubleSided = true;
            return leaf;
        }

        /// Append one leaf quad as the generator builds it: corners centre -+u -+v, normal `n`,
        /// UVs over the whole texture, 4 own vertices, 2 triangles, material `material`; its leaf
        /// record (centre, normal, area, UV box) updated.
        inline void addQuadLeaf(TreeModel& m, const glm::vec3& centre, const glm::vec3& u, const glm::vec3& v,
                                const glm::vec3& n, std::uint32_t material = 0)
        {
            Leaf l;
            l.firstVertex = std::uint32_t(m.leafVertices.size());
            l.vertexCount = 4;
            l.firstIndex = std::uint32_t(m.leafIndices.size());
            l.indexCount = 6;
            l.material = material;
            const glm::vec3 corners[4] = {centre - u - v, centre + u - v, centre + u + v, centre - u + v};
            const glm::vec2 uvs[4] = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
            for (int k = 0; k < 4; ++k)
                m.leafVertices.push_back({corners[k], n, uvs[k]});
            for (std::uint32_t k : {0u, 1u, 2u, 0u, 2u, 3u})
                m.leafIndices.push_back(l.firstVertex + k);
            m.leaves.push_back(l);
            m.updateLeafRecord(m.leaves.size() - 1);
        }

        /// `m` with every vertex and skeleton node at `s * position + offset`, skeleton radii times
        /// `s` (and its bounds and leaf records).
        inline TreeModel transformed(const TreeModel& m, float s, const glm::vec3& offset)
        {
            TreeModel out = m;
            for (Vertex& v : out.barkVertices)
                v.position = s * v.position + offset;
            for (Vertex& v : out.leafVertices)
                v.position = s * v.position + offset;
            for (SkeletonNode& n : out.skeleton)
            {
                n.position = s * n.position + offset;
                n.radius *= s;
            }
            for (std::size_t i = 0; i < out.leaves.size(); ++i)
                out.updateLeafRecord(i);
            out.updateBounds();
            return out;
        }

        /// `m` scaled by `s` about the origin.
        inline TreeModel scaled(const TreeModel& m, float s) { return transformed(m, s, glm::vec3(0.0f)); }

        /// `m` moved by `offset`.
        inline TreeModel translated(const TreeModel& m, const glm::vec3& offset) { return transformed(m, 1.0f, offset); }

        /// Bake options that keep a test's bake of a few hundred leaves within a second or two where
        /// a technique's defaults cost more (the volume octree's default reconstruction, 24
        /// photographs of 256 px and 7 levels, is a minute under the sanitizers): the chunk has the
        /// same layout at any size. Empty for the others.
        inline std::map<std::string, std::string> quickBakeOptions(const std::string& technique)
        {
            static const std::map<std::string, std::map<std::string, std::string>> quick = {
                {"volume-octree", {{"cameras", "8"}, {"resolution", "64"}, {"levels", "4"}}},
                {"ellipsoids", {{"tries", "1"}, {"viewResolution", "32"}}},
                {"ellipsoid-lines", {{"viewResolution", "32"}}},
                {"billboard-cloud", {{"clusteringTries", "1"}, {"aoRays", "4"}}},
                {"classic-billboard-cloud", {{"clusteringTries", "1"}, {"aoRays", "4"}}},
                {"octahedral-impostor", {{"framesPerSide", "4"}, {"frameResolution", "32"}, {"samplesPerPixel", "1"}}},
                {"crossed-quads", {{"resolution", "64"}}},
                {"impostor", {{"resolution", "64"}}}};
            const auto found = quick.find(technique);
            return found == quick.end() ? std::map<std::string, std::string>{} : found->second;
        }
    }
}
