// The core descriptor of the one-quad impostor, bake half: ImpostorBaker.h.
#include "TreeLod/BakeTechniques.h"
#include "TreeLod/ImpostorBaker.h"
#include "TreeLod/ImpostorData.h"

namespace TreeLod
{
    namespace
    {
        const BakeTechniqueRegistration registration(
            {IMPOSTOR_CHUNK,
             "one camera-facing quad with baked colour and normal textures, the speed floor (adds reference)",
             &addImpostorChunk});
    }
}
