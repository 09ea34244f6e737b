// The core descriptors of the billboard clouds (García et al. 2007), bake half:
// BillboardCloudBaker.h. Two techniques: the multi-layered cloud and the classic cloud it is
// measured against at equal memory (Fig. 13).
#include "TreeLod/BakeTechniques.h"
#include "TreeLod/BillboardCloudBaker.h"
#include "TreeLod/BillboardCloudData.h"

namespace TreeLod
{
    namespace
    {
        const BakeTechniqueRegistration layered(
            {BILLBOARD_CLOUD_CHUNK,
             "billboard cloud, multi-layered indirect texturing, García et al. 2007 (adds reference)",
             &addBillboardCloudChunk});
        const BakeTechniqueRegistration classic(
            {CLASSIC_BILLBOARD_CLOUD_CHUNK,
             "classic billboard cloud at equal memory, García et al. 2007 Fig. 13 (adds reference)",
             &addClassicBillboardCloudChunk});
    }
}
