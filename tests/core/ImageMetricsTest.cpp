// Images (read/write, sRGB) and image metrics (multi-scale RMSE, FLIP, PSNR).
#include "TreeLod/Image.h"
#include "TreeLod/ImageMetrics.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

using namespace TreeLod;

namespace
{
    std::string outDir()
    {
        const char* env = std::getenv("TREELOD_TEST_OUT");
        std::filesystem::path dir = std::filesystem::path(env ? env : TREELOD_BINARY_DIR "/test-out") / "metrics";
        std::filesystem::create_directories(dir);
        return dir.string();
    }

    /// Grey image with the given row-major values (alpha 1).
    Image grey(int w, int h, const std::vector<float>& values)
    {
        Image image(w, h);
        for (std::size_t i = 0; i < values.size(); ++i)
            image.pixels[i] = glm::vec4(values[i], values[i], values[i], 1.0f);
        return image;
    }

    /// Seeded random colour image with values in [lo, hi].
    Image randomImage(int w, int h, std::uint32_t seed, float lo = 0.0f, float hi = 1.0f)
    {
        std::mt19937 rng(seed);
        Image image(w, h);
        for (glm::vec4& p : image.pixels)
            for (int c = 0; c < 3; ++c)
                p[c] = lo + (hi - lo) * float(rng() >> 8) / float(1 << 24);
        return image;
    }

    /// `base` plus `amplitude` times a fixed seeded noise pattern in [-1, 1].
    Image addNoise(const Image& base, float amplitude, std::uint32_t seed)
    {
        std::mt19937 rng(seed);
        Image out = base;
        for (glm::vec4& p : out.pixels)
            for (int c = 0; c < 3; ++c)
                p[c] += amplitude * (2.0f * float(rng() >> 8) / float(1 << 24) - 1.0f);
        return out;
    }

    // ---- hand-made PNG bytes (stored deflate block, computed CRC and Adler-32) ----------

    std::uint32_t crc32(const std::vector<std::uint8_t>& bytes)
    {
        std::uint32_t c = 0xffffffffu;
        for (std::uint8_t byte : bytes)
        {
            c ^= byte;
            for (int k = 0; k < 8; ++k)
                c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
        }
        return ~c;
    }

    void putBigEndian(std::vector<std::uint8_t>& out, std::uint32_t v)
    {
        for (int shift = 24; shift >= 0; shift -= 8)
            out.push_back(std::uint8_t(v >> shift));
    }

    void putChunk(std::vector<std::uint8_t>& png, const char* type, const std::vector<std::uint8_t>& data)
    {
        putBigEndian(png, std::uint32_t(data.size()));
        std::vector<std::uint8_t> typed(type, type + 4);
        typed.insert(typed.end(), data.begin(), data.end());
        png.insert(png.end(), typed.begin(), typed.end());
        putBigEndian(png, crc32(typed));
    }

    /// An 8-bit PNG of `colourType` (0 grey, 3 palette) whose rows are `samples`
    /// (width samples per row, filter byte 0 added here), plus optional PLTE and tRNS.
    std::vector<std::uint8_t> makePng(int width, int height, std::uint8_t colourType,
                                      const std::vector<std::uint8_t>& samples,
                                      const std::vector<std::uint8_t>& palette = {},
                                      const std::vector<std::uint8_t>& transparency = {})
    {
        std::vector<std::uint8_t> png = {0x89, 'P', 'N', 'G', 0x0d, 0x0a, 0x1a, 0x0a};
        std::vector<std::uint8_t> header;
        putBigEndian(header, std::uint32_t(width));
        putBigEndian(header, std::uint32_t(height));
        header.insert(header.end(), {8, colourType, 0, 0, 0});
        putChunk(png, "IHDR", header);
        if (!palette.empty())
            putChunk(png, "PLTE", palette);
        if (!transparency.empty())
            putChunk(png, "tRNS", transparency);

        std::vector<std::uint8_t> raw;
        for (int y = 0; y < height; ++y)
        {
            raw.push_back(0); // filter: none
            raw.insert(raw.end(), samples.begin() + y * width, samples.begin() + (y + 1) * width);
        }
        // zlib: header 78 01, one final stored block (LEN, ~LEN), Adler-32.
        std::vector<std::uint8_t> z = {0x78, 0x01, 0x01};
        const std::uint16_t len = std::uint16_t(raw.size());
        z.insert(z.end(), {std::uint8_t(len), std::uint8_t(len >> 8), std::uint8_t(~len), std::uint8_t((~len) >> 8)});
        z.insert(z.end(), raw.begin(), raw.end());
        std::uint32_t a = 1, b = 0;
        for (std::uint8_t v : raw)
        {
            a = (a + v) % 65521;
            b = (b + a) % 65521;
        }
        putBigEndian(z, (b << 16) | a);
        putChunk(png, "IDAT", z);
        putChunk(png, "IEND", {});
        return png;
    }

