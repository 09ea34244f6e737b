// BakeCache: keys, cache file validation, and baking only the missing techniques (BakeCache.h).
#include "TreeLod/BakeCache.h"

#include "TreeLod/AtomicFile.h"
#include "TreeLod/BakeTechniques.h"
#include "TreeLod/GltfImporter.h"
#include "TreeLod/ModelChunk.h"
#include "TreeLod/Package.h"
#include "TreeLod/PackageWriter.h"
#include "TreeLod/TechniqueDescriptor.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <map>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <set>

namespace TreeLod
{
    namespace
    {
        /// Bump when a baker's output changes without a chunk format version change, so that
        /// caches made by older builds are not reused.
        constexpr int BAKE_CACHE_KEY_VERSION = 11;

        std::string hex16(std::uint64_t value)
        {
            char text[17];
            std::snprintf(text, sizeof(text), "%016llx", (unsigned long long)value);
            return text;
        }

        std::uint64_t hashString(const std::string& text) { return fnv1a64(text.data(), text.size()); }

        /// A file-name-safe stem: [A-Za-z0-9._] kept, runs of anything else one '-', at most 48 bytes.
        std::string safeStem(const std::string& text)
        {
            std::string out;
            for (char c : text)
            {
                const bool keep = std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_';
                if (keep)
                    out += c;
                else if (!out.empty() && out.back() != '-')
                    out += '-';
                if (out.size() >= 48)
                    break;
            }
            while (!out.empty() && (out.back() == '-' || out.back() == '.'))
                out.pop_back();
            return out.empty() ? "tree" : out;
        }

        std::string percentDecode(const std::string& uri)
        {
            std::string out;
            for (std::size_t i = 0; i < uri.size(); ++i)
            {
                if (uri[i] == '%' && i + 2 < uri.size() && std::isxdigit(static_cast<unsigned char>(uri[i + 1])) &&
                    std::isxdigit(static_cast<unsigned char>(uri[i + 2])))
                {
                    out += char(std::stoi(uri.substr(i + 1, 2), nullptr, 16));
                    i += 2;
                }
                else
                    out += uri[i];
            }
            return out;
        }

        /// Hash of a file source: its bytes and, for glTF JSON, the external buffers and images it
        /// names (so that editing a .bin or a texture beside a .gltf is a new key). References
        /// that cannot be read hash as missing; the import reports them.
        Result<std::uint64_t> hashFileSource(const std::string& path)
        {
            Result<std::vector<std::uint8_t>> bytes = readFile(path);
            if (!bytes)
                return bytes.error();
            std::string digest = "file " + hex16(fnv1a64(bytes->data(), bytes->size()));
            const auto first =
                std::find_if(bytes->begin(), bytes->end(), [](std::uint8_t c) { return !std::isspace(c); });
            if (first != bytes->end() && *first == '{')
            {
                const nlohmann::json json = nlohmann::json::parse(bytes->begin(), bytes->end(), nullptr, false);
                const std::filesystem::path dir = std::filesystem::path(path).parent_path();
                for (const char* list : {"buffers", "images"})
                {
                    if (!json.is_object() || !json.contains(list) || !json[list].is_array())
                        continue;
                    for (const nlohmann::json& item : json[list])
                    {
                        if (!item.is_object() || !item.contains("uri") || !item["uri"].is_string())
                            continue;
                        const std::string uri = item["uri"].get<std::string>();
                        if (uri.rfind("data:", 0) == 0)
                            continue;
                        Result<std::vector<std::uint8_t>> ref = readFile((dir / percentDecode(uri)).string());
                        digest += "\n" + uri + " " +
                                  (ref ? hex16(fnv1a64(ref->data(), ref->size())) : std::string("missing"));
                    }
                }
            }
            return hashString(digest);
        }

