#include "TreeLod/TreePreset.h"

namespace TreeLod
{
    const char* presetName(TreePreset preset)
    {
        switch (preset)
        {
        case TreePreset::Oak: return "oak";
        case TreePreset::Conifer: return "conifer";
        case TreePreset::Birch: return "birch";
        case TreePreset::Shrub: return "shrub";
        }
        return "unknown";
    }

    bool parsePreset(const std::string& name, TreePreset& out)
    {
        if (name == "oak" || name == "broadleaf")
            out = TreePreset::Oak;
        else if (name == "conifer")
            out = TreePreset::Conifer;
        else if (name == "birch")
            out = TreePreset::Birch;
        else if (name == "shrub")
            out = TreePreset::Shrub;
        else
            return false;
        return true;
    }

    const char* presetNames() { return "oak, conifer, birch, shrub"; }
}
