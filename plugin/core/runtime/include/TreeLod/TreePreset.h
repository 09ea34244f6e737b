// TreePreset: the procedural generator's tree kinds by name. Runtime side so that scene scripts
// (TreeLodScript) and the Ogre side check "preset:NAME" sources without linking the generator
// (TreeGenerator.h, in TreeLodBake). The one list of preset names.
#pragma once

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

    /// "oak, conifer, birch, shrub": the names parsePreset accepts (less the alias), for messages.
    const char* presetNames();
}
