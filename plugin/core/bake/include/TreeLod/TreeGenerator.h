// TreeGenerator: `treelod generate`, our own procedural trees.
//
// This work is based on:
//   Jason Weber, Joseph Penn, "Creation and Rendering of Realistic Trees", SIGGRAPH 1995
//   (recursive stems with per-level length/radius ratios, taper, curvature, branching
//   angles, phyllotaxis, leaves on the last level). Written from the paper's ideas; where
//   this code deviates (exact leaf count, leaf size rule, no stem splits) the .cpp says so.
//
// Output units are metres, +Y up, the trunk base at the origin. The model has one bark
// material (procedural bark texture, opaque) and one leaf material (procedural leaf
// texture, alpha-tested at 0.5, double-sided, with a back colour). Every leaf is one quad
// (4 vertices of its own, 2 triangles) whose UVs cover the whole leaf texture (0..1).
// The skeleton has a node per stem point, parents before children.
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
// large ones. Measured (oak, CPU renderer, 256 px): image coverage 0.115 at 1k leaves,
// 0.110 at 10k, 0.107 at 100k.
#pragma once

#include "TreeLod/Progress.h"
#include "TreeLod/Result.h"
#include "TreeLod/TreeModel.h"

#include <cstdint>
#include <string>

namespace TreeLod
{
    enum class TreePreset
    {
        Oak,     ///< broadleaf, decurrent, broad rounded crown (also "broadleaf")
        Conifer, ///< excurrent, conical, near-horizontal whorled branches, needle sprays
        Birch,   ///< slender white trunk, narrow crown, pendulous twigs
        Shrub    ///< many stems from the ground, low rounded bush
    };

    /// "oak", "conifer", "birch", "shrub".
    const char* presetName(TreePreset preset);

    /// Accepts the names above (case-sensitive) and "broadleaf" as Oak. False otherwise.
    bool parsePreset(const std::string& name, TreePreset& out);

    struct GeneratorOptions
    {
        TreePreset preset = TreePreset::Oak;
        std::uint32_t seed = 1;
        std::uint32_t leafCount = 0; ///< exact number of leaves; 0 = preset default; else 100..200000
        float height = 0.0f;         ///< metres, top of the stems (leaves may reach a little higher); 0 = preset default; else 0.1..1000
        int textureSize = 256;       ///< leaf texture edge in texels, power of two, 16..4096
    };

    /// The preset's leaf count and height when the options leave them 0.
    std::uint32_t presetDefaultLeafCount(TreePreset preset);
    float presetDefaultHeight(TreePreset preset);

    /// Generate a tree. Fails (element names the option, e.g. "option --leaves") when an
    /// option is out of range. About 0.5 s for 200k leaves on one core.
    /// Progress steps: "generate stems", "generate bark", "generate leaves", "draw textures".
    Result<TreeModel> generateTree(const GeneratorOptions& options, const ProgressCallback& progress = {});
}
