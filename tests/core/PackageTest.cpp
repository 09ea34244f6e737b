// The *.treelod package: writer -> reader round trips, determinism, corrupt and hostile
// files, the reference chunk, and GPU-ready mip chains.
#include "AllocationTracker.h"

#include "TreeLod/Crc32.h"
#include "TreeLod/ModelChunk.h"
#include "TreeLod/Package.h"
#include "TreeLod/PackageWriter.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>

using namespace TreeLod;

namespace
{
    std::string outDir()
    {
        const char* env = std::getenv("TREELOD_TEST_OUT");
        std::filesystem::path dir = env ? env : TREELOD_BINARY_DIR "/test-out";
        dir /= "package";
        std::filesystem::create_directories(dir);
        return dir.string();
    }

    std::vector<std::uint8_t> fileBytes(const std::string& path)
    {
        std::ifstream in(path, std::ios::binary);
        return std::vector<std::uint8_t>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    }

    TextureImage makeTexture(const std::string& name, int w, int h, std::uint8_t seed, bool alpha)
    {
        TextureImage t;
        t.name = name;
        t.width = w;
        t.height = h;
        t.rgba.resize(std::size_t(w) * h * 4);
        for (std::size_t i = 0; i < t.rgba.size(); ++i)
            t.rgba[i] = std::uint8_t(seed + i * 37);
        if (!alpha)
            for (std::size_t i = 3; i < t.rgba.size(); i += 4)
                t.rgba[i] = 255;
        return t;
    }

    void addQuad(std::vector<Vertex>& vertices, std::vector<std::uint32_t>& indices, glm::vec3 origin, glm::vec3 u,
                 glm::vec3 v)
    {
        const std::uint32_t base = std::uint32_t(vertices.size());
        const glm::vec3 n = glm::normalize(glm::cross(u, v));
        vertices.push_back({origin, n, {0, 1}});
        vertices.push_back({origin + u, n, {1, 1}});
        vertices.push_back({origin + u + v, n, {1, 0}});
        vertices.push_back({origin + v, n, {0, 0}});
        for (std::uint32_t k : {0u, 1u, 2u, 0u, 2u, 3u})
            indices.push_back(base + k);
    }

    /// A trunk quad, two leaf quads, two textures (the leaf one with alpha), a 3-node skeleton.
    TreeModel makeTree(bool withLeaves = true)
    {
        TreeModel m;
        m.name = "tiny tree";
        Material bark;
        bark.name = "Bark";
        bark.baseColour = {0.4f, 0.3f, 0.2f, 1.0f};
        bark.texture = 0;
        Material leaf;
        leaf.name = "Leaves";
        leaf.baseColour = {0.2f, 0.6f, 0.1f, 1.0f};
        leaf.backColour = {0.3f, 0.5f, 0.1f};
        leaf.texture = 1;
        leaf.alphaCutoff = 0.4f;
        leaf.isLeaf = true;
        leaf.doubleSided = true;
        m.materials = {bark, leaf};
        m.textures = {makeTexture("bark.png", 4, 4, 11, false), makeTexture("leaf.png", 8, 4, 99, true)};

        addQuad(m.barkVertices, m.barkIndices, {-0.1f, 0, 0}, {0.2f, 0, 0}, {0, 2, 0});
        m.barkTriangleMaterial = {0, 0};
        if (withLeaves)
        {
            for (int i = 0; i < 2; ++i)
            {
                Leaf l;
                l.firstVertex = std::uint32_t(m.leafVertices.size());
                l.firstIndex = std::uint32_t(m.leafIndices.size());
                addQuad(m.leafVertices, m.leafIndices, {0.1f + i, 1.5f, 0.05f * i}, {0.1f, 0, 0}, {0, 0.05f, 0.1f});
                l.vertexCount = 4;
                l.indexCount = 6;
                l.material = 1;
                m.leaves.push_back(l);
                m.updateLeafRecord(m.leaves.size() - 1);
            }
        }
        m.skeleton = {{{0, 0, 0}, 0.1f, -1}, {{0, 1, 0}, 0.08f, 0}, {{0, 2, 0}, 0.02f, 1}};
        m.updateBounds();
        return m;
    }

    void expectVerticesEqual(const std::vector<Vertex>& a, const std::vector<Vertex>& b)
    {
        ASSERT_EQ(a.size(), b.size());
        for (std::size_t i = 0; i < a.size(); ++i)
        {
            EXPECT_EQ(a[i].position, b[i].position) << i;
            EXPECT_EQ(a[i].normal, b[i].normal) << i;
            EXPECT_EQ(a[i].uv, b[i].uv) << i;
        }
    }

    void expectModelsEqual(const TreeModel& a, const TreeModel& b)
    {
        EXPECT_EQ(a.name, b.name);
        ASSERT_EQ(a.materials.size(), b.materials.size());
        for (std::size_t i = 0; i < a.materials.size(); ++i)
        {
            const Material &x = a.materials[i], &y = b.materials[i];
            EXPECT_EQ(x.name, y.name);
            EXPECT_EQ(x.baseColour, y.baseColour);
            EXPECT_EQ(x.backColour, y.backColour);
            EXPECT_EQ(x.texture, y.texture);
            EXPECT_EQ(x.alphaCutoff, y.alphaCutoff);
            EXPECT_EQ(x.isLeaf, y.isLeaf);
            EXPECT_EQ(x.doubleSided, y.doubleSided);
        }
        ASSERT_EQ(a.textures.size(), b.textures.size());
        for (std::size_t i = 0; i < a.textures.size(); ++i)
        {
            EXPECT_EQ(a.textures[i].name, b.textures[i].name);
            EXPECT_EQ(a.textures[i].width, b.textures[i].width);
            EXPECT_EQ(a.textures[i].height, b.textures[i].height);
            EXPECT_EQ(a.textures[i].rgba, b.textures[i].rgba);
        }
        expectVerticesEqual(a.barkVertices, b.barkVertices);
        EXPECT_EQ(a.barkIndices, b.barkIndices);
        EXPECT_EQ(a.barkTriangleMaterial, b.barkTriangleMaterial);
        expectVerticesEqual(a.leafVertices, b.leafVertices);
        EXPECT_EQ(a.leafIndices, b.leafIndices);
        ASSERT_EQ(a.leaves.size(), b.leaves.size());
        for (std::size_t i = 0; i < a.leaves.size(); ++i)
        {
            const Leaf &x = a.leaves[i], &y = b.leaves[i];
            EXPECT_EQ(x.firstVertex, y.firstVertex);
            EXPECT_EQ(x.vertexCount, y.vertexCount);
            EXPECT_EQ(x.firstIndex, y.firstIndex);
            EXPECT_EQ(x.indexCount, y.indexCount);
            EXPECT_EQ(x.material, y.material);
            EXPECT_EQ(x.centre, y.centre);
            EXPECT_EQ(x.normal, y.normal);
            EXPECT_EQ(x.area, y.area);
            EXPECT_EQ(x.uvMin, y.uvMin);
            EXPECT_EQ(x.uvMax, y.uvMax);
        }
        ASSERT_EQ(a.skeleton.size(), b.skeleton.size());
        for (std::size_t i = 0; i < a.skeleton.size(); ++i)
        {
            EXPECT_EQ(a.skeleton[i].position, b.skeleton[i].position);
            EXPECT_EQ(a.skeleton[i].radius, b.skeleton[i].radius);
            EXPECT_EQ(a.skeleton[i].parent, b.skeleton[i].parent);
        }
        EXPECT_EQ(a.boundsMin, b.boundsMin);
        EXPECT_EQ(a.boundsMax, b.boundsMax);
    }

