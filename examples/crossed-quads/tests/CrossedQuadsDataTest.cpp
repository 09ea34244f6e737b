// The crossed quads' core half: the bake frames the tree in each quad, the chunk round-trips,
// hostile bytes are refused with a message naming the chunk (never a crash), and the
// registries know the technique (inspect for `treelod info`, the fuzz hook, the baker).
#include "TestTrees.h"

#include "TreeLod/BakeTechniques.h"
#include "TreeLod/CrossedQuadsBaker.h"
#include "TreeLod/CrossedQuadsData.h"
#include "TreeLod/Package.h"
#include "TreeLod/TechniqueDescriptor.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>

namespace TreeLod
{
    namespace
    {
        /// The generated 1200-leaf oak baked small and fast (RGBA8 so texels can be read back).
        const CrossedQuadsData& baked()
        {
            static const CrossedQuadsData data = [] {
                CrossedQuadsOptions options;
                options.resolution = 64;
                options.samplesPerPixel = 4;
                options.compress = false;
                Result<CrossedQuadsData> d = bakeCrossedQuads(test::generatedOak(1200), options, "oak");
                if (!d)
                    throw std::runtime_error(d.error().message());
                return std::move(d).value();
            }();
            return data;
        }

        /// Fraction of level-0 texels with alpha at or above the cutoff.
        double covered(const CrossedQuad& q, float cutoff)
        {
            std::size_t n = 0;
            const std::size_t count = std::size_t(q.colour.width) * q.colour.height;
            for (std::size_t i = 0; i < count; ++i)
                n += q.colour.data[4 * i + 3] >= std::uint8_t(std::lround(cutoff * 255.0f));
            return double(n) / double(count);
        }

        void expectRefused(const std::vector<std::uint8_t>& bytes, const std::string& why)
        {
            Result<CrossedQuadsData> d = decodeCrossedQuadsChunk(bytes, "bad.treelod");
            ASSERT_FALSE(d.ok()) << why;
            const std::string message = d.error().message();
            EXPECT_NE(message.find("bad.treelod"), std::string::npos) << message;
            EXPECT_NE(message.find("chunk 'crossed-quads' level 0"), std::string::npos) << message;
        }

        void putU32(std::vector<std::uint8_t>& bytes, std::size_t at, std::uint32_t v)
        {
            for (int i = 0; i < 4; ++i)
                bytes[at + i] = std::uint8_t(v >> (8 * i));
        }

        void putF32(std::vector<std::uint8_t>& bytes, std::size_t at, float f)
        {
            std::uint32_t v;
            std::memcpy(&v, &f, 4);
            putU32(bytes, at, v);
        }
    }

    TEST(CrossedQuads, bakeFramesTheTreeInEveryQuad)
    {
        // Each rectangle holds the model's vertices projected on its frame, margins included, and
        // its texture shows the tree (a crown covers a good part of it, the corners are empty).
        const TreeModel& model = test::generatedOak(1200);
        const CrossedQuadsData& d = baked();
        ASSERT_EQ(d.quads.size(), 2u);
        EXPECT_FLOAT_EQ(d.quads[0].azimuth, 0.0f);
        EXPECT_FLOAT_EQ(d.quads[1].azimuth, 90.0f);
        for (const CrossedQuad& q : d.quads)
        {
            const glm::vec3 r = q.rightAxis();
            EXPECT_NEAR(glm::dot(r, q.facing()), 0.0f, 1e-6f);
            for (const std::vector<Vertex>* vertices : {&model.barkVertices, &model.leafVertices})
                for (const Vertex& v : *vertices)
                {
                    const float s = glm::dot(v.position, r);
                    ASSERT_TRUE(s >= q.left && s <= q.right && v.position.y >= q.bottom && v.position.y <= q.top);
                }
            EXPECT_EQ(std::max(q.colour.width, q.colour.height), 64u);
            EXPECT_EQ(q.colour.mipCount, fullMipCount(q.colour.width, q.colour.height));
            // Square texels: the texture's aspect is the rectangle's.
            EXPECT_NEAR((q.right - q.left) / (q.top - q.bottom), double(q.colour.width) / q.colour.height, 1e-3);
            const double c = covered(q, d.alphaCutoff);
            EXPECT_GT(c, 0.2) << "azimuth " << q.azimuth;
            EXPECT_LT(c, 0.95) << "azimuth " << q.azimuth;
            EXPECT_EQ(q.colour.data[3], 0) << "the top-left texel is margin";
        }
        // 0 and 90 degrees see the tree from different sides: different pictures.
        EXPECT_NE(d.quads[0].colour.data, d.quads[1].colour.data);
    }

