#include "TreeLod/PackageListBaker.h"

#include "TreeLod/AtomicFile.h"

#include <OgreException.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>

namespace TreeLod
{
    namespace
    {
        [[noreturn]] void badList(const std::string& path, const std::string& where, const std::string& reason)
        {
            OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS,
                        "package list " + path + ": " + (where.empty() ? "" : where + ": ") + reason,
                        "PackageListBaker");
        }
    }

    std::string PackageListBaker::resolve(const std::string& listPath, const std::string& entry)
    {
        if (entry.rfind("preset:", 0) == 0 || entry.empty())
            return entry;
        std::filesystem::path p(entry);
        if (p.is_relative())
            p = std::filesystem::absolute(std::filesystem::path(listPath).parent_path()) / p;
        return p.lexically_normal().string();
    }

    std::string PackageListBaker::relativeTo(const std::string& listPath, const std::string& entry)
    {
        if (entry.rfind("preset:", 0) == 0 || entry.empty())
            return entry;
        const std::filesystem::path base =
            std::filesystem::absolute(std::filesystem::path(listPath).parent_path()).lexically_normal();
        const std::filesystem::path relative =
            std::filesystem::absolute(entry).lexically_normal().lexically_relative(base);
        return relative.empty() ? entry : relative.string();
    }

    PackageListBaker::PackageListBaker(const std::string& path) : mPath(path)
    {
        Result<std::vector<std::uint8_t>> bytes = readFile(path);
        if (!bytes)
            badList(path, "", bytes.error().reason);
        nlohmann::json list;
        try
        {
            list = nlohmann::json::parse(bytes->begin(), bytes->end());
        }
        catch (const nlohmann::json::exception& e)
        {
            badList(path, "", std::string("not JSON (") + e.what() + ")");
        }
        const auto text = [&](const nlohmann::json& j, const char* key, const std::string& where) {
            auto it = j.find(key);
            if (it == j.end() || !it->is_string() || it->get<std::string>().empty())
                badList(path, where, std::string("expected a non-empty string '") + key + "'");
            return it->get<std::string>();
        };
        if (!list.is_object() || list.value("format", "") != FORMAT)
            badList(path, "", std::string("not a package list (\"format\": \"") + FORMAT + "\")");
        if (list.value("version", 0) != VERSION)
            badList(path, "", "version " + list.value("version", nlohmann::json()).dump() + " (this program reads " +
                                  std::to_string(VERSION) + ")");
        auto packages = list.find("packages");
        if (packages == list.end() || !packages->is_array())
            badList(path, "", "expected an array 'packages'");
        for (std::size_t i = 0; i < packages->size(); ++i)
        {
            const nlohmann::json& p = (*packages)[i];
            const std::string where = "packages[" + std::to_string(i) + "]";
            if (!p.is_object())
                badList(path, where, "expected an object");
            Entry entry;
            entry.source = resolve(path, text(p, "source", where));
            entry.path = resolve(path, text(p, "path", where));
            auto techniques = p.find("techniques");
            if (techniques == p.end() || !techniques->is_array())
                badList(path, where, "expected an array 'techniques'");
            for (const nlohmann::json& t : *techniques)
            {
                if (!t.is_string())
                    badList(path, where, "'techniques' holds a " + std::string(t.type_name()) + ", not a name");
                entry.techniques.push_back(t.get<std::string>());
            }
            std::sort(entry.techniques.begin(), entry.techniques.end());
            mEntries.push_back(std::move(entry));
        }
    }

    Ogre::String PackageListBaker::requirePackage(const Ogre::String& source,
                                                  const std::vector<Ogre::String>& techniques)
    {
        // The request's file path is the caller's (relative to the working directory); the list's
        // entries are relative to the list's folder (resolve()).
        const std::string wanted = source.rfind("preset:", 0) == 0
                                       ? source
                                       : std::filesystem::absolute(source).lexically_normal().string();
        std::vector<std::string> missing = techniques; // of the entry that lacks the fewest
        bool listed = false;
        for (const Entry& e : mEntries)
        {
            if (e.source != wanted)
                continue;
            listed = true;
            std::vector<std::string> lacks;
            for (const std::string& t : techniques)
                if (!std::binary_search(e.techniques.begin(), e.techniques.end(), t) &&
                    std::find(lacks.begin(), lacks.end(), t) == lacks.end())
                    lacks.push_back(t);
            if (lacks.empty())
                return e.path;
            if (lacks.size() < missing.size())
                missing = lacks;
        }
        std::string names;
        for (const std::string& t : missing)
            names += (names.empty() ? "" : ", ") + t;
        OGRE_EXCEPT(Ogre::Exception::ERR_ITEM_NOT_FOUND,
                    "package list " + mPath + ": " +
                        (listed ? "the package of " + source + " lacks " + names
                                : "no package for " + source + " (techniques " + names + ")") +
                        "; run `treelod bench`, which bakes them",
                    "PackageListBaker::requirePackage");
    }
}
