// BakeCache: lazy baking into a content-keyed cache. Each test bakes a tiny generated tree
// (100 leaves, 16-texel textures) into its own directory under TREELOD_TEST_OUT.
#include "TestOutput.h"

#include "TreeLod/AtomicFile.h"
#include "TreeLod/BakeCache.h"
#include "TreeLod/FoliageLodData.h"
#include "TreeLod/GltfExporter.h"
#include "TreeLod/ImpostorData.h"
#include "TreeLod/Package.h"
#include "TreeLod/TreeGenerator.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <thread>

using namespace TreeLod;

namespace
{
    using Strings = std::vector<std::string>;

    /// A fresh (emptied) directory for one test.
    std::string testDir(const std::string& name) { return TreeLod::test::freshTestDir("bakecache", name); }

    Result<TreeModel> tinyTree(std::uint32_t seed)
    {
        GeneratorOptions options;
        options.preset = TreePreset::Oak;
        options.seed = seed;
        options.leafCount = 100;
        options.textureSize = 16;
        return generateTree(options);
    }

    /// dir/name, a .glb of the tiny tree with this seed.
    std::string writeTinyGlb(const std::string& dir, const std::string& name, std::uint32_t seed = 1)
    {
        const std::string path = dir + "/" + name;
        Result<TreeModel> model = tinyTree(seed);
        EXPECT_TRUE(model.ok()) << (model.ok() ? "" : model.error().message());
        if (model)
        {
            Result<void> written = writeGlb(model.value(), path);
            EXPECT_TRUE(written.ok()) << (written.ok() ? "" : written.error().message());
        }
        return path;
    }

    std::vector<std::uint8_t> fileBytes(const std::string& path)
    {
        Result<std::vector<std::uint8_t>> bytes = readFile(path);
        return bytes ? bytes.value() : std::vector<std::uint8_t>();
    }

    /// The payload of a chunk of the package at `path`, empty if it cannot be read.
    std::vector<std::uint8_t> chunkBytes(const std::string& path, const std::string& technique)
    {
        Result<PackageReader> reader = PackageReader::open(path);
        if (!reader)
            return {};
        Result<std::vector<std::uint8_t>> bytes = reader->readChunk(technique, 0);
        return bytes ? bytes.value() : std::vector<std::uint8_t>();
    }

    BakeCacheEntry requireOk(const BakeCache& cache, const std::string& source, const Strings& techniques,
                             const std::string& options = "{}", const ProgressCallback& progress = {})
    {
        Result<BakeCacheEntry> entry = cache.require(source, techniques, options, progress);
        EXPECT_TRUE(entry.ok()) << (entry.ok() ? "" : entry.error().message());
        return entry ? entry.value() : BakeCacheEntry();
    }

    /// Steps seen by a progress callback.
    struct StepLog
    {
        Strings steps;
        ProgressCallback callback()
        {
            return [this](const std::string& step, float) { steps.push_back(step); };
        }
        bool any(const std::string& prefix) const
        {
            return std::any_of(steps.begin(), steps.end(),
                               [&](const std::string& s) { return s.rfind(prefix, 0) == 0; });
        }
    };

    /// Sets an environment variable for one scope, restoring it afterwards.
    class ScopedEnv
    {
    public:
        ScopedEnv(const char* name, const char* value) : mName(name)
        {
            const char* old = std::getenv(name);
            mHad = old != nullptr;
            if (old)
                mOld = old;
            if (value)
                setenv(name, value, 1);
            else
                unsetenv(name);
        }
        ~ScopedEnv()
        {
            if (mHad)
                setenv(mName.c_str(), mOld.c_str(), 1);
            else
                unsetenv(mName.c_str());
        }

    private:
        std::string mName;
        std::string mOld;
        bool mHad = false;
    };
}

