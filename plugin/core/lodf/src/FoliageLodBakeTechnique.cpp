// The core descriptor of LoDF (Rebollo et al. 2006), bake half: FoliageLodBaker.h.
#include "TreeLod/BakeTechniques.h"
#include "TreeLod/FoliageLodBaker.h"
#include "TreeLod/FoliageLodData.h"

namespace TreeLod
{
    namespace
    {
        const BakeTechniqueRegistration registration(
            {FOLIAGE_LOD_CHUNK, "LoDF continuous foliage by leaf collapse, Rebollo et al. 2006 (adds reference)",
             static_cast<BakeFunction>(&addFoliageLodChunk)});
    }
}