        /// Hash of a capture folder (CaptureSet.h): cameras.json's bytes and those of the image
        /// each of its cameras names, in order. Images that cannot be read hash as missing;
        /// readCaptureSet reports them.
        Result<std::uint64_t> hashCaptureFolder(const std::string& folder)
        {
            const std::filesystem::path dir(folder);
            Result<std::vector<std::uint8_t>> bytes = readFile((dir / "cameras.json").string());
            if (!bytes)
                return bytes.error();
            std::string digest = "capture " + hex16(fnv1a64(bytes->data(), bytes->size()));
            const nlohmann::json json = nlohmann::json::parse(bytes->begin(), bytes->end(), nullptr, false);
            if (json.is_object() && json.contains("cameras") && json["cameras"].is_array())
                for (const nlohmann::json& camera : json["cameras"])
                {
                    if (!camera.is_object() || !camera.contains("image") || !camera["image"].is_string())
                        continue;
                    const std::string image = camera["image"].get<std::string>();
                    Result<std::vector<std::uint8_t>> file = readFile((dir / image).string());
                    digest += "\n" + image + " " +
                              (file ? hex16(fnv1a64(file->data(), file->size())) : std::string("missing"));
                }
            return hashString(digest);
        }

        /// The options as compact JSON with sorted keys; "" is {}.
        Result<std::string> canonicalOptions(const std::string& source, const std::string& optionsJson)
        {
            if (optionsJson.find_first_not_of(" \t\r\n") == std::string::npos)
                return std::string("{}");
            const nlohmann::json json = nlohmann::json::parse(optionsJson, nullptr, false);
            if (json.is_discarded() || !json.is_object())
                return fail(source, "bake options", "not a JSON object: " + optionsJson);
            return json.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
        }

        /// Importer and baker steps shown as "<prefix>: step"; warnings stay warnings.
        ProgressCallback prefixed(const ProgressCallback& progress, const std::string& prefix)
        {
            if (!progress)
                return {};
            return [progress, prefix](const std::string& step, float fraction) {
                if (step.rfind("warning:", 0) == 0)
                    progress("warning: " + prefix + ":" + step.substr(8), fraction);
                else
                    progress(prefix + ": " + step, fraction);
            };
        }

        /// A chunk of the cached package, copied into the rewritten one byte for byte.
        struct CachedChunk
        {
            ChunkInfo info;
            std::vector<std::uint8_t> bytes;
        };

        /// The cache file opened, its meta checked against the key and the chunks a request for
        /// `requested` returns (theirs and the reference every technique adds) verified; an Error
        /// says why the file is unusable. Other chunks are not read.
        Result<PackageReader> openCachedPackage(const std::string& path, const std::string& sourceHash,
                                                const std::string& options, const std::set<std::string>& requested)
        {
            Result<PackageReader> reader = PackageReader::open(path);
            if (!reader)
                return reader.error();
            Result<std::vector<std::uint8_t>> meta = reader->readChunk(META_CHUNK, 0);
            if (!meta)
                return meta.error();
            const nlohmann::json json = nlohmann::json::parse(meta->begin(), meta->end(), nullptr, false);
            if (json.is_discarded() || !json.is_object() || !json.contains("sourceHash") || !json.contains("options"))
                return fail(path, chunkElement(META_CHUNK, 0), "not the JSON object a bake writes");
            if (json["sourceHash"] != sourceHash ||
                json["options"].dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) != options)
                return fail(path, chunkElement(META_CHUNK, 0), "made for another source or options");
            for (std::size_t i = 0; i < reader->chunks().size(); ++i)
            {
                const std::string& technique = reader->chunks()[i].technique;
                if (technique != REFERENCE_CHUNK && !requested.count(technique))
                    continue;
                Result<std::vector<std::uint8_t>> bytes = reader->readChunk(i);
                if (!bytes)
                    return bytes.error();
            }
            return reader;
        }

        /// Every chunk of the cached package but "meta", each CRC-checked.
        Result<std::vector<CachedChunk>> readCachedChunks(const PackageReader& reader)
        {
            std::vector<CachedChunk> chunks;
            for (std::size_t i = 0; i < reader.chunks().size(); ++i)
            {
                const ChunkInfo& info = reader.chunks()[i];
                if (info.technique == META_CHUNK)
                    continue;
                Result<std::vector<std::uint8_t>> bytes = reader.readChunk(i);
                if (!bytes)
                    return bytes.error();
                chunks.push_back({info, std::move(bytes.value())});
            }
            return chunks;
        }