// The second request finds everything and touches nothing: no bake, same file, same mtime.
TEST(BakeCache, FirstCallBakesSecondReuses)
{
    const std::string dir = testDir("reuse");
    const std::string glb = writeTinyGlb(dir, "oak.glb");
    const BakeCache cache(dir + "/cache");

    const BakeCacheEntry first = requireOk(cache, glb, {"reference"});
    EXPECT_EQ(first.builtTechniques, Strings{"reference"});
    EXPECT_TRUE(first.reusedTechniques.empty());
    EXPECT_GT(first.bakeSeconds, 0.0);
    EXPECT_TRUE(first.discardedReason.empty());
    ASSERT_TRUE(std::filesystem::is_regular_file(first.path));
    EXPECT_EQ(std::filesystem::path(first.path).parent_path(), std::filesystem::path(dir + "/cache"));
    EXPECT_EQ(std::filesystem::path(first.path).filename().string().rfind("oak-", 0), 0u) << first.path;
    EXPECT_NE(first.describe().find("oak.glb: baked reference ("), std::string::npos) << first.describe();

    const std::vector<std::uint8_t> bytes = fileBytes(first.path);
    const auto mtime = std::filesystem::last_write_time(first.path);
    StepLog log;
    const BakeCacheEntry second = requireOk(cache, glb, {"reference"}, "{}", log.callback());
    EXPECT_EQ(second.path, first.path);
    EXPECT_TRUE(second.builtTechniques.empty());
    EXPECT_EQ(second.reusedTechniques, Strings{"reference"});
    EXPECT_EQ(second.bakeSeconds, 0.0);
    EXPECT_TRUE(log.steps.empty()) << log.steps.front(); // no import, no bake, no write
    EXPECT_EQ(std::filesystem::last_write_time(first.path), mtime);
    EXPECT_EQ(fileBytes(first.path), bytes);
    EXPECT_EQ(second.describe(), "oak.glb: reused reference -> " + first.path);

    // The cached package is a normal package with a meta chunk naming what it holds.
    const std::vector<std::uint8_t> meta = chunkBytes(first.path, META_CHUNK);
    const nlohmann::json json = nlohmann::json::parse(meta.begin(), meta.end(), nullptr, false);
    ASSERT_TRUE(json.is_object());
    EXPECT_EQ(json["source"], "oak.glb");
    EXPECT_EQ(json["techniques"], nlohmann::json::array({"reference"}));
}

// A new technique is baked alone; the chunks already cached are copied byte for byte, and the
// result equals a package baked in one request (the key has no technique list in it).
TEST(BakeCache, NewTechniqueBakesOnlyThatOne)
{
    const std::string dir = testDir("incremental");
    const std::string glb = writeTinyGlb(dir, "oak.glb");
    const BakeCache cache(dir + "/cache");

    const BakeCacheEntry first = requireOk(cache, glb, {"reference"});
    const std::vector<std::uint8_t> reference = chunkBytes(first.path, REFERENCE_CHUNK);
    ASSERT_FALSE(reference.empty());

    StepLog log;
    const BakeCacheEntry second = requireOk(cache, glb, {"reference", FOLIAGE_LOD_CHUNK}, "{}", log.callback());
    EXPECT_EQ(second.path, first.path);
    EXPECT_EQ(second.builtTechniques, Strings{FOLIAGE_LOD_CHUNK});
    EXPECT_EQ(second.reusedTechniques, Strings{"reference"});
    EXPECT_GT(second.bakeSeconds, 0.0);
    EXPECT_TRUE(log.any("oak.glb lodf: ")) << "the lodf baker reports its steps under its name";
    EXPECT_FALSE(log.any("oak.glb reference: ")) << "the reference baker did not run";
    EXPECT_EQ(chunkBytes(second.path, REFERENCE_CHUNK), reference);
    EXPECT_FALSE(chunkBytes(second.path, FOLIAGE_LOD_CHUNK).empty());
    EXPECT_NE(second.describe().find("baked lodf ("), std::string::npos) << second.describe();
    EXPECT_NE(second.describe().find("), reused reference -> "), std::string::npos) << second.describe();

    // Asking for a subset reuses it without a rewrite.
    const BakeCacheEntry third = requireOk(cache, glb, {FOLIAGE_LOD_CHUNK});
    EXPECT_TRUE(third.builtTechniques.empty());
    EXPECT_EQ(third.reusedTechniques, Strings{FOLIAGE_LOD_CHUNK});

    const BakeCache fresh(dir + "/fresh");
    const BakeCacheEntry once = requireOk(fresh, glb, {FOLIAGE_LOD_CHUNK, "reference"});
    EXPECT_EQ(once.builtTechniques, (Strings{FOLIAGE_LOD_CHUNK, "reference"}));
    EXPECT_EQ(std::filesystem::path(once.path).filename(), std::filesystem::path(second.path).filename());
    EXPECT_EQ(fileBytes(once.path), fileBytes(second.path));
}

