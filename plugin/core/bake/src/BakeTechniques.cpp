// The technique table of BakeTechniques.h.
#include "TreeLod/BakeTechniques.h"

#include "TreeLod/BillboardCloudBaker.h"
#include "TreeLod/FoliageLodBaker.h"
#include "TreeLod/FoliageLodData.h"
#include "TreeLod/ImpostorBaker.h"
#include "TreeLod/Package.h"

namespace TreeLod
{
    const std::vector<BakeTechnique>& bakeTechniques()
    {
        static const std::vector<BakeTechnique> techniques = {
            {REFERENCE_CHUNK, "the polygonal tree with GPU-ready mip-mapped textures", &addReferenceChunk},
            {FOLIAGE_LOD_CHUNK, "LoDF continuous foliage by leaf collapse, paper 004 (adds reference)",
             static_cast<BakeFunction>(&addFoliageLodChunk)},
            {BILLBOARD_CLOUD_CHUNK, "billboard cloud, multi-layered indirect texturing, paper 000 (adds reference)",
             &addBillboardCloudChunk},
            {CLASSIC_BILLBOARD_CLOUD_CHUNK,
             "classic billboard cloud at equal memory, paper 000 Fig. 13 (adds reference)",
             &addClassicBillboardCloudChunk},
            {IMPOSTOR_CHUNK,
             "one camera-facing quad with baked colour and normal textures, the speed floor (adds reference)",
             &addImpostorChunk},
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