    TEST(CrossedQuads, chunkRoundTrips)
    {
        const CrossedQuadsData& d = baked();
        const std::vector<std::uint8_t> bytes = encodeCrossedQuadsChunk(d);
        Result<CrossedQuadsData> back = decodeCrossedQuadsChunk(bytes, "oak.treelod");
        ASSERT_TRUE(back.ok()) << back.error().message();
        EXPECT_EQ(back->alphaCutoff, d.alphaCutoff);
        ASSERT_EQ(back->quads.size(), d.quads.size());
        for (std::size_t i = 0; i < d.quads.size(); ++i)
        {
            const CrossedQuad &a = d.quads[i], &b = back->quads[i];
            EXPECT_EQ(b.azimuth, a.azimuth);
            EXPECT_EQ(b.left, a.left);
            EXPECT_EQ(b.right, a.right);
            EXPECT_EQ(b.bottom, a.bottom);
            EXPECT_EQ(b.top, a.top);
            EXPECT_EQ(b.colour.name, a.colour.name);
            EXPECT_EQ(b.colour.format, a.colour.format);
            EXPECT_EQ(b.colour.data, a.colour.data);
        }
        EXPECT_EQ(encodeCrossedQuadsChunk(back.value()), bytes) << "deterministic";
    }

    TEST(CrossedQuads, corruptedBytesAreRefusedNamingTheChunk)
    {
        const std::vector<std::uint8_t> good = encodeCrossedQuadsChunk(baked());
        // Header: u32 flags @0, f32 alphaCutoff @4, u32 quadCount @8, quad 0 @12 (azimuth, left,
        // right, bottom, top), quad 1 @32, the first texture @52.
        auto with = [&](auto edit) {
            std::vector<std::uint8_t> b = good;
            edit(b);
            return b;
        };
        expectRefused({}, "empty");
        expectRefused(with([](auto& b) { putU32(b, 0, 1); }), "unknown flags");
        expectRefused(with([](auto& b) { putF32(b, 4, 0.0f); }), "cutoff 0");
        expectRefused(with([](auto& b) { putF32(b, 4, std::nanf("")); }), "cutoff NaN");
        expectRefused(with([](auto& b) { putU32(b, 8, 0); }), "no quads");
        expectRefused(with([](auto& b) { putU32(b, 8, 9); }), "too many quads");
        expectRefused(with([](auto& b) { putU32(b, 8, 0xffffffffu); }), "huge quad count");
        expectRefused(with([](auto& b) { putF32(b, 12, 360.0f); }), "azimuth 360");
        expectRefused(with([](auto& b) { putF32(b, 16, 1e30f); }), "left > right");
        expectRefused(with([](auto& b) { putF32(b, 28, std::numeric_limits<float>::infinity()); }), "top inf");
        expectRefused(with([](auto& b) { putU32(b, 8, 1); }), "one quad: the second record is read as a texture");
        expectRefused(with([](auto& b) { b.push_back(0); }), "a trailing byte");
        // Every truncation, and a byte flipped at many places: refused or decoded, never a crash;
        // a refusal names the chunk.
        for (std::size_t size = 0; size < good.size(); size += 1 + size / 16)
            expectRefused(std::vector<std::uint8_t>(good.begin(), good.begin() + std::ptrdiff_t(size)),
                          "truncated to " + std::to_string(size));
        const TechniqueDescriptor* descriptor = findTechniqueDescriptor(CROSSED_QUADS_CHUNK);
        ASSERT_NE(descriptor, nullptr);
        for (std::size_t at = 0; at < good.size(); at += 1 + at / 8)
        {
            std::vector<std::uint8_t> b = good;
            b[at] ^= 0xa5;
            Result<CrossedQuadsData> d = decodeCrossedQuadsChunk(b, "flip.treelod");
            if (!d)
            {
                EXPECT_NE(d.error().message().find("chunk 'crossed-quads' level 0"), std::string::npos);
            }
            descriptor->fuzz(b); // traps if a decoded chunk breaks what the renderer reads
        }
    }