// The key follows the content of the input and the options, not their spelling.
TEST(BakeCache, KeyFollowsInputBytesAndOptions)
{
    const std::string dir = testDir("key");
    const std::string glb = writeTinyGlb(dir, "oak.glb", 1);
    const BakeCache cache(dir + "/cache");

    auto path = [&](const std::string& source, const std::string& options) {
        Result<std::string> p = cache.packagePath(source, options);
        EXPECT_TRUE(p.ok()) << (p.ok() ? "" : p.error().message());
        return p ? p.value() : std::string();
    };
    const std::string base = path(glb, "{}");
    EXPECT_EQ(path(glb, ""), base);
    EXPECT_EQ(path(glb, "{\"leafMaterials\":[\"Leaves\"],\"x\":1}"),
              path(glb, " { \"x\" : 1, \"leafMaterials\" : [ \"Leaves\" ] } "));
    EXPECT_NE(path(glb, "{\"leafMaterials\":[\"Leaves\"]}"), base);

    // The same bytes under another directory share the key; other bytes under the same name do not.
    std::filesystem::create_directories(dir + "/copy");
    std::filesystem::copy_file(glb, dir + "/copy/oak.glb");
    EXPECT_EQ(path(dir + "/copy/oak.glb", "{}"), base);
    writeTinyGlb(dir, "oak.glb", 2);
    const std::string changed = path(glb, "{}");
    EXPECT_NE(changed, base);
    EXPECT_EQ(std::filesystem::path(changed).parent_path(), std::filesystem::path(base).parent_path());

    // Nothing was baked or created by asking.
    EXPECT_FALSE(std::filesystem::exists(dir + "/cache"));

    Result<std::string> bad = cache.packagePath(glb, "[1, 2]");
    ASSERT_FALSE(bad.ok());
    EXPECT_EQ(bad.error().element, "bake options");
}

// A .gltf's key covers the external buffer it references.
TEST(BakeCache, GltfKeyCoversExternalBuffers)
{
    const std::string dir = testDir("gltf-external");
    {
        std::ofstream gltf(dir + "/tri.gltf");
        gltf << R"({"asset":{"version":"2.0"},"buffers":[{"uri":"tri%20data.bin","byteLength":36}]})";
    }
    auto writeBin = [&](float x) {
        std::ofstream bin(dir + "/tri data.bin", std::ios::binary);
        const float data[9] = {0, 0, 0, x, 0, 0, 0, 1, 0};
        bin.write(reinterpret_cast<const char*>(data), sizeof(data));
    };
    const BakeCache cache(dir + "/cache");
    writeBin(1.0f);
    Result<std::string> a = cache.packagePath(dir + "/tri.gltf", "{}");
    writeBin(2.0f);
    Result<std::string> b = cache.packagePath(dir + "/tri.gltf", "{}");
    ASSERT_TRUE(a.ok() && b.ok());
    EXPECT_NE(a.value(), b.value());
}

// A damaged cache file is detected (checksums), thrown away and baked again, never trusted.
TEST(BakeCache, CorruptCacheFileIsRebaked)
{
    const std::string dir = testDir("corrupt");
    const std::string glb = writeTinyGlb(dir, "oak.glb");
    const BakeCache cache(dir + "/cache");
    const BakeCacheEntry first = requireOk(cache, glb, {"reference"});
    const std::vector<std::uint8_t> good = fileBytes(first.path);
    ASSERT_GT(good.size(), 1000u);

    // One flipped byte in the last payload (the reference chunk).
    std::vector<std::uint8_t> flipped = good;
    flipped[flipped.size() - 100] ^= 0x5a;
    ASSERT_TRUE(writeFileAtomic(first.path, flipped).ok());
    const BakeCacheEntry rebaked = requireOk(cache, glb, {"reference"});
    EXPECT_EQ(rebaked.builtTechniques, Strings{"reference"});
    EXPECT_TRUE(rebaked.reusedTechniques.empty());
    EXPECT_NE(rebaked.discardedReason.find("checksum"), std::string::npos) << rebaked.discardedReason;
    EXPECT_NE(rebaked.describe().find("discarded the cached package"), std::string::npos) << rebaked.describe();
    EXPECT_EQ(fileBytes(first.path), good);

    // Truncated to half.
    const std::vector<std::uint8_t> half(good.begin(), good.begin() + good.size() / 2);
    ASSERT_TRUE(writeFileAtomic(first.path, half).ok());
    const BakeCacheEntry truncated = requireOk(cache, glb, {"reference"});
    EXPECT_EQ(truncated.builtTechniques, Strings{"reference"});
    EXPECT_NE(truncated.discardedReason.find("truncated"), std::string::npos) << truncated.discardedReason;
    EXPECT_EQ(fileBytes(first.path), good);

    // A valid package made for another input, at this key's path.
    const std::string other = writeTinyGlb(dir, "other.glb", 2);
    const BakeCacheEntry otherEntry = requireOk(cache, other, {"reference"});
    std::filesystem::copy_file(otherEntry.path, first.path, std::filesystem::copy_options::overwrite_existing);
    const BakeCacheEntry foreign = requireOk(cache, glb, {"reference"});
    EXPECT_EQ(foreign.builtTechniques, Strings{"reference"});
    EXPECT_NE(foreign.discardedReason.find("another source"), std::string::npos) << foreign.discardedReason;
    EXPECT_EQ(fileBytes(first.path), good);
}

