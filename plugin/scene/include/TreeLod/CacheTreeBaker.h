// CacheTreeBaker: the TreeBaker (TreeBaker.h) of programs that bake: `treelod bench`, the sample
// browser. Over a BakeCache, with the tree generator's presets registered as
// "preset:NAME?seed=S&leaves=N&height=H" sources. In TreeLodSceneBake (links TreeLodBake);
// programs that only draw read the list it writes with PackageListBaker (PackageListBaker.h).
#pragma once

#include "TreeLod/BakeCache.h"
#include "TreeLod/TreeBaker.h"

#include <string>
#include <vector>

namespace TreeLod
{
    class CacheTreeBaker : public TreeBaker
    {
    public:
        /// Progress goes to `progress`; every requirePackage() adds its BakeCacheEntry to getEntries().
        explicit CacheTreeBaker(const std::string& directory = defaultBakeCacheDirectory(),
                                ProgressCallback progress = {});

        /// @copydoc TreeBaker::requirePackage
        Ogre::String requirePackage(const Ogre::String& source, const std::vector<Ogre::String>& techniques) override;

        const std::vector<BakeCacheEntry>& getEntries() const { return mEntries; }
        const BakeCache& getCache() const { return mCache; }

        /// Writes (atomically) the JSON list PackageListBaker reads: one entry per source required
        /// so far, with every technique (chunk) its package holds and the package's path (both relative to the list's folder)
        /// (docs/scene-format.md, "Package lists"). Error naming `path` when it cannot write.
        Result<void> writePackageList(const std::string& path) const;

    private:
        BakeCache mCache;
        ProgressCallback mProgress;
        std::vector<BakeCacheEntry> mEntries;
    };
}