    std::vector<std::uint8_t> packageOf(const TreeModel& model)
    {
        PackageWriter writer;
        EXPECT_TRUE(writer.addChunk(REFERENCE_CHUNK, 0, REFERENCE_CHUNK_FORMAT_VERSION,
                                    encodeReferenceChunk(makeReferenceChunk(model))));
        const std::string meta = "{\"source\":\"tiny.glb\"}";
        EXPECT_TRUE(writer.addChunk(META_CHUNK, 0, 1, std::vector<std::uint8_t>(meta.begin(), meta.end())));
        return writer.toBytes();
    }

    std::uint32_t getU32(const std::vector<std::uint8_t>& b, std::size_t at)
    {
        return std::uint32_t(b[at]) | std::uint32_t(b[at + 1]) << 8 | std::uint32_t(b[at + 2]) << 16 |
               std::uint32_t(b[at + 3]) << 24;
    }

    void putU32(std::vector<std::uint8_t>& b, std::size_t at, std::uint32_t v)
    {
        for (int i = 0; i < 4; ++i)
            b[at + i] = std::uint8_t(v >> (8 * i));
    }

    void putU64(std::vector<std::uint8_t>& b, std::size_t at, std::uint64_t v)
    {
        putU32(b, at, std::uint32_t(v));
        putU32(b, at + 4, std::uint32_t(v >> 32));
    }

    /// Recompute the table and header checksums after a test edited them, so that the
    /// reader gets past the checksums to the check under test.
    void reseal(std::vector<std::uint8_t>& b, bool table = true)
    {
        if (table)
            putU32(b, 24, crc32(b.data() + 32, getU32(b, 8) * PACKAGE_TABLE_ENTRY_SIZE));
        putU32(b, 28, crc32(b.data(), 28));
    }

    Result<ReferenceChunk> decodeFrom(const std::vector<std::uint8_t>& package)
    {
        Result<PackageReader> reader = PackageReader::fromMemory(package, "mem.treelod");
        if (!reader)
            return reader.error();
        Result<std::vector<std::uint8_t>> bytes = reader->readChunk(REFERENCE_CHUNK, 0);
        if (!bytes)
            return bytes.error();
        return decodeReferenceChunk(bytes.value(), reader->label());
    }

    /// Fraction of texels of mip `level` whose alpha passes `alpha >= cutoff` (a / 255).
    double coverage(const GpuTexture& tex, std::uint32_t level, float cutoff)
    {
        const std::uint8_t* p = tex.data.data() + tex.mipOffset(level);
        const std::size_t n = std::size_t(tex.mipWidth(level)) * tex.mipHeight(level);
        std::size_t passed = 0;
        for (std::size_t i = 0; i < n; ++i)
            passed += float(p[4 * i + 3]) / 255.0f >= cutoff ? 1 : 0;
        return double(passed) / double(n);
    }

    /// A 64x64 leaf-like alpha: an ellipse with a 2-texel soft rim, serrated edge and a
    /// 1-texel stem; alpha 0 outside.
    TextureImage leafAlpha()
    {
        TextureImage t;
        t.name = "leaf";
        t.width = t.height = 64;
        t.rgba.assign(64 * 64 * 4, 0);
        for (int y = 0; y < 64; ++y)
            for (int x = 0; x < 64; ++x)
            {
                const float dx = (x + 0.5f - 32.0f) / 14.0f, dy = (y + 0.5f - 26.0f) / 24.0f;
                const float serration = 0.08f * std::sin(12.0f * std::atan2(dy, dx));
                const float r = std::sqrt(dx * dx + dy * dy) - serration;
                float a = std::clamp((1.0f - r) * 7.0f + 0.5f, 0.0f, 1.0f);
                if (x == 32 && y >= 50)
                    a = 1.0f; // stem
                std::uint8_t* p = &t.rgba[4 * (std::size_t(y) * 64 + x)];
                p[0] = 40;
                p[1] = 160;
                p[2] = 30;
                p[3] = std::uint8_t(std::lround(a * 255.0f));
            }
        return t;
    }
}

TEST(Crc32, MatchesTheStandardCheckValueAndIsIncremental)
{
    // 0xCBF43926 is the published check value of CRC-32/ISO-HDLC (zlib, PNG).
    const char* text = "123456789";
    EXPECT_EQ(crc32(text, 9), 0xCBF43926u);
    EXPECT_EQ(crc32(text + 4, 5, crc32(text, 4)), 0xCBF43926u);
    EXPECT_EQ(crc32(nullptr, 0), 0u);
    // Longer than the 8-byte fast path, so both loops run: compare with the bytewise path.
    std::vector<std::uint8_t> data(1000);
    for (std::size_t i = 0; i < data.size(); ++i)
        data[i] = std::uint8_t(i * 7 + 3);
    std::uint32_t bytewise = 0;
    for (std::uint8_t b : data)
        bytewise = crc32(&b, 1, bytewise);
    EXPECT_EQ(crc32(data.data(), data.size()), bytewise);
}

TEST(Package, RoundTripKeepsEveryModelField)
{
    // Writer -> reader -> decode must give back exactly what was baked: floats are stored
    // bit for bit and mip level 0 is the original texture.
    const TreeModel model = makeTree();
    ASSERT_TRUE(model.validate());
    Result<ReferenceChunk> decoded = decodeFrom(packageOf(model));
    ASSERT_TRUE(decoded) << decoded.error().message();
    expectModelsEqual(model, decoded->model);
    ASSERT_EQ(decoded->textures.size(), 2u);
    EXPECT_EQ(decoded->textures[1].width, 8u);
    EXPECT_EQ(decoded->textures[1].height, 4u);
    EXPECT_EQ(decoded->textures[1].mipCount, 4u);
}

TEST(Package, RoundTripThroughAFileWithBakeReferencePackage)
{
    const TreeModel model = makeTree();
    const std::string path = outDir() + "/roundtrip.treelod";
    PackageMeta meta;
    meta.source = "tiny.glb";
    meta.sourceHash = "fnv1a64:0123456789abcdef";
    meta.optionsJson = "{\"leafMaterials\":[\"Leaves\"]}";
    ASSERT_TRUE(bakeReferencePackage(model, path, meta));

    Result<PackageReader> reader = PackageReader::open(path);
    ASSERT_TRUE(reader) << reader.error().message();
    EXPECT_EQ(reader->fileSize(), std::filesystem::file_size(path));
    EXPECT_EQ(reader->version(), PACKAGE_VERSION);
    Result<std::vector<std::uint8_t>> ref = reader->readChunk(REFERENCE_CHUNK, 0);
    ASSERT_TRUE(ref) << ref.error().message();
    Result<ReferenceChunk> decoded = decodeReferenceChunk(ref.value(), path);
    ASSERT_TRUE(decoded) << decoded.error().message();
    expectModelsEqual(model, decoded->model);

    Result<std::vector<std::uint8_t>> metaBytes = reader->readChunk(META_CHUNK, 0);
    ASSERT_TRUE(metaBytes);
    const std::string text(metaBytes->begin(), metaBytes->end());
    EXPECT_NE(text.find("\"source\": \"tiny.glb\""), std::string::npos) << text;
    EXPECT_NE(text.find("fnv1a64:0123456789abcdef"), std::string::npos) << text;
    EXPECT_NE(text.find("\"leafMaterials\""), std::string::npos) << text;
    EXPECT_NE(text.find("\"reference\""), std::string::npos) << text;
}

