// TreeInput: loading a tree file for a command (TreeInput.h).
#include "TreeInput.h"

#include "TreeLod/AtomicFile.h"
#include "TreeLod/BakeCache.h"
#include "TreeLod/BakeTechniques.h"
#include "TreeLod/ModelChunk.h"
#include "TreeLod/Package.h"
#include "TreeLod/PackageWriter.h"

#include <filesystem>

namespace TreeLod
{
    Result<TreeInput> loadTreeInput(const std::string& path, const std::vector<std::string>& leafMaterials,
                                    const ProgressCallback& progress, const MeshImporter& meshImporter,
                                    const std::vector<std::string>& chunks)
    {
        TreeInput input;
        input.name = std::filesystem::path(path).filename().string();
        const std::string ext = lowerCaseExtension(path);
        if (ext == ".treelod")
        {
            Result<PackageReader> package = PackageReader::open(path);
            if (!package)
                return package.error();
            Result<std::vector<std::uint8_t>> chunk = package->readChunk(REFERENCE_CHUNK, 0);
            if (!chunk)
                return chunk.error();
            Result<ReferenceChunk> reference = decodeReferenceChunk(chunk.value(), path);
            if (!reference)
                return reference.error();
            input.model = std::move(reference->model);
            for (const std::string& chunk : chunks)
                if (package->findChunk(chunk, 0) < 0)
                {
                    if (!hasPolygons(input.model)) // photographs bake only what bakes from a capture folder
                        return requirePolygons(input.model, path, "chunk '" + chunk + "'").error();
                    return fail(path, chunkElement(chunk, 0), "missing: bake the package with --technique " + chunk);
                }
            Result<std::vector<std::uint8_t>> bytes = readFile(path);
            if (!bytes)
                return bytes.error();
            input.packageBytes = std::move(bytes.value());
            return input;
        }
        if (ext != ".glb" && ext != ".gltf" && ext != ".mesh")
            return fail(path, "", "unknown tree format '" + ext + "' (expected .glb, .gltf, .mesh or .treelod)");
        if (ext == ".mesh" && !meshImporter)
            return fail(path, "", ".mesh input needs Ogre: use the Ogre renderer");
        Result<TreeModel> model = importTreeFile(path, leafMaterials, progress, meshImporter);
        if (!model)
            return model.error();
        input.model = std::move(model.value());
        PackageWriter writer;
        for (const std::string& chunk : chunks)
        {
            const BakeTechnique* technique = findBakeTechnique(chunk);
            if (!technique)
                return fail(path, "", "no baker for chunk '" + chunk + "' (known: " + knownBakeTechniques() + ")");
            Result<void> added = technique->bake(writer, input.model, {}, input.name, progress);
            if (!added)
                return added.error();
        }
        input.packageBytes = writer.toBytes();
        return input;
    }
}
