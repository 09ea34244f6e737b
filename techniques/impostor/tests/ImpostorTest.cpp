// The one-quad impostor (chunk "impostor"): chunk round trip and every corruption named,
// coverage of a generated tree against its own geometry, a one-leaf tree texel by texel, an
// empty and an edge-on tree, the same textures for a 0.5 m and a 500 m tree, determinism over
// thread counts, no dark fringe in any mip level, DXT size and fidelity, and `treelod bake`'s
// table entry.
// The baked textures of the generated oak are written to $TREELOD_TEST_OUT/impostor/ to look at.
#include "TreeLod/BakeTechniques.h"
#include "TreeLod/Image.h"
#include "TreeLod/ImpostorBaker.h"
#include "TreeLod/ImpostorData.h"
#include "TreeLod/Package.h"
#include "TreeLod/PackageWriter.h"
#include "TreeLod/TreeGenerator.h"
#include "TestTrees.h"

#include <gtest/gtest.h>
#include <squish.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>

namespace TreeLod
{
    namespace
    {
        using test::generatedOak;

        /// Small and uncompressed, so that texels can be read back.
        ImpostorOptions fastOptions()
        {
            ImpostorOptions o;
            o.resolution = 96;
            o.samplesPerPixel = 4;
            o.aoRays = 4;
            o.compress = false;
            return o;
        }

        ImpostorData bakeOrFail(const TreeModel& m, const ImpostorOptions& options)
        {
            Result<ImpostorData> r = bakeImpostor(m, options, "test tree");
            EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message());
            return r.ok() ? std::move(r).value() : ImpostorData();
        }

        /// One square leaf of edge `size` centred at `centre`, facing `normal` (+Z or -Z or +X),
        /// one untextured leaf material; as the generator builds leaves (4 vertices, 2 triangles).
        TreeModel oneLeaf(const glm::vec3& centre, const glm::vec3& normal, float size)
        {
            TreeModel m;
            m.name = "one leaf";
            Material leaf = test::leafMaterial("Leaves");
            leaf.baseColour = glm::vec4(0.2f, 0.5f, 0.1f, 1.0f);
            leaf.backColour = glm::vec3(0.6f, 0.5f, 0.1f);
            m.materials.push_back(leaf);
            const glm::vec3 n = glm::normalize(normal);
            const glm::vec3 u = 0.5f * size * (std::abs(n.x) > 0.9f ? glm::vec3(0, 0, -n.x) : glm::vec3(n.z, 0, 0));
            const glm::vec3 v(0.0f, 0.5f * size, 0.0f);
            test::addQuadLeaf(m, centre, u, v, n);
            m.updateBounds();
            return m;
        }

        const std::uint8_t* texel(const GpuTexture& t, std::uint32_t mip, std::uint32_t x, std::uint32_t y)
        {
            return t.data.data() + t.mipOffset(mip) + (std::size_t(y) * t.mipWidth(mip) + x) * 4;
        }

        /// Texel coordinates (continuous, level 0) of local point p on the quad.
        glm::vec2 toTexel(const ImpostorData& d, const glm::vec3& p)
        {
            return glm::vec2((p.x + d.halfWidth) / (2.0f * d.halfWidth) * float(d.colour.width),
                             (d.top - p.y) / (d.top - d.bottom) * float(d.colour.height));
        }

        std::string outDir()
        {
            const char* out = std::getenv("TREELOD_TEST_OUT");
            const std::string dir =
                (out && *out ? std::string(out) : std::string(TREELOD_BINARY_DIR) + "/test-out") + "/impostor";
            std::filesystem::create_directories(dir);
            return dir;
        }

