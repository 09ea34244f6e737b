#include "TreeLod/TechniqueDescriptor.h"

#include "TreeLod/ErrorCurves.h"
#include "TreeLod/ModelChunk.h"
#include "TreeLod/Package.h"

#include <nlohmann/json.hpp>

#include <algorithm>

namespace TreeLod
{
    namespace
    {
        Result<ChunkSummary> inspectReference(const std::vector<std::uint8_t>& bytes, const std::string& label)
        {
            Result<ReferenceChunk> chunk = decodeReferenceChunk(bytes, label);
            if (!chunk)
                return chunk.error();
            const TreeModel& model = chunk->model;
            std::uint64_t textureBytes = 0;
            for (const GpuTexture& t : chunk->textures)
                textureBytes += t.data.size();
            ChunkSummary summary;
            summary.text = std::to_string(model.barkIndices.size() / 3) + " bark triangles, " +
                           std::to_string(model.leaves.size()) + " leaves, " + std::to_string(model.materials.size()) +
                           " materials, " + std::to_string(chunk->textures.size()) + " textures (" +
                           std::to_string(textureBytes) + " bytes with mips)";
            summary.json = nlohmann::json{{"barkTriangles", model.barkIndices.size() / 3},
                                          {"leaves", model.leaves.size()},
                                          {"materials", model.materials.size()},
                                          {"textures", chunk->textures.size()},
                                          {"textureBytes", textureBytes}}
                               .dump();
            return summary;
        }

        void fuzzReference(const std::vector<std::uint8_t>& bytes)
        {
            Result<ReferenceChunk> decoded = decodeReferenceChunk(bytes, "fuzz");
            if (!decoded)
                return;
            // What a loader does next: walk the mips of each texture.
            for (const GpuTexture& t : decoded->textures)
                for (std::uint32_t level = 0; level < t.mipCount; ++level)
                    if (t.mipOffset(level) + t.mipBytes(level) > t.data.size())
                        __builtin_trap();
        }

        std::vector<TechniqueDescriptor>& registry()
        {
            static std::vector<TechniqueDescriptor> descriptors = {
                {REFERENCE_CHUNK, "the polygonal tree with GPU-ready mip-mapped textures",
                 REFERENCE_CHUNK_FORMAT_VERSION, &inspectReference, &fuzzReference},
                // Here, not by a TechniqueRegistration: nothing else may pull ErrorCurves.o out
                // of the static library, and the Ogre side writes the chunk, no baker.
                errorCurvesDescriptor()};
            return descriptors;
        }
    }

    void registerTechniqueDescriptor(TechniqueDescriptor descriptor)
    {
        std::vector<TechniqueDescriptor>& all = registry();
        auto same = std::find_if(all.begin(), all.end(),
                                 [&](const TechniqueDescriptor& d) { return d.name == descriptor.name; });
        if (same != all.end())
        {
            *same = std::move(descriptor);
            return;
        }
        // "reference" stays first; the others by name, so that every listing is stable whatever
        // the order static initialisation ran in.
        auto at = std::find_if(all.begin() + 1, all.end(),
                               [&](const TechniqueDescriptor& d) { return descriptor.name < d.name; });
        all.insert(at, std::move(descriptor));
    }

    const std::vector<TechniqueDescriptor>& techniqueDescriptors() { return registry(); }

    bool readsFormatVersion(const TechniqueDescriptor& descriptor, std::uint32_t formatVersion)
    {
        if (formatVersion == descriptor.formatVersion)
            return true;
        return descriptor.inspectVersion && descriptor.oldestFormatVersion != 0 &&
               formatVersion >= descriptor.oldestFormatVersion && formatVersion < descriptor.formatVersion;
    }

    std::string readFormatVersions(const TechniqueDescriptor& descriptor)
    {
        const bool older = descriptor.inspectVersion && descriptor.oldestFormatVersion != 0 &&
                           descriptor.oldestFormatVersion < descriptor.formatVersion;
        return (older ? std::to_string(descriptor.oldestFormatVersion) + ".." : std::string()) +
               std::to_string(descriptor.formatVersion);
    }

    Result<ChunkSummary> inspectChunk(const TechniqueDescriptor& descriptor, const std::vector<std::uint8_t>& bytes,
                                      const std::string& label, std::uint32_t formatVersion)
    {
        if (!readsFormatVersion(descriptor, formatVersion))
            return fail(label, descriptor.name,
                        "unsupported format version " + std::to_string(formatVersion) + ", this build reads " +
                            readFormatVersions(descriptor));
        if (descriptor.inspectVersion)
            return descriptor.inspectVersion(bytes, label, formatVersion);
        return descriptor.inspect(bytes, label);
    }

    const TechniqueDescriptor* findTechniqueDescriptor(const std::string& name)
    {
        for (const TechniqueDescriptor& d : registry())
            if (d.name == name)
                return &d;
        return nullptr;
    }
}
