// TechniqueDescriptor: the runtime half of a technique's core descriptor, and the registry of
// them. A technique's package chunks are named after it ("<technique>", ...); its
// descriptor says which format version this build reads, how to decode and validate a chunk
// (what `treelod info` prints, as text and JSON) and what the package fuzzer exercises after a
// successful decode. The bake half (the function that writes the chunks) is BakeTechniques.h.
//
// A technique registers itself once, in its own runtime target, with a namespace-scope
// TechniqueRegistration; the target is linked whole (CMake: treelod_add_technique) so that the
// registration runs. Every layer that needs to know the techniques (`treelod info`, the bake
// cache's key, the package fuzzer) iterates techniqueDescriptors() and names none. "reference",
// the polygonal tree every technique is measured against, is always registered.
#pragma once

#include "TreeLod/Result.h"

#include <cstdint>
#include <string>
#include <vector>

namespace TreeLod
{
    /// What `treelod info` shows of one decoded chunk.
    struct ChunkSummary
    {
        std::string text; ///< one line, without the technique's name or a newline
        std::string json; ///< a JSON object (serialised), e.g. {"leaves":1200,"bytes":4096}
    };

    struct TechniqueDescriptor
    {
        std::string name;        ///< chunk technique name, also the name on the command line
        std::string description; ///< one line for `treelod bake --help` and `treelod info`
        std::uint32_t formatVersion = 1; ///< of its chunks, the one this build reads
        /// Decode and validate the chunk of one level as a loader would; errors name `label`
        /// and the element. Never throws, whatever the bytes.
        Result<ChunkSummary> (*inspect)(const std::vector<std::uint8_t>& bytes, const std::string& label) = nullptr;
        /// For the package fuzzer: decode `bytes` and walk what a renderer reads from the result,
        /// trapping (__builtin_trap) where an invariant of the validated data does not hold. Null
        /// when inspect() alone covers what a renderer reads.
        void (*fuzz)(const std::vector<std::uint8_t>& bytes) = nullptr;
        /// The oldest version of its chunks this build still reads (0: formatVersion only), with
        /// inspectVersion, inspect of a chunk of the version given (from the package's chunk table).
        std::uint32_t oldestFormatVersion = 0;
        Result<ChunkSummary> (*inspectVersion)(const std::vector<std::uint8_t>& bytes, const std::string& label,
                                               std::uint32_t formatVersion) = nullptr;
    };

    /// Whether this build reads chunks of `formatVersion` of `descriptor`'s technique.
    bool readsFormatVersion(const TechniqueDescriptor& descriptor, std::uint32_t formatVersion);
    /// The versions it reads, for messages: "2", or "1..2".
    std::string readFormatVersions(const TechniqueDescriptor& descriptor);
    /// `descriptor`'s inspect of a chunk of `formatVersion`; an error naming `label` and the
    /// technique when this build does not read that version.
    Result<ChunkSummary> inspectChunk(const TechniqueDescriptor& descriptor, const std::vector<std::uint8_t>& bytes,
                                      const std::string& label, std::uint32_t formatVersion);

    /// Add (or replace, by name) a descriptor. Not thread-safe: registration happens during static
    /// initialisation or before any lookup.
    void registerTechniqueDescriptor(TechniqueDescriptor descriptor);
    /// Every registered technique, "reference" first, then by name.
    const std::vector<TechniqueDescriptor>& techniqueDescriptors();
    /// nullptr when no technique of that name is registered.
    const TechniqueDescriptor* findTechniqueDescriptor(const std::string& name);

    /// Registers a descriptor when constructed: one namespace-scope instance per technique.
    struct TechniqueRegistration
    {
        explicit TechniqueRegistration(TechniqueDescriptor descriptor)
        {
            registerTechniqueDescriptor(std::move(descriptor));
        }
    };
}