    void expectColour(const glm::vec4& actual, const glm::vec4& expected)
    {
        for (int c = 0; c < 4; ++c)
            EXPECT_NEAR(actual[c], expected[c], 1e-6) << "channel " << c;
    }

    std::string writeBytes(const std::string& name, const std::vector<std::uint8_t>& bytes)
    {
        const std::string path = outDir() + "/" + name;
        std::ofstream out(path, std::ios::binary | std::ios::trunc);
        out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
        return path;
    }
}

// ---- Image I/O -------------------------------------------------------------------------

TEST(Image, PngRoundTripKeepsEightBitValuesAndStraightAlpha)
{
    // Values that are exact multiples of 1/255 survive 8-bit storage unchanged; colour
    // under partial alpha must not be premultiplied on the way.
    Image image(3, 2);
    for (int i = 0; i < 6; ++i)
        image.pixels[std::size_t(i)] = glm::vec4(i * 40, 255 - i * 30, 17 * i, 255 - i * 50) / 255.0f;
    const std::string path = outDir() + "/roundtrip.png";
    ASSERT_TRUE(writePng(path, image).ok());
    Result<Image> back = readImage(path);
    ASSERT_TRUE(back.ok()) << back.error().message();
    ASSERT_EQ(back->width, 3);
    ASSERT_EQ(back->height, 2);
    for (std::size_t i = 0; i < 6; ++i)
        for (int c = 0; c < 4; ++c)
            EXPECT_NEAR(back->pixels[i][c], image.pixels[i][c], 1e-6) << "pixel " << i << " channel " << c;
}

TEST(Image, WritePngClampsOutOfRangeValues)
{
    // writePng promises clamping to [0, 1]: -0.5 stores as 0, 2 as 255.
    Image image(1, 1, glm::vec4(-0.5f, 2.0f, 0.5f, 1.0f));
    const std::string path = outDir() + "/clamped.png";
    ASSERT_TRUE(writePng(path, image).ok());
    Result<Image> back = readImage(path);
    ASSERT_TRUE(back.ok()) << back.error().message();
    EXPECT_EQ(back->pixels[0].r, 0.0f);
    EXPECT_EQ(back->pixels[0].g, 1.0f);
    EXPECT_NEAR(back->pixels[0].b, 128.0f / 255.0f, 1e-6); // 0.5 * 255 rounds to 128
}

TEST(Image, WritePngIntoMissingDirectoryFailsAndWritesNothing)
{
    const std::string path = outDir() + "/no-such-dir/out.png";
    Result<void> r = writePng(path, Image(2, 2, glm::vec4(1.0f)));
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().file, path);
    EXPECT_FALSE(std::filesystem::exists(path));
}

TEST(Image, ReadMissingFileNamesFileAndReason)
{
    const std::string path = outDir() + "/does-not-exist.png";
    Result<Image> r = readImage(path);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().file, path);
    EXPECT_NE(r.error().reason.find("does not exist"), std::string::npos) << r.error().reason;
}

TEST(Image, ReadNonImageNamesFileAndReason)
{
    const std::string path = writeBytes("not-an-image.png", {'h', 'e', 'l', 'l', 'o', '\n'});
    Result<Image> r = readImage(path);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().file, path);
    EXPECT_NE(r.error().reason.find("not an image"), std::string::npos) << r.error().reason;
}