TEST(Package, FindChunkGivesTheTableIndexOrMinusOne)
{
    // The writer sorts by technique then level: "meta" < "reference" < "zeta".
    PackageWriter writer;
    ASSERT_TRUE(writer.addChunk("zeta", 2, 1, {1, 2, 3}));
    ASSERT_TRUE(writer.addChunk("reference", 0, 1, {4}));
    ASSERT_TRUE(writer.addChunk("meta", 0, 1, {}));
    ASSERT_TRUE(writer.addChunk("zeta", 1, 3, {5, 6}));
    Result<PackageReader> reader = PackageReader::fromMemory(writer.toBytes(), "mem");
    ASSERT_TRUE(reader) << reader.error().message();
    ASSERT_EQ(reader->chunks().size(), 4u);
    EXPECT_EQ(reader->findChunk("meta", 0), 0);
    EXPECT_EQ(reader->findChunk("reference", 0), 1);
    EXPECT_EQ(reader->findChunk("zeta", 1), 2);
    EXPECT_EQ(reader->findChunk("zeta", 2), 3);
    EXPECT_EQ(reader->findChunk("zeta", 0), -1);
    EXPECT_EQ(reader->findChunk("lodf", 0), -1);
    EXPECT_EQ(reader->chunks()[2].formatVersion, 3u);
    for (const ChunkInfo& c : reader->chunks())
        EXPECT_EQ(c.offset % PACKAGE_ALIGNMENT, 0u) << c.element();
    Result<std::vector<std::uint8_t>> zeta = reader->readChunk(3);
    ASSERT_TRUE(zeta);
    EXPECT_EQ(zeta.value(), (std::vector<std::uint8_t>{1, 2, 3}));
    Result<std::vector<std::uint8_t>> empty = reader->readChunk(0);
    ASSERT_TRUE(empty);
    EXPECT_TRUE(empty->empty());
    EXPECT_FALSE(reader->readChunk(4));
    Result<std::vector<std::uint8_t>> missing = reader->readChunk("lodf", 0);
    ASSERT_FALSE(missing);
    EXPECT_EQ(missing.error().element, "chunk 'lodf' level 0");
}

TEST(Package, SameInputGivesByteIdenticalFiles)
{
    // No timestamps and sorted chunks: two bakes, and two writers fed in different orders,
    // give the same bytes.
    const TreeModel model = makeTree();
    const std::string a = outDir() + "/same-a.treelod", b = outDir() + "/same-b.treelod";
    ASSERT_TRUE(bakeReferencePackage(model, a, "tiny.glb"));
    ASSERT_TRUE(bakeReferencePackage(model, b, "tiny.glb"));
    EXPECT_EQ(fileBytes(a), fileBytes(b));
    EXPECT_FALSE(fileBytes(a).empty());

    PackageWriter first, second;
    ASSERT_TRUE(first.addChunk("x", 0, 1, {1}));
    ASSERT_TRUE(first.addChunk("y", 0, 1, {2, 2}));
    ASSERT_TRUE(second.addChunk("y", 0, 1, {2, 2}));
    ASSERT_TRUE(second.addChunk("x", 0, 1, {1}));
    EXPECT_EQ(first.toBytes(), second.toBytes());
}

TEST(Package, TruncatedPackageIsRejectedAtEveryCutPoint)
{
    // Cutting anywhere loses the header, part of the table or the end of the last chunk;
    // each must be an error, never a crash or a short read.
    const std::vector<std::uint8_t> whole = packageOf(makeTree());
    ASSERT_TRUE(PackageReader::fromMemory(whole, "whole"));
    for (std::size_t cut : {std::size_t(0), std::size_t(3), std::size_t(4), std::size_t(20), std::size_t(31),
                            std::size_t(32), std::size_t(40), std::size_t(96), std::size_t(127), std::size_t(160),
                            whole.size() / 2, whole.size() - 1})
    {
        std::vector<std::uint8_t> part(whole.begin(), whole.begin() + std::ptrdiff_t(cut));
        Result<PackageReader> r = PackageReader::fromMemory(part, "cut.treelod");
        ASSERT_FALSE(r) << "cut at " << cut;
        EXPECT_EQ(r.error().file, "cut.treelod");
        if (cut >= 4 && cut < whole.size() - 1)
        {
            EXPECT_NE(r.error().reason.find("truncated"), std::string::npos) << r.error().message();
        }
    }
    // The last cut names the entry and the chunk that no longer fits.
    std::vector<std::uint8_t> part(whole.begin(), whole.end() - 1);
    Result<PackageReader> r = PackageReader::fromMemory(part, "cut.treelod");
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().element, "chunk table entry 1 (chunk 'reference' level 0)") << r.error().message();
    EXPECT_NE(r.error().reason.find("file has " + std::to_string(part.size())), std::string::npos)
        << r.error().message();
}

TEST(Package, TruncatedFileOnDiskIsRejected)
{
    const std::vector<std::uint8_t> whole = packageOf(makeTree());
    const std::string path = outDir() + "/truncated.treelod";
    {
        std::ofstream out(path, std::ios::binary | std::ios::trunc);
        out.write(reinterpret_cast<const char*>(whole.data()), std::streamsize(whole.size() - 10));
    }
    Result<PackageReader> r = PackageReader::open(path);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().file, path);
    EXPECT_NE(r.error().reason.find("truncated"), std::string::npos);

    Result<PackageReader> missing = PackageReader::open(outDir() + "/no-such.treelod");
    ASSERT_FALSE(missing);
    EXPECT_EQ(missing.error().reason, "file does not exist");
}

TEST(Package, BitFlippedPayloadGivesAChecksumErrorNamingTheChunk)
{
    // The table is intact, so the package opens; the damaged chunk fails its own CRC and the
    // other chunk still reads.
    std::vector<std::uint8_t> bytes = packageOf(makeTree());
    Result<PackageReader> clean = PackageReader::fromMemory(bytes, "x");
    ASSERT_TRUE(clean);
    const ChunkInfo ref = clean->chunks()[std::size_t(clean->findChunk(REFERENCE_CHUNK, 0))];
    bytes[ref.offset + ref.size / 2] ^= 0x10;
    Result<PackageReader> reader = PackageReader::fromMemory(bytes, "flipped.treelod");
    ASSERT_TRUE(reader) << reader.error().message();
    Result<std::vector<std::uint8_t>> chunk = reader->readChunk(REFERENCE_CHUNK, 0);
    ASSERT_FALSE(chunk);
    EXPECT_EQ(chunk.error().file, "flipped.treelod");
    EXPECT_EQ(chunk.error().element, "chunk 'reference' level 0");
    EXPECT_NE(chunk.error().reason.find("checksum mismatch"), std::string::npos) << chunk.error().message();
    EXPECT_TRUE(reader->readChunk(META_CHUNK, 0));
}

