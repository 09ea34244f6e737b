// The core descriptor of the crossed quads, bake half: CrossedQuadsBaker.h.
#include "TreeLod/BakeTechniques.h"
#include "TreeLod/CrossedQuadsBaker.h"
#include "TreeLod/CrossedQuadsData.h"

namespace TreeLod
{
    namespace
    {
        const BakeTechniqueRegistration registration(
            {CROSSED_QUADS_CHUNK,
             "two or three textured vertical quads crossing on the trunk axis, an example (adds reference)",
             &addCrossedQuadsChunk});
    }
}
