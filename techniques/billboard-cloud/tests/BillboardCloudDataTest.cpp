// Billboard clouds (García et al. 2007): the "billboard-cloud" chunk (BillboardCloudData.h), list entry
// quantisation (§4.2, Fig. 8), the hemi-octahedral orientations of the Leaves Texture (§3, §5),
// validation of corrupt input, and BillboardCloudSampler, the shader's hash/lists addressing,
// including its exactness on a 4096 x 4096 hash atlas with 2^24 list entries.
#include "TreeLod/BillboardCloudData.h"
#include "TreeLod/Package.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <iostream>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace TreeLod
{
    namespace
    {
        constexpr float PI = 3.14159265358979f;
        constexpr float SCALE_STEPS = 32.0f; ///< scale codes per octave: side = 2^((s - 128) / 32)

        GpuTexture makeTexture(const std::string& name, GpuTextureFormat format, std::uint32_t w, std::uint32_t h,
                               std::uint32_t mips, std::uint32_t seed)
        {
            GpuTexture t;
            t.name = name;
            t.format = format;
            t.width = w;
            t.height = h;
            t.mipCount = mips;
            t.data.resize(gpuTextureBytes(format, w, h, mips));
            std::mt19937 rng(seed);
            for (std::uint8_t& b : t.data)
                b = std::uint8_t(rng());
            return t;
        }

        void putTexel(BillboardCloudData& d, std::uint32_t x, std::uint32_t y, std::uint32_t start,
                      std::uint32_t length)
        {
            std::uint8_t* t = &d.hashAtlas[(std::size_t(y) * d.hashAtlasWidth + x) * 4];
            t[0] = std::uint8_t(start);
            t[1] = std::uint8_t(start >> 8);
            t[2] = std::uint8_t(start >> 16);
            t[3] = std::uint8_t(length);
        }

        /// Billboard with axes turned by `angle` about +y: U = (cos, 0, -sin) su, V = (0, sv, 0).
        Billboard makeBillboard(const glm::vec3& origin, float angle, float su, float sv)
        {
            Billboard b;
            b.origin = origin;
            b.axisU = glm::vec3(std::cos(angle), 0.0f, -std::sin(angle)) * su;
            b.axisV = glm::vec3(0.0f, sv, 0.0f);
            b.normal = glm::normalize(glm::cross(b.axisU, b.axisV));
            return b;
        }

        /// Two levels (3 layered billboards, 1 low-res only), a 16x8 hash atlas, 30 entries in an
        /// 8x4 lists atlas, 2 leaf materials x 2 sides x 4 orientations in 8-texel tiles (DXT5
        /// colour, DXT1 normals, 32x32), a 16x16 RGBA8 low-res texture and 7 bark AO values.
        BillboardCloudData smallCloud()
        {
            BillboardCloudData d;
            d.listFactor = 1.5f;
            d.boundsMin = {-1.0f, 0.0f, -1.0f};
            d.boundsMax = {1.0f, 2.0f, 1.0f};
            d.levels = {{0, 3, true, 0.1f, 0.05f}, {3, 1, false, 0.0f, 0.2f}};
            const std::uint32_t hashRects[3][4] = {{0, 0, 4, 4}, {4, 0, 8, 8}, {12, 0, 4, 8}};
            const std::uint32_t lowRects[4][4] = {{0, 0, 4, 4}, {4, 0, 8, 8}, {0, 4, 4, 4}, {0, 8, 16, 8}};
            for (std::uint32_t b = 0; b < 4; ++b)
            {
                Billboard bb = makeBillboard({0.1f * b, 0.5f, -0.2f}, 0.7f * b, 0.4f + 0.1f * b, 0.8f);
                if (b < 3)
                {
                    bb.hashX = hashRects[b][0];
                    bb.hashY = hashRects[b][1];
                    bb.hashWidth = hashRects[b][2];
                    bb.hashHeight = hashRects[b][3];
                }
                bb.lowResX = lowRects[b][0];
                bb.lowResY = lowRects[b][1];
                bb.lowResWidth = lowRects[b][2];
                bb.lowResHeight = lowRects[b][3];
                d.billboards.push_back(bb);
            }
            d.tileSize = 8;
            d.orientationGrid = 2;
            d.tileColumns = 4;
            d.leavesMaxLod = 2;
            d.leafImages = {{3, 0.5f}, {5, 0.3f}};
            d.leavesColour = makeTexture("leaves colour", GpuTextureFormat::DXT5, 32, 32, 6, 1);
            d.leavesNormal = makeTexture("leaves normal", GpuTextureFormat::DXT1, 32, 32, 6, 2);
            d.lowRes = makeTexture("low-res", GpuTextureFormat::RGBA8, 16, 16, 1, 3);

            std::mt19937 rng(11);
            std::uniform_real_distribution<float> unit(0.0f, 1.0f);
            const std::uint32_t entryCount = 30;
            for (std::uint32_t e = 0; e < entryCount; ++e)
            {
                const std::uint32_t material = e % 2, k = (e / 2) % 4;
                d.entries.push_back(BillboardListEntry::encode(
                    unit(rng) * 4.0f - 2.0f, unit(rng) * 4.0f - 2.0f, material * 2 * d.orientationCount() + k,
                    (e % 3) == 0, unit(rng) * 2.0f * PI, 0.5f + 2.5f * unit(rng)));
                for (int c = 0; c < 4; ++c)
                    d.entryAo.push_back(std::uint8_t(rng()));
            }
            d.hashAtlasWidth = 16;
            d.hashAtlasHeight = 8;
            d.hashAtlas.assign(16 * 8 * 4, 0);
            for (std::uint32_t b = 0; b < 3; ++b)
            {
                const Billboard& bb = d.billboards[b];
                for (std::uint32_t j = 0; j < bb.hashHeight; ++j)
                    for (std::uint32_t i = 0; i < bb.hashWidth; ++i)
                    {
                        const std::uint32_t length = (i * 7 + j * 3 + b) % 4;
                        const std::uint32_t start = (i * 5 + j * 11 + b * 3) % (entryCount - length + 1);
                        putTexel(d, bb.hashX + i, bb.hashY + j, start, length);
                    }
            }
            d.listsAtlasWidth = 8;
            d.listsAtlasHeight = 4;
            d.barkAo = {0, 10, 20, 128, 200, 254, 255};
            return d;
        }

        void expectTextureEqual(const GpuTexture& a, const GpuTexture& b)
        {
            EXPECT_EQ(a.name, b.name);
            EXPECT_EQ(a.format, b.format);
            EXPECT_EQ(a.width, b.width);
            EXPECT_EQ(a.height, b.height);
            EXPECT_EQ(a.mipCount, b.mipCount);
            EXPECT_EQ(a.data, b.data);
        }

        void expectCloudEqual(const BillboardCloudData& a, const BillboardCloudData& b)
        {
            EXPECT_EQ(a.classic, b.classic);
            EXPECT_EQ(a.listFactor, b.listFactor);
            EXPECT_EQ(a.boundsMin, b.boundsMin);
            EXPECT_EQ(a.boundsMax, b.boundsMax);
            ASSERT_EQ(a.levels.size(), b.levels.size());
            for (std::size_t l = 0; l < a.levels.size(); ++l)
            {
                EXPECT_EQ(a.levels[l].firstBillboard, b.levels[l].firstBillboard);
                EXPECT_EQ(a.levels[l].billboardCount, b.levels[l].billboardCount);
                EXPECT_EQ(a.levels[l].layered, b.levels[l].layered);
                EXPECT_EQ(a.levels[l].cellSize, b.levels[l].cellSize);
                EXPECT_EQ(a.levels[l].lowResTexelSize, b.levels[l].lowResTexelSize);
            }
            ASSERT_EQ(a.billboards.size(), b.billboards.size());
            for (std::size_t i = 0; i < a.billboards.size(); ++i)
            {
                const Billboard &x = a.billboards[i], &y = b.billboards[i];
                EXPECT_EQ(x.origin, y.origin);
                EXPECT_EQ(x.axisU, y.axisU);
                EXPECT_EQ(x.axisV, y.axisV);
                EXPECT_EQ(x.normal, y.normal);
                EXPECT_EQ(x.hashX, y.hashX);
                EXPECT_EQ(x.hashY, y.hashY);
                EXPECT_EQ(x.hashWidth, y.hashWidth);
                EXPECT_EQ(x.hashHeight, y.hashHeight);
                EXPECT_EQ(x.lowResX, y.lowResX);
                EXPECT_EQ(x.lowResY, y.lowResY);
                EXPECT_EQ(x.lowResWidth, y.lowResWidth);
                EXPECT_EQ(x.lowResHeight, y.lowResHeight);
            }
            EXPECT_EQ(a.hashAtlasWidth, b.hashAtlasWidth);
            EXPECT_EQ(a.hashAtlasHeight, b.hashAtlasHeight);
            EXPECT_EQ(a.hashAtlas, b.hashAtlas);
            EXPECT_EQ(a.listsAtlasWidth, b.listsAtlasWidth);
            EXPECT_EQ(a.listsAtlasHeight, b.listsAtlasHeight);
            ASSERT_EQ(a.entries.size(), b.entries.size());
            for (std::size_t e = 0; e < a.entries.size(); ++e)
                for (int k = 0; k < 4; ++k)
                    EXPECT_EQ(a.entries[e].words[k], b.entries[e].words[k]) << "entry " << e << " word " << k;
            EXPECT_EQ(a.entryAo, b.entryAo);
            EXPECT_EQ(a.tileSize, b.tileSize);
            EXPECT_EQ(a.tileColumns, b.tileColumns);
            EXPECT_EQ(a.orientationGrid, b.orientationGrid);
            EXPECT_EQ(a.leavesMaxLod, b.leavesMaxLod);
            ASSERT_EQ(a.leafImages.size(), b.leafImages.size());
            for (std::size_t m = 0; m < a.leafImages.size(); ++m)
            {
                EXPECT_EQ(a.leafImages[m].material, b.leafImages[m].material);
                EXPECT_EQ(a.leafImages[m].alphaCutoff, b.leafImages[m].alphaCutoff);
            }
            expectTextureEqual(a.leavesColour, b.leavesColour);
            expectTextureEqual(a.leavesNormal, b.leavesNormal);
            expectTextureEqual(a.lowRes, b.lowRes);
            EXPECT_EQ(a.barkAo, b.barkAo);
        }

        void expectRejected(const std::vector<std::uint8_t>& bytes, const std::string& element,
                            const std::string& reason)
        {
            Result<BillboardCloudData> r = decodeBillboardCloudChunk(bytes, "bad.treelod");
            ASSERT_FALSE(r.ok()) << element;
            EXPECT_EQ(r.error().file, "bad.treelod");
            EXPECT_EQ(r.error().element, element) << r.error().message();
            EXPECT_NE(r.error().reason.find(reason), std::string::npos) << r.error().message();
        }

        void putU32(std::vector<std::uint8_t>& b, std::size_t at, std::uint32_t v)
        {
            for (int i = 0; i < 4; ++i)
                b[at + i] = std::uint8_t(v >> (8 * i));
        }

        /// Angle between two unit vectors, robust near 0.
        float angleBetween(const glm::vec3& a, const glm::vec3& b)
        {
            return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
        }

        /// The documented forward map: point c of [-1, 1]^2 -> hemisphere direction.
        glm::vec3 squareToHemisphere(float cx, float cy)
        {
            const float a = (cx + cy) * 0.5f, b = (cy - cx) * 0.5f;
            return glm::normalize(glm::vec3(a, b, 1.0f - std::abs(a) - std::abs(b)));
        }
    }

    // ---- list entries (§4.2, Fig. 8) -----------------------------------------------------

    TEST(BillboardCloudData, entryEncodeRoundTripsWithinQuantisationError)
    {
        // 20000 random entries: centre within half a code (64 / 65535 / 2 cells), rotation
        // within half a step (pi / 256, modulo 2 pi), side within half a step (a factor 2^(1/64)), orientation
        // and mirror exact; the code chosen is the nearest (its neighbours decode no closer);
        // encoding the decoded values gives the same words.
        std::mt19937 rng(5);
        std::uniform_real_distribution<float> centre(-31.9f, 31.9f), angle(-20.0f, 20.0f);
        std::uniform_real_distribution<float> logSide(-3.9f, 3.9f); // codes 3 .. 253
        const float halfCode = BILLBOARD_CENTRE_RANGE / 65535.0f;
        for (int n = 0; n < 20000; ++n)
        {
            const float cx = centre(rng), cy = centre(rng), psi = angle(rng), side = std::exp2(logSide(rng));
            const std::uint32_t k = rng() % 0x8000u;
            const bool mirror = (rng() & 1u) != 0;
            const BillboardListEntry e = BillboardListEntry::encode(cx, cy, k, mirror, psi, side);
            ASSERT_NEAR(e.centreX(), cx, halfCode * 1.01f);
            ASSERT_NEAR(e.centreY(), cy, halfCode * 1.01f);
            float dpsi = std::fmod(std::abs(e.rotation() - psi), 2.0f * PI);
            dpsi = std::min(dpsi, 2.0f * PI - dpsi);
            ASSERT_LE(dpsi, PI / 256.0f * 1.001f) << psi;
            ASSERT_LE(std::abs(std::log2(e.side() / side)), 0.5f / SCALE_STEPS * 1.001f) << side;
            ASSERT_EQ(e.orientation(), k);
            ASSERT_EQ(e.mirrored(), mirror);
            ASSERT_GE(e.rotation(), 0.0f);
            ASSERT_LT(e.rotation(), 2.0f * PI);
            // Nearest code: the neighbouring centre codes are no closer.
            for (int step : {-1, 1})
            {
                BillboardListEntry other = e;
                other.words[0] = std::uint16_t(e.words[0] + step);
                ASSERT_GE(std::abs(other.centreX() - cx), std::abs(e.centreX() - cx) - 1e-5f);
                other = e;
                other.words[3] = std::uint16_t((e.words[3] & 0xff00u) | ((e.words[3] + step) & 0xffu));
                ASSERT_GE(std::abs(std::log2(other.side() / side)), std::abs(std::log2(e.side() / side)) - 1e-4f);
            }
            const BillboardListEntry again = BillboardListEntry::encode(e.centreX(), e.centreY(), e.orientation(),
                                                                        e.mirrored(), e.rotation(), e.side());
            for (int w = 0; w < 4; ++w)
                ASSERT_EQ(again.words[w], e.words[w]) << "word " << w;
        }
    }

    TEST(BillboardCloudData, entryEncodeClampsAtTheExtremes)
    {
        const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
        BillboardListEntry e = BillboardListEntry::encode(1000.0f, -1000.0f, 40000, false, 0.0f, 1.0f);
        EXPECT_EQ(e.words[0], 65535u);
        EXPECT_EQ(e.words[1], 0u);
        EXPECT_FLOAT_EQ(e.centreX(), 32.0f);
        EXPECT_FLOAT_EQ(e.centreY(), -32.0f);
        EXPECT_EQ(e.orientation(), 0x7fffu); // clamped, and the mirror bit stays clear
        EXPECT_FALSE(e.mirrored());
        EXPECT_FLOAT_EQ(e.side(), 1.0f);     // code 128
        EXPECT_EQ(e.words[3] & 0xffu, 128u);

        e = BillboardListEntry::encode(inf, -inf, 0, true, 0.0f, 1e9f);
        EXPECT_EQ(e.words[0], 65535u);
        EXPECT_EQ(e.words[1], 0u);
        EXPECT_TRUE(e.mirrored());
        EXPECT_EQ(e.orientation(), 0u);
        EXPECT_EQ(e.words[3] & 0xffu, 255u);
        EXPECT_FLOAT_EQ(e.side(), std::exp2(127.0f / SCALE_STEPS));
        for (float tiny : {1e-9f, 0.0f, -1.0f, nan})
        {
            e = BillboardListEntry::encode(0.0f, 0.0f, 0, false, 0.0f, tiny);
            EXPECT_EQ(e.words[3] & 0xffu, 0u) << tiny;
            EXPECT_FLOAT_EQ(e.side(), std::exp2(-128.0f / SCALE_STEPS));
        }
        EXPECT_EQ(BillboardListEntry::encode(0.0f, 0.0f, 0, false, 0.0f, inf).words[3] & 0xffu, 255u);
        EXPECT_FLOAT_EQ(BillboardListEntry::encode(0.0f, 0.0f, 0, false, 0.0f, 2.0f).side(), 2.0f); // code 128 + steps
        EXPECT_EQ(BillboardListEntry::encode(0.0f, 0.0f, 0, false, 0.0f, 0.5f).words[3] & 0xffu,
                  std::uint32_t(128.0f - SCALE_STEPS));

        // NaN centres land in the middle, NaN and infinite angles at 0; angles wrap.
        e = BillboardListEntry::encode(nan, nan, 0, false, nan, 1.0f);
        EXPECT_NEAR(e.centreX(), 0.0f, BILLBOARD_CENTRE_RANGE / 65535.0f);
        EXPECT_EQ(e.words[3] >> 8, 0u);
        EXPECT_EQ(BillboardListEntry::encode(0, 0, 0, false, inf, 1.0f).words[3] >> 8, 0u);
        EXPECT_EQ(BillboardListEntry::encode(0, 0, 0, false, 2.0f * PI - 1e-4f, 1.0f).words[3] >> 8, 0u);
        EXPECT_EQ(BillboardListEntry::encode(0, 0, 0, false, -0.5f * PI, 1.0f).words[3] >> 8, 192u);
        EXPECT_EQ(BillboardListEntry::encode(0, 0, 0, false, 5.0f * PI, 1.0f).words[3] >> 8, 128u);
    }

    // ---- orientations (§3, §5) -----------------------------------------------------------

    TEST(BillboardCloudData, orientationIndexInvertsDirectionForGrids1To8)
    {
        for (std::uint32_t grid = 1; grid <= 8; ++grid)
        {
            std::vector<glm::vec3> seen;
            for (std::uint32_t k = 0; k < grid * grid; ++k)
            {
                const glm::vec3 d = billboardOrientationDirection(k, grid);
                EXPECT_NEAR(glm::length(d), 1.0f, 1e-5f);
                EXPECT_GE(d.z, 0.0f);
                EXPECT_EQ(billboardOrientationIndex(d, grid), k) << "grid " << grid;
                for (const glm::vec3& o : seen)
                    EXPECT_GT(angleBetween(o, d), 1e-3f) << "grid " << grid << " k " << k;
                seen.push_back(d);
            }
        }
        EXPECT_EQ(billboardOrientationDirection(0, 1), glm::vec3(0.0f, 0.0f, 1.0f)); // one orientation: the pole
    }

    TEST(BillboardCloudData, orientationIndexPicksTheCellContainingTheDirection)
    {
        std::mt19937 rng(3);
        std::uniform_real_distribution<float> unit(0.0f, 1.0f);
        for (std::uint32_t grid = 1; grid <= 8; ++grid)
        {
            const float cellEdge = 2.0f / float(grid);
            // Points strictly inside each cell of the square, mapped by the documented formula,
            // come back to that cell; and each cell's angular radius (sampled) for the check below.
            std::vector<float> radius(grid * grid, 0.0f);
            for (std::uint32_t y = 0; y < grid; ++y)
                for (std::uint32_t x = 0; x < grid; ++x)
                {
                    const std::uint32_t k = x + grid * y;
                    const glm::vec3 centre = billboardOrientationDirection(k, grid);
                    for (int n = 0; n < 200; ++n)
                    {
                        const float cx = -1.0f + cellEdge * (float(x) + 0.001f + 0.998f * unit(rng));
                        const float cy = -1.0f + cellEdge * (float(y) + 0.001f + 0.998f * unit(rng));
                        ASSERT_EQ(billboardOrientationIndex(squareToHemisphere(cx, cy), grid), k)
                            << "grid " << grid << " c " << cx << ", " << cy;
                    }
                    for (int a = 0; a <= 8; ++a)
                        for (int b = 0; b <= 8; ++b)
                        {
                            const glm::vec3 p = squareToHemisphere(-1.0f + cellEdge * (float(x) + a / 8.0f),
                                                                   -1.0f + cellEdge * (float(y) + b / 8.0f));
                            radius[k] = std::max(radius[k], angleBetween(p, centre));
                        }
                }
            // Uniform random hemisphere directions: the chosen orientation is within its cell's radius.
            for (int n = 0; n < 2000; ++n)
            {
                const float z = unit(rng), phi = 2.0f * PI * unit(rng), r = std::sqrt(1.0f - z * z);
                const glm::vec3 d(r * std::cos(phi), r * std::sin(phi), z);
                const std::uint32_t k = billboardOrientationIndex(d, grid);
                ASSERT_LT(k, grid * grid);
                ASSERT_LE(angleBetween(d, billboardOrientationDirection(k, grid)), radius[k] + 2e-3f)
                    << "grid " << grid;
            }
            // The pole: the centre cell (odd grids) or one of the four around the centre.
            const std::uint32_t pole = billboardOrientationIndex({0.0f, 0.0f, 1.0f}, grid);
            const std::uint32_t px = pole % grid, py = pole / grid;
            EXPECT_LE(std::abs(2.0f * (float(px) + 0.5f) - float(grid)), 1.0f) << grid;
            EXPECT_LE(std::abs(2.0f * (float(py) + 0.5f) - float(grid)), 1.0f) << grid;
            // The equator: the square's corners (a, b) = (1, 0) -> c = (1, 1), ...
            EXPECT_EQ(billboardOrientationIndex({1.0f, 0.0f, 0.0f}, grid), grid * grid - 1);
            EXPECT_EQ(billboardOrientationIndex({0.0f, 1.0f, 0.0f}, grid), grid * (grid - 1));
            EXPECT_EQ(billboardOrientationIndex({-1.0f, 0.0f, 0.0f}, grid), 0u);
            EXPECT_EQ(billboardOrientationIndex({0.0f, -1.0f, 0.0f}, grid), grid - 1);
            EXPECT_EQ(billboardOrientationIndex({1.0f, 0.0f, -1e-7f}, grid), grid * grid - 1); // clamped to d.z = 0
            // ... and the midpoints of the square's top edge, (a, b) = (0.5, 0.5) -> c = (0, 1).
            EXPECT_EQ(billboardOrientationIndex(glm::normalize(glm::vec3(1.0f, 1.0f, 0.0f)), grid) / grid, grid - 1);
        }
        // Degenerate input does not crash and stays in range.
        const float nan = std::numeric_limits<float>::quiet_NaN();
        EXPECT_LT(billboardOrientationIndex({nan, 0.0f, 1.0f}, 4), 16u);
        EXPECT_LT(billboardOrientationIndex({0.0f, 0.0f, 0.0f}, 4), 16u);
        EXPECT_LT(billboardOrientationIndex({0.0f, 0.0f, -1.0f}, 4), 16u);
    }

    // ---- chunk ----------------------------------------------------------------------------

    TEST(BillboardCloudData, chunkRoundTripKeepsEveryFieldAndIsDeterministic)
    {
        const BillboardCloudData d = smallCloud();
        ASSERT_TRUE(d.validate("small")) << d.validate("small").error().message();
        const std::vector<std::uint8_t> bytes = encodeBillboardCloudChunk(d);
        EXPECT_EQ(encodeBillboardCloudChunk(smallCloud()), bytes); // same data, same bytes
        Result<BillboardCloudData> back = decodeBillboardCloudChunk(bytes, "trip");
        ASSERT_TRUE(back) << back.error().message();
        expectCloudEqual(d, *back);
        EXPECT_EQ(encodeBillboardCloudChunk(*back), bytes);

        // A classic cloud: one low-res level, no hash or lists, placeholder leaves textures.
        BillboardCloudData c;
        c.classic = true;
        c.levels = {{0, 1, false, 0.0f, 0.01f}};
        Billboard b = makeBillboard({0.0f, 0.0f, 0.0f}, 0.3f, 1.0f, 2.0f);
        b.lowResWidth = 8;
        b.lowResHeight = 16;
        c.billboards = {b};
        c.leavesColour = makeTexture("none", GpuTextureFormat::RGBA8, 1, 1, 1, 4);
        c.leavesNormal = makeTexture("none", GpuTextureFormat::RGBA8, 1, 1, 1, 5);
        c.lowRes = makeTexture("classic", GpuTextureFormat::DXT1, 8, 16, 5, 6);
        const std::vector<std::uint8_t> classicBytes = encodeBillboardCloudChunk(c);
        Result<BillboardCloudData> classicBack = decodeBillboardCloudChunk(classicBytes, "classic");
        ASSERT_TRUE(classicBack) << classicBack.error().message();
        expectCloudEqual(c, *classicBack);
        // A classic cloud may not hold a layered level; errors name the classic chunk.
        c.levels[0].layered = true;
        c.levels[0].cellSize = 0.1f;
        expectRejected(encodeBillboardCloudChunk(c), "classic-billboard-cloud level 0", "classic");

        // A cloud without leaves or billboards (a tree with no leaves) is valid too.
        BillboardCloudData empty;
        empty.leavesColour = c.leavesColour;
        empty.leavesNormal = c.leavesNormal;
        empty.lowRes = makeTexture("none", GpuTextureFormat::RGBA8, 1, 1, 1, 7);
        empty.barkAo = {1, 2, 3};
        Result<BillboardCloudData> emptyBack = decodeBillboardCloudChunk(encodeBillboardCloudChunk(empty), "empty");
        ASSERT_TRUE(emptyBack) << emptyBack.error().message();
        expectCloudEqual(empty, *emptyBack);
    }

    TEST(BillboardCloudData, truncatedOrTrailingBytesAreRejected)
    {
        // Every proper prefix (every byte, not only every 97th: the chunk is small) fails with
        // an error naming the chunk and its part; extra bytes at the end fail too.
        const std::vector<std::uint8_t> bytes = encodeBillboardCloudChunk(smallCloud());
        const std::string chunk = chunkElement(BILLBOARD_CLOUD_CHUNK, 0);
        for (std::size_t n = 0; n < bytes.size(); ++n)
        {
            Result<BillboardCloudData> r =
                decodeBillboardCloudChunk({bytes.begin(), bytes.begin() + std::ptrdiff_t(n)}, "cut");
            ASSERT_FALSE(r.ok()) << n << " of " << bytes.size() << " bytes";
            ASSERT_EQ(r.error().element.rfind(chunk, 0), 0u) << r.error().message();
            ASSERT_TRUE(r.error().reason.find("truncated") != std::string::npos ||
                        r.error().reason.find("count") != std::string::npos)
                << r.error().message();
        }
        std::vector<std::uint8_t> trailing = bytes;
        trailing.insert(trailing.end(), 16, 0);
        expectRejected(trailing, chunk, "16 trailing bytes");
    }

    TEST(BillboardCloudData, badCountsAndFlagsAreRejectedBeforeAllocating)
    {
        const std::vector<std::uint8_t> bytes = encodeBillboardCloudChunk(smallCloud());
        const std::string chunk = chunkElement(BILLBOARD_CLOUD_CHUNK, 0);
        // Layout: u32 flags, f32 listFactor, f32x3 x 2 -> levelCount at 32, 2 levels of 20 bytes,
        // billboardCount at 76.
        std::vector<std::uint8_t> b = bytes;
        putU32(b, 32, 0x7fffffffu);
        expectRejected(b, chunk + ", levels", "count 2147483647");
        b = bytes;
        putU32(b, 76, 0xffffffffu);
        expectRejected(b, chunk + ", billboards", "count 4294967295");
        b = bytes;
        putU32(b, 0, 6u);
        expectRejected(b, chunk, "unknown flags 6");
        b = bytes;
        putU32(b, 36 + 8, 2u); // level 0's layered word
        expectRejected(b, chunk + ", level 0", "layered flag 2");
        // The hash atlas size: at 80 + 4 billboards x 80 = 400.
        b = bytes;
        putU32(b, 400, 40000u);
        expectRejected(b, chunk + ", hash atlas", "size 40000x8");
    }

    TEST(BillboardCloudData, inconsistentContentIsRejectedNamingTheElement)
    {
        // Each invariant the shader relies on, broken once in a valid cloud (encode does not check).
        const BillboardCloudData good = smallCloud();
        const float nan = std::numeric_limits<float>::quiet_NaN();
        {
            BillboardCloudData d = good; // a list start past the entries
            putTexel(d, 5, 1, std::uint32_t(d.entries.size()), 1);
            expectRejected(encodeBillboardCloudChunk(d), "billboard-cloud hash texel (5, 1)", "outside the 30 entries");
        }
        {
            BillboardCloudData d = good; // a list longer than the entries
            putTexel(d, 0, 0, 0, 255);
            expectRejected(encodeBillboardCloudChunk(d), "billboard-cloud hash texel (0, 0)", "[0, 255)");
        }
        {
            BillboardCloudData d = good; // the last list ends exactly at the end: valid
            putTexel(d, 0, 0, 29, 1);
            EXPECT_TRUE(decodeBillboardCloudChunk(encodeBillboardCloudChunk(d), "edge"));
        }
        {
            BillboardCloudData d = good; // billboard 2's grid overlapping billboard 1's
            d.billboards[2].hashX = 11;
            expectRejected(encodeBillboardCloudChunk(d), "billboard-cloud billboard 2", "overlaps billboard 1");
        }
        {
            BillboardCloudData d = good; // a grid past the atlas edge
            d.billboards[2].hashWidth = 5;
            expectRejected(encodeBillboardCloudChunk(d), "billboard-cloud billboard 2", "outside the 16x8 hash atlas");
        }
        {
            BillboardCloudData d = good; // a layered billboard without a grid
            d.billboards[0].hashHeight = 0;
            expectRejected(encodeBillboardCloudChunk(d), "billboard-cloud billboard 0", "empty");
        }
        {
            BillboardCloudData d = good; // a grid on a low-res only billboard
            d.billboards[3].hashWidth = 1;
            expectRejected(encodeBillboardCloudChunk(d), "billboard-cloud billboard 3", "not layered");
        }
        {
            BillboardCloudData d = good; // an orientation past the tiles
            d.entries[3].words[2] = std::uint16_t(d.tileCount());
            expectRejected(encodeBillboardCloudChunk(d), "billboard-cloud entry 3", "orientation 16");
        }
        {
            BillboardCloudData d = good; // an orientation in a side-1 block (k' >= orientationCount)
            d.entries[4].words[2] = std::uint16_t(8 + 5);
            expectRejected(encodeBillboardCloudChunk(d), "billboard-cloud entry 4", "not a side-0 tile");
        }
        {
            BillboardCloudData d = good; // NaN geometry
            d.billboards[2].origin.x = nan;
            expectRejected(encodeBillboardCloudChunk(d), "billboard-cloud billboard 2", "not finite");
        }
        {
            BillboardCloudData d = good; // a normal that is not unit
            d.billboards[1].normal *= 2.0f;
            expectRejected(encodeBillboardCloudChunk(d), "billboard-cloud billboard 1", "normal of length");
        }
        {
            BillboardCloudData d = good; // a normal on the wrong side
            d.billboards[1].normal = -d.billboards[1].normal;
            expectRejected(encodeBillboardCloudChunk(d), "billboard-cloud billboard 1", "cross(axisU, axisV)");
        }
        {
            BillboardCloudData d = good; // a low-res rect outside its texture
            d.billboards[3].lowResY = 9;
            expectRejected(encodeBillboardCloudChunk(d), "billboard-cloud billboard 3", "low-res rect");
        }
        {
            BillboardCloudData d = good; // levels leaving a gap
            d.levels[1].firstBillboard = 4;
            d.levels[1].billboardCount = 0;
            expectRejected(encodeBillboardCloudChunk(d), "billboard-cloud level 1", "first billboard 4, expected 3");
        }
        {
            BillboardCloudData d = good; // levels not covering every billboard
            d.levels.pop_back();
            expectRejected(encodeBillboardCloudChunk(d), "billboard-cloud levels", "cover 3 of 4");
        }
        {
            BillboardCloudData d = good; // a layered level without a cell size
            d.levels[0].cellSize = 0.0f;
            expectRejected(encodeBillboardCloudChunk(d), "billboard-cloud level 0", "cell size");
        }
        {
            BillboardCloudData d = good; // more entries than the lists atlas holds
            d.listsAtlasHeight = 3;
            expectRejected(encodeBillboardCloudChunk(d), "billboard-cloud lists atlas", "30 entries do not fit");
        }
        {
            BillboardCloudData d = good; // tile size not a power of two
            d.tileSize = 6;
            expectRejected(encodeBillboardCloudChunk(d), "billboard-cloud leaves", "power of two");
        }
        {
            BillboardCloudData d = good; // tiles that do not fit the texture
            d.tileColumns = 5;
            expectRejected(encodeBillboardCloudChunk(d), "billboard-cloud leaves", "do not fit");
        }
        {
            BillboardCloudData d = good; // a max LoD the textures do not have
            d.leavesMaxLod = 6;
            expectRejected(encodeBillboardCloudChunk(d), "billboard-cloud leaves", "max LoD 6");
        }
        {
            BillboardCloudData d = good; // a list factor that is not positive
            d.listFactor = nan;
            expectRejected(encodeBillboardCloudChunk(d), "billboard-cloud", "list factor");
        }
        // validate() alone: sizes encode cannot produce mismatched.
        {
            BillboardCloudData d = good;
            d.entryAo.pop_back();
            Result<void> r = d.validate("v");
            ASSERT_FALSE(r);
            EXPECT_EQ(r.error().element, "billboard-cloud AO atlas");
        }
        {
            BillboardCloudData d = good;
            d.hashAtlas.resize(d.hashAtlas.size() - 4);
            Result<void> r = d.validate("v");
            ASSERT_FALSE(r);
            EXPECT_EQ(r.error().element, "billboard-cloud hash atlas");
        }
        {
            BillboardCloudData d = good;
            d.leavesColour.data.pop_back();
            Result<void> r = d.validate("v");
            ASSERT_FALSE(r);
            EXPECT_EQ(r.error().element, "billboard-cloud leaves colour texture 'leaves colour'");
        }
    }

    TEST(BillboardCloudData, randomByteFlipsNeverCrashDecodeOrTheSampler)
    {
        // 400 single-byte corruptions: decode returns an error, or data that validates and
        // whose every sampled fragment reads an existing entry and tile.
        const std::vector<std::uint8_t> bytes = encodeBillboardCloudChunk(smallCloud());
        std::mt19937 rng(77);
        std::uniform_int_distribution<std::size_t> where(0, bytes.size() - 1);
        std::uniform_int_distribution<int> mask(1, 255);
        int rejected = 0;
        for (int i = 0; i < 400; ++i)
        {
            std::vector<std::uint8_t> b = bytes;
            const std::size_t at = where(rng);
            b[at] = std::uint8_t(b[at] ^ mask(rng));
            Result<BillboardCloudData> r = decodeBillboardCloudChunk(b, "flip");
            if (!r)
            {
                ++rejected;
                EXPECT_FALSE(r.error().reason.empty());
                continue;
            }
            ASSERT_TRUE(r->validate("flip"));
            const BillboardCloudSampler sampler(*r);
            for (std::uint32_t bb = 0; bb < r->billboards.size(); ++bb)
                for (float u : {0.0f, 0.3f, 0.77f, 1.0f})
                    for (bool front : {true, false})
                        for (const BillboardCloudSampler::Fragment& f : sampler.walk(bb, u, 1.0f - u, front))
                        {
                            ASSERT_LT(f.entry, r->entries.size()) << "flip at byte " << at;
                            ASSERT_LT(f.tile, r->tileCount()) << "flip at byte " << at;
                        }
        }
        // Texel data (textures, AO) is most of the chunk and not checked, so many flips pass.
        EXPECT_GT(rejected, 20);
    }

    TEST(BillboardCloudData, gpuBytesCountsAtlasesAtFullSizeTexturesAndBarkAo)
    {
        BillboardCloudData d = smallCloud();
        // hash 16x8 x 4 = 512; lists 8x4 x (8 + 4 AO) = 384; colour DXT5 32x32, 6 mips:
        // 1024 + 256 + 64 + 16 + 16 + 16 = 1392; normal DXT1: 512 + 128 + 32 + 8 + 8 + 8 = 696;
        // low-res RGBA8 16x16 = 1024; bark AO 7.
        EXPECT_EQ(d.gpuBytes(), 512u + 384u + 1392u + 696u + 1024u + 7u);
        d.entries.pop_back(); // the GPU allocates the whole atlas, however many entries it holds
        d.entryAo.resize(d.entryAo.size() - 4);
        EXPECT_EQ(d.gpuBytes(), 4015u);
        d.listsAtlasHeight = 8;
        EXPECT_EQ(d.gpuBytes(), 4015u + 384u);
        d.barkAo.push_back(1);
        EXPECT_EQ(d.gpuBytes(), 4016u + 384u);
    }

    // ---- the shader's addressing on the CPU (§4.2, §5) ----------------------------------

    TEST(BillboardCloudData, samplerWalksTheListInOrderFromEitherSideWithTheDocumentedFrame)
    {
        // One billboard of 4x4 cells; cell (1, 2) lists [C, A, B]:
        //   C: centre (10, 10), side 1: never covers the cell (skipped, but counted);
        //   A: centre (0.5, 0.5), side 0.5, rotation 0, orientation 1: local = 2 p - 0.5;
        //   B: centre (0.25, 0.75), side 2, rotation pi/2, mirrored, orientation 10 (material 1):
        //      local = R(-pi/2) q / 2 + 0.5 = (q.y, -q.x) / 2 + 0.5, then x -> 1 - x.
        BillboardCloudData d;
        d.levels = {{0, 1, true, 0.1f, 0.1f}};
        Billboard b = makeBillboard({0.0f, 0.0f, 0.0f}, 0.0f, 0.4f, 0.4f);
        b.hashWidth = b.hashHeight = 4;
        b.lowResWidth = b.lowResHeight = 1;
        d.billboards = {b};
        d.hashAtlasWidth = d.hashAtlasHeight = 4;
        d.hashAtlas.assign(4 * 4 * 4, 0);
        putTexel(d, 1, 2, 0, 3);
        d.listsAtlasWidth = 4;
        d.listsAtlasHeight = 1;
        d.entries = {BillboardListEntry::encode(10.0f, 10.0f, 2, false, 0.0f, 1.0f),
                     BillboardListEntry::encode(0.5f, 0.5f, 1, false, 0.0f, 0.5f),
                     BillboardListEntry::encode(0.25f, 0.75f, 10, true, 0.5f * PI, 2.0f)};
        d.entryAo.assign(12, 255);
        d.tileSize = 8;
        d.tileColumns = 4;
        d.orientationGrid = 2;
        d.leafImages = {{0, 0.5f}, {1, 0.5f}};
        d.leavesColour = makeTexture("c", GpuTextureFormat::RGBA8, 32, 32, 1, 1);
        d.leavesNormal = makeTexture("n", GpuTextureFormat::RGBA8, 32, 32, 1, 2);
        d.lowRes = makeTexture("l", GpuTextureFormat::RGBA8, 1, 1, 1, 3);
        ASSERT_TRUE(d.validate("walk")) << d.validate("walk").error().message();
        ASSERT_EQ(d.entries[2].words[3] >> 8, 64u);
        const BillboardCloudSampler s(d);
        const float tol = 2e-3f; // centres are quantised to 1/1024 cell

        // p = (0.3, 0.6): both A and B cover it.
        const float u = (1.0f + 0.3f) / 4.0f, v = (2.0f + 0.6f) / 4.0f;
        const BillboardCloudSampler::Cell cell = s.lookup(0, u, v);
        EXPECT_EQ(cell.i, 1u);
        EXPECT_EQ(cell.j, 2u);
        EXPECT_EQ(cell.start, 0u);
        EXPECT_EQ(cell.length, 3u);
        std::vector<BillboardCloudSampler::Fragment> f = s.walk(0, u, v, true);
        ASSERT_EQ(f.size(), 2u);
        EXPECT_EQ(f[0].entry, 1u);
        EXPECT_EQ(f[0].tile, 1u); // side 0, not mirrored
        EXPECT_NEAR(f[0].local.x, 0.1f, tol);
        EXPECT_NEAR(f[0].local.y, 0.7f, tol);
        EXPECT_EQ(f[1].entry, 2u);
        EXPECT_EQ(f[1].tile, 10u + 4u); // side 0 XOR mirror: the back tile of its block
        // q = (0.05, -0.15) -> (q.y, -q.x) / 2 + 0.5 = (0.425, 0.475) -> mirrored x 0.575
        EXPECT_NEAR(f[1].local.x, 0.575f, tol);
        EXPECT_NEAR(f[1].local.y, 0.475f, tol);

        // From the back: the list reversed, side 1.
        f = s.walk(0, u, v, false);
        ASSERT_EQ(f.size(), 2u);
        EXPECT_EQ(f[0].entry, 2u);
        EXPECT_EQ(f[0].tile, 10u); // side 1 XOR mirror = 0
        EXPECT_EQ(f[1].entry, 1u);
        EXPECT_EQ(f[1].tile, 1u + 4u);
        EXPECT_NEAR(f[1].local.x, 0.1f, tol); // same tile-local position either side
        EXPECT_NEAR(f[1].local.y, 0.7f, tol);

        // The LoD budget counts list entries, skipped ones too.
        EXPECT_TRUE(s.walk(0, u, v, true, 1).empty()); // C only
        f = s.walk(0, u, v, true, 2);
        ASSERT_EQ(f.size(), 1u);
        EXPECT_EQ(f[0].entry, 1u);
        f = s.walk(0, u, v, false, 1);
        ASSERT_EQ(f.size(), 1u);
        EXPECT_EQ(f[0].entry, 2u);
        EXPECT_TRUE(s.walk(0, u, v, true, 0).empty());

        // p = (0.05, 0.6): outside A (local x = -0.4), inside B: q = (-0.2, -0.15) -> (0.425, 0.6) -> 0.575.
        f = s.walk(0, (1.0f + 0.05f) / 4.0f, v, true);
        ASSERT_EQ(f.size(), 1u);
        EXPECT_EQ(f[0].entry, 2u);
        EXPECT_NEAR(f[0].local.x, 0.575f, tol);
        EXPECT_NEAR(f[0].local.y, 0.6f, tol);

        // Empty cells, the grid's edges (clamped), bad billboards.
        EXPECT_TRUE(s.walk(0, 0.1f, 0.1f, true).empty());
        BillboardCloudSampler::Cell edge = s.lookup(0, 1.0f, 1.0f);
        EXPECT_EQ(edge.i, 3u);
        EXPECT_EQ(edge.j, 3u);
        edge = s.lookup(0, -0.5f, 7.0f);
        EXPECT_EQ(edge.i, 0u);
        EXPECT_EQ(edge.j, 3u);
        edge = s.lookup(0, std::numeric_limits<float>::quiet_NaN(), 0.0f);
        EXPECT_EQ(edge.i, 0u);
        EXPECT_EQ(s.lookup(1, 0.5f, 0.5f).length, 0u);
        EXPECT_TRUE(s.walk(1, u, v, true).empty());
        EXPECT_EQ(d.cell(0, 1, 2), std::make_pair(0u, 3u));
    }

    TEST(BillboardCloudData, hashAndListsAddressingIsExactAt4096Squared)
    {
        // The addressing limit: a 4096 x 4096 hash atlas fully covered by billboards of uneven
        // sizes (not powers of two), and a 4096 x 4096 lists atlas holding 2^24 entries. Hash
        // texel t (row-major) lists start = (t * 0x9E3779B1 + 12345) mod 2^24 (a bijection, so
        // every 24-bit start occurs, 2^24 - 1 included, with a list of length <= 1 there) and
        // a pseudo-random length 0..255 clipped to the entries. Entry e's words encode e itself
        // (orientation e mod 16384, mirror bit 14, rotation bits 15-22, scale bit 23), so an
        // entry fetched at a computed address tells which one it is.
        //   1. For EVERY hash texel: the sampler's lookup at the texel centre u = (i + 0.5) / W
        //      returns cell (i, j) and the written (start, length); decoding start from the
        //      RGBA8 bytes as GLSL sees them (texelFetch -> c / 255.0, uint(f * 255.0 + 0.5))
        //      gives the same integer; the lists-atlas address (e % W, e / W) of the list's
        //      first and last entry, in 32-bit unsigned integer math, holds entry e.
        //   2. For a sample (every texel of each billboard's last row and column, and a
        //      pseudo-random eighth of the rest): walk() with a budget of 1 returns the list's
        //      first entry from the front and its last from the back, with the documented tile.
        //   3. Float math for the lists address is NOT exact here, so the shader must use ints.
        const auto started = std::chrono::steady_clock::now();
        constexpr std::uint32_t W = 4096, ENTRIES = 1u << 24, ORIENTATIONS = 16384;
        auto startOf = [](std::uint32_t t) { return (t * 0x9E3779B1u + 12345u) & (ENTRIES - 1); };
        auto lengthOf = [&](std::uint32_t t) {
            return std::min((t * 2246822519u + 977u) >> 24, ENTRIES - startOf(t));
        };
        // Centre 0.5 and side >= 2^(120/32) = 13.4 cells: every entry covers every cell.
        const std::uint16_t half = BillboardListEntry::encode(0.5f, 0.5f, 0, false, 0.0f, 1.0f).words[0];
        auto entryOf = [half](std::uint32_t e) {
            BillboardListEntry x;
            x.words[0] = x.words[1] = half;
            x.words[2] = std::uint16_t((e % ORIENTATIONS) | ((e >> 14) & 1u) << 15);
            x.words[3] = std::uint16_t(((e >> 15) & 0xffu) << 8 | (248u + ((e >> 23) & 1u)));
            return x;
        };
        auto idOf = [](const BillboardListEntry& x) {
            return std::uint32_t(x.words[2] & 0x3fffu) | std::uint32_t(x.words[2] >> 15) << 14 |
                   std::uint32_t(x.words[3] >> 8) << 15 | std::uint32_t((x.words[3] & 0xffu) - 248u) << 23;
        };

        BillboardCloudData d;
        d.hashAtlasWidth = d.hashAtlasHeight = W;
        d.listsAtlasWidth = d.listsAtlasHeight = W;
        d.hashAtlas.resize(std::size_t(W) * W * 4);
        for (std::uint32_t t = 0; t < W * W; ++t)
        {
            const std::uint32_t s = startOf(t), n = lengthOf(t);
            std::memcpy(&d.hashAtlas[std::size_t(t) * 4], &s, 3); // little-endian: R G B
            d.hashAtlas[std::size_t(t) * 4 + 3] = std::uint8_t(n);
        }
        d.entries.resize(ENTRIES);
        for (std::uint32_t e = 0; e < ENTRIES; ++e)
            d.entries[e] = entryOf(e);
        d.entryAo.assign(std::size_t(ENTRIES) * 4, 0);
        d.tileSize = 1;
        d.orientationGrid = 128; // 16384 orientations, 1 material: 32768 tiles of 1 texel
        d.tileColumns = 256;
        d.leafImages = {{0, 0.5f}};
        d.leavesColour = makeTexture("c", GpuTextureFormat::RGBA8, 256, 128, 1, 1);
        d.leavesNormal = makeTexture("n", GpuTextureFormat::RGBA8, 256, 128, 1, 2);
        d.lowRes = makeTexture("l", GpuTextureFormat::RGBA8, 1, 1, 1, 3);
        // Billboards: rows of uneven heights, each split into uneven widths (97..299 texels).
        std::mt19937 rng(2024);
        auto split = [&](std::uint32_t total) {
            std::vector<std::uint32_t> parts;
            while (total > 400)
            {
                const std::uint32_t p = 97 + rng() % 203;
                parts.push_back(p);
                total -= p;
            }
            parts.push_back(total);
            return parts;
        };
        std::uint32_t y = 0;
        for (std::uint32_t h : split(W))
        {
            std::uint32_t x = 0;
            for (std::uint32_t w : split(W))
            {
                Billboard b = makeBillboard({float(x), float(y), 0.0f}, 0.0f, float(w), float(h));
                b.hashX = x;
                b.hashY = y;
                b.hashWidth = w;
                b.hashHeight = h;
                b.lowResWidth = b.lowResHeight = 1;
                d.billboards.push_back(b);
                x += w;
            }
            y += h;
        }
        d.levels = {{0, std::uint32_t(d.billboards.size()), true, 0.01f, 0.01f}};
        ASSERT_GT(d.billboards.size(), 150u);
        const Result<void> valid = d.validate("4096");
        ASSERT_TRUE(valid) << valid.error().message();

        const BillboardCloudSampler sampler(d);
        std::uint64_t texels = 0, walked = 0, topStartSeen = 0, mismatches = 0;
        std::string firstMismatch;
        auto mismatch = [&](const std::string& what) {
            if (mismatches++ == 0)
                firstMismatch = what;
        };
        auto unorm8 = [](std::uint8_t c) { return float(c) / 255.0f; };          // texelFetch of RGBA8
        auto channel = [](float f) { return std::uint32_t(f * 255.0f + 0.5f); }; // uint(f * 255.0 + 0.5)
        for (std::uint32_t b = 0; b < d.billboards.size(); ++b)
        {
            const Billboard& bb = d.billboards[b];
            for (std::uint32_t j = 0; j < bb.hashHeight; ++j)
                for (std::uint32_t i = 0; i < bb.hashWidth; ++i)
                {
                    const std::uint32_t t = (bb.hashY + j) * W + bb.hashX + i;
                    const std::uint32_t start = startOf(t), length = lengthOf(t);
                    const float u = (float(i) + 0.5f) / float(bb.hashWidth);
                    const float v = (float(j) + 0.5f) / float(bb.hashHeight);
                    const BillboardCloudSampler::Cell c = sampler.lookup(b, u, v);
                    ++texels;
                    if (c.i != i || c.j != j || c.start != start || c.length != length)
                        mismatch("billboard " + std::to_string(b) + " cell (" + std::to_string(i) + ", " +
                                 std::to_string(j) + ") looked up as (" + std::to_string(c.i) + ", " +
                                 std::to_string(c.j) + ") start " + std::to_string(c.start));
                    const std::uint8_t* h = &d.hashAtlas[std::size_t(t) * 4];
                    const std::uint32_t glslStart =
                        channel(unorm8(h[0])) | channel(unorm8(h[1])) << 8 | channel(unorm8(h[2])) << 16;
                    if (glslStart != start || channel(unorm8(h[3])) != length)
                        mismatch("GLSL decode of texel " + std::to_string(t));
                    topStartSeen += start == ENTRIES - 1;
                    if (length == 0)
                        continue;
                    for (std::uint32_t e : {start, start + length - 1})
                    {
                        const std::uint32_t ex = e % W, ey = e / W; // the shader's integer ops
                        if (ex >= W || ey >= W || idOf(d.entries[std::size_t(ey) * W + ex]) != e)
                            mismatch("lists address of entry " + std::to_string(e));
                    }
                    const bool sampled =
                        i + 1 == bb.hashWidth || j + 1 == bb.hashHeight || (t * 2654435761u) >> 29 == 0;
                    if (!sampled)
                        continue;
                    ++walked;
                    for (bool front : {true, false})
                    {
                        const std::vector<BillboardCloudSampler::Fragment> f = sampler.walk(b, u, v, front, 1);
                        const std::uint32_t e = front ? start : start + length - 1;
                        const std::uint32_t side = (front ? 0u : 1u) ^ ((e >> 14) & 1u);
                        const std::uint32_t tile = e % ORIENTATIONS + side * ORIENTATIONS;
                        if (f.size() != 1 || f[0].entry != e || f[0].tile != tile || f[0].local.x < 0.0f ||
                            f[0].local.x > 1.0f || f[0].local.y < 0.0f || f[0].local.y > 1.0f)
                            mismatch("walk at texel " + std::to_string(t) + (front ? " front" : " back"));
                    }
                }
        }
        EXPECT_EQ(texels, std::uint64_t(W) * W);
        EXPECT_EQ(topStartSeen, 1u); // the start 2^24 - 1 needs all 24 bits
        EXPECT_GT(walked, texels / 10);
        EXPECT_EQ(mismatches, 0u) << "first: " << firstMismatch;

        // Every channel value survives the GLSL float round trip: RGBA8 (hash) and RGBA16 (lists).
        for (std::uint32_t c = 0; c < 256; ++c)
            ASSERT_EQ(channel(unorm8(std::uint8_t(c))), c);
        for (std::uint32_t w = 0; w < 65536; ++w)
            ASSERT_EQ(std::uint32_t(float(w) / 65535.0f * 65535.0f + 0.5f), w); // uint(f * 65535.0 + 0.5)

        // One entry more than 24 bits address is an error, however large the lists atlas.
        d.entries.push_back(entryOf(0));
        d.entryAo.resize(d.entryAo.size() + 4);
        d.listsAtlasHeight = W + 1;
        const Result<void> tooMany = d.validate("4096");
        ASSERT_FALSE(tooMany);
        EXPECT_EQ(tooMany.error().element, "billboard-cloud lists atlas");
        EXPECT_NE(tooMany.error().reason.find("16777217 entries"), std::string::npos) << tooMany.error().message();

        // 3. Integer addressing is exact at the last entry; float addressing is not:
        const std::uint32_t last = ENTRIES - 1;
        EXPECT_EQ(last % W, W - 1);
        EXPECT_EQ(last / W, W - 1);
        EXPECT_EQ(idOf(d.entries[std::size_t(last / W) * W + last % W]), last);
        //  - a texel-centre coordinate (e + 0.5) / W: e + 0.5 rounds to 2^24, row 4096 (outside);
        volatile float lastAsFloat = float(last);
        EXPECT_EQ(std::floor((lastAsFloat + 0.5f) / float(W)), float(W));
        //  - the end of the last list, start + length = 2^24 + 1 when entries grow, is no float;
        volatile std::uint32_t pastEnd = ENTRIES + 1;
        EXPECT_NE(std::uint32_t(float(pastEnd)), ENTRIES + 1);
        //  - widths that are not powers of two: floor(e * (1.0 / W')), the usual shader idiom,
        //    misses rows below 2^24 for many W' (IEEE division happens to be exact there, but
        //    GLSL only promises 2.5 ULP for x / y).
        std::uint32_t wrongWidths = 0;
        for (std::uint32_t odd = 2049; odd < W; ++odd)
        {
            const volatile float inverse = 1.0f / float(odd);
            bool wrong = false;
            for (std::uint32_t row = 1; row < ENTRIES / odd && !wrong; ++row)
                for (std::uint32_t e : {row * odd - 1, row * odd})
                    wrong = wrong || std::uint32_t(std::floor(float(e) * inverse)) != e / odd;
            wrongWidths += wrong;
        }
        EXPECT_GT(wrongWidths, 0u);
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
        std::cout << "4096^2 addressing: " << texels << " texels looked up, " << walked << " walked, "
                  << wrongWidths << " of 2047 widths 2049..4095 with float row errors, " << seconds << " s\n";
    }
}