    TEST(CrossedQuads, descriptorInspectsAndBakerIsRegistered)
    {
        const TechniqueDescriptor* descriptor = findTechniqueDescriptor(CROSSED_QUADS_CHUNK);
        ASSERT_NE(descriptor, nullptr) << "the runtime half registers itself (TreeLodTechniques)";
        EXPECT_EQ(descriptor->formatVersion, CROSSED_QUADS_CHUNK_FORMAT_VERSION);
        ASSERT_NE(descriptor->inspect, nullptr);
        const std::vector<std::uint8_t> bytes = encodeCrossedQuadsChunk(baked());
        Result<ChunkSummary> summary = descriptor->inspect(bytes, "oak.treelod");
        ASSERT_TRUE(summary.ok()) << summary.error().message();
        EXPECT_NE(summary->text.find("2 quads at azimuths 0, 90 degrees"), std::string::npos) << summary->text;
        const nlohmann::json json = nlohmann::json::parse(summary->json);
        EXPECT_EQ(json["quadCount"], 2);
        EXPECT_EQ(json["quads"].size(), 2u);
        EXPECT_EQ(json["textureBytes"], baked().textureBytes());
        EXPECT_FALSE(descriptor->inspect({1, 2, 3}, "bad.treelod").ok());

        const BakeTechnique* baker = findBakeTechnique(CROSSED_QUADS_CHUNK);
        ASSERT_NE(baker, nullptr) << "the bake half registers itself (TreeLodBakeTechniques)";
        EXPECT_NE(knownBakeTechniques().find(CROSSED_QUADS_CHUNK), std::string::npos);
        PackageWriter writer;
        Result<void> added = baker->bake(writer, test::generatedOak(300), {}, "small", {});
        ASSERT_TRUE(added.ok()) << added.error().message();
        EXPECT_TRUE(writer.hasChunk(REFERENCE_CHUNK, 0)) << "the reference is added when missing";
        ASSERT_TRUE(writer.hasChunk(CROSSED_QUADS_CHUNK, 0));
        Result<CrossedQuadsData> d = decodeCrossedQuadsChunk(*writer.chunkBytes(CROSSED_QUADS_CHUNK, 0), "small");
        ASSERT_TRUE(d.ok()) << d.error().message();
        EXPECT_EQ(d->quads.front().colour.format, GpuTextureFormat::DXT5) << "default options compress";
    }

    TEST(CrossedQuads, badOptionsAndEmptyModelsAreRefused)
    {
        const TreeModel& model = test::generatedOak(300);
        auto refused = [&](CrossedQuadsOptions o, const char* element) {
            Result<CrossedQuadsData> d = bakeCrossedQuads(model, o, "oak");
            ASSERT_FALSE(d.ok()) << element;
            EXPECT_NE(d.error().message().find(element), std::string::npos) << d.error().message();
        };
        CrossedQuadsOptions o;
        o.azimuths = {};
        refused(o, "azimuths");
        o.azimuths = {0.0f, 180.0f};
        refused(o, "azimuths");
        o = {};
        o.resolution = 18;
        refused(o, "resolution");
        o = {};
        o.samplesPerPixel = 3;
        refused(o, "samplesPerPixel");
        o = {};
        o.alphaCutoff = 0.0f;
        refused(o, "alphaCutoff");
        Result<CrossedQuadsData> empty = bakeCrossedQuads(TreeModel{}, CrossedQuadsOptions{}, "empty");
        EXPECT_FALSE(empty.ok());
    }
}
