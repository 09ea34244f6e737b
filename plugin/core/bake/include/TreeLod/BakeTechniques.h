// BakeTechniques: the bake half of a technique's core descriptor (TechniqueDescriptor.h), and the
// registry of them, shared by `treelod bake` (to a file), `render`/`info` on a .glb (baked in
// memory) and the lazy baking cache (BakeCache.h). A technique registers its bake function once,
// in its own bake target, with a namespace-scope BakeTechniqueRegistration; "reference" is always
// registered. Nothing here names a technique.
#pragma once

#include "TreeLod/PackageWriter.h"

#include <string>
#include <vector>

namespace TreeLod
{
    /// Adds a technique's chunks for `model` to the package (and the chunks it needs, such as the
    /// reference, when missing); `label` names the output in errors.
    using BakeFunction = Result<void> (*)(PackageWriter& writer, const TreeModel& model, const std::string& label,
                                          const ProgressCallback& progress);

    struct BakeTechnique
    {
        const char* name; ///< the chunk's technique name ("reference", "lodf", ...)
        const char* description;
        BakeFunction bake;
    };

    /// Add (or replace, by name) a baker. Registration happens during static initialisation.
    void registerBakeTechnique(const BakeTechnique& technique);
    /// Every registered baker, "reference" first, then by name.
    const std::vector<BakeTechnique>& bakeTechniques();
    const BakeTechnique* findBakeTechnique(const std::string& name);
    /// "reference, lodf" for messages.
    std::string knownBakeTechniques();

    /// Registers a baker when constructed: one namespace-scope instance per technique.
    struct BakeTechniqueRegistration
    {
        explicit BakeTechniqueRegistration(const BakeTechnique& technique) { registerBakeTechnique(technique); }
    };
}
