#include "BakeTechniques.h"

#include "TreeLod/FoliageLodBaker.h"
#include "TreeLod/FoliageLodData.h"
#include "TreeLod/Package.h"

namespace TreeLod
{
    const std::vector<BakeTechnique>& bakeTechniques()
    {
        static const std::vector<BakeTechnique> techniques = {
            {REFERENCE_CHUNK, "the polygonal tree with GPU-ready mip-mapped textures", &addReferenceChunk},
            {FOLIAGE_LOD_CHUNK, "LoDF continuous foliage by leaf collapse, paper 004 (adds reference)",
             static_cast<BakeFunction>(&addFoliageLodChunk)},
        };
        return techniques;
    }

    const BakeTechnique* findBakeTechnique(const std::string& name)
    {
        for (const BakeTechnique& t : bakeTechniques())
            if (name == t.name)
                return &t;
        return nullptr;
    }

    std::string knownBakeTechniques()
    {
        std::string list;
        for (const BakeTechnique& t : bakeTechniques())
            list += (list.empty() ? "" : ", ") + std::string(t.name);
        return list;
    }
}