TEST(Package, BitFlippedTableOrHeaderIsRejected)
{
    const std::vector<std::uint8_t> clean = packageOf(makeTree());
    std::vector<std::uint8_t> table = clean;
    table[32 + 64 + 40] ^= 0x01; // offset of entry 1
    Result<PackageReader> r = PackageReader::fromMemory(table, "t.treelod");
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().element, "chunk table");
    EXPECT_NE(r.error().reason.find("checksum mismatch"), std::string::npos);

    std::vector<std::uint8_t> header = clean;
    header[16] ^= 0x20; // table offset
    r = PackageReader::fromMemory(header, "h.treelod");
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().element, "header");
    EXPECT_NE(r.error().reason.find("checksum mismatch"), std::string::npos);
}

TEST(Package, WrongMagicSaysItIsNotAPackage)
{
    std::vector<std::uint8_t> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    png.resize(200, 0);
    Result<PackageReader> r = PackageReader::fromMemory(png, "leaf.png");
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().message(),
              "leaf.png: header: not a TreeLod package (magic 89 50 4e 47, expected 54 52 4c 44 \"TRLD\")");
    Result<PackageReader> empty = PackageReader::fromMemory({}, "empty.treelod");
    ASSERT_FALSE(empty);
    EXPECT_NE(empty.error().reason.find("empty file"), std::string::npos);
}

TEST(Package, FutureVersionIsRefusedByNumber)
{
    std::vector<std::uint8_t> bytes = packageOf(makeTree());
    putU32(bytes, 4, 7);
    reseal(bytes);
    Result<PackageReader> r = PackageReader::fromMemory(bytes, "new.treelod");
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().message(), "new.treelod: header: unsupported version 7, this build reads 1");
}

TEST(Package, EmptyPackageHasAHeaderAndNoChunks)
{
    // A package with no chunks is 32 header bytes: valid, just empty.
    const std::vector<std::uint8_t> bytes = PackageWriter().toBytes();
    EXPECT_EQ(bytes.size(), PACKAGE_HEADER_SIZE);
    Result<PackageReader> r = PackageReader::fromMemory(bytes, "empty");
    ASSERT_TRUE(r) << r.error().message();
    EXPECT_TRUE(r->chunks().empty());
    EXPECT_EQ(r->findChunk(REFERENCE_CHUNK, 0), -1);
}

TEST(Package, HostileTableEntriesAreRejected)
{
    // Entries that pass the checksum (resealed) but point outside the file, at a misaligned
    // offset, into the table, or repeat a key.
    const std::vector<std::uint8_t> clean = packageOf(makeTree());
    const std::size_t entry1 = 32 + 64;

    std::vector<std::uint8_t> far = clean;
    putU32(far, entry1 + 40 + 4, 0x10); // offset high word: 2^36
    reseal(far);
    Result<PackageReader> r = PackageReader::fromMemory(far, "p");
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().reason.find("truncated"), std::string::npos) << r.error().message();

    std::vector<std::uint8_t> huge = clean;
    putU32(huge, entry1 + 48 + 4, 0xffffffffu); // size near 2^64: offset + size overflows
    putU32(huge, entry1 + 48, 0xffffffffu);
    reseal(huge);
    r = PackageReader::fromMemory(huge, "p");
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().reason.find("truncated"), std::string::npos) << r.error().message();

    std::vector<std::uint8_t> misaligned = clean;
    putU32(misaligned, entry1 + 40, getU32(misaligned, entry1 + 40) + 4);
    reseal(misaligned);
    r = PackageReader::fromMemory(misaligned, "p");
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().reason.find("not a multiple of 16"), std::string::npos) << r.error().message();

    std::vector<std::uint8_t> intoTable = clean;
    putU32(intoTable, entry1 + 40, 32);
    reseal(intoTable);
    r = PackageReader::fromMemory(intoTable, "p");
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().reason.find("overlaps"), std::string::npos) << r.error().message();

    std::vector<std::uint8_t> duplicate = clean;
    std::memcpy(&duplicate[entry1], &duplicate[32], 32); // entry 1 renamed "meta"
    putU32(duplicate, entry1 + 32, 0);
    reseal(duplicate);
    r = PackageReader::fromMemory(duplicate, "p");
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().element, "chunk table entry 1");
    EXPECT_NE(r.error().reason.find("duplicate of entry 0"), std::string::npos) << r.error().message();

    std::vector<std::uint8_t> count = clean;
    putU32(count, 8, 0x7fffffff); // a table of 2^31 entries cannot fit
    reseal(count, false);
    r = PackageReader::fromMemory(count, "p");
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().element, "chunk table");
}

TEST(AllocationTracker, SeesTheLargestRequestOfNewAndMallocWhileAlive)
{
    // The tests below rely on the tracker seeing big requests; this one shows that it does.
    if (!test::AllocationTracker::available())
        GTEST_SKIP() << "allocation tracking needs glibc and no sanitizer";
    static void* volatile sink = nullptr; // keeps the allocations from being optimised away
    {
        test::AllocationTracker tracker;
        sink = ::operator new(3u << 20);
        ::operator delete(sink);
        EXPECT_EQ(tracker.largest(), 3u << 20);
        sink = new std::uint8_t[5u << 20];
        delete[] static_cast<std::uint8_t*>(sink);
        EXPECT_EQ(tracker.largest(), 5u << 20);
        sink = std::malloc(7u << 20);
        std::free(sink);
        EXPECT_EQ(tracker.largest(), 7u << 20);
        sink = std::calloc(1u << 20, 9);
        std::free(sink);
        EXPECT_EQ(tracker.largest(), 9u << 20);
    }
    test::AllocationTracker fresh;
    EXPECT_EQ(fresh.largest(), 0u);
}

