#include "TreeLod/CacheTreeBaker.h"

#include "TreeLod/AtomicFile.h"
#include "TreeLod/PackageListBaker.h"
#include "TreeLod/TreeGenerator.h"

#include <OgreException.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <set>

namespace TreeLod
{
    namespace
    {
        /// "preset:NAME?seed=S&leaves=N&height=H" (every key optional) -> generateTree.
        Result<TreeModel> generatePreset(const std::string& source, const ProgressCallback& progress)
        {
            const std::string body = source.substr(source.find(':') + 1);
            const std::size_t q = body.find('?');
            GeneratorOptions options;
            if (!parsePreset(body.substr(0, q), options.preset))
                return fail(source, "preset", "unknown preset '" + body.substr(0, q) + "' (known: " +
                                                  presetNames() + ")");
            std::string query = q == std::string::npos ? "" : body.substr(q + 1);
            while (!query.empty())
            {
                const std::size_t amp = query.find('&');
                const std::string pair = query.substr(0, amp);
                query = amp == std::string::npos ? "" : query.substr(amp + 1);
                const std::size_t eq = pair.find('=');
                const std::string key = pair.substr(0, eq);
                const std::string value = eq == std::string::npos ? "" : pair.substr(eq + 1);
                char* end = nullptr;
                const double number = std::strtod(value.c_str(), &end);
                if (value.empty() || *end != '\0' || !std::isfinite(number) || number < 0.0)
                    return fail(source, key, "'" + value + "' is not a non-negative number");
                if (key == "seed")
                    options.seed = std::uint32_t(number);
                else if (key == "leaves")
                    options.leafCount = std::uint32_t(number);
                else if (key == "height")
                    options.height = float(number);
                else
                    return fail(source, key, "unknown generator option (known: seed, leaves, height)");
            }
            return generateTree(options, progress);
        }
    }

    CacheTreeBaker::CacheTreeBaker(const std::string& directory, ProgressCallback progress)
        : mCache(directory), mProgress(std::move(progress))
    {
        Result<void> r = mCache.addGenerator("preset", generatePreset);
        OgreAssert(bool(r), "the preset scheme is valid");
    }

    Ogre::String CacheTreeBaker::requirePackage(const Ogre::String& source, const std::vector<Ogre::String>& techniques)
    {
        Result<BakeCacheEntry> entry = mCache.require(source, techniques, "", mProgress);
        if (!entry)
            OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS, entry.error().message(), "CacheTreeBaker::requirePackage");
        mEntries.push_back(*entry);
        return entry->path;
    }

    Result<void> CacheTreeBaker::writePackageList(const std::string& path) const
    {
        // A source's package holds every chunk asked for so far (BakeCache.h): its entries' union,
        // at the path of its last entry.
        std::map<std::string, std::pair<std::string, std::set<std::string>>> packages; // source -> (path, techniques)
        for (const BakeCacheEntry& e : mEntries)
        {
            auto& [packagePath, techniques] = packages[PackageListBaker::relativeTo(path, e.source)];
            packagePath = PackageListBaker::relativeTo(path, e.path);
            techniques.insert(e.builtTechniques.begin(), e.builtTechniques.end());
            techniques.insert(e.reusedTechniques.begin(), e.reusedTechniques.end());
        }
        nlohmann::json list = {{"format", PackageListBaker::FORMAT}, {"version", PackageListBaker::VERSION},
                               {"packages", nlohmann::json::array()}};
        for (const auto& [source, package] : packages)
            list["packages"].push_back({{"source", source},
                                        {"techniques", std::vector<std::string>(package.second.begin(),
                                                                                package.second.end())},
                                        {"path", package.first}});
        const std::string text = list.dump(2) + "\n";
        return writeFileAtomic(path, std::vector<std::uint8_t>(text.begin(), text.end()));
    }
}