TEST(Image, PalettePngKeepsTrnsAlpha)
{
    // Palette: entry 0 red with tRNS alpha 128, entry 1 blue with alpha 255 (tRNS may
    // list fewer entries than PLTE; here it lists both). Pixels: index 0, then 1.
    const std::string path = writeBytes("palette-trns.png",
                                        makePng(2, 1, 3, {0, 1}, {255, 0, 0, 0, 0, 255}, {128, 255}));
    Result<Image> r = readImage(path);
    ASSERT_TRUE(r.ok()) << r.error().message();
    ASSERT_EQ(r->width, 2);
    ASSERT_EQ(r->height, 1);
    expectColour(r->pixels[0], glm::vec4(1.0f, 0.0f, 0.0f, 128.0f / 255.0f));
    expectColour(r->pixels[1], glm::vec4(0.0f, 0.0f, 1.0f, 1.0f));
}

TEST(Image, GreyPngBecomesOpaqueGreyRgba)
{
    // One grey channel is copied to R, G and B; with no alpha channel alpha is 1.
    const std::string path = writeBytes("grey.png", makePng(2, 1, 0, {0, 51}));
    Result<Image> r = readImage(path);
    ASSERT_TRUE(r.ok()) << r.error().message();
    expectColour(r->pixels[0], glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
    expectColour(r->pixels[1], glm::vec4(0.2f, 0.2f, 0.2f, 1.0f)); // 51 / 255
}

TEST(Image, SrgbTransferMatchesStandardAndInverts)
{
    // IEC 61966-2-1: 0.5 encodes linear ((0.5 + 0.055) / 1.055)^2.4 = 0.214041; the linear
    // segment below 0.04045 is c / 12.92.
    EXPECT_NEAR(srgbToLinear(0.5f), 0.214041f, 1e-6);
    EXPECT_NEAR(srgbToLinear(0.02f), 0.02f / 12.92f, 1e-9);
    EXPECT_EQ(srgbToLinear(0.0f), 0.0f);
    EXPECT_NEAR(srgbToLinear(1.0f), 1.0f, 1e-6);
    for (float c = 0.0f; c <= 1.0f; c += 0.05f)
        EXPECT_NEAR(linearToSrgb(srgbToLinear(c)), c, 1e-5) << c;
}

TEST(Image, EverySrgbByteSurvivesTheLinearRoundTrip)
{
    // OffscreenRenderer::render copies bytes at one sample per pixel on the strength of this.
    for (int b = 0; b < 256; ++b)
        EXPECT_EQ(int(linearToSrgbByte(srgbByteToLinear(std::uint8_t(b)))), b);
}

// ---- multi-scale RMSE (ellipsoids-and-lines paper §4) ---------------------------------

TEST(MultiScaleRmse, IdenticalImagesGiveZeroInEveryBand)
{
    const Image a = randomImage(16, 16, 1);
    Result<MultiScaleRmseResult> r = multiScaleRmse(a, a);
    ASSERT_TRUE(r.ok());
    ASSERT_EQ(r->bands.size(), 5u); // 16, 8, 4, 2, 1
    for (double band : r->bands)
        EXPECT_EQ(band, 0.0);
    EXPECT_EQ(r->combined, 0.0);
}

TEST(MultiScaleRmse, HandComputedTwoByTwo)
{
    // Differences (grey, so equal in R, G, B): 0.4 at one pixel, 0 elsewhere.
    // Band 0: sqrt(0.4^2 / 4) = 0.2. Band 1 (1x1): block mean 0.1, so 0.1.
    // Combined = mean of bands = 0.15.
    Result<MultiScaleRmseResult> r = multiScaleRmse(grey(2, 2, {0.5f, 0.5f, 0.5f, 0.5f}), grey(2, 2, {0.9f, 0.5f, 0.5f, 0.5f}));
    ASSERT_TRUE(r.ok());
    ASSERT_EQ(r->bands.size(), 2u);
    EXPECT_NEAR(r->bands[0], 0.2, 1e-7);
    EXPECT_NEAR(r->bands[1], 0.1, 1e-7);
    EXPECT_NEAR(r->combined, 0.15, 1e-7);
}

TEST(MultiScaleRmse, FineCheckerboardVanishesAtCoarseBands)
{
    // +-0.25 in a 1-pixel checkerboard: every pixel is off by 0.25, but every 2x2 block
    // averages to 0, so only band 0 sees it: bands (4x4, 2x2, 1x1) = (0.25, 0, 0).
    std::vector<float> ref(16, 0.5f), test(16);
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 4; ++x)
            test[std::size_t(y * 4 + x)] = (x + y) % 2 ? 0.75f : 0.25f;
    Result<MultiScaleRmseResult> r = multiScaleRmse(grey(4, 4, ref), grey(4, 4, test));
    ASSERT_TRUE(r.ok());
    ASSERT_EQ(r->bands.size(), 3u);
    EXPECT_NEAR(r->bands[0], 0.25, 1e-7);
    EXPECT_NEAR(r->bands[1], 0.0, 1e-12);
    EXPECT_NEAR(r->bands[2], 0.0, 1e-12);
}