TEST(Package, GigabyteClaimsInASmallFileAreRefusedBeforeAllocating)
{
    // Table entries, a chunk count and a table offset that claim about 4 GiB (or, for the count,
    // 4 billion 64-byte entries) in a package of 1.4 KB, checksums resealed: each is
    // refused from the header and table alone. Bound on the largest single allocation while the
    // reader opens it: 2 x the file size + 8 KiB (the table, the chunk list and, from disk, the
    // file stream's buffer); reading a claimed payload would need 4 GiB.
    const std::vector<std::uint8_t> clean = packageOf(makeTree());
    Result<PackageReader> cleanReader = PackageReader::fromMemory(clean, "clean");
    ASSERT_TRUE(cleanReader);
    ASSERT_EQ(cleanReader->chunks()[1].technique, REFERENCE_CHUNK);
    const std::uint64_t refOffset = cleanReader->chunks()[1].offset, refSize = cleanReader->chunks()[1].size;
    const std::size_t entry1 = 32 + 64;
    const std::string fileHas = ", file has " + std::to_string(clean.size());
    const std::string refEntry = "chunk table entry 1 (chunk 'reference' level 0)";

    struct Case
    {
        std::string what;
        std::vector<std::uint8_t> bytes;
        std::string element, reason;
    };
    std::vector<Case> cases;
    auto edited = [&](auto edit, bool table) {
        std::vector<std::uint8_t> b = clean;
        edit(b);
        reseal(b, table);
        return b;
    };
    cases.push_back({"chunk size 4 GiB - 16",
                     edited([&](auto& b) { putU64(b, entry1 + 48, 0xfffffff0ull); }, true), refEntry,
                     "truncated: needs 4294967280 bytes at offset " + std::to_string(refOffset) + fileHas});
    cases.push_back({"chunk offset 4 GiB",
                     edited([&](auto& b) { putU64(b, entry1 + 40, 0x100000000ull); }, true), refEntry,
                     "truncated: needs " + std::to_string(refSize) + " bytes at offset 4294967296" + fileHas});
    cases.push_back({"chunk offset and size 4 GiB",
                     edited([&](auto& b) {
                         putU64(b, entry1 + 40, 0x100000000ull);
                         putU64(b, entry1 + 48, 0x100000000ull);
                     }, true),
                     refEntry, "truncated: needs 4294967296 bytes at offset 4294967296" + fileHas});
    cases.push_back({"4294967295 chunks", edited([&](auto& b) { putU32(b, 8, 0xffffffffu); }, false),
                     "chunk table", "truncated: needs 274877906880 bytes at offset 32" + fileHas});
    cases.push_back({"table offset 4 GiB", edited([&](auto& b) { putU64(b, 16, 0x100000000ull); }, false),
                     "chunk table", "truncated: needs 128 bytes at offset 4294967296" + fileHas});

    const bool tracked = test::AllocationTracker::available();
    const std::size_t bound = 2 * clean.size() + 8192;
    for (Case& c : cases)
    {
        const std::string path = outDir() + "/claims-4gib.treelod";
        {
            std::ofstream out(path, std::ios::binary | std::ios::trunc);
            out.write(reinterpret_cast<const char*>(c.bytes.data()), std::streamsize(c.bytes.size()));
        }
        for (bool fromDisk : {false, true})
        {
            const std::string label = fromDisk ? path : "claims-4gib";
            std::vector<std::uint8_t> bytes = c.bytes; // copied before tracking: fromMemory takes it
            std::size_t largest = 0;
            Result<PackageReader> r = PackageReader();
            {
                test::AllocationTracker tracker;
                r = fromDisk ? PackageReader::open(path) : PackageReader::fromMemory(std::move(bytes), label);
                largest = tracker.largest();
            }
            const std::string where = c.what + (fromDisk ? " (file)" : " (memory)");
            ASSERT_FALSE(r) << where;
            EXPECT_EQ(r.error().file, label) << where;
            EXPECT_EQ(r.error().element, c.element) << where;
            EXPECT_EQ(r.error().reason, c.reason) << where;
            if (tracked)
            {
                EXPECT_LE(largest, bound) << where << ": largest allocation " << largest << " bytes";
            }
        }
    }

    // Inside a well-formed package, the reference chunk's leaf texture claims 16384 x 16384 with
    // all 15 mip levels (1.4 GB of texels): refused from its header, nothing of that size asked for.
    std::vector<std::uint8_t> chunk = encodeReferenceChunk(makeReferenceChunk(makeTree()));
    const std::vector<std::uint8_t> named = {8, 0, 0, 0, 'l', 'e', 'a', 'f', '.', 'p', 'n', 'g'};
    auto found = std::search(chunk.begin(), chunk.end(), named.begin(), named.end());
    ASSERT_NE(found, chunk.end());
    const std::size_t fields = std::size_t(found - chunk.begin()) + named.size(); // format, w, h, mips, bytes
    const GpuTextureFormat format = GpuTextureFormat(getU32(chunk, fields));
    const std::uint64_t claimed = gpuTextureBytes(format, 16384, 16384, 15);
    ASSERT_GT(claimed, std::uint64_t(1) << 30);
    putU32(chunk, fields + 4, 16384);
    putU32(chunk, fields + 8, 16384);
    putU32(chunk, fields + 12, 15);
    putU64(chunk, fields + 16, claimed);
    PackageWriter writer;
    ASSERT_TRUE(writer.addChunk(REFERENCE_CHUNK, 0, REFERENCE_CHUNK_FORMAT_VERSION, chunk));
    std::vector<std::uint8_t> package = writer.toBytes();
    std::size_t largest = 0;
    Result<ReferenceChunk> decoded = ReferenceChunk();
    {
        test::AllocationTracker tracker;
        decoded = decodeFrom(package);
        largest = tracker.largest();
    }
    ASSERT_FALSE(decoded);
    EXPECT_EQ(decoded.error().file, "mem.treelod");
    EXPECT_EQ(decoded.error().element, "chunk 'reference' level 0, texture 1 'leaf.png'");
    EXPECT_EQ(decoded.error().reason.rfind("truncated: needs " + std::to_string(claimed) + " bytes", 0), 0u)
        << decoded.error().message();
    if (tracked)
    {
        // fromMemory copies the package, readChunk copies the payload: each at most the package.
        EXPECT_LE(largest, 2 * package.size() + 8192) << "largest allocation " << largest << " bytes";
    }
}

TEST(ModelChunk, ZeroLeafAndEmptyModelsRoundTrip)
{
    // A bare trunk is a tree, and so is an empty model: both must survive the package.
    const TreeModel bare = makeTree(false);
    ASSERT_TRUE(bare.leaves.empty());
    Result<ReferenceChunk> decoded = decodeFrom(packageOf(bare));
    ASSERT_TRUE(decoded) << decoded.error().message();
    expectModelsEqual(bare, decoded->model);

    const TreeModel empty;
    decoded = decodeFrom(packageOf(empty));
    ASSERT_TRUE(decoded) << decoded.error().message();
    expectModelsEqual(empty, decoded->model);
}

TEST(ModelChunk, EveryTruncationAndTrailingByteIsAnError)
{
    // Each prefix of a valid chunk is missing some declared data; a trailing byte is data the
    // layout does not declare. None may decode.
    const std::vector<std::uint8_t> chunk = encodeReferenceChunk(makeReferenceChunk(makeTree()));
    ASSERT_TRUE(decodeReferenceChunk(chunk, "c"));
    for (std::size_t cut = 0; cut < chunk.size(); ++cut)
    {
        std::vector<std::uint8_t> part(chunk.begin(), chunk.begin() + std::ptrdiff_t(cut));
        Result<ReferenceChunk> r = decodeReferenceChunk(part, "c");
        ASSERT_FALSE(r) << "cut at " << cut;
        EXPECT_EQ(r.error().element.rfind("chunk 'reference' level 0", 0), 0u) << r.error().message();
    }
    std::vector<std::uint8_t> longer = chunk;
    longer.push_back(0);
    Result<ReferenceChunk> r = decodeReferenceChunk(longer, "c");
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().reason.find("1 trailing bytes"), std::string::npos) << r.error().message();
}

TEST(ModelChunk, InconsistentModelsAreRejectedWithTheElement)
{
    ReferenceChunk chunk = makeReferenceChunk(makeTree());

    ReferenceChunk badTexture = chunk;
    badTexture.model.materials[1].texture = 5;
    Result<ReferenceChunk> r = decodeReferenceChunk(encodeReferenceChunk(badTexture), "pkg");
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().element, "chunk 'reference' level 0, material 1 'Leaves'");

    ReferenceChunk badMips = chunk;
    badMips.textures[1].mipCount = 5; // 8x4 has 4 levels
    r = decodeReferenceChunk(encodeReferenceChunk(badMips), "pkg");
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().element, "chunk 'reference' level 0, texture 1 'leaf.png'");

    ReferenceChunk badIndex = chunk;
    badIndex.model.barkIndices[2] = 99;
    r = decodeReferenceChunk(encodeReferenceChunk(badIndex), "pkg");
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().element, "chunk 'reference' level 0, bark index 2");

    ReferenceChunk overlapping = chunk;
    overlapping.model.leaves[1] = overlapping.model.leaves[0];
    r = decodeReferenceChunk(encodeReferenceChunk(overlapping), "pkg");
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().reason.find("overlap"), std::string::npos) << r.error().message();

    ReferenceChunk nan = chunk;
    nan.model.leafVertices[3].position.y = std::nanf("");
    r = decodeReferenceChunk(encodeReferenceChunk(nan), "pkg");
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().element, "chunk 'reference' level 0, leaf vertex 3");

    // A count far beyond the chunk size fails before anything is allocated.
    std::vector<std::uint8_t> bytes = encodeReferenceChunk(chunk);
    const std::size_t materialCountAt = 4 + chunk.model.name.size();
    putU32(bytes, materialCountAt, 0xfffffff0u);
    r = decodeReferenceChunk(bytes, "pkg");
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().element, "chunk 'reference' level 0, materials");
    EXPECT_NE(r.error().reason.find("count 4294967280"), std::string::npos) << r.error().message();
}

