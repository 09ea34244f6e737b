// PackageListBaker: the TreeBaker (TreeBaker.h) of programs that draw but never bake
// (treelod_frames; docs/architecture.md, "Runtime vs bake"). It answers requirePackage() from a
// package list, the JSON file CacheTreeBaker::writePackageList() writes after baking
// (docs/scene-format.md, "Package lists"):
//   {"format": "treelod-package-list", "version": 1,
//    "packages": [{"source": "../media/oak.glb", "techniques": ["<technique>", "reference"],
//                  "path": "cache/oak-1234.treelod"}]}
// File sources and package paths are stored relative to the list's folder (absolute when they
// share no root), so a checkout copied to another machine (a GPU device) still finds them.
// In TreeLodScene: links no baker.
#pragma once

#include "TreeLod/TreeBaker.h"

#include <string>
#include <vector>

namespace TreeLod
{
    class PackageListBaker : public TreeBaker
    {
    public:
        static constexpr const char* FORMAT = "treelod-package-list";
        static constexpr int VERSION = 1;

        /// Reads the list at `path`. Throws Ogre::Exception naming the file and the entry when it
        /// is missing, not JSON, of another format or version, or an entry lacks a key. Package
        /// files are not opened here (TreeAssetManager reads them).
        explicit PackageListBaker(const std::string& path);

        /// The path of the entry for `source` that holds every one of `techniques`. Throws
        /// Ogre::Exception naming the list file, the source and the techniques the list lacks for
        /// it ("run `treelod bench`, which bakes them") when there is none.
        Ogre::String requirePackage(const Ogre::String& source, const std::vector<Ogre::String>& techniques) override;

        struct Entry
        {
            std::string source;
            std::vector<std::string> techniques; ///< sorted
            std::string path;
        };
        const std::vector<Entry>& getEntries() const { return mEntries; }
        const std::string& getPath() const { return mPath; }

        /// An entry of the list at `listPath` as an absolute, normal path ("preset:..." as it is).
        static std::string resolve(const std::string& listPath, const std::string& entry);
        /// The inverse: `entry` relative to the list's folder ("preset:..." as it is).
        static std::string relativeTo(const std::string& listPath, const std::string& entry);

    private:
        std::string mPath;
        std::vector<Entry> mEntries;
    };
}