TEST(MultiScaleRmse, UniformOffsetStaysInEveryBand)
{
    // A constant difference of 0.125 is the same at every resolution.
    Result<MultiScaleRmseResult> r = multiScaleRmse(grey(4, 4, std::vector<float>(16, 0.25f)),
                                                    grey(4, 4, std::vector<float>(16, 0.375f)));
    ASSERT_TRUE(r.ok());
    for (double band : r->bands)
        EXPECT_NEAR(band, 0.125, 1e-7);
}

TEST(MultiScaleRmse, NonPowerOfTwoAveragesRealPixelsOnly)
{
    // 3x1 pads to 4x4. Differences 0.25, 0.25, 0.5.
    // Band 0: sqrt((0.0625 + 0.0625 + 0.25) / 3) = sqrt(0.125).
    // Band 1: blocks {0.25, 0.25} (mean 0.25, 2 pixels) and {0.5} (1 pixel):
    //         sqrt((2 * 0.0625 + 1 * 0.25) / 3) = sqrt(0.125).
    // Band 2: one block, mean 1/3 over 3 pixels: sqrt(3 * (1/3)^2 / 3) = 1/3.
    Result<MultiScaleRmseResult> r = multiScaleRmse(grey(3, 1, {0.0f, 0.0f, 0.0f}), grey(3, 1, {0.25f, 0.25f, 0.5f}));
    ASSERT_TRUE(r.ok());
    ASSERT_EQ(r->bands.size(), 3u);
    EXPECT_NEAR(r->bands[0], std::sqrt(0.125), 1e-7);
    EXPECT_NEAR(r->bands[1], std::sqrt(0.125), 1e-7);
    EXPECT_NEAR(r->bands[2], 1.0 / 3.0, 1e-7);
}

TEST(MultiScaleRmse, MatchesBoxDownsampledRmseOnRandomImages)
{
    // Band k must equal the plain RMSE of the two images box-downsampled by 2^k
    // (computed here directly, row-major, without a Z curve).
    const int n = 16;
    const Image a = randomImage(n, n, 7), b = randomImage(n, n, 8);
    Result<MultiScaleRmseResult> r = multiScaleRmse(a, b);
    ASSERT_TRUE(r.ok());
    ASSERT_EQ(r->bands.size(), 5u);
    for (int k = 0; k < 5; ++k)
    {
        const int s = 1 << k, m = n / s;
        double sum = 0.0;
        for (int by = 0; by < m; ++by)
            for (int bx = 0; bx < m; ++bx)
            {
                glm::dvec3 d(0.0);
                for (int y = by * s; y < (by + 1) * s; ++y)
                    for (int x = bx * s; x < (bx + 1) * s; ++x)
                        d += glm::dvec3(b.at(x, y)) - glm::dvec3(a.at(x, y));
                d /= double(s * s);
                sum += glm::dot(d, d);
            }
        EXPECT_NEAR(r->bands[std::size_t(k)], std::sqrt(sum / (3.0 * m * m)), 1e-6) << "band " << k;
    }
}