TEST(MipChain, LevelCountsAndSizesGoDownToOneByOne)
{
    // 8x4 -> 8x4, 4x2, 2x1, 1x1; 1x1 has one level; 5x3 -> 5x3, 2x1, 1x1 (floor halving).
    GpuTexture a = buildMipChain(makeTexture("a", 8, 4, 1, true));
    EXPECT_EQ(a.mipCount, 4u);
    EXPECT_EQ(a.data.size(), (32u + 8u + 2u + 1u) * 4u);
    EXPECT_EQ(a.mipWidth(2), 2u);
    EXPECT_EQ(a.mipHeight(2), 1u);
    EXPECT_EQ(a.mipOffset(3), (32u + 8u + 2u) * 4u);

    GpuTexture b = buildMipChain(makeTexture("b", 1, 1, 1, true));
    EXPECT_EQ(b.mipCount, 1u);
    EXPECT_EQ(b.data.size(), 4u);

    GpuTexture c = buildMipChain(makeTexture("c", 5, 3, 1, true));
    EXPECT_EQ(c.mipCount, 3u);
    EXPECT_EQ(c.data.size(), (15u + 2u + 1u) * 4u);
    EXPECT_EQ(fullMipCount(1, 1000), 10u);
    EXPECT_EQ(fullMipCount(0, 0), 0u);

    GpuTexture none = buildMipChain(TextureImage{});
    EXPECT_EQ(none.mipCount, 0u);
    EXPECT_TRUE(none.data.empty());
}

TEST(MipChain, LevelZeroIsExactAndFilteringIsInLinearLight)
{
    const TextureImage image = makeTexture("x", 6, 6, 7, true);
    GpuTexture tex = buildMipChain(image);
    EXPECT_TRUE(std::equal(image.rgba.begin(), image.rgba.end(), tex.data.begin()));

    // 3x1 white, white, black -> 1x1: the three texels weigh 1/3 each (non-power-of-two box),
    // averaged in linear light: linear 2/3 is sRGB 1.055 * (2/3)^(1/2.4) - 0.055 = 0.836 = 213,
    // not the 170 of an average of the sRGB bytes.
    TextureImage odd;
    odd.width = 3;
    odd.height = 1;
    odd.rgba = {255, 255, 255, 255, 255, 255, 255, 255, 0, 0, 0, 255};
    GpuTexture t = buildMipChain(odd);
    ASSERT_EQ(t.mipCount, 2u);
    const std::uint8_t* p = t.data.data() + t.mipOffset(1);
    EXPECT_NEAR(p[0], 213, 1);
    EXPECT_EQ(p[3], 255);
}

TEST(MipChain, TransparentTexelsLendNoColour)
{
    // Opaque red beside transparent black: the 1x1 mip stays pure red (colour weighted by
    // alpha), with half alpha (no coverage preservation here).
    TextureImage image;
    image.width = 2;
    image.height = 1;
    image.rgba = {255, 0, 0, 255, 0, 0, 0, 0};
    MipChainOptions plain;
    plain.preserveAlphaCoverage = false;
    GpuTexture tex = buildMipChain(image, plain);
    const std::uint8_t* p = tex.data.data() + tex.mipOffset(1);
    EXPECT_EQ(p[0], 255);
    EXPECT_EQ(p[1], 0);
    EXPECT_EQ(p[2], 0);
    EXPECT_EQ(p[3], 128);
}

TEST(MipChain, AlphaCoverageStaysWithinTwoPercentDownTo8x8)
{
    // Castaño's rescaling picks, per level, the alpha threshold whose coverage is nearest to
    // level 0's, so the error is bounded by the level's alpha histogram granularity. Bound:
    // 0.02 down to 8x8 (64 texels; one texel is 0.016), and within one texel (1/texels) on
    // the smaller levels. Measured on this leaf: at most 0.006 down to 8x8. The plain box
    // filter drifts by 0.04 (cutoff 0.3) and 0.08 (cutoff 0.7) by 8x8: a soft rim averages
    // towards 0.5, so leaves swell under low cutoffs and go bald under high ones.
    const TextureImage leaf = leafAlpha();
    for (float cutoff : {0.3f, 0.5f, 0.7f})
    {
        MipChainOptions preserving;
        preserving.alphaCutoff = cutoff;
        MipChainOptions plain = preserving;
        plain.preserveAlphaCoverage = false;
        const GpuTexture kept = buildMipChain(leaf, preserving), drifted = buildMipChain(leaf, plain);
        ASSERT_EQ(kept.mipCount, 7u);
        const double c0 = coverage(kept, 0, cutoff);
        EXPECT_GT(c0, 0.2);
        EXPECT_LT(c0, 0.6);
        double worstPlain = 0.0;
        for (std::uint32_t level = 1; level < kept.mipCount; ++level)
        {
            const double texels = double(kept.mipWidth(level)) * kept.mipHeight(level);
            const double bound = kept.mipWidth(level) >= 8 ? 0.02 : 1.0 / texels;
            EXPECT_NEAR(coverage(kept, level, cutoff), c0, bound) << "level " << level << " cutoff " << cutoff;
            if (kept.mipWidth(level) >= 8)
                worstPlain = std::max(worstPlain, std::abs(coverage(drifted, level, cutoff) - c0));
        }
        if (cutoff != 0.5f) // a symmetric rim averages to 0.5 where it crossed 0.5: little drift there
        {
            EXPECT_GT(worstPlain, 0.03) << "cutoff " << cutoff;
        }
    }
}