// A hit verifies the chunks it returns (the technique's and the reference) and no others; a
// rewrite copies every cached chunk, so a damaged one is found then and everything is rebaked.
TEST(BakeCache, HitVerifiesOnlyTheRequestedChunks)
{
    const std::string dir = testDir("verify");
    const std::string glb = writeTinyGlb(dir, "oak.glb");
    const BakeCache cache(dir + "/cache");
    const BakeCacheEntry first = requireOk(cache, glb, {"reference", FOLIAGE_LOD_CHUNK});
    const std::vector<std::uint8_t> lodfBytes = chunkBytes(first.path, FOLIAGE_LOD_CHUNK);
    ASSERT_FALSE(lodfBytes.empty());
    std::vector<std::uint8_t> damaged = fileBytes(first.path);
    Result<PackageReader> reader = PackageReader::open(first.path);
    ASSERT_TRUE(reader.ok()) << reader.error().message();
    const int lodf = reader->findChunk(FOLIAGE_LOD_CHUNK, 0);
    ASSERT_GE(lodf, 0);
    const ChunkInfo& info = reader->chunks()[std::size_t(lodf)];
    ASSERT_GT(info.size, 2u);
    damaged[std::size_t(info.offset + info.size / 2)] ^= 0x5a;
    ASSERT_TRUE(writeFileAtomic(first.path, damaged).ok());

    // The reference alone: the damaged lodf chunk is not read, nothing is rebaked.
    const BakeCacheEntry hit = requireOk(cache, glb, {"reference"});
    EXPECT_EQ(hit.reusedTechniques, Strings{"reference"});
    EXPECT_TRUE(hit.builtTechniques.empty());
    EXPECT_TRUE(hit.discardedReason.empty()) << hit.discardedReason;
    EXPECT_EQ(fileBytes(first.path), damaged);

    // A new technique rewrites the package: the damaged chunk is found and the request rebaked whole.
    const BakeCacheEntry rewrite = requireOk(cache, glb, {"reference", IMPOSTOR_CHUNK});
    EXPECT_EQ(rewrite.builtTechniques, (Strings{"reference", IMPOSTOR_CHUNK}));
    EXPECT_TRUE(rewrite.reusedTechniques.empty());
    EXPECT_NE(rewrite.discardedReason.find("checksum"), std::string::npos) << rewrite.discardedReason;
    EXPECT_TRUE(chunkBytes(rewrite.path, FOLIAGE_LOD_CHUNK).empty()) << "the damaged chunk is not copied";
    EXPECT_FALSE(chunkBytes(rewrite.path, IMPOSTOR_CHUNK).empty());

    // Asking for the damaged technique itself verifies it.
    ASSERT_TRUE(writeFileAtomic(first.path, damaged).ok());
    const BakeCacheEntry again = requireOk(cache, glb, {FOLIAGE_LOD_CHUNK});
    EXPECT_EQ(again.builtTechniques, Strings{FOLIAGE_LOD_CHUNK});
    EXPECT_NE(again.discardedReason.find("checksum"), std::string::npos) << again.discardedReason;
    EXPECT_EQ(chunkBytes(again.path, FOLIAGE_LOD_CHUNK), lodfBytes);
}