TEST(MultiScaleRmse, MatchesRealPixelBlockMeansOnOddSizes)
{
    // The documented padding rule, computed directly: band k is the RMSE over the real
    // pixels after replacing each pixel's difference by the mean over the real pixels of
    // its aligned 2^k block. Sizes cover odd widths, odd heights and a thin strip.
    const int sizes[][2] = {{13, 7}, {1, 9}, {6, 5}};
    for (const auto& size : sizes)
    {
        const int w = size[0], h = size[1];
        const Image a = randomImage(w, h, 11), b = randomImage(w, h, 12);
        Result<MultiScaleRmseResult> r = multiScaleRmse(a, b);
        ASSERT_TRUE(r.ok());
        int levels = 0;
        while ((1 << levels) < std::max(w, h))
            ++levels;
        ASSERT_EQ(r->bands.size(), std::size_t(levels) + 1) << w << "x" << h;
        for (int k = 0; k <= levels; ++k)
        {
            const int s = 1 << k;
            double sum = 0.0;
            for (int by = 0; by < h; by += s)
                for (int bx = 0; bx < w; bx += s)
                {
                    glm::dvec3 d(0.0);
                    int count = 0;
                    for (int y = by; y < std::min(by + s, h); ++y)
                        for (int x = bx; x < std::min(bx + s, w); ++x, ++count)
                            d += glm::dvec3(b.at(x, y)) - glm::dvec3(a.at(x, y));
                    sum += glm::dot(d, d) / count; // count * |d / count|^2
                }
            EXPECT_NEAR(r->bands[std::size_t(k)], std::sqrt(sum / (3.0 * w * h)), 1e-6)
                << w << "x" << h << " band " << k;
        }
    }
}

TEST(MultiScaleRmse, OnePixelImageHasOneBand)
{
    // 1x1 is its own coarsest level: one band, the absolute difference (0.25 in each channel).
    Result<MultiScaleRmseResult> r = multiScaleRmse(grey(1, 1, {0.5f}), grey(1, 1, {0.75f}));
    ASSERT_TRUE(r.ok());
    ASSERT_EQ(r->bands.size(), 1u);
    EXPECT_NEAR(r->bands[0], 0.25, 1e-7);
    EXPECT_NEAR(r->combined, 0.25, 1e-7);
}

TEST(MultiScaleRmse, IsSymmetric)
{
    // Swapping the images negates every difference; squares are unchanged exactly.
    const Image a = randomImage(13, 7, 2), b = randomImage(13, 7, 3);
    Result<MultiScaleRmseResult> ab = multiScaleRmse(a, b), ba = multiScaleRmse(b, a);
    ASSERT_TRUE(ab.ok() && ba.ok());
    EXPECT_EQ(ab->bands, ba->bands);
    EXPECT_EQ(ab->combined, ba->combined);
    EXPECT_GT(ab->combined, 0.0);
}

TEST(MultiScaleRmse, GrowsWithMoreNoise)
{
    // The same noise pattern at larger amplitude scales every band up linearly.
    const Image base = randomImage(32, 32, 4, 0.3f, 0.7f);
    double previous = 0.0;
    for (float amplitude : {0.02f, 0.05f, 0.1f, 0.2f})
    {
        Result<MultiScaleRmseResult> r = multiScaleRmse(base, addNoise(base, amplitude, 5));
        ASSERT_TRUE(r.ok());
        EXPECT_GT(r->combined, previous) << amplitude;
        previous = r->combined;
    }
}

TEST(MultiScaleRmse, IgnoresAlpha)
{
    Image a(4, 4, glm::vec4(0.5f, 0.5f, 0.5f, 1.0f)), b(4, 4, glm::vec4(0.5f, 0.5f, 0.5f, 0.0f));
    Result<MultiScaleRmseResult> r = multiScaleRmse(a, b);
    ASSERT_TRUE(r.ok());
    EXPECT_EQ(r->combined, 0.0);
}

TEST(MultiScaleRmse, SizeMismatchNamesBothSizes)
{
    Result<MultiScaleRmseResult> r = multiScaleRmse(Image(4, 4), Image(4, 2));
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().reason.find("4x4"), std::string::npos) << r.error().reason;
    EXPECT_NE(r.error().reason.find("4x2"), std::string::npos) << r.error().reason;
}

// ---- PSNR -------------------------------------------------------------------------------

TEST(Psnr, IdenticalImagesGiveInfinity)
{
    const Image a = randomImage(8, 8, 1);
    Result<double> r = psnr(a, a);
    ASSERT_TRUE(r.ok());
    EXPECT_EQ(*r, std::numeric_limits<double>::infinity());
}

TEST(Psnr, HandComputedUniformDifference)
{
    // Every channel off by 0.1: MSE = 0.01, PSNR = 10 log10(1 / 0.01) = 20 dB.
    Result<double> r = psnr(Image(3, 3, glm::vec4(0.5f)), Image(3, 3, glm::vec4(0.6f)));
    ASSERT_TRUE(r.ok());
    EXPECT_NEAR(*r, 20.0, 1e-5);
}