// Leaf materials sharing one texture under cutoffs 0.3, 0.7 and 0.3 again: two chains, each
// keeping the coverage of its own cutoff, the third material on the first chain; the chunk
// round-trips and the bark texture keeps its index.
TEST(PackageWriter, ReferenceChunkKeepsEveryLeafMaterialsCoverageOnASharedTexture)
{
    TreeModel model = makeTree();
    model.textures[1] = leafAlpha();
    model.materials[1].alphaCutoff = 0.3f;
    Material strict = model.materials[1];
    strict.name = "Leaves strict";
    strict.alphaCutoff = 0.7f;
    Material loose = model.materials[1];
    loose.name = "Leaves loose";
    model.materials.push_back(strict);
    model.materials.push_back(loose);
    model.leaves[1].material = 2;
    ASSERT_TRUE(model.validate().ok());
    const ReferenceChunk chunk = makeReferenceChunk(model);
    ASSERT_EQ(chunk.textures.size(), 3u);
    EXPECT_EQ(chunk.model.materials[0].texture, 0);
    EXPECT_EQ(chunk.model.materials[1].texture, 1);
    EXPECT_EQ(chunk.model.materials[2].texture, 2);
    EXPECT_EQ(chunk.model.materials[3].texture, 1);
    EXPECT_EQ(chunk.textures[2].name, chunk.textures[1].name + " at cutoff 0.7");
    for (const auto& [texture, cutoff] : {std::pair<int, float>{1, 0.3f}, {2, 0.7f}})
    {
        const GpuTexture& chain = chunk.textures[std::size_t(texture)];
        const double c0 = coverage(chain, 0, cutoff);
        for (std::uint32_t level = 1; chain.mipWidth(level) >= 8; ++level)
            EXPECT_NEAR(coverage(chain, level, cutoff), c0, 0.02) << "cutoff " << cutoff << " level " << level;
    }
    Result<ReferenceChunk> back = decodeReferenceChunk(encodeReferenceChunk(chunk), "shared texture");
    ASSERT_TRUE(back.ok()) << back.error().message();
    EXPECT_EQ(back->textures.size(), 3u);
    EXPECT_EQ(back->model.materials[2].texture, 2);
}

TEST(PackageWriter, AtomicWriteLeavesNoFileWhenTheDirectoryIsMissing)
{
    const std::string dir = outDir() + "/no-such-dir";
    std::filesystem::remove_all(dir);
    const std::string path = dir + "/tree.treelod";
    Result<void> r = bakeReferencePackage(makeTree(), path, "tiny.glb");
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().file, path);
    EXPECT_FALSE(std::filesystem::exists(dir));

    // An invalid model is refused before anything is written.
    TreeModel broken = makeTree();
    broken.barkIndices[0] = 1000;
    const std::string target = outDir() + "/broken.treelod";
    std::filesystem::remove(target);
    ASSERT_FALSE(bakeReferencePackage(broken, target, "tiny.glb"));
    EXPECT_FALSE(std::filesystem::exists(target));
}

TEST(PackageWriter, RefusesWhatTheReferenceChunkCannotHold)
{
    // The decoder caps names at MODEL_CHUNK_MAX_STRING bytes and texture edges at
    // GPU_TEXTURE_MAX_SIZE; the baker refuses such models instead of writing a package that
    // would not load. A long but legal name round-trips.
    const std::string path = outDir() + "/refused.treelod";
    std::filesystem::remove(path);
    TreeModel longName = makeTree();
    longName.name.assign(MODEL_CHUNK_MAX_STRING + 1, 'n');
    Result<void> r = bakeReferencePackage(longName, path, "x");
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().element, "model");

    TreeModel wide = makeTree();
    wide.textures[0].width = int(GPU_TEXTURE_MAX_SIZE) + 1;
    wide.textures[0].height = 1;
    wide.textures[0].rgba.assign(std::size_t(wide.textures[0].width) * 4, 255);
    r = bakeReferencePackage(wide, path, "x");
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().element, "texture 0 'bark.png'");
    EXPECT_FALSE(std::filesystem::exists(path));

    TreeModel legal = makeTree();
    legal.name.assign(MODEL_CHUNK_MAX_STRING, 'n');
    Result<ReferenceChunk> decoded = decodeFrom(packageOf(legal));
    ASSERT_TRUE(decoded) << decoded.error().message();
    EXPECT_EQ(decoded->model.name, legal.name);
}

TEST(PackageWriter, RejectsTechniqueNamesTheTableCannotHold)
{
    PackageWriter w;
    EXPECT_FALSE(w.addChunk("", 0, 1, {}));
    EXPECT_FALSE(w.addChunk(std::string(33, 'a'), 0, 1, {}));
    EXPECT_FALSE(w.addChunk("tab\there", 0, 1, {}));
    EXPECT_TRUE(w.addChunk(std::string(32, 'a'), 0, 1, {}));
    EXPECT_EQ(w.chunkCount(), 1u);
    Result<PackageReader> r = PackageReader::fromMemory(w.toBytes(), "m");
    ASSERT_TRUE(r) << r.error().message();
    EXPECT_EQ(r->chunks()[0].technique, std::string(32, 'a'));
}

TEST(PackageWriter, Fnv1aMatchesPublishedValues)
{
    // FNV-1a 64 test vectors from the reference (Fowler/Noll/Vo) test suite.
    EXPECT_EQ(fnv1a64("", 0), 0xcbf29ce484222325ull);
    EXPECT_EQ(fnv1a64("a", 1), 0xaf63dc4c8601ec8cull);
    EXPECT_EQ(fnv1a64("foobar", 6), 0x85944171f73967e8ull);
}

namespace
{
    /// An RGBA8 texture of `mips` levels, each a ramp of red along x and green along y (0 to 255,
    /// the same ramps at every level) and alpha `alpha`, or a ramp along x + y when 0: values a
    /// 4x4 block holds on a line, so that a block format's error is its quantisation only.
    GpuTexture rampTexture(std::uint32_t size, std::uint32_t mips, std::uint8_t alpha = 0)
    {
        GpuTexture t;
        t.name = "ramp";
        t.width = t.height = size;
        t.mipCount = mips;
        t.data.resize(gpuTextureBytes(GpuTextureFormat::RGBA8, size, size, mips));
        for (std::uint32_t m = 0; m < mips; ++m)
        {
            const std::uint32_t w = t.mipWidth(m), h = t.mipHeight(m);
            std::uint8_t* p = t.data.data() + t.mipOffset(m);
            for (std::uint32_t y = 0; y < h; ++y)
                for (std::uint32_t x = 0; x < w; ++x, p += 4)
                {
                    p[0] = std::uint8_t(255 * x / std::max(1u, w - 1));
                    p[1] = std::uint8_t(255 * y / std::max(1u, h - 1));
                    p[2] = 0;
                    p[3] = alpha ? alpha : std::uint8_t(255 - 255 * (x + y) / std::max(1u, w + h - 2));
                }
        }
        return t;
    }

    /// Largest absolute difference of channel `c` between two RGBA8 textures of one size, over
    /// mip level `level` (-1: every level).
    int maxChannelError(const GpuTexture& a, const GpuTexture& b, int c, int level = -1)
    {
        const std::size_t begin = level < 0 ? 0 : a.mipOffset(std::uint32_t(level));
        const std::size_t end = level < 0 ? a.data.size() : begin + a.mipBytes(std::uint32_t(level));
        int worst = 0;
        for (std::size_t i = begin + std::size_t(c); i < end; i += 4)
            worst = std::max(worst, std::abs(int(a.data[i]) - int(b.data[i])));
        return worst;
    }
}

