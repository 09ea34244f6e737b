// The octahedral impostor (chunk "octahedral-impostor"): the hemi-octahedral view mapping, chunk
// round trip and every corruption named, a one-leaf tree seen from its face (colour, normal,
// depth) and edge-on from above, mips that never mix two frames, 0.5 m vs 500 m, determinism
// over thread counts, bad options and models named, and `treelod bake`'s table entry.
// The baked atlases of the generated oak are written to $TREELOD_TEST_OUT/octahedral-impostor/.
#include "TreeLod/BakeTechniques.h"
#include "TreeLod/Image.h"
#include "TreeLod/OctahedralImpostorBaker.h"
#include "TreeLod/OctahedralImpostorData.h"
#include "TreeLod/Package.h"
#include "TreeLod/PackageWriter.h"
#include "TestTrees.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>

namespace TreeLod
{
    namespace
    {
        using test::generatedOak;

        OctahedralImpostorOptions fastOptions(std::uint32_t frames = 4)
        {
            OctahedralImpostorOptions o;
            o.framesPerSide = frames;
            o.frameResolution = 32;
            o.samplesPerPixel = 4;
            o.aoRays = 4;
            o.compress = false; // texels read back as baked
            return o;
        }

        OctahedralImpostorData bakeOrFail(const TreeModel& m, const OctahedralImpostorOptions& options)
        {
            Result<OctahedralImpostorData> r = bakeOctahedralImpostor(m, options, "test tree");
            EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message());
            return r.ok() ? std::move(r).value() : OctahedralImpostorData();
        }

        /// One square leaf of edge `size` centred at `centre`, facing +Z, green front, one material.
        TreeModel leafFacingZ(const glm::vec3& centre, float size)
        {
            TreeModel m;
            m.name = "one leaf";
            Material leaf = test::leafMaterial("Leaves");
            leaf.baseColour = glm::vec4(0.2f, 0.5f, 0.1f, 1.0f);
            m.materials.push_back(leaf);
            test::addQuadLeaf(m, centre, glm::vec3(0.5f * size, 0, 0), glm::vec3(0, 0.5f * size, 0), glm::vec3(0, 0, 1));
            m.updateBounds();
            return m;
        }

        const std::uint8_t* texel(const GpuTexture& t, std::uint32_t mip, std::uint32_t x, std::uint32_t y)
        {
            return t.data.data() + t.mipOffset(mip) + (std::size_t(y) * t.mipWidth(mip) + x) * 4;
        }

        /// Texels of frame (i, j) at `mip` whose coverage byte is above `above`.
        std::size_t coveredTexels(const OctahedralImpostorData& d, std::uint32_t i, std::uint32_t j, std::uint32_t mip,
                                  int above = 0)
        {
            const std::uint32_t f = d.frameTexels() >> mip;
            std::size_t n = 0;
            for (std::uint32_t y = j * f; y < (j + 1) * f; ++y)
                for (std::uint32_t x = i * f; x < (i + 1) * f; ++x)
                    n += texel(d.colour, mip, x, y)[3] > above;
            return n;
        }