TEST(Psnr, IsSymmetricAndFallsWithMoreNoise)
{
    const Image base = randomImage(16, 16, 4, 0.3f, 0.7f);
    const Image other = randomImage(16, 16, 9);
    EXPECT_EQ(*psnr(base, other), *psnr(other, base));
    double previous = std::numeric_limits<double>::infinity();
    for (float amplitude : {0.02f, 0.05f, 0.1f, 0.2f})
    {
        Result<double> r = psnr(base, addNoise(base, amplitude, 5));
        ASSERT_TRUE(r.ok());
        EXPECT_LT(*r, previous) << amplitude;
        previous = *r;
    }
}

TEST(Psnr, SizeMismatchNamesBothSizes)
{
    Result<double> r = psnr(Image(2, 3), Image(3, 2));
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().reason.find("2x3"), std::string::npos) << r.error().reason;
    EXPECT_NE(r.error().reason.find("3x2"), std::string::npos) << r.error().reason;
}

// ---- FLIP -------------------------------------------------------------------------------

TEST(Flip, IdenticalImagesGiveZero)
{
    const Image a = randomImage(24, 16, 1);
    Result<FlipResult> r = flip(a, a);
    ASSERT_TRUE(r.ok());
    EXPECT_EQ(r->mean, 0.0);
    EXPECT_EQ(r->max, 0.0);
    EXPECT_EQ(r->width, 24);
    EXPECT_EQ(r->height, 16);
}

TEST(Flip, BlackVersusWhiteIsNearlyOne)
{
    // Uniform images: the CSF filters (unit sum) and feature detectors change nothing,
    // so the error is the colour term alone. Hunt-adjusted Lab: black (0, 0, 0), white
    // (100, 0, 0); HyAB = 100, compressed 100^0.7 = 25.12. cmax = HyAB(green, blue)^0.7
    // = 203.3^0.7 = 41.27; 25.12 > 0.4 cmax = 16.51, so the error is
    // 0.95 + (25.12 - 16.51) / (41.27 - 16.51) * 0.05 = 0.967 everywhere.
    Result<FlipResult> r = flip(Image(8, 8, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f)), Image(8, 8, glm::vec4(1.0f)));
    ASSERT_TRUE(r.ok());
    EXPECT_NEAR(r->mean, 0.967, 0.002);
    EXPECT_NEAR(r->max, r->mean, 1e-6);
    EXPECT_NEAR(r->weightedMedian, r->mean, 1e-6);
}

TEST(Flip, OnePixelTinyChangeGivesSmallMean)
{
    // A 1/255 change in one pixel of a 32x32 grey image is invisible: the mean error
    // must be tiny, yet not zero (the pixel did change).
    Image a(32, 32, glm::vec4(0.5f, 0.5f, 0.5f, 1.0f));
    Image b = a;
    b.at(10, 20) = glm::vec4(0.5f + 1.0f / 255.0f, 0.5f, 0.5f, 1.0f);
    Result<FlipResult> r = flip(a, b);
    ASSERT_TRUE(r.ok());
    EXPECT_GT(r->mean, 0.0);
    EXPECT_LT(r->mean, 0.001);
    EXPECT_LT(r->max, 0.1);
}

TEST(Flip, IsSymmetric)
{
    // Every per-pixel term is an absolute difference of quantities computed identically
    // for both images, so swapping them gives bit-identical results.
    const Image a = randomImage(20, 12, 2), b = randomImage(20, 12, 3);
    FlipOptions options;
    options.keepErrorMap = true;
    Result<FlipResult> ab = flip(a, b, options), ba = flip(b, a, options);
    ASSERT_TRUE(ab.ok() && ba.ok());
    EXPECT_EQ(ab->mean, ba->mean);
    EXPECT_EQ(ab->max, ba->max);
    EXPECT_EQ(ab->errorMap, ba->errorMap);
    EXPECT_GT(ab->mean, 0.0);
}