        /// The "leafMaterials" option (canonical options JSON) for importGltf.
        Result<std::vector<std::string>> leafMaterialsOption(const std::string& source, const std::string& options)
        {
            const nlohmann::json json = nlohmann::json::parse(options);
            if (!json.contains("leafMaterials"))
                return std::vector<std::string>();
            const nlohmann::json& names = json["leafMaterials"];
            bool strings = names.is_array();
            if (strings)
                for (const nlohmann::json& n : names)
                    strings = strings && n.is_string();
            if (!strings)
                return fail(source, "bake options", "\"leafMaterials\" must be an array of strings");
            return names.get<std::vector<std::string>>();
        }

        /// The options of baker `technique` in the bake options (key technique.name: an object of
        /// strings, numbers or booleans), checked against what it declares.
        Result<BakeOptions> techniqueOptions(const std::string& source, const std::string& options,
                                             const BakeTechnique& technique)
        {
            const nlohmann::json json = nlohmann::json::parse(options);
            BakeOptions values;
            if (!json.contains(technique.name))
                return values;
            const nlohmann::json& object = json[technique.name];
            if (!object.is_object())
                return fail(source, "bake options", "\"" + std::string(technique.name) + "\" must be an object");
            for (const auto& [name, value] : object.items())
            {
                if (value.is_string())
                    values[name] = value.get<std::string>();
                else if (value.is_number() || value.is_boolean())
                    values[name] = value.dump();
                else
                    return fail(source, "bake options",
                                "\"" + std::string(technique.name) + "." + name + "\" must be a string, number or boolean");
            }
            if (Result<void> checked = checkBakeOptions(technique, values, source); !checked)
                return checked.error();
            return values;
        }

