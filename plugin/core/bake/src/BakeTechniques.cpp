// The baker registry of BakeTechniques.h.
#include "TreeLod/BakeTechniques.h"

#include "TreeLod/Package.h"

#include <algorithm>

namespace TreeLod
{
    namespace
    {
        std::vector<BakeTechnique>& registry()
        {
            static std::vector<BakeTechnique> techniques = {
                {REFERENCE_CHUNK, "the polygonal tree with GPU-ready mip-mapped textures", &addReferenceChunk}};
            return techniques;
        }
    }

    void registerBakeTechnique(const BakeTechnique& technique)
    {
        std::vector<BakeTechnique>& all = registry();
        const std::string name = technique.name;
        auto same = std::find_if(all.begin(), all.end(), [&](const BakeTechnique& t) { return name == t.name; });
        if (same != all.end())
        {
            *same = technique;
            return;
        }
        auto at = std::find_if(all.begin() + 1, all.end(), [&](const BakeTechnique& t) { return name < t.name; });
        all.insert(at, technique);
    }

    const std::vector<BakeTechnique>& bakeTechniques() { return registry(); }

    const BakeTechnique* findBakeTechnique(const std::string& name)
    {
        for (const BakeTechnique& t : registry())
            if (name == t.name)
                return &t;
        return nullptr;
    }

    std::string knownBakeTechniques()
    {
        std::string list;
        for (const BakeTechnique& t : registry())
            list += (list.empty() ? "" : ", ") + std::string(t.name);
        return list;
    }
}