TEST(Flip, ResultDoesNotDependOnThreadCount)
{
    // Rows are filtered independently and the mean is summed in row order, so one thread
    // and all threads must give bit-identical maps and statistics.
    const Image a = randomImage(40, 70, 6), b = randomImage(40, 70, 7);
    FlipOptions options;
    options.keepErrorMap = true;
    Result<FlipResult> many = flip(a, b, options);
    tbb::task_arena single(1);
    Result<FlipResult> one = single.execute([&] { return flip(a, b, options); });
    ASSERT_TRUE(many.ok() && one.ok());
    EXPECT_EQ(many->errorMap, one->errorMap);
    EXPECT_EQ(many->mean, one->mean);
    EXPECT_EQ(many->weightedMedian, one->weightedMedian);
}

TEST(Flip, GrowsWithMoreNoise)
{
    const Image base = randomImage(32, 32, 4, 0.3f, 0.7f);
    double previous = 0.0;
    for (float amplitude : {0.02f, 0.05f, 0.1f, 0.2f})
    {
        Result<FlipResult> r = flip(base, addNoise(base, amplitude, 5));
        ASSERT_TRUE(r.ok());
        EXPECT_GT(r->mean, previous) << amplitude;
        EXPECT_LE(r->max, 1.0);
        previous = r->mean;
    }
}

TEST(Flip, MorePixelsPerDegreeHidesFineNoise)
{
    // With more pixels per degree each pixel spans a smaller visual angle, so the same
    // pixel noise is finer and the CSF (a low-pass filter in degrees) removes more of it.
    const Image base = randomImage(32, 32, 4, 0.3f, 0.7f);
    const Image noisy = addNoise(base, 0.1f, 5);
    FlipOptions coarse, fine;
    coarse.pixelsPerDegree = 10.0;
    fine.pixelsPerDegree = 120.0;
    Result<FlipResult> rc = flip(base, noisy, coarse), rf = flip(base, noisy, fine);
    ASSERT_TRUE(rc.ok() && rf.ok());
    EXPECT_GT(rc->mean, rf->mean);
}

TEST(Flip, ErrorMapOnlyWhenAskedAndHeatmapMatchesIt)
{
    const Image a(4, 3, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
    Image b = a;
    b.at(1, 1) = glm::vec4(1.0f);
    Result<FlipResult> plain = flip(a, b);
    ASSERT_TRUE(plain.ok());
    EXPECT_TRUE(plain->errorMap.empty());
    EXPECT_TRUE(flipHeatmap(*plain).empty());

    FlipOptions options;
    options.keepErrorMap = true;
    Result<FlipResult> r = flip(a, b, options);
    ASSERT_TRUE(r.ok());
    ASSERT_EQ(r->errorMap.size(), 12u);
    const Image heat = flipHeatmap(*r);
    ASSERT_EQ(heat.width, 4);
    ASSERT_EQ(heat.height, 3);
    // The changed pixel has the largest error, so the brightest heatmap colour.
    auto brightness = [](const glm::vec4& c) { return c.r + c.g + c.b; };
    for (int y = 0; y < 3; ++y)
        for (int x = 0; x < 4; ++x)
        {
            if (x != 1 || y != 1)
            {
                EXPECT_LT(brightness(heat.at(x, y)), brightness(heat.at(1, 1)));
            }
        }
    EXPECT_EQ(heat.at(1, 1).a, 1.0f);
}

TEST(Flip, HeatmapEndsAreDarkAndPale)
{
    // Magma-like: error 0 is (nearly) black, error 1 pale yellow.
    FlipResult r;
    r.width = 2;
    r.height = 1;
    r.errorMap = {0.0f, 1.0f};
    const Image heat = flipHeatmap(r);
    ASSERT_EQ(heat.pixels.size(), 2u);
    EXPECT_LT(heat.pixels[0].r + heat.pixels[0].g + heat.pixels[0].b, 0.05f);
    EXPECT_GT(heat.pixels[1].r, 0.9f);
    EXPECT_GT(heat.pixels[1].g, 0.9f);
    EXPECT_LT(heat.pixels[1].b, heat.pixels[1].g);
}

TEST(Flip, SizeMismatchAndBadPpdAreErrors)
{
    Result<FlipResult> r = flip(Image(5, 4), Image(4, 5));
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().reason.find("5x4"), std::string::npos) << r.error().reason;
    EXPECT_NE(r.error().reason.find("4x5"), std::string::npos) << r.error().reason;

    FlipOptions options;
    options.pixelsPerDegree = -1.0;
    EXPECT_FALSE(flip(Image(2, 2), Image(2, 2), options).ok());
}