        std::string joined(const std::vector<std::string>& names)
        {
            std::string out;
            for (const std::string& n : names)
                out += (out.empty() ? "" : ", ") + n;
            return out;
        }
    }

    struct BakeCache::Key
    {
        std::string name;       ///< for messages: the file name, or the whole generator source
        std::string sourceHash; ///< "fnv1a64:" + 16 hex, recorded in the meta chunk
        std::string options;    ///< canonical options JSON
        std::string path;       ///< the cache file
        const GenerateFunction* generator = nullptr; ///< null for file sources
    };

    std::string BakeCacheEntry::describe() const
    {
        std::string out = (name.empty() ? source : name) + ":";
        if (!discardedReason.empty())
            out += " discarded the cached package (" + discardedReason + "),";
        if (!builtTechniques.empty())
        {
            char seconds[32];
            std::snprintf(seconds, sizeof(seconds), "%.1f s", bakeSeconds);
            out += " baked " + joined(builtTechniques) + " (" + seconds + ")";
        }
        if (!reusedTechniques.empty())
            out += std::string(builtTechniques.empty() ? "" : ",") + " reused " + joined(reusedTechniques);
        return out + " -> " + path;
    }

    std::string lowerCaseExtension(const std::string& path)
    {
        std::string ext = std::filesystem::path(path).extension().string();
        for (char& c : ext)
            c = char(std::tolower(static_cast<unsigned char>(c)));
        return ext;
    }

    Result<std::string> sourceHashOf(const std::string& path)
    {
        std::error_code ec;
        Result<std::uint64_t> hash =
            std::filesystem::is_directory(path, ec) ? hashCaptureFolder(path) : hashFileSource(path);
        if (!hash)
            return hash.error();
        return "fnv1a64:" + hex16(hash.value());
    }

    Result<TreeModel> importTreeFile(const std::string& path, const std::vector<std::string>& leafMaterials,
                                     const ProgressCallback& progress, const ImportFunction& import,
                                     ImportReport* report)
    {
        const std::string ext = lowerCaseExtension(path);
        if (ext == ".glb" || ext == ".gltf")
        {
            ImportOptions options;
            options.leafMaterials = leafMaterials;
            options.progress = progress;
            return importGltf(path, options, report);
        }
        if (!import)
            return fail(path, "", "no importer for '" + ext + "' files (.glb and .gltf are built in; other "
                                  "formats need the caller's ImportFunction)");
        return import(path);
    }

    std::string defaultBakeCacheDirectory() { return userCacheDirectory(); }

    BakeCache::BakeCache(std::string directory) : mDirectory(std::move(directory)) {}

    Result<void> BakeCache::addGenerator(const std::string& scheme, GenerateFunction generate)
    {
        const bool valid = scheme.size() >= 2 && std::all_of(scheme.begin(), scheme.end(), [](char c) {
                               return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-';
                           });
        if (!valid)
            return fail("", "generator scheme '" + scheme + "'", "must be two or more characters of [a-z0-9-]");
        if (!generate)
            return fail("", "generator scheme '" + scheme + "'", "no function given");
        mGenerators[scheme] = std::move(generate);
        return {};
    }

    Result<BakeCache::Key> BakeCache::makeKey(const std::string& source, const std::string& optionsJson) const
    {
        Key key;
        const std::size_t colon = source.find(':');
        const auto generator =
            colon == std::string::npos ? mGenerators.end() : mGenerators.find(source.substr(0, colon));
        if (generator != mGenerators.end())
        {
            key.name = source;
            key.generator = &generator->second;
            key.sourceHash = "fnv1a64:" + hex16(hashString("generated " + source));
        }
        else
        {
            key.name = std::filesystem::path(source).filename().string();
            Result<std::string> hash = sourceHashOf(source);
            if (!hash)
            {
                Error error = hash.error();
                if (colon != std::string::npos && colon >= 2 && source.find('/') > colon)
                    error.reason += " (and no generator is registered for '" + source.substr(0, colon) + ":' sources)";
                return error;
            }
            key.sourceHash = hash.value();
        }

        Result<std::string> options = canonicalOptions(source, optionsJson);
        if (!options)
            return options.error();
        key.options = options.value();

        // Every version that changes what a cached chunk means: a bump gives a new file name.
        std::string versions = "cache " + std::to_string(BAKE_CACHE_KEY_VERSION) + " package " +
                               std::to_string(PACKAGE_VERSION);
        for (const TechniqueDescriptor& technique : techniqueDescriptors())
            versions += " " + technique.name + " " + std::to_string(technique.formatVersion);
        const std::uint64_t fileKey = hashString(versions + "\nsource " + key.sourceHash +
                                                 "\noptions " + key.options);
        const std::string stem =
            safeStem(key.generator ? source : std::filesystem::path(source).stem().string());
        key.path = (std::filesystem::path(mDirectory) / (stem + "-" + hex16(fileKey) + ".treelod")).string();
        return key;
    }

    Result<std::string> BakeCache::packagePath(const std::string& source, const std::string& optionsJson) const
    {
        Result<Key> key = makeKey(source, optionsJson);
        if (!key)
            return key.error();
        return key->path;
    }

    Result<BakeCacheEntry> BakeCache::require(const std::string& source, const std::vector<std::string>& techniques,
                                              const std::string& optionsJson, const ProgressCallback& progress,
                                              const ImportFunction& import) const
    {
        // The request: known techniques, each once, before any file is read.
        std::vector<const BakeTechnique*> requested;
        for (const std::string& name : techniques)
        {
            const BakeTechnique* technique = findBakeTechnique(name);
            if (!technique)
                return fail(source, "technique '" + name + "'",
                            "not a known technique (known: " + knownBakeTechniques() + ")");
            if (std::find(requested.begin(), requested.end(), technique) == requested.end())
                requested.push_back(technique);
        }
        if (requested.empty())
            return fail(source, "techniques", "none requested (known: " + knownBakeTechniques() + ")");

        Result<Key> keyResult = makeKey(source, optionsJson);
        if (!keyResult)
            return keyResult.error();
        const Key& key = keyResult.value();

        BakeCacheEntry entry;
        entry.source = source;
        entry.name = key.name;
        entry.path = key.path;

        // Checked before the cache is, so that a bad option fails whatever the cache holds.
        Result<std::vector<std::string>> leafMaterials = leafMaterialsOption(source, key.options);
        if (!leafMaterials)
            return leafMaterials.error();
        std::map<const BakeTechnique*, BakeOptions> options;
        for (const BakeTechnique* technique : requested)
        {
            Result<BakeOptions> given = techniqueOptions(source, key.options, *technique);
            if (!given)
                return given.error();
            options[technique] = std::move(given.value());
        }

        // What the cache holds; an unusable file is baked again from scratch. Only the chunks this
        // request returns are verified here; the others are read when the package is rewritten.
        std::set<std::string> requestedNames;
        for (const BakeTechnique* technique : requested)
            requestedNames.insert(technique->name);
        PackageReader reader;
        std::error_code ec;
        if (std::filesystem::exists(key.path, ec))
        {
            Result<PackageReader> opened = openCachedPackage(key.path, key.sourceHash, key.options, requestedNames);
            if (opened)
                reader = std::move(opened.value());
            else
                entry.discardedReason = opened.error().message();
        }
        std::set<std::string> present;
        for (const ChunkInfo& info : reader.chunks())
            if (info.technique != META_CHUNK)
                present.insert(info.technique);
        auto partition = [&] {
            std::vector<const BakeTechnique*> missing;
            entry.reusedTechniques.clear();
            for (const BakeTechnique* technique : requested)
            {
                if (present.count(technique->name))
                    entry.reusedTechniques.push_back(technique->name);
                else
                    missing.push_back(technique);
            }
            return missing;
        };
        std::vector<const BakeTechnique*> missing = partition();
        if (missing.empty())
            return entry;

        // The package is rewritten: every cached chunk is copied, so all must be intact.
        std::vector<CachedChunk> cached;
        if (!present.empty())
        {
            Result<std::vector<CachedChunk>> read = readCachedChunks(reader);
            if (read)
                cached = std::move(read.value());
            else
            {
                entry.discardedReason = read.error().message();
                present.clear();
                missing = partition();
            }
        }

        // Bake the missing techniques from one import, then put the cached chunks back over
        // whatever the bakers added again (the reference), so their bytes stay as they were.
        const auto start = std::chrono::steady_clock::now();
        Result<TreeModel> model = fail(source, "", "not imported");
        if (key.generator)
            model = (*key.generator)(source, prefixed(progress, key.name));
        else
        {
            ImportReport importReport;
            model = importTreeFile(source, leafMaterials.value(), prefixed(progress, key.name), import, &importReport);
            for (const std::string& warning : importReport.warnings)
                report(progress, "warning: " + key.name + ": " + warning, 1.0f);
        }
        if (!model)
            return model.error();

        PackageWriter writer;
        for (const BakeTechnique* technique : missing)
        {
            Result<void> baked = technique->bake(writer, model.value(), options[technique], source,
                                                 prefixed(progress, key.name + " " + technique->name));
            if (!baked)
                return baked.error();
            entry.builtTechniques.push_back(technique->name);
        }
        std::set<std::string> contents(present);
        for (CachedChunk& chunk : cached)
        {
            Result<void> added = writer.addChunk(chunk.info.technique, chunk.info.level, chunk.info.formatVersion,
                                                 std::move(chunk.bytes));
            if (!added)
                return added.error();
        }
        for (const std::string& name : entry.builtTechniques)
            contents.insert(name);
        if (writer.hasChunk(REFERENCE_CHUNK, 0))
            contents.insert(REFERENCE_CHUNK);

        PackageMeta meta;
        meta.source = key.generator ? source : key.name;
        meta.sourceHash = key.sourceHash;
        meta.optionsJson = key.options;
        meta.techniques.assign(contents.begin(), contents.end());
        Result<void> added = addMetaChunk(writer, meta);
        if (!added)
            return added.error();

        report(progress, key.name + ": write", 0.0f);
        std::filesystem::create_directories(mDirectory, ec);
        if (!std::filesystem::is_directory(mDirectory, ec))
            return fail(mDirectory, "", "cannot create the bake cache directory" + (ec ? ": " + ec.message() : ""));
        Result<void> written = writer.write(key.path);
        if (!written)
            return written.error();
        report(progress, key.name + ": write", 1.0f);
        entry.bakeSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        return entry;
    }
}