// The options reach the importer: "leafMaterials" is checked and changes what is baked.
TEST(BakeCache, LeafMaterialsOptionReachesTheImporter)
{
    const std::string dir = testDir("leaf-materials");
    const std::string glb = writeTinyGlb(dir, "oak.glb");
    const BakeCache cache(dir + "/cache");

    Result<BakeCacheEntry> bad = cache.require(glb, {"reference"}, "{\"leafMaterials\": \"Leaves\"}");
    ASSERT_FALSE(bad.ok());
    EXPECT_EQ(bad.error().file, glb);
    EXPECT_EQ(bad.error().element, "bake options");
    EXPECT_NE(bad.error().reason.find("\"leafMaterials\" must be an array of strings"), std::string::npos)
        << bad.error().message();
    EXPECT_FALSE(std::filesystem::exists(dir + "/cache")) << "nothing written";

    const BakeCacheEntry byDefault = requireOk(cache, glb, {"reference"});
    const std::vector<std::uint8_t> reference = chunkBytes(byDefault.path, REFERENCE_CHUNK);
    ASSERT_FALSE(reference.empty());

    // No material declared a leaf: the leaves become bark, a different reference chunk.
    StepLog log;
    const BakeCacheEntry noLeaves =
        requireOk(cache, glb, {"reference"}, "{\"leafMaterials\": [\"NoSuchMaterial\"]}", log.callback());
    EXPECT_EQ(noLeaves.builtTechniques, Strings{"reference"});
    EXPECT_NE(noLeaves.path, byDefault.path);
    const std::vector<std::uint8_t> bark = chunkBytes(noLeaves.path, REFERENCE_CHUNK);
    ASSERT_FALSE(bark.empty());
    EXPECT_NE(bark, reference);
    EXPECT_TRUE(log.any("warning: oak.glb: leaf material")) << "the importer's warning, prefixed";

    // The meta chunk records the options and the same source hash as sourceHashOf().
    const std::vector<std::uint8_t> meta = chunkBytes(noLeaves.path, META_CHUNK);
    const nlohmann::json json = nlohmann::json::parse(meta.begin(), meta.end(), nullptr, false);
    ASSERT_TRUE(json.is_object());
    EXPECT_EQ(json["options"], nlohmann::json::parse("{\"leafMaterials\": [\"NoSuchMaterial\"]}"));
    Result<std::string> hash = sourceHashOf(glb);
    ASSERT_TRUE(hash.ok()) << hash.error().message();
    EXPECT_EQ(json["sourceHash"], hash.value());
    EXPECT_EQ(hash.value().rfind("fnv1a64:", 0), 0u);
    EXPECT_EQ(hash.value().size(), 8u + 16u);

    // Naming the leaf material the importer finds by itself bakes the default's chunk under another key.
    const BakeCacheEntry named = requireOk(cache, glb, {"reference"}, "{\"leafMaterials\": [\"Leaves\"]}");
    EXPECT_NE(named.path, byDefault.path);
    EXPECT_EQ(chunkBytes(named.path, REFERENCE_CHUNK), reference);
}

// A baker's options (BakeTechniques.h) under the technique's key: checked against what the baker
// declares before anything is read, part of the key, and they reach the baker.
TEST(BakeCache, TechniqueOptionsReachTheBaker)
{
    const std::string dir = testDir("technique-options");
    const std::string glb = writeTinyGlb(dir, "oak.glb");
    const BakeCache cache(dir + "/cache");

    for (const char* bad : {"{\"lodf\": {\"nosuch\": 1}}", "{\"lodf\": {\"clusterSize\": 0}}",
                            "{\"lodf\": 16}", "{\"lodf\": {\"clusterSize\": [16]}}"})
    {
        Result<BakeCacheEntry> refused = cache.require(glb, {"lodf"}, bad);
        ASSERT_FALSE(refused.ok()) << bad;
        EXPECT_EQ(refused.error().file, glb);
        EXPECT_FALSE(std::filesystem::exists(dir + "/cache")) << bad << ": nothing written";
    }
    Result<BakeCacheEntry> unknown = cache.require(glb, {"lodf"}, "{\"lodf\": {\"nosuch\": 1}}");
    ASSERT_FALSE(unknown.ok());
    EXPECT_EQ(unknown.error().element, "option 'lodf.nosuch'");
    EXPECT_NE(unknown.error().reason.find("known: clusterSize, costBands"), std::string::npos)
        << unknown.error().message();

    const BakeCacheEntry byDefault = requireOk(cache, glb, {"lodf"});
    const BakeCacheEntry small = requireOk(cache, glb, {"lodf"}, "{\"lodf\": {\"clusterSize\": 8}}");
    EXPECT_NE(small.path, byDefault.path);
    Result<FoliageLodData> a = decodeFoliageLodChunk(chunkBytes(byDefault.path, FOLIAGE_LOD_CHUNK), "default");
    Result<FoliageLodData> b = decodeFoliageLodChunk(chunkBytes(small.path, FOLIAGE_LOD_CHUNK), "small");
    ASSERT_TRUE(a.ok() && b.ok());
    EXPECT_GT(b->clusters.size(), a->clusters.size()) << "clusters of 8 leaves instead of 64";
    // A string and a number spell the same option.
    const BakeCacheEntry asText = requireOk(cache, glb, {"lodf"}, "{\"lodf\": {\"clusterSize\": \"8\"}}");
    EXPECT_EQ(chunkBytes(asText.path, FOLIAGE_LOD_CHUNK), chunkBytes(small.path, FOLIAGE_LOD_CHUNK));
}

