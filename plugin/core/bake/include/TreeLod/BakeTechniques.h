// BakeTechniques: the bake half of a technique's core descriptor (TechniqueDescriptor.h), and the
// registry of them, shared by `treelod bake` (to a file), `render`/`info` on a .glb (baked in
// memory) and the lazy baking cache (BakeCache.h). A technique registers its bake function once,
// in its own bake target, with a namespace-scope BakeTechniqueRegistration; "reference" is always
// registered. Nothing here names a technique.
#pragma once

#include "TreeLod/PackageWriter.h"

#include <map>
#include <string>
#include <vector>

namespace TreeLod
{
    /// The values given for one baker's options, by option name, as text (`treelod bake --option
    /// TECHNIQUE.NAME=VALUE`; in a bake cache's options JSON, {"TECHNIQUE": {"NAME": VALUE}}).
    using BakeOptions = std::map<std::string, std::string>;

    /// Adds a technique's chunks for `model` to the package (and the chunks it needs, such as the
    /// reference, when missing), with `options` (checked by checkBakeOptions: only declared names);
    /// `label` names the output in errors.
    using BakeFunction = Result<void> (*)(PackageWriter& writer, const TreeModel& model, const BakeOptions& options,
                                          const std::string& label, const ProgressCallback& progress);
    /// Adds a technique's chunks baked from the capture folder `folder` (photographs and their
    /// cameras, no polygons) and a reference of bounds only; `source` names the tree in them.
    using CaptureBakeFunction = Result<void> (*)(PackageWriter& writer, const std::string& folder,
                                                 const std::string& source, const BakeOptions& options,
                                                 const std::string& label, const ProgressCallback& progress);

    /// One option a baker reads.
    struct BakeOptionInfo
    {
        std::string name;
        std::string description; ///< with its range and unit
        std::string defaultValue;
    };

    struct BakeTechnique
    {
        const char* name; ///< the chunk's technique name ("reference", ...)
        const char* description;
        BakeFunction bake;
        std::vector<BakeOptionInfo> options; ///< what `options` may hold
        CaptureBakeFunction bakeCapture = nullptr; ///< null: bakes from polygons only
    };

    /// Add (or replace, by name) a baker. Registration happens during static initialisation.
    void registerBakeTechnique(const BakeTechnique& technique);
    /// Every registered baker, "reference" first, then by name.
    const std::vector<BakeTechnique>& bakeTechniques();
    const BakeTechnique* findBakeTechnique(const std::string& name);
    /// "reference, <technique>, ..." for messages.
    std::string knownBakeTechniques();

    /// An error naming `label` and "option '<technique>.<name>'" for a name `technique` does not
    /// declare (the declared ones listed).
    Result<void> checkBakeOptions(const BakeTechnique& technique, const BakeOptions& options, const std::string& label);
    /// One "TECHNIQUE.NAME=VALUE" (`treelod bake --option`), split.
    struct BakeOptionAssignment
    {
        std::string technique, name, value;
    };
    /// Splits `text`; an error naming "option --option '<text>'" when it has no '.' before an '='.
    Result<BakeOptionAssignment> parseBakeOptionAssignment(const std::string& text);

    /// Option `name` of `options` as a number in [lo, hi], `fallback` when absent; errors name `label`
    /// and "option '<technique>.<name>'".
    Result<double> bakeOptionNumber(const BakeOptions& options, const std::string& technique, const std::string& name,
                                    double fallback, double lo, double hi, const std::string& label);
    /// Option `name` as true or false, `fallback` when absent.
    Result<bool> bakeOptionFlag(const BakeOptions& options, const std::string& technique, const std::string& name,
                                bool fallback, const std::string& label);

    /// Registers a baker when constructed: one namespace-scope instance per technique.
    struct BakeTechniqueRegistration
    {
        explicit BakeTechniqueRegistration(const BakeTechnique& technique) { registerBakeTechnique(technique); }
    };
}