TEST(Flip, DefaultPixelsPerDegreeIsSixtySeven)
{
    // 0.7 m * (3840 px / 0.7 m) * pi / 180 = 67.02 pixels per degree.
    EXPECT_NEAR(flipDefaultPixelsPerDegree(), 67.02, 0.01);
}

TEST(Flip, APreparedReferenceGivesTheSameResultForEveryTest)
{
    const Image a = randomImage(33, 21, 8);
    FlipOptions options;
    options.pixelsPerDegree = 30.0;
    Result<FlipReference> prepared = FlipReference::make(a, options);
    ASSERT_TRUE(prepared.ok()) << prepared.error().message();
    EXPECT_EQ(prepared->width(), 33);
    EXPECT_EQ(prepared->height(), 21);
    options.keepErrorMap = true;
    for (std::uint32_t seed : {9u, 10u, 11u})
    {
        const Image b = randomImage(33, 21, seed);
        Result<FlipResult> once = flip(a, b, options), reused = flip(*prepared, b, true);
        ASSERT_TRUE(once.ok() && reused.ok());
        EXPECT_GT(once->mean, 0.0);
        EXPECT_EQ(once->mean, reused->mean);
        EXPECT_EQ(once->max, reused->max);
        EXPECT_EQ(once->weightedMedian, reused->weightedMedian);
        EXPECT_EQ(once->errorMap, reused->errorMap);
    }

    Result<FlipResult> mismatch = flip(*prepared, Image(21, 33));
    ASSERT_FALSE(mismatch.ok());
    EXPECT_NE(mismatch.error().reason.find("33x21"), std::string::npos) << mismatch.error().reason;
    EXPECT_NE(mismatch.error().reason.find("21x33"), std::string::npos) << mismatch.error().reason;
    EXPECT_FALSE(FlipReference::make(Image()).ok());
    options.pixelsPerDegree = std::nan("");
    EXPECT_FALSE(FlipReference::make(a, options).ok());
    EXPECT_FALSE(flip(FlipReference{}, a).ok());
}

TEST(Flip, TwoPreparedImagesGiveTheSameResultAsTheImages)
{
    FlipOptions options;
    options.pixelsPerDegree = 30.0;
    const Image a = randomImage(33, 21, 8), b = randomImage(33, 21, 9);
    Result<FlipReference> preparedA = FlipReference::make(a, options), preparedB = FlipReference::make(b, options);
    ASSERT_TRUE(preparedA.ok() && preparedB.ok());
    options.keepErrorMap = true;
    Result<FlipResult> once = flip(a, b, options), prepared = flip(*preparedA, *preparedB, true),
                       swapped = flip(*preparedB, *preparedA, true);
    ASSERT_TRUE(once.ok() && prepared.ok() && swapped.ok()) << (prepared.ok() ? "" : prepared.error().message());
    EXPECT_GT(once->mean, 0.0);
    EXPECT_EQ(once->mean, prepared->mean);
    EXPECT_EQ(once->max, prepared->max);
    EXPECT_EQ(once->weightedMedian, prepared->weightedMedian);
    EXPECT_EQ(once->errorMap, prepared->errorMap);
    EXPECT_EQ(swapped->errorMap, prepared->errorMap); // FLIP is symmetric per pixel

    // Another size or another pixels per degree: refused.
    Result<FlipReference> other = FlipReference::make(randomImage(21, 33, 8), options);
    ASSERT_TRUE(other.ok());
    Result<FlipResult> mismatch = flip(*preparedA, *other);
    ASSERT_FALSE(mismatch.ok());
    EXPECT_NE(mismatch.error().reason.find("33x21 vs 21x33"), std::string::npos) << mismatch.error().reason;
    options.pixelsPerDegree = 60.0;
    Result<FlipReference> finer = FlipReference::make(b, options);
    ASSERT_TRUE(finer.ok());
    EXPECT_FALSE(flip(*preparedA, *finer).ok());
    EXPECT_FALSE(flip(*preparedA, FlipReference{}).ok());
}
