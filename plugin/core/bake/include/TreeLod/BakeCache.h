// BakeCache: scene-driven, lazy baking ("model only what a scene requires").
//
// A scene names, per tree, a source and the techniques it draws it with; require() returns a
// package holding those chunks, baking only the ones the cache lacks and reporting what it
// built and what it reused.
//
// Layout: one package per (source content, options): <directory>/<stem>-<16 hex>.treelod,
// the hex being FNV-1a 64 over the source's content hash (sourceHashOf), the canonical options JSON and the
// package and chunk format versions (a format change gives new files; old ones are never read
// again and may be deleted). The technique list is not part of the key: the package holds every
// chunk asked for so far, and a request for a new technique bakes that one alone and rewrites the
// package with the other chunks' bytes copied unchanged. The "meta" chunk (PackageWriter.h)
// records the source, its hash, the options and the sorted technique list, so the same chunks
// give the same bytes however many requests built them.
//
// Sources:
// - A file path. Its key hashes the file's bytes; for a .gltf (JSON) also the bytes of the
//   external buffers and images it references. .glb/.gltf are imported with importGltf
//   (options "leafMaterials", as `treelod bake` records them); other formats (Ogre .mesh) need
//   the caller's ImportFunction, which must read what optionsJson describes.
// - "scheme:rest" where `scheme` was registered with addGenerator(), e.g.
//   "preset:oak?leaves=20000&seed=1": the generator makes the model and the key hashes the
//   source string, so the string must spell every generator option that changes the tree.
//
// Failures: unknown technique, missing or unreadable source, import or bake errors return an
// Error naming the source (or the cache file) and write nothing. A write that fails (a full
// disk: EFBIG, ENOSPC) returns an Error naming the cache file and the OS's reason, leaves the
// package cached before byte for byte as it was and no temporary file (AtomicFile.h); the next
// request reuses what it holds. A cached file that cannot be used (truncated, checksum mismatch,
// foreign meta) is rebaked whole and the entry says why. A request that finds everything
// verifies only the chunks it returns (its techniques' and the reference); one that rewrites the
// package verifies every chunk it copies.
//
// Concurrency: packages are written to a temporary file of the writer's own (process id and
// counter), synced and renamed (PackageWriter::write), so a reader sees an old or a new package,
// never a torn one; and it reads the whole request from the file it opened (PackageReader), so a
// package renamed over it meanwhile is not taken for a damaged one. Two processes (or threads)
// baking the same key both produce complete files and the last rename wins; if they asked for
// different techniques, one set may be lost and is baked again by the next request that needs
// it. No lock is taken: the cost of a race is repeated work, not a corrupt cache.
// tests/core/BakeCacheProcessTest.cpp checks both: a full disk in a child process (RLIMIT_FSIZE;
// a small tmpfs where a mount namespace is allowed), and two processes baking at once.
#pragma once

#include "TreeLod/GltfImporter.h"
#include "TreeLod/Progress.h"
#include "TreeLod/Result.h"
#include "TreeLod/TreeModel.h"

#include <functional>
#include <map>
#include <string>
#include <vector>

namespace TreeLod
{
    /// Reads a tree file the cache has no importer for (the Ogre side's .mesh reader). `path` as
    /// given to BakeCache::require().
    using ImportFunction = std::function<Result<TreeModel>(const std::string& path)>;

    /// The extension of `path` with its dot, lower-cased: "Oak.GLB" -> ".glb".
    std::string lowerCaseExtension(const std::string& path);

    /// "fnv1a64:" + 16 hex digits identifying a tree file's content: FNV-1a 64 over its bytes and,
    /// for a .gltf (JSON), the external buffers and images it references (missing ones hash as
    /// missing; the import reports them). For a directory, a capture folder (CaptureSet.h): its
    /// cameras.json and the image of each camera it lists, in its order (missing ones hash as
    /// missing; readCaptureSet reports them). The meta chunk's "sourceHash" of `treelod bake` and
    /// of the cache. Error when the file (cameras.json) cannot be read.
    Result<std::string> sourceHashOf(const std::string& path);