TEST(GpuTextureDecode, Bc4AndBc5RoundTripTheirChannelsAndSampleAsTheGpuDoes)
{
    // A ramp is what BC4/BC5 encode best: 8 levels between two endpoints a block, so at level 0 a
    // 4-texel stretch of a 0..255 ramp over 64 texels is within 3 of exact. On the small levels a
    // block spans up to the whole ramp (2x2: 0 and 255, 3 texels: 0, 127, 255), and the bound is
    // half a palette step of the whole range in the 6-step mode: 255 / 5 / 2 < 26.
    const GpuTexture ramp = rampTexture(64, 7);
    for (GpuTextureFormat format : {GpuTextureFormat::BC4, GpuTextureFormat::BC5})
    {
        const GpuTexture packed = compressTexture(ramp, format);
        EXPECT_EQ(gpuTextureProblem(packed, {format}), "") << gpuTextureFormatName(format);
        EXPECT_EQ(packed.data.size(), gpuTextureBytes(format, 64, 64, 7));
        EXPECT_EQ(packed.mipBytes(0), format == GpuTextureFormat::BC4 ? 16u * 16u * 8u : 16u * 16u * 16u);
        const GpuTexture decoded = decodeGpuTexture(packed);
        ASSERT_EQ(decoded.format, GpuTextureFormat::RGBA8);
        ASSERT_EQ(decoded.data.size(), ramp.data.size());
        for (int c = 0; c < (format == GpuTextureFormat::BC5 ? 2 : 1); ++c)
        {
            EXPECT_LE(maxChannelError(decoded, ramp, c, 0), 3) << gpuTextureFormatName(format) << " channel " << c;
            EXPECT_LE(maxChannelError(decoded, ramp, c), 26) << gpuTextureFormatName(format) << " channel " << c;
        }
        // The channels the format does not hold read as a GPU samples them: (r, 0, 0, 1), (r, g, 0, 1).
        for (std::size_t i = 0; i < decoded.data.size(); i += 4)
        {
            if (format == GpuTextureFormat::BC4)
                ASSERT_EQ(decoded.data[i + 1], 0) << "texel " << i / 4;
            ASSERT_EQ(decoded.data[i + 2], 0) << "texel " << i / 4;
            ASSERT_EQ(decoded.data[i + 3], 255) << "texel " << i / 4;
        }
    }
}

TEST(GpuTextureDecode, HandMadeBlocksGiveTheirPalettes)
{
    // BC4, a0 = 200 > a1 = 60: index 0 is a0, 1 is a1, 2..7 the six steps between (200*6+60)/7 = 180, ...
    // Indices 0, 1, 2, 7 then zeros, 3 bits each from the lowest bit of byte 2.
    GpuTexture bc4;
    bc4.format = GpuTextureFormat::BC4;
    bc4.width = bc4.height = 4;
    bc4.mipCount = 1;
    const std::uint64_t indices = 0u | 1u << 3 | 2u << 6 | 7u << 9;
    bc4.data = {200, 60};
    for (int i = 0; i < 6; ++i)
        bc4.data.push_back(std::uint8_t(indices >> (8 * i)));
    GpuTexture d = decodeGpuTexture(bc4);
    EXPECT_EQ(d.data[0], 200);
    EXPECT_EQ(d.data[4], 60);
    EXPECT_EQ(d.data[8], (6 * 200 + 60) / 7);
    EXPECT_EQ(d.data[12], (200 + 6 * 60) / 7);
    // a0 <= a1 is the other mode: four steps, then 0 and 255 (indices 6 and 7).
    bc4.data[0] = 60;
    bc4.data[1] = 200;
    d = decodeGpuTexture(bc4);
    EXPECT_EQ(d.data[8], (4 * 60 + 200) / 5);
    EXPECT_EQ(d.data[12], 255);

    // DXT1 with c0 <= c1: index 3 is transparent black; DXT5's colour block ignores that order.
    GpuTexture dxt1;
    dxt1.format = GpuTextureFormat::DXT1;
    dxt1.width = dxt1.height = 4;
    dxt1.mipCount = 1;
    dxt1.data = {0x00, 0x00, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF}; // black, white; every index 3
    d = decodeGpuTexture(dxt1);
    EXPECT_EQ(d.data[3], 0) << "transparent";
    GpuTexture dxt5 = dxt1;
    dxt5.format = GpuTextureFormat::DXT5;
    dxt5.data.insert(dxt5.data.begin(), {255, 255, 0, 0, 0, 0, 0, 0}); // alpha 255 everywhere
    d = decodeGpuTexture(dxt5);
    EXPECT_EQ(d.data[3], 255);
    EXPECT_EQ(d.data[0], (0 + 2 * 255) / 3) << "the four-colour palette's last step";
}

TEST(GpuTextureDecode, DxtDecodesWhatTheEncoderMadeOfEveryMipLevel)
{
    // Odd sizes too: the last blocks of a 6x6 or 3x3 level hang over its edge. Opaque for DXT1,
    // whose encoder makes texels under alpha 128 transparent black.
    for (std::uint32_t size : {64u, 6u})
    {
        for (GpuTextureFormat format : {GpuTextureFormat::DXT1, GpuTextureFormat::DXT5})
        {
            // Grey along x: every block's colours lie on a line, which DXT's four steps between
            // two 5:6:5 endpoints hold at level 0 (64 texels) to within an endpoint's rounding (8
            // levels of 255 at 5 bits). A small level's block spans the whole ramp, where three
            // even steps hold 0, 127, 255 only to half a step, 43, plus that rounding.
            GpuTexture ramp = rampTexture(size, fullMipCount(size, size), format == GpuTextureFormat::DXT1 ? 255 : 0);
            for (std::size_t i = 0; i < ramp.data.size(); i += 4)
                ramp.data[i + 1] = ramp.data[i + 2] = ramp.data[i];
            const GpuTexture decoded = decodeGpuTexture(compressTexture(ramp, format));
            ASSERT_EQ(decoded.data.size(), ramp.data.size());
            for (int c = 0; c < 3; ++c)
            {
                if (size == 64)
                    EXPECT_LE(maxChannelError(decoded, ramp, c, 0), 8) << gpuTextureFormatName(format);
                EXPECT_LE(maxChannelError(decoded, ramp, c), 51) << gpuTextureFormatName(format) << " " << size;
            }
            if (format == GpuTextureFormat::DXT5) // alpha: BC4's block, as above
            {
                if (size == 64)
                    EXPECT_LE(maxChannelError(decoded, ramp, 3, 0), 3);
                EXPECT_LE(maxChannelError(decoded, ramp, 3), 26) << size;
            }
        }
    }
}

TEST(ModelChunk, UnknownTextureFormatsNameFileChunkTextureAndFormat)
{
    std::vector<std::uint8_t> chunk = encodeReferenceChunk(makeReferenceChunk(makeTree()));
    const std::vector<std::uint8_t> named = {8, 0, 0, 0, 'l', 'e', 'a', 'f', '.', 'p', 'n', 'g'};
    auto found = std::search(chunk.begin(), chunk.end(), named.begin(), named.end());
    ASSERT_NE(found, chunk.end());
    const std::size_t format = std::size_t(found - chunk.begin()) + named.size();
    for (std::uint32_t value : {6u, 0u})
    {
        std::vector<std::uint8_t> bad = chunk;
        putU32(bad, format, value);
        PackageWriter writer;
        ASSERT_TRUE(writer.addChunk(REFERENCE_CHUNK, 0, REFERENCE_CHUNK_FORMAT_VERSION, bad));
        Result<ReferenceChunk> decoded = decodeFrom(writer.toBytes());
        ASSERT_FALSE(decoded) << value;
        EXPECT_EQ(decoded.error().file, "mem.treelod");
        EXPECT_EQ(decoded.error().element.rfind("chunk 'reference' level 0, texture", 0), 0u) << decoded.error().message();
        EXPECT_NE(decoded.error().element.find("leaf.png"), std::string::npos) << decoded.error().message();
        EXPECT_NE(decoded.error().reason.find("unknown format " + std::to_string(value)), std::string::npos)
            << decoded.error().message();
    }
}