        /// Level `mip` of an RGBA8 texture as a picture (alpha forced to 1 when `opaque`).
        Image toImage(const GpuTexture& t, std::uint32_t mip, bool opaque)
        {
            Image image(int(t.mipWidth(mip)), int(t.mipHeight(mip)));
            for (int y = 0; y < image.height; ++y)
                for (int x = 0; x < image.width; ++x)
                {
                    const std::uint8_t* p = texel(t, mip, std::uint32_t(x), std::uint32_t(y));
                    image.at(x, y) = glm::vec4(p[0], p[1], p[2], opaque ? 255 : p[3]) / 255.0f;
                }
            return image;
        }
    }

    TEST(ImpostorData, chunkRoundTripKeepsEveryField)
    {
        const ImpostorData data = bakeOrFail(oneLeaf({0.3f, 1.0f, 0.0f}, {0, 0, 1}, 0.2f), fastOptions());
        const std::vector<std::uint8_t> bytes = encodeImpostorChunk(data);
        Result<ImpostorData> decoded = decodeImpostorChunk(bytes, "round.treelod");
        ASSERT_TRUE(decoded.ok()) << decoded.error().message();
        EXPECT_EQ(decoded->halfWidth, data.halfWidth);
        EXPECT_EQ(decoded->bottom, data.bottom);
        EXPECT_EQ(decoded->top, data.top);
        EXPECT_EQ(decoded->alphaCutoff, data.alphaCutoff);
        for (const auto& [a, b] : {std::make_pair(&decoded->colour, &data.colour),
                                   std::make_pair(&decoded->normal, &data.normal)})
        {
            EXPECT_EQ(a->name, b->name);
            EXPECT_EQ(a->format, b->format);
            EXPECT_EQ(a->width, b->width);
            EXPECT_EQ(a->height, b->height);
            EXPECT_EQ(a->mipCount, b->mipCount);
            EXPECT_EQ(a->data, b->data);
        }
        EXPECT_EQ(encodeImpostorChunk(decoded.value()), bytes);
    }

    TEST(ImpostorData, corruptChunksAreNamed)
    {
        const ImpostorData good = bakeOrFail(oneLeaf({0.3f, 1.0f, 0.0f}, {0, 0, 1}, 0.2f), fastOptions());
        const std::vector<std::uint8_t> bytes = encodeImpostorChunk(good);
        auto expectError = [](const std::vector<std::uint8_t>& b, const std::string& element,
                              const std::string& reason) {
            Result<ImpostorData> r = decodeImpostorChunk(b, "bad.treelod");
            ASSERT_FALSE(r.ok()) << element;
            const std::string message = r.error().message();
            EXPECT_NE(message.find("bad.treelod"), std::string::npos) << message;
            EXPECT_NE(message.find("chunk 'impostor' level 0"), std::string::npos) << message;
            EXPECT_NE(message.find(element), std::string::npos) << message;
            EXPECT_NE(message.find(reason), std::string::npos) << message;
        };
        // Truncated anywhere: in the quad, in a texture header, in the texel data.
        for (std::size_t cut : {std::size_t(3), std::size_t(10), std::size_t(30), bytes.size() / 2, bytes.size() - 1})
            expectError(std::vector<std::uint8_t>(bytes.begin(), bytes.begin() + std::ptrdiff_t(cut)), "",
                        "truncated");
        std::vector<std::uint8_t> trailing = bytes;
        trailing.push_back(0);
        expectError(trailing, "chunk 'impostor' level 0", "1 trailing bytes");
        std::vector<std::uint8_t> flags = bytes;
        flags[0] = 4;
        expectError(flags, "chunk 'impostor' level 0", "unknown flags 4");

        ImpostorData bad = good;
        bad.halfWidth = std::nanf("");
        expectError(encodeImpostorChunk(bad), "quad", "half width nan");
        bad = good;
        bad.top = bad.bottom;
        expectError(encodeImpostorChunk(bad), "quad", "top > bottom needed");
        bad = good;
        bad.alphaCutoff = 0.0f;
        expectError(encodeImpostorChunk(bad), "quad", "alpha cutoff 0.000000 outside (0, 1]");
        bad = good;
        bad.colour.format = GpuTextureFormat::DXT1; // a colour texture needs its alpha
        bad.colour.data.resize(gpuTextureBytes(GpuTextureFormat::DXT1, bad.colour.width, bad.colour.height,
                                               bad.colour.mipCount));
        expectError(encodeImpostorChunk(bad), "colour texture 'impostor colour'", "RGBA8 or DXT5 needed");
        bad = good;
        bad.normal.mipCount = 1;
        bad.normal.data.resize(bad.normal.mipBytes(0));
        expectError(encodeImpostorChunk(bad), "normal texture 'impostor normal'", "the colour texture is");
        bad = good;
        bad.normal.data.pop_back(); // the byte count in the chunk no longer matches the size
        expectError(encodeImpostorChunk(bad), "normal texture 'impostor normal'", "bytes of texel data, expected");
    }

    TEST(ImpostorBaker, generatedTreeCoversItsGeometryAndNothingElse)
    {
        const TreeModel& m = generatedOak(1500);
        const ImpostorData d = bakeOrFail(m, fastOptions());
        ASSERT_TRUE(d.validate("oak").ok());
        const std::uint32_t W = d.colour.width, H = d.colour.height;
        // The longer side (the oak is taller than wide) gets the resolution; texels are square.
        EXPECT_EQ(H, 96u);
        EXPECT_LE(W, H);
        EXPECT_NEAR(2.0f * d.halfWidth / float(W), (d.top - d.bottom) / float(H), 1e-4f * (d.top - d.bottom));
        EXPECT_LE(d.bottom, m.boundsMin.y);
        EXPECT_GE(d.top, m.boundsMax.y);

        // Conservative footprint: texels that some triangle's projected box touches (plus one).
        std::vector<std::uint8_t> possible(std::size_t(W) * H, 0);
        auto mark = [&](const std::vector<Vertex>& vertices, const std::vector<std::uint32_t>& indices) {
            for (std::size_t t = 0; t + 2 < indices.size(); t += 3)
            {
                glm::vec2 lo(1e30f), hi(-1e30f);
                for (int k = 0; k < 3; ++k)
                {
                    const glm::vec2 p = toTexel(d, vertices[indices[t + k]].position);
                    lo = glm::min(lo, p);
                    hi = glm::max(hi, p);
                }
                for (int y = std::max(0, int(lo.y) - 1); y <= std::min(int(H) - 1, int(hi.y) + 1); ++y)
                    for (int x = std::max(0, int(lo.x) - 1); x <= std::min(int(W) - 1, int(hi.x) + 1); ++x)
                        possible[std::size_t(y) * W + std::size_t(x)] = 1;
            }
        };
        mark(m.barkVertices, m.barkIndices);
        mark(m.leafVertices, m.leafIndices);
        std::size_t covered = 0, outside = 0;
        for (std::uint32_t y = 0; y < H; ++y)
            for (std::uint32_t x = 0; x < W; ++x)
            {
                const std::uint8_t a = texel(d.colour, 0, x, y)[3];
                covered += a > 0;
                outside += a > 0 && !possible[std::size_t(y) * W + x];
                const bool border = x < IMPOSTOR_MARGIN_TEXELS || y < IMPOSTOR_MARGIN_TEXELS ||
                                    x >= W - IMPOSTOR_MARGIN_TEXELS || y >= H - IMPOSTOR_MARGIN_TEXELS;
                if (border)
                {
                    EXPECT_EQ(a, 0) << "margin texel " << x << ", " << y;
                }
            }
        EXPECT_EQ(outside, 0u);
        // Where the tree is: the trunk's base, and every leaf that faces the view (its centre is
        // inside the leaf's opaque blade).
        const glm::vec2 base = toTexel(d, glm::vec3(0.0f, m.boundsMin.y + 0.01f * (m.boundsMax.y - m.boundsMin.y), 0));
        EXPECT_GT(texel(d.colour, 0, std::uint32_t(base.x), std::uint32_t(base.y))[3], 128);
        const TextureImage& leafTexture = m.textures[std::size_t(m.materials[1].texture)];
        const std::uint8_t centreAlpha =
            leafTexture.rgba[(std::size_t(leafTexture.height / 2) * std::size_t(leafTexture.width) +
                              std::size_t(leafTexture.width / 2)) * 4 + 3];
        ASSERT_EQ(centreAlpha, 255);
        std::size_t facing = 0, facingCovered = 0;
        for (const Leaf& leaf : m.leaves)
            if (std::abs(leaf.normal.z) > 0.9f)
            {
                const glm::vec2 p = toTexel(d, leaf.centre);
                ++facing;
                facingCovered += texel(d.colour, 0, std::uint32_t(p.x), std::uint32_t(p.y))[3] > 0;
            }
        EXPECT_GT(facing, 20u);
        EXPECT_EQ(facingCovered, facing);
        const double fraction = double(covered) / double(W * H);
        std::cout << "[ coverage ] oak 1500 leaves: " << W << "x" << H << ", " << fraction * 100.0
                  << " % of the texels covered\n";
        EXPECT_GT(fraction, 0.15);
        EXPECT_LT(fraction, 0.9);

        // Look at them: colour with alpha, colour opaque (the bleeding), normal + AO.
        const std::string dir = outDir();
        EXPECT_TRUE(writePng(dir + "/oak-colour.png", toImage(d.colour, 0, false)).ok());
        EXPECT_TRUE(writePng(dir + "/oak-colour-opaque.png", toImage(d.colour, 0, true)).ok());
        EXPECT_TRUE(writePng(dir + "/oak-normal-ao.png", toImage(d.normal, 0, true)).ok());
        EXPECT_TRUE(writePng(dir + "/oak-colour-mip2.png", toImage(d.colour, 2, false)).ok());
    }

    TEST(ImpostorBaker, oneLeafIsItsSquareWithItsColourNormalAndNoOcclusion)
    {
        // A 0.2 m square leaf at x 0.2..0.4, y 0.9..1.1 facing the view: the quad spans
        // x -0.4..0.4 and y 0.9..1.1 plus the margins, so the longer side (x) has 96 texels.
        const TreeModel m = oneLeaf({0.3f, 1.0f, 0.0f}, {0, 0, 1}, 0.2f);
        ImpostorOptions options = fastOptions();
        options.samplesPerPixel = 16;
        const ImpostorData d = bakeOrFail(m, options);
        ASSERT_EQ(d.colour.width, 96u);
        const float texelSize = 0.8f / 92.0f;
        EXPECT_NEAR(d.halfWidth, 48.0f * texelSize, 1e-5f);
        EXPECT_NEAR(0.5f * (d.top + d.bottom), 1.0f, 1e-5f);
        const std::uint8_t green[3] = {unitToByte(linearToSrgb(0.2f)), unitToByte(linearToSrgb(0.5f)),
                                       unitToByte(linearToSrgb(0.1f))};
        std::size_t inside = 0;
        for (std::uint32_t y = 0; y < d.colour.height; ++y)
            for (std::uint32_t x = 0; x < d.colour.width; ++x)
            {
                // The texel's square in metres against the leaf's.
                const float x0 = -d.halfWidth + float(x) * texelSize, x1 = x0 + texelSize;
                const float y1 = d.top - float(y) * texelSize, y0 = y1 - texelSize;
                const bool in = x0 >= 0.2f + 1e-4f && x1 <= 0.4f - 1e-4f && y0 >= 0.9f + 1e-4f && y1 <= 1.1f - 1e-4f;
                const bool out = x1 <= 0.2f - 1e-4f || x0 >= 0.4f + 1e-4f || y1 <= 0.9f - 1e-4f || y0 >= 1.1f + 1e-4f;
                const std::uint8_t* c = texel(d.colour, 0, x, y);
                const std::uint8_t* n = texel(d.normal, 0, x, y);
                if (out)
                {
                    EXPECT_EQ(c[3], 0) << x << ", " << y;
                }
                if (!in)
                    continue;
                ++inside;
                EXPECT_EQ(c[3], 255) << x << ", " << y;
                for (int k = 0; k < 3; ++k)
                    EXPECT_NEAR(c[k], green[k], 1) << x << ", " << y;
                EXPECT_NEAR(n[0], 128, 1); // normal (0, 0, 1)
                EXPECT_NEAR(n[1], 128, 1);
                EXPECT_EQ(n[2], 255);      // nothing occludes a lone leaf
            }
        EXPECT_GT(inside, 400u); // about 21 x 21 texels

        // Seen from its back: the back colour.
        const ImpostorData back = bakeOrFail(oneLeaf({0.3f, 1.0f, 0.0f}, {0, 0, -1}, 0.2f), options);
        const glm::vec2 centre = toTexel(back, glm::vec3(0.3f, 1.0f, 0.0f));
        const std::uint8_t* c = texel(back.colour, 0, std::uint32_t(centre.x), std::uint32_t(centre.y));
        EXPECT_EQ(c[3], 255);
        EXPECT_NEAR(c[0], unitToByte(linearToSrgb(0.6f)), 1);
        EXPECT_NEAR(c[1], unitToByte(linearToSrgb(0.5f)), 1);
    }

    TEST(ImpostorBaker, emptyModelIsAnErrorAndAnEdgeOnLeafGivesATransparentQuad)
    {
        TreeModel empty;
        empty.name = "empty";
        Result<ImpostorData> r = bakeImpostor(empty, fastOptions(), "empty.glb");
        ASSERT_FALSE(r.ok());
        EXPECT_NE(r.error().message().find("empty.glb"), std::string::npos) << r.error().message();
        EXPECT_NE(r.error().message().find("no vertices"), std::string::npos) << r.error().message();

        // A leaf in the y-z plane through the axis: no width, and the view sees only its edge.
        const ImpostorData d = bakeOrFail(oneLeaf({0.0f, 1.0f, 0.0f}, {1, 0, 0}, 0.2f), fastOptions());
        EXPECT_TRUE(d.validate("edge-on").ok());
        EXPECT_GT(d.halfWidth, 0.0f);
        std::size_t covered = 0;
        for (std::uint32_t i = 0; i < d.colour.width * d.colour.height; ++i)
            covered += d.colour.data[4 * i + 3] > 0;
        EXPECT_EQ(covered, 0u);

        ImpostorOptions bad = fastOptions();
        bad.resolution = 250;
        r = bakeImpostor(oneLeaf({0.3f, 1.0f, 0.0f}, {0, 0, 1}, 0.2f), bad, "opts.glb");
        ASSERT_FALSE(r.ok());
        EXPECT_NE(r.error().message().find("resolution"), std::string::npos) << r.error().message();
        bad = fastOptions();
        bad.samplesPerPixel = 5;
        r = bakeImpostor(oneLeaf({0.3f, 1.0f, 0.0f}, {0, 0, 1}, 0.2f), bad, "opts.glb");
        ASSERT_FALSE(r.ok());
        EXPECT_NE(r.error().message().find("samplesPerPixel"), std::string::npos) << r.error().message();
    }

    TEST(ImpostorBaker, halfMetreAndFiveHundredMetreTreesGiveTheSameTextures)
    {
        // Every size in the baker is relative to the bounds. Scaled by 1024 (exact in floats)
        // the textures are byte-identical, DXT included. Scaled by 1000 the input itself
        // rounds differently (fl(1000 v) != 1000 fl(v)), so a few texels may round to the next
        // byte; coverage stays the same everywhere.
        const TreeModel& small = generatedOak(600, 0.5f);
        auto scaled = [&](float factor) {
            TreeModel large = small;
            for (std::vector<Vertex>* vertices : {&large.leafVertices, &large.barkVertices})
                for (Vertex& v : *vertices)
                    v.position *= factor;
            for (std::size_t l = 0; l < large.leaves.size(); ++l)
                large.updateLeafRecord(l);
            large.updateBounds();
            return large;
        };
        ImpostorOptions options = fastOptions();
        options.compress = true;
        const ImpostorData a = bakeOrFail(small, options);
        const ImpostorData b = bakeOrFail(scaled(1024.0f), options);
        EXPECT_EQ(b.halfWidth / a.halfWidth, 1024.0f);
        EXPECT_EQ(b.top / a.top, 1024.0f);
        ASSERT_EQ(a.colour.width, b.colour.width);
        ASSERT_EQ(a.colour.height, b.colour.height);
        EXPECT_TRUE(a.colour.data == b.colour.data);
        EXPECT_TRUE(a.normal.data == b.normal.data);

        const ImpostorData c = bakeOrFail(small, fastOptions());
        const ImpostorData d = bakeOrFail(scaled(1000.0f), fastOptions());
        EXPECT_NEAR(d.halfWidth / c.halfWidth, 1000.0f, 0.01f);
        ASSERT_EQ(c.colour.width, d.colour.width);
        ASSERT_EQ(c.colour.height, d.colour.height);
        std::size_t differ = 0, bytes = 0;
        for (const auto& [t, u] : {std::make_pair(&c.colour, &d.colour), std::make_pair(&c.normal, &d.normal)})
            for (std::size_t i = 0; i < t->data.size(); ++i)
            {
                const int delta = std::abs(int(t->data[i]) - int(u->data[i]));
                if (i % 4 == 3 && t == &c.colour && i < t->mipBytes(0))
                {
                    EXPECT_EQ(delta, 0) << "coverage of texel " << i / 4;
                }
                EXPECT_LE(delta, 1) << "byte " << i;
                differ += delta > 0;
                ++bytes;
            }
        std::cout << "[ scale    ] x1000: " << differ << " of " << bytes << " bytes one step apart\n";
        EXPECT_LT(differ, bytes / 100);
    }

    TEST(ImpostorBaker, deterministicForAnyThreadCount)
    {
        const TreeModel& m = generatedOak(600);
        ImpostorOptions options = fastOptions();
        options.compress = true;
        std::vector<std::uint8_t> one, all;
        {
            tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
            one = encodeImpostorChunk(bakeOrFail(m, options));
        }
        all = encodeImpostorChunk(bakeOrFail(m, options));
        EXPECT_FALSE(one.empty());
        EXPECT_TRUE(one == all);
        EXPECT_TRUE(all == encodeImpostorChunk(bakeOrFail(m, options)));
    }

    TEST(ImpostorBaker, noDarkFringeInAnyMipLevel)
    {
        // Colour is bled into transparent texels and averaged over covered ones, so the texels
        // a bilinear lookup mixes in at the silhouette are as bright as the leaves they border.
        const ImpostorData d = bakeOrFail(generatedOak(1500), fastOptions());
        for (std::uint32_t mip = 0; mip + 2 < d.colour.mipCount; ++mip)
        {
            const std::uint32_t w = d.colour.mipWidth(mip), h = d.colour.mipHeight(mip);
            double coveredSum = 0.0, fringeSum = 0.0;
            std::size_t coveredCount = 0, fringeCount = 0;
            for (std::uint32_t y = 1; y + 1 < h; ++y)
                for (std::uint32_t x = 1; x + 1 < w; ++x)
                {
                    const std::uint8_t* c = texel(d.colour, mip, x, y);
                    const double luminance = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
                    if (c[3] >= 128)
                    {
                        coveredSum += luminance;
                        ++coveredCount;
                        continue;
                    }
                    bool nextToCovered = false;
                    for (int dy = -1; dy <= 1; ++dy)
                        for (int dx = -1; dx <= 1; ++dx)
                            nextToCovered |= texel(d.colour, mip, x + dx, y + dy)[3] >= 128;
                    if (nextToCovered)
                    {
                        fringeSum += luminance;
                        ++fringeCount;
                    }
                }
            ASSERT_GT(coveredCount, 0u) << "mip " << mip;
            ASSERT_GT(fringeCount, 0u) << "mip " << mip;
            const double covered = coveredSum / double(coveredCount), fringe = fringeSum / double(fringeCount);
            EXPECT_GT(fringe, 0.7 * covered) << "mip " << mip;
            EXPECT_LT(fringe, 1.3 * covered) << "mip " << mip;
        }
    }

    TEST(ImpostorBaker, defaultBakeIsRgba8AndDxtKeepsTheCoverage)
    {
        ImpostorOptions options;
        const TreeModel& m = generatedOak(1500);
        const ImpostorData raw = bakeOrFail(m, options);
        EXPECT_EQ(raw.colour.format, GpuTextureFormat::RGBA8);
        EXPECT_EQ(raw.normal.format, GpuTextureFormat::RGBA8);
        // No AO by default (the polygonal tree draws its leaves without): B = 1 in every texel.
        for (std::size_t t = 0; t < std::size_t(raw.normal.width) * raw.normal.height; ++t)
            ASSERT_EQ(raw.normal.data[4 * t + 2], 255) << "texel " << t;
        EXPECT_EQ(std::max(raw.colour.width, raw.colour.height), 256u);
        EXPECT_EQ(raw.colour.mipCount, fullMipCount(raw.colour.width, raw.colour.height));
        EXPECT_EQ(raw.gpuBytes(), raw.colour.data.size() + raw.normal.data.size());
        EXPECT_LT(raw.gpuBytes(), 800u * 1024u);

        // compress = true: DXT5 + DXT1, a quarter of the bytes, keeping the alpha test's answer:
        // level 0 decompressed against the default RGBA8 bake.
        options.compress = true;
        const ImpostorData d = bakeOrFail(m, options);
        EXPECT_EQ(d.colour.format, GpuTextureFormat::DXT5);
        EXPECT_EQ(d.normal.format, GpuTextureFormat::DXT1);
        EXPECT_LT(d.gpuBytes(), 200u * 1024u);
        std::cout << "[ bytes    ] impostor " << d.colour.width << "x" << d.colour.height << ": " << raw.gpuBytes()
                  << " bytes RGBA8 (default), " << d.gpuBytes() << " bytes DXT\n";
        ASSERT_EQ(raw.colour.width, d.colour.width);
        GpuTexture colour = raw.colour, normal = raw.normal;
        squish::DecompressImage(colour.data.data(), int(d.colour.width), int(d.colour.height), d.colour.data.data(),
                                squish::kDxt5);
        squish::DecompressImage(normal.data.data(), int(d.normal.width), int(d.normal.height), d.normal.data.data(),
                                squish::kDxt1);
        const std::uint8_t cutoff = std::uint8_t(std::ceil(d.alphaCutoff * 255.0f));
        std::size_t passes = 0, flipped = 0;
        for (std::uint32_t i = 0; i < d.colour.width * d.colour.height; ++i)
        {
            passes += raw.colour.data[4 * i + 3] >= cutoff;
            flipped += (raw.colour.data[4 * i + 3] >= cutoff) != (colour.data[4 * i + 3] >= cutoff);
        }
        std::cout << "[ dxt      ] alpha test changed on " << flipped << " of " << passes << " covered texels\n";
        EXPECT_LT(flipped, passes / 50);
        const std::string dir = outDir();
        EXPECT_TRUE(writePng(dir + "/oak-dxt-colour.png", toImage(colour, 0, false)).ok());
        EXPECT_TRUE(writePng(dir + "/oak-dxt-normal-ao.png", toImage(normal, 0, true)).ok());
    }

    TEST(ImpostorBaker, bakeTableAddsTheReferenceAndTheImpostor)
    {
        const BakeTechnique* technique = findBakeTechnique(IMPOSTOR_CHUNK);
        ASSERT_NE(technique, nullptr) << knownBakeTechniques();
        PackageWriter writer;
        std::vector<std::string> steps;
        Result<void> baked = technique->bake(writer, oneLeaf({0.3f, 1.0f, 0.0f}, {0, 0, 1}, 0.2f), {}, "leaf.treelod",
                                             [&](const std::string& step, float) {
                                                 if (steps.empty() || steps.back() != step)
                                                     steps.push_back(step);
                                             });
        ASSERT_TRUE(baked.ok()) << baked.error().message();
        EXPECT_TRUE(writer.hasChunk(REFERENCE_CHUNK, 0));
        ASSERT_TRUE(writer.hasChunk(IMPOSTOR_CHUNK, 0));
        EXPECT_NE(std::find(steps.begin(), steps.end(), "impostor: render"), steps.end());
        Result<PackageReader> package = PackageReader::fromMemory(writer.toBytes(), "leaf.treelod");
        ASSERT_TRUE(package.ok()) << package.error().message();
        const int index = package->findChunk(IMPOSTOR_CHUNK, 0);
        ASSERT_GE(index, 0);
        EXPECT_EQ(package->chunks()[std::size_t(index)].formatVersion, IMPOSTOR_CHUNK_FORMAT_VERSION);
        Result<std::vector<std::uint8_t>> bytes = package->readChunk(std::size_t(index));
        ASSERT_TRUE(bytes.ok());
        Result<ImpostorData> decoded = decodeImpostorChunk(bytes.value(), "leaf.treelod");
        ASSERT_TRUE(decoded.ok()) << decoded.error().message();
        EXPECT_EQ(decoded->colour.format, GpuTextureFormat::RGBA8);
    }
}