    /// Imports a tree file: .glb/.gltf with importGltf (`leafMaterials` as ImportOptions, `progress`
    /// its steps, `report` filled when given), any other format with `import`; an error naming
    /// the file and its extension when that is empty.
    Result<TreeModel> importTreeFile(const std::string& path, const std::vector<std::string>& leafMaterials,
                                     const ProgressCallback& progress, const ImportFunction& import = {},
                                     ImportReport* report = nullptr);

    /// Makes a tree from a whole source string ("preset:oak?leaves=20000&seed=1").
    using GenerateFunction =
        std::function<Result<TreeModel>(const std::string& source, const ProgressCallback& progress)>;

    /// What one BakeCache::require() call found and did.
    struct BakeCacheEntry
    {
        std::string source;                        ///< as given to require()
        std::string name;                          ///< for messages: the file name, or the whole generator source
        std::string path;                          ///< the cached package holding every requested chunk
        std::vector<std::string> builtTechniques;  ///< baked by this call, in request order
        std::vector<std::string> reusedTechniques; ///< already in the cache, in request order
        double bakeSeconds = 0.0; ///< wall time of import, bake and write; exactly 0 when nothing was built
        std::string discardedReason; ///< why an existing cache file was thrown away, "" if none was

        /// One line for the user, e.g.
        /// "oak.glb: baked <technique> (1.9 s), reused reference, <technique> -> /home/u/.cache/treelod/oak-....treelod"
        std::string describe() const;
    };

    /// `$XDG_CACHE_HOME/treelod` when XDG_CACHE_HOME is an absolute path (the XDG Base Directory
    /// specification ignores relative ones), else `$HOME/.cache/treelod`, else
    /// `<system temp dir>/treelod-cache` when HOME is unset too.
    std::string defaultBakeCacheDirectory();

    class BakeCache
    {
    public:
        /// `directory` is created (with its parents) by the first require() that writes.
        explicit BakeCache(std::string directory = defaultBakeCacheDirectory());

        const std::string& directory() const { return mDirectory; }

        /// Sources "scheme:..." are made by `generate` (replacing one registered before). Error
        /// unless `scheme` is two or more characters of [a-z0-9-], so that no path ("C:/...",
        /// "./a:b") reads as one.
        Result<void> addGenerator(const std::string& scheme, GenerateFunction generate);

        /// A package at path() holding the chunks of every technique in `techniques` (names of
        /// BakeTechniques.h; duplicates ignored) for `source` baked with `optionsJson` (a JSON
        /// object; "" means {}; key order and spacing do not matter: "leafMaterials" for the
        /// importer, and per technique an object of its BakeOptions, {"<technique>": {"<option>": 32}},
        /// checked against what the baker declares before anything is read). Chunks already cached are
        /// reused, the others baked from one import of the source. `import` reads file formats
        /// other than glTF. `progress` sees the importer's and bakers' steps, prefixed with the
        /// source's name and technique ("oak.glb <technique>: <step>"); "warning: ..." steps keep
        /// their prefix. Safe to call from several threads, though not during addGenerator() (see the
        /// header comment on races).
        Result<BakeCacheEntry> require(const std::string& source, const std::vector<std::string>& techniques,
                                       const std::string& optionsJson, const ProgressCallback& progress = {},
                                       const ImportFunction& import = {}) const;

        /// The file require() uses for (source, options), without importing or baking; reads a
        /// file source to hash it. Errors as require().
        Result<std::string> packagePath(const std::string& source, const std::string& optionsJson) const;

    private:
        struct Key;
        Result<Key> makeKey(const std::string& source, const std::string& optionsJson) const;

        std::string mDirectory;
        std::map<std::string, GenerateFunction> mGenerators;
    };
}
