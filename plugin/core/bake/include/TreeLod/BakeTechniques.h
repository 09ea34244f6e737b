// The chunks TreeLodBake can bake: one entry per technique, shared by `treelod bake` (to a
// file), `render`/`info` on a .glb (baked in memory) and the lazy baking cache (BakeCache.h).
// A new technique adds one line in BakeTechniques.cpp.
#pragma once

#include "TreeLod/PackageWriter.h"

#include <string>
#include <vector>

namespace TreeLod
{
    /// Adds a technique's chunks for `model` to the package; `label` names the output in errors.
    using BakeFunction = Result<void> (*)(PackageWriter& writer, const TreeModel& model, const std::string& label,
                                          const ProgressCallback& progress);

    struct BakeTechnique
    {
        const char* name; ///< the chunk's technique name ("reference", "lodf", ...)
        const char* description;
        BakeFunction bake;
    };

    const std::vector<BakeTechnique>& bakeTechniques();
    const BakeTechnique* findBakeTechnique(const std::string& name);
    /// "reference, lodf" for messages.
    std::string knownBakeTechniques();
}