TEST(BakeCache, BadRequestsNameWhatIsWrong)
{
    const std::string dir = testDir("errors");
    const BakeCache cache(dir + "/cache");
    const std::string missing = dir + "/nowhere.glb";

    // Unknown technique: named, with the known list, before the input is even read.
    Result<BakeCacheEntry> unknown = cache.require(missing, {"reference", "octree"}, "{}");
    ASSERT_FALSE(unknown.ok());
    EXPECT_EQ(unknown.error().element, "technique 'octree'");
    EXPECT_NE(unknown.error().reason.find("known: reference, "), std::string::npos) << unknown.error().message();
    EXPECT_NE(unknown.error().reason.find("lodf"), std::string::npos) << unknown.error().message();

    Result<BakeCacheEntry> none = cache.require(missing, {}, "{}");
    ASSERT_FALSE(none.ok());
    EXPECT_EQ(none.error().element, "techniques");

    Result<BakeCacheEntry> absent = cache.require(missing, {"reference"}, "{}");
    ASSERT_FALSE(absent.ok());
    EXPECT_EQ(absent.error().file, missing);
    EXPECT_NE(absent.error().reason.find("does not exist"), std::string::npos) << absent.error().message();

    // A file format the cache cannot read without the caller's importer.
    std::ofstream(dir + "/tree.mesh") << "not really a mesh";
    Result<BakeCacheEntry> mesh = cache.require(dir + "/tree.mesh", {"reference"}, "{}");
    ASSERT_FALSE(mesh.ok());
    EXPECT_EQ(mesh.error().file, dir + "/tree.mesh");
    EXPECT_NE(mesh.error().reason.find("'.mesh'"), std::string::npos) << mesh.error().message();

    // Looks like a generator source, but no generator is registered for it.
    Result<BakeCacheEntry> preset = cache.require("preset:oak?seed=1", {"reference"}, "{}");
    ASSERT_FALSE(preset.ok());
    EXPECT_NE(preset.error().reason.find("no generator is registered for 'preset:'"), std::string::npos)
        << preset.error().message();

    // An importer failure is passed through, and nothing is written.
    Result<BakeCacheEntry> broken = cache.require(
        dir + "/tree.mesh", {"reference"}, "{}", {},
        [](const std::string& path) -> Result<TreeModel> { return fail(path, "submesh 0", "no vertices"); });
    ASSERT_FALSE(broken.ok());
    EXPECT_EQ(broken.error().message(), dir + "/tree.mesh: submesh 0: no vertices");
    EXPECT_FALSE(std::filesystem::exists(dir + "/cache"));
}

// Other formats go through the caller's importer (the Ogre side's .mesh reader).
TEST(BakeCache, ImportFunctionReadsOtherFormats)
{
    const std::string dir = testDir("import");
    std::ofstream(dir + "/tree.mesh") << "mesh bytes";
    const BakeCache cache(dir + "/cache");
    int imports = 0;
    const ImportFunction import = [&](const std::string& path) -> Result<TreeModel> {
        ++imports;
        EXPECT_EQ(path, dir + "/tree.mesh");
        return tinyTree(1);
    };
    Result<BakeCacheEntry> first = cache.require(dir + "/tree.mesh", {"reference"}, "{}", {}, import);
    ASSERT_TRUE(first.ok()) << first.error().message();
    EXPECT_EQ(first->builtTechniques, Strings{"reference"});
    Result<BakeCacheEntry> second = cache.require(dir + "/tree.mesh", {"reference"}, "{}", {}, import);
    ASSERT_TRUE(second.ok()) << second.error().message();
    EXPECT_EQ(second->reusedTechniques, Strings{"reference"});
    EXPECT_EQ(imports, 1);
}

