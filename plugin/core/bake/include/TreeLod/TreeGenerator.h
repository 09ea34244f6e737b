// TreeGenerator: `treelod generate`, our own procedural trees.
//
// This work is based on:
//   Jason Weber, Joseph Penn, "Creation and Rendering of Realistic Trees", SIGGRAPH 1995
//   (recursive stems with per-level length/radius ratios, taper, curvature, branching
//   angles, phyllotaxis, leaves on the last level). Written from the paper's ideas; where
//   this code deviates (exact leaf count, leaf size rule, no stem splits) the .cpp says so.
//
// Output units are metres, +Y up, the trunk base at the origin (the shrub's stems start
// within a small disc around it). Materials: 0 "Bark" (opaque, white factor, procedural
// bark texture of textureSize/2 texels, textures[0]) and 1 "Leaves" (isLeaf, alpha-tested
// at 0.5, double-sided, back colour = the leaf texture's mean colour made lighter and
// yellower, textures[1]). Every leaf is one quad (4 vertices of its own, 2 triangles) whose
// UVs cover the whole leaf texture (0..1), unless leafImages or leafMaterials ask for an
// atlas or several leaf materials (GeneratorOptions). The skeleton has a node per stem point (the
// first node of a branch hangs off the parent's node at or below where it grows), parents
// before children. Defaults: oak 12 m / 6000 leaves, conifer 16 m / 10000, birch 15 m /
// 6000, shrub 2.5 m / 3000. Bark: 6.6k..13.8k triangles (all presets, seeds 1..100),
// independent of the leaf count.
//
// Deterministic: the same options give a byte-identical model on any machine with the
// same libm (own random distributions over std::mt19937, no threads). The branches depend
// on preset, seed and height only; the leaf count changes leaves, not branches.
//
// Leaf size rule: the preset holds the total one-sided quad area of the crown fixed at
// k * height^2 (k per preset), so each leaf quad has area k * height^2 / leafCount and the
// crown covers the same silhouette at 1k and at 100k leaves (fewer, larger leaves or more,
// smaller ones). Leaves sit on invisible twigs around the last-level stems so that they
// fill a tube of radius r * height around each stem whatever their size (twig length =
// max(reach - leaf length, reach / 4)): many small leaves fill the same volume as a few
// large ones. Measured (oak seed 1, CPU reference renderer, 256 px, azimuth 30°): image
// coverage 0.114 at 1k leaves, 0.114 at 10k, 0.110 at 100k. Leaves are at most height / 10
// long, which binds only near 100 leaves (a sparse crown there).
#pragma once

#include "TreeLod/Progress.h"
#include "TreeLod/Result.h"
#include "TreeLod/TreeModel.h"
#include "TreeLod/TreePreset.h" // TreePreset, presetName, parsePreset

#include <cstdint>
#include <string>

namespace TreeLod
{
    struct GeneratorOptions
    {
        TreePreset preset = TreePreset::Oak;
        std::uint32_t seed = 1;
        std::uint32_t leafCount = 0; ///< exact number of leaves; 0 = preset default; else 100..200000
        float height = 0.0f;         ///< metres, top of the stems (leaves may reach a little
                                     ///< higher); 0 = preset default; else 0.1..1000
        int textureSize = 256;       ///< leaf texture edge in texels, power of two, 16..4096
        /// Leaf images, 1..4. Above 1 the leaf texture is an atlas of 2 x 2 cells (this preset's
        /// leaf, then the other presets' leaves, each at half the texture size) and every leaf
        /// maps one cell, chosen at random: the UV sub-rectangles of game and SpeedTree assets.
        std::uint32_t leafImages = 1;
        /// Leaf materials, 1..16 ("Leaves", "Leaves 2", ...): leaves are dealt to them in turn;
        /// each has its own tint and alpha cutoff (0.5 for the first, 0.3..0.7 for the others).
        std::uint32_t leafMaterials = 1;
        /// Leaf fold in degrees, 0..80: above 0 every leaf is one mesh of two quads folded along
        /// its midrib, each wing raised by this angle towards the leaf's face (the wings keep their
        /// width); 0: one flat quad.
        float leafFold = 0.0f;
    };

    /// The preset's leaf count and height when the options leave them 0.
    std::uint32_t presetDefaultLeafCount(TreePreset preset);
    float presetDefaultHeight(TreePreset preset);

    /// Generate a tree. Fails (element names the option, e.g. "option --leaves") when an
    /// option is out of range. Single-threaded; about 0.1 s for 200k leaves (256 texture).
    /// Progress steps: "generate stems", "generate bark", "generate leaves", "draw textures".
    Result<TreeModel> generateTree(const GeneratorOptions& options, const ProgressCallback& progress = {});
}