        Image toImage(const GpuTexture& t, bool opaque)
        {
            Image image(int(t.width), int(t.height));
            for (int y = 0; y < image.height; ++y)
                for (int x = 0; x < image.width; ++x)
                {
                    const std::uint8_t* p = texel(t, 0, std::uint32_t(x), std::uint32_t(y));
                    image.at(x, y) = glm::vec4(p[0], p[1], p[2], opaque ? 255 : p[3]) / 255.0f;
                }
            return image;
        }
    }

    TEST(OctahedralMapping, encodeDecodeRoundTripAndFramesCoverTheHemisphere)
    {
        for (int a = 0; a < 36; ++a)
            for (int e = 0; e <= 9; ++e)
            {
                const float az = glm::radians(10.0f * float(a)), el = glm::radians(10.0f * float(e));
                const glm::vec3 d(std::cos(el) * std::sin(az), std::sin(el), std::cos(el) * std::cos(az));
                const glm::vec2 p = hemiOctahedralEncode(d);
                EXPECT_LE(std::max(std::abs(p.x), std::abs(p.y)), 1.0f + 1e-6f);
                const glm::vec3 back = hemiOctahedralDecode(p);
                EXPECT_NEAR(glm::length(back - d), 0.0f, 1e-5f) << a << " " << e;
            }
        // Below the horizon: the horizontal part; straight down: the view from above.
        EXPECT_NEAR(glm::length(hemiOctahedralDecode(hemiOctahedralEncode(glm::normalize(glm::vec3(1, -1, 0)))) -
                                glm::vec3(1, 0, 0)),
                    0.0f, 1e-6f);
        EXPECT_EQ(hemiOctahedralDecode(hemiOctahedralEncode(glm::vec3(0, -1, 0))), glm::vec3(0, 1, 0));

        // The outer ring of frames lies on the horizon, the middle one (odd N) looks down; frame
        // (N-1, 0) looks from +Z, as the quad impostor.
        const std::uint32_t n = 5;
        for (std::uint32_t j = 0; j < n; ++j)
            for (std::uint32_t i = 0; i < n; ++i)
            {
                const glm::vec3 t = octahedralFrameDirection(i, j, n);
                EXPECT_NEAR(glm::length(t), 1.0f, 1e-6f);
                if (i == 0 || j == 0 || i == n - 1 || j == n - 1)
                {
                    EXPECT_NEAR(t.y, 0.0f, 1e-6f) << i << " " << j;
                }
                const OctahedralFrameAxes axes = octahedralFrameAxes(t);
                EXPECT_NEAR(glm::length(glm::cross(axes.right, axes.up) - t), 0.0f, 1e-5f);
                EXPECT_NEAR(axes.right.y, 0.0f, 1e-6f); // the trunk stays upright in every frame
            }
        EXPECT_EQ(octahedralFrameDirection(2, 2, n), glm::vec3(0, 1, 0));
        EXPECT_NEAR(glm::length(octahedralFrameDirection(n - 1, 0, n) - glm::vec3(0, 0, 1)), 0.0f, 1e-6f);
        const OctahedralFrameAxes side = octahedralFrameAxes(glm::vec3(0, 0, 1));
        EXPECT_EQ(side.right, glm::vec3(1, 0, 0));
        EXPECT_EQ(side.up, glm::vec3(0, 1, 0));
        // The cylinder's projection: its height from the side, its disc from above.
        EXPECT_NEAR(octahedralHalfHeight(glm::vec3(0, 0, 1), 1.0f, 0.0f, 10.0f), 5.0f, 1e-5f);
        EXPECT_NEAR(octahedralHalfHeight(glm::vec3(0, 1, 0), 1.0f, 0.0f, 10.0f), 1.0f, 1e-5f);
    }

    TEST(OctahedralImpostorData, chunkRoundTripAndCorruptChunksAreNamed)
    {
        const OctahedralImpostorData good = bakeOrFail(leafFacingZ({0.0f, 1.0f, 0.0f}, 0.2f), fastOptions());
        const std::vector<std::uint8_t> bytes = encodeOctahedralImpostorChunk(good);
        Result<OctahedralImpostorData> decoded = decodeOctahedralImpostorChunk(bytes, "round.treelod");
        ASSERT_TRUE(decoded.ok()) << decoded.error().message();
        EXPECT_EQ(decoded->framesPerSide, good.framesPerSide);
        EXPECT_EQ(decoded->radius, good.radius);
        EXPECT_EQ(decoded->colour.data, good.colour.data);
        EXPECT_EQ(decoded->normal.data, good.normal.data);
        EXPECT_EQ(encodeOctahedralImpostorChunk(decoded.value()), bytes);

        auto expectError = [](const std::vector<std::uint8_t>& b, const std::string& element,
                              const std::string& reason) {
            Result<OctahedralImpostorData> r = decodeOctahedralImpostorChunk(b, "bad.treelod");
            ASSERT_FALSE(r.ok()) << element;
            const std::string message = r.error().message();
            EXPECT_NE(message.find("bad.treelod"), std::string::npos) << message;
            EXPECT_NE(message.find("chunk 'octahedral-impostor' level 0"), std::string::npos) << message;
            EXPECT_NE(message.find(element), std::string::npos) << message;
            EXPECT_NE(message.find(reason), std::string::npos) << message;
        };
        for (std::size_t cut : {std::size_t(2), std::size_t(6), std::size_t(20), bytes.size() / 2, bytes.size() - 1})
            expectError(std::vector<std::uint8_t>(bytes.begin(), bytes.begin() + std::ptrdiff_t(cut)), "", "truncated");
        std::vector<std::uint8_t> trailing = bytes;
        trailing.push_back(0);
        expectError(trailing, "", "1 trailing bytes");
        std::vector<std::uint8_t> flags = bytes;
        flags[0] = 2;
        expectError(flags, "", "unknown flags 2");

        OctahedralImpostorData bad = good;
        bad.framesPerSide = 1;
        expectError(encodeOctahedralImpostorChunk(bad), "frames", "1 frames a side (2 to 32 needed)");
        bad = good;
        bad.framesPerSide = 3; // 128 texels are not 3 whole frames
        expectError(encodeOctahedralImpostorChunk(bad), "colour texture", "is not 3 frames a side");
        bad = good;
        bad.radius = std::nanf("");
        expectError(encodeOctahedralImpostorChunk(bad), "cylinder", "radius nan");
        bad = good;
        bad.top = bad.bottom - 1.0f;
        expectError(encodeOctahedralImpostorChunk(bad), "cylinder", "top > bottom needed");
        bad = good;
        bad.alphaCutoff = 2.0f;
        expectError(encodeOctahedralImpostorChunk(bad), "cylinder", "alpha cutoff 2.000000 outside (0, 1]");
        bad = good;
        bad.colour.mipCount += 1; // frames of 32 texels halve to 4 in 4 levels, no further
        bad.colour.data.resize(gpuTextureBytes(bad.colour.format, bad.colour.width, bad.colour.height,
                                               bad.colour.mipCount));
        expectError(encodeOctahedralImpostorChunk(bad), "colour texture", "5 mip levels for frames of 32 texels");
        bad = good;
        bad.normal.format = GpuTextureFormat::DXT1; // depth needs the alpha
        bad.normal.data.resize(gpuTextureBytes(GpuTextureFormat::DXT1, bad.normal.width, bad.normal.height,
                                               bad.normal.mipCount));
        expectError(encodeOctahedralImpostorChunk(bad), "normal texture", "RGBA8 or DXT5 needed");
        bad = good;
        bad.normal.format = GpuTextureFormat::BC5; // two channels: no AO, no depth
        bad.normal.data.resize(gpuTextureBytes(GpuTextureFormat::BC5, bad.normal.width, bad.normal.height,
                                               bad.normal.mipCount));
        expectError(encodeOctahedralImpostorChunk(bad), "normal texture", "format 5 (BC5): RGBA8 or DXT5 needed");
        bad = good;
        bad.normal.data.pop_back();
        expectError(encodeOctahedralImpostorChunk(bad), "normal texture", "bytes of texel data, expected");
    }

    TEST(OctahedralImpostorBaker, oneLeafFromItsFaceAndEdgeOnFromAbove)
    {
        // A 0.2 m leaf 0.3 m in front of the axis, facing +Z. N = 3: frame (2, 0) looks from +Z,
        // frame (1, 1) from straight above, where the leaf is edge-on.
        const glm::vec3 centre(0.0f, 1.0f, 0.3f);
        OctahedralImpostorOptions options = fastOptions(3);
        options.aoRays = 0;
        const OctahedralImpostorData d = bakeOrFail(leafFacingZ(centre, 0.2f), options);
        ASSERT_EQ(d.framesPerSide, 3u);
        ASSERT_EQ(d.frameTexels(), 32u);
        EXPECT_NEAR(d.radius, std::sqrt(0.1f * 0.1f + 0.3f * 0.3f), 1e-5f);
        EXPECT_NEAR(d.bottom, 0.9f, 1e-5f);
        EXPECT_NEAR(d.top, 1.1f, 1e-5f);
        EXPECT_EQ(d.colour.mipCount, 4u); // 32, 16, 8, 4 texels a frame

        // In frame (2, 0) the leaf lies at its projection: x in [-0.1, 0.1] on right (+X), centred
        // vertically on the cylinder's centre.
        const glm::vec3 t = octahedralFrameDirection(2, 0, 3);
        const float side = octahedralFrameSide(t, d.radius, d.bottom, d.top, 32);
        const std::uint32_t x = 2 * 32 + 16, y = 0 * 32 + 16; // the frame's middle texel
        const std::uint8_t* c = texel(d.colour, 0, x, y);
        EXPECT_EQ(c[3], 255);
        EXPECT_NEAR(c[0], unitToByte(linearToSrgb(0.2f)), 1);
        EXPECT_NEAR(c[1], unitToByte(linearToSrgb(0.5f)), 1);
        const std::uint8_t* n = texel(d.normal, 0, x, y);
        EXPECT_NEAR(n[0], 128, 1); // facing the viewer: x = y = 0
        EXPECT_NEAR(n[1], 128, 1);
        EXPECT_EQ(n[2], 255); // no AO baked
        const float depthRadius = octahedralDepthRadius(d.radius, d.bottom, d.top);
        EXPECT_NEAR(n[3], unitToByte(0.5f + 0.5f * 0.3f / depthRadius), 1); // 0.3 m in front of the plane
        // The leaf's texels: its 0.2 m square at side / 32 metres a texel.
        const float expected = std::pow(0.2f / (side / 32.0f), 2.0f);
        const float covered = float(coveredTexels(d, 2, 0, 0, 127));
        EXPECT_NEAR(covered, expected, 0.25f * expected) << "side " << side;

        // From above, edge-on: nothing in frame (1, 1) at any level, while the side frames keep the
        // leaf at every level (no level mixes frames).
        for (std::uint32_t mip = 0; mip < d.colour.mipCount; ++mip)
        {
            EXPECT_EQ(coveredTexels(d, 1, 1, mip), 0u) << "mip " << mip;
            EXPECT_GT(coveredTexels(d, 2, 0, mip), 0u) << "mip " << mip;
        }
    }

    TEST(OctahedralImpostorBaker, generatedOakEveryFrameCoveredScaleFreeAndDeterministic)
    {
        const TreeModel& small = generatedOak(600, 0.5f);
        const OctahedralImpostorOptions options = fastOptions(4);
        const OctahedralImpostorData a = bakeOrFail(small, options);
        for (std::uint32_t j = 0; j < 4; ++j)
            for (std::uint32_t i = 0; i < 4; ++i)
                EXPECT_GT(coveredTexels(a, i, j, 0, 127), 0u) << "frame " << i << ", " << j;

        TreeModel large = small;
        for (std::vector<Vertex>* vertices : {&large.leafVertices, &large.barkVertices})
            for (Vertex& v : *vertices)
                v.position *= 1024.0f;
        for (std::size_t l = 0; l < large.leaves.size(); ++l)
            large.updateLeafRecord(l);
        large.updateBounds();
        const OctahedralImpostorData b = bakeOrFail(large, options);
        EXPECT_EQ(b.radius / a.radius, 1024.0f);
        EXPECT_EQ(b.top / a.top, 1024.0f);
        EXPECT_TRUE(a.colour.data == b.colour.data);
        EXPECT_TRUE(a.normal.data == b.normal.data);

        std::vector<std::uint8_t> one;
        {
            tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
            one = encodeOctahedralImpostorChunk(bakeOrFail(small, options));
        }
        EXPECT_TRUE(one == encodeOctahedralImpostorChunk(a));

        // To look at: the RGBA8 atlases of a fuller bake.
        OctahedralImpostorOptions look = fastOptions(6);
        look.frameResolution = 64;
        const OctahedralImpostorData picture = bakeOrFail(generatedOak(600), look);
        const char* out = std::getenv("TREELOD_TEST_OUT");
        const std::string dir =
            (out && *out ? std::string(out) : std::string(TREELOD_BINARY_DIR) + "/test-out") + "/octahedral-impostor";
        std::filesystem::create_directories(dir);
        EXPECT_TRUE(writePng(dir + "/oak-colour.png", toImage(picture.colour, false)).ok());
        EXPECT_TRUE(writePng(dir + "/oak-normal-ao.png", toImage(picture.normal, true)).ok());
    }

    TEST(OctahedralImpostorBaker, badModelsAndOptionsAreNamed)
    {
        TreeModel empty;
        empty.name = "empty";
        Result<OctahedralImpostorData> r = bakeOctahedralImpostor(empty, fastOptions(), "empty.glb");
        ASSERT_FALSE(r.ok());
        EXPECT_NE(r.error().message().find("empty.glb"), std::string::npos) << r.error().message();
        EXPECT_NE(r.error().message().find("no vertices"), std::string::npos) << r.error().message();

        // A leaf through the axis in the y-z plane: no radius from the side, still a valid impostor.
        TreeModel edge = leafFacingZ({0.0f, 1.0f, 0.0f}, 0.2f);
        for (Vertex& v : edge.leafVertices)
            v.position = glm::vec3(0.0f, v.position.y, v.position.x);
        const OctahedralImpostorData d = bakeOrFail(edge, fastOptions());
        EXPECT_TRUE(d.validate("edge").ok());

        const TreeModel leaf = leafFacingZ({0.3f, 1.0f, 0.0f}, 0.2f);
        auto expectOptionError = [&](OctahedralImpostorOptions o, const std::string& what) {
            Result<OctahedralImpostorData> bad = bakeOctahedralImpostor(leaf, o, "opts.glb");
            ASSERT_FALSE(bad.ok()) << what;
            EXPECT_NE(bad.error().message().find("opts.glb"), std::string::npos) << bad.error().message();
            EXPECT_NE(bad.error().message().find(what), std::string::npos) << bad.error().message();
        };
        OctahedralImpostorOptions o = fastOptions();
        o.framesPerSide = 1;
        expectOptionError(o, "framesPerSide");
        o = fastOptions();
        o.frameResolution = 30;
        expectOptionError(o, "frameResolution");
        o = fastOptions(32);
        o.frameResolution = 1024; // a 32768-texel atlas
        expectOptionError(o, "wider than");
        o = fastOptions();
        o.samplesPerPixel = 5;
        expectOptionError(o, "samplesPerPixel");

        TreeModel nan = leaf;
        nan.leafVertices[0].position.x = std::nanf("");
        r = bakeOctahedralImpostor(nan, fastOptions(), "nan.glb");
        ASSERT_FALSE(r.ok());
        EXPECT_NE(r.error().message().find("nan.glb"), std::string::npos) << r.error().message();
    }

    TEST(OctahedralImpostorBaker, bakeTableAddsTheReferenceAndTheChunk)
    {
        const BakeTechnique* technique = findBakeTechnique(OCTAHEDRAL_IMPOSTOR_CHUNK);
        ASSERT_NE(technique, nullptr) << knownBakeTechniques();
        PackageWriter writer;
        std::vector<std::string> steps;
        BakeOptions given;
        given["framesPerSide"] = "3"; // a technique's options, by name (the CLI's --option technique.name)
        given["frameResolution"] = "16";
        Result<void> baked = technique->bake(writer, leafFacingZ({0.3f, 1.0f, 0.0f}, 0.2f), given, "leaf.treelod",
                                             [&](const std::string& step, float) {
                                                 if (steps.empty() || steps.back() != step)
                                                     steps.push_back(step);
                                             });
        ASSERT_TRUE(baked.ok()) << baked.error().message();
        EXPECT_TRUE(writer.hasChunk(REFERENCE_CHUNK, 0));
        ASSERT_TRUE(writer.hasChunk(OCTAHEDRAL_IMPOSTOR_CHUNK, 0));
        EXPECT_NE(std::find(steps.begin(), steps.end(), "octahedral impostor: views"), steps.end());
        Result<PackageReader> package = PackageReader::fromMemory(writer.toBytes(), "leaf.treelod");
        ASSERT_TRUE(package.ok()) << package.error().message();
        const int index = package->findChunk(OCTAHEDRAL_IMPOSTOR_CHUNK, 0);
        ASSERT_GE(index, 0);
        Result<std::vector<std::uint8_t>> bytes = package->readChunk(std::size_t(index));
        ASSERT_TRUE(bytes.ok());
        Result<OctahedralImpostorData> decoded = decodeOctahedralImpostorChunk(bytes.value(), "leaf.treelod");
        ASSERT_TRUE(decoded.ok()) << decoded.error().message();
        EXPECT_EQ(decoded->framesPerSide, 3u);
        EXPECT_EQ(decoded->frameTexels(), 16u);

        BakeOptions wrong;
        wrong["framesPerSide"] = "40";
        PackageWriter other;
        Result<void> refused = technique->bake(other, leafFacingZ({0.3f, 1.0f, 0.0f}, 0.2f), wrong, "leaf.treelod", {});
        ASSERT_FALSE(refused.ok());
        EXPECT_NE(refused.error().message().find("framesPerSide"), std::string::npos) << refused.error().message();
    }
}