// Generator sources: keyed by the source string, made only when something must be baked.
TEST(BakeCache, GeneratorSourcesAreKeyedByTheirString)
{
    const std::string dir = testDir("generator");
    BakeCache cache(dir + "/cache");
    Strings generated;
    const GenerateFunction generate = [&](const std::string& source, const ProgressCallback& progress) {
        generated.push_back(source);
        const std::size_t seed = source.find("seed=");
        return generateTree(GeneratorOptions{TreePreset::Oak, std::uint32_t(std::stoul(source.substr(seed + 5))), 100,
                                             0.0f, 16},
                            progress);
    };
    ASSERT_TRUE(cache.addGenerator("preset", generate).ok());
    for (const char* bad : {"", "c", "Preset", "a/b", "x:y"})
        EXPECT_FALSE(cache.addGenerator(bad, generate).ok()) << bad;
    EXPECT_FALSE(cache.addGenerator("empty", {}).ok());
    const BakeCacheEntry a = requireOk(cache, "preset:oak?leaves=100&seed=1", {"reference"});
    EXPECT_EQ(a.builtTechniques, Strings{"reference"});
    EXPECT_EQ(std::filesystem::path(a.path).filename().string().rfind("preset-oak-leaves-100-seed-1-", 0), 0u)
        << a.path;
    EXPECT_EQ(a.describe().rfind("preset:oak?leaves=100&seed=1: baked reference", 0), 0u) << a.describe();
    const BakeCacheEntry again = requireOk(cache, "preset:oak?leaves=100&seed=1", {"reference"});
    EXPECT_EQ(again.reusedTechniques, Strings{"reference"});
    const BakeCacheEntry b = requireOk(cache, "preset:oak?leaves=100&seed=2", {"reference"});
    EXPECT_NE(b.path, a.path);
    EXPECT_EQ(generated, (Strings{"preset:oak?leaves=100&seed=1", "preset:oak?leaves=100&seed=2"}));
    EXPECT_NE(chunkBytes(a.path, REFERENCE_CHUNK), chunkBytes(b.path, REFERENCE_CHUNK));
}

// Two bakes of one key at once both succeed and leave one whole package (temp file + rename).
TEST(BakeCache, ConcurrentBakesOfOneKeyLeaveAWholePackage)
{
    const std::string dir = testDir("concurrent");
    const std::string glb = writeTinyGlb(dir, "oak.glb");
    const BakeCache cache(dir + "/cache");
    std::atomic<int> ok{0};
    std::vector<std::thread> threads;
    for (int i = 0; i < 2; ++i)
        threads.emplace_back([&] {
            if (cache.require(glb, {"reference"}, "{}").ok())
                ++ok;
        });
    for (std::thread& t : threads)
        t.join();
    EXPECT_EQ(ok.load(), 2);
    const BakeCacheEntry after = requireOk(cache, glb, {"reference"});
    EXPECT_EQ(after.reusedTechniques, Strings{"reference"});
    EXPECT_TRUE(after.discardedReason.empty()) << after.discardedReason;
    std::size_t files = 0;
    for (const auto& e : std::filesystem::directory_iterator(dir + "/cache"))
        files += e.is_regular_file() ? 1 : 0;
    EXPECT_EQ(files, 1u) << "no temporary file is left behind";
}

TEST(BakeCache, DefaultDirectoryHonoursXdgCacheHome)
{
    {
        ScopedEnv xdg("XDG_CACHE_HOME", "/somewhere/cache");
        EXPECT_EQ(defaultBakeCacheDirectory(), "/somewhere/cache/treelod");
        EXPECT_EQ(BakeCache().directory(), "/somewhere/cache/treelod");
    }
    {
        ScopedEnv xdg("XDG_CACHE_HOME", "relative/cache"); // invalid per the XDG spec: ignored
        ScopedEnv home("HOME", "/home/someone");
        EXPECT_EQ(defaultBakeCacheDirectory(), "/home/someone/.cache/treelod");
    }
    {
        ScopedEnv xdg("XDG_CACHE_HOME", nullptr);
        ScopedEnv home("HOME", "/home/someone");
        EXPECT_EQ(defaultBakeCacheDirectory(), "/home/someone/.cache/treelod");
    }
}
