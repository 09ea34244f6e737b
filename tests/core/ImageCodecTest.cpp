// ImageCodec: PNG and JPEG through libpng and libjpeg-turbo. The inputs are made here with
// zlib and libjpeg directly, so each test knows the samples the file stores.
#include "TreeLod/Image.h"
#include "TreeLod/ImageCodec.h"

#include <gtest/gtest.h>
#include <jpeglib.h>
#include <zlib.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

using namespace TreeLod;

namespace
{
    using Bytes = std::vector<std::uint8_t>;

    std::string codecOutDir()
    {
        const char* env = std::getenv("TREELOD_TEST_OUT");
        std::filesystem::path dir = std::filesystem::path(env ? env : TREELOD_BINARY_DIR "/test-out") / "image-codec";
        std::filesystem::create_directories(dir);
        return dir.string();
    }

    std::string saveBytes(const std::string& name, const Bytes& bytes)
    {
        const std::string path = codecOutDir() + "/" + name;
        std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()),
                                                    std::streamsize(bytes.size()));
        return path;
    }

    void appendU32(Bytes& out, std::uint32_t v)
    {
        for (int shift = 24; shift >= 0; shift -= 8)
            out.push_back(std::uint8_t(v >> shift));
    }

    void appendPngChunk(Bytes& out, const char* type, const Bytes& data)
    {
        appendU32(out, std::uint32_t(data.size()));
        const std::size_t start = out.size();
        out.insert(out.end(), type, type + 4);
        out.insert(out.end(), data.begin(), data.end());
        appendU32(out, std::uint32_t(::crc32(0, out.data() + start, uInt(out.size() - start))));
    }

    /// A PNG of `rows` (each starting with its filter byte), bit depth and colour type as given.
    Bytes handMadePng(std::uint32_t width, std::uint32_t height, int depth, int colourType, const Bytes& rows)
    {
        Bytes out = {0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A};
        Bytes header;
        appendU32(header, width);
        appendU32(header, height);
        header.insert(header.end(), {std::uint8_t(depth), std::uint8_t(colourType), 0, 0, 0});
        appendPngChunk(out, "IHDR", header);
        uLongf packed = compressBound(uLong(rows.size()));
        Bytes deflated(packed);
        EXPECT_EQ(compress(deflated.data(), &packed, rows.data(), uLong(rows.size())), Z_OK);
        deflated.resize(packed);
        appendPngChunk(out, "IDAT", deflated);
        appendPngChunk(out, "IEND", {});
        return out;
    }

    /// A baseline JPEG at quality 100 of `components` samples a pixel (1 grey, 3 RGB, 4 CMYK
    /// with libjpeg's Adobe marker).
    Bytes jpegOf(int width, int height, int components, const Bytes& samples)
    {
        jpeg_compress_struct info;
        jpeg_error_mgr errors;
        info.err = jpeg_std_error(&errors);
        jpeg_create_compress(&info);
        unsigned char* buffer = nullptr;
        unsigned long size = 0;
        jpeg_mem_dest(&info, &buffer, &size);
        info.image_width = JDIMENSION(width);
        info.image_height = JDIMENSION(height);
        info.input_components = components;
        info.in_color_space = components == 1 ? JCS_GRAYSCALE : components == 3 ? JCS_RGB : JCS_CMYK;
        jpeg_set_defaults(&info);
        jpeg_set_quality(&info, 100, TRUE);
        jpeg_start_compress(&info, TRUE);
        while (info.next_scanline < info.image_height)
        {
            JSAMPROW row = const_cast<JSAMPROW>(samples.data() + std::size_t(info.next_scanline) * width * components);
            jpeg_write_scanlines(&info, &row, 1);
        }
        jpeg_finish_compress(&info);
        Bytes out(buffer, buffer + size);
        jpeg_destroy_compress(&info);
        std::free(buffer);
        return out;
    }

    Bytes solid(int pixels, const Bytes& value)
    {
        Bytes out;
        for (int i = 0; i < pixels; ++i)
            out.insert(out.end(), value.begin(), value.end());
        return out;
    }
}

TEST(ImageCodec, SixteenBitPngKeepsItsPrecision)
{
    // Grey 16-bit, 2x1: 1000 and 65535 (big-endian in the file).
    const Bytes png = handMadePng(2, 1, 16, 0, {0, 0x03, 0xE8, 0xFF, 0xFF});
    Result<DecodedImage> decoded = decodeImage(png.data(), png.size(), 64, 64);
    ASSERT_TRUE(decoded.ok()) << decoded.error().message();
    EXPECT_EQ(decoded->bits, 16);
    EXPECT_EQ(decoded->channels, 1);
    EXPECT_EQ(decoded->samples, (std::vector<std::uint16_t>{1000, 65535}));

    Result<GreyImage> grey = readGreyImage(saveBytes("grey16.png", png));
    ASSERT_TRUE(grey.ok()) << grey.error().message();
    ASSERT_EQ(grey->values.size(), 2u);
    EXPECT_FLOAT_EQ(grey->values[0], 1000.0f / 65535.0f);
    EXPECT_FLOAT_EQ(grey->values[1], 1.0f);
}

TEST(ImageCodec, LowBitGreyAndRgbColourKeyExpand)
{
    // 2-bit grey, 4x1: 0, 1, 2, 3 in one byte, expanded to 0, 85, 170, 255.
    const Bytes grey = handMadePng(4, 1, 2, 0, {0, 0b00011011});
    Result<DecodedImage> g = decodeImage(grey.data(), grey.size(), 64, 64);
    ASSERT_TRUE(g.ok()) << g.error().message();
    EXPECT_EQ(g->samples, (std::vector<std::uint16_t>{0, 85, 170, 255}));

    // 8-bit RGB with a tRNS colour key (10, 20, 30): that pixel gets alpha 0, the other 255.
    Bytes rgb = handMadePng(2, 1, 8, 2, {0, 10, 20, 30, 40, 50, 60});
    Bytes keyed(rgb.begin(), rgb.begin() + 33); // signature + IHDR
    appendPngChunk(keyed, "tRNS", {0, 10, 0, 20, 0, 30});
    keyed.insert(keyed.end(), rgb.begin() + 33, rgb.end());
    Result<DecodedImage> k = decodeImage(keyed.data(), keyed.size(), 64, 64);
    ASSERT_TRUE(k.ok()) << k.error().message();
    EXPECT_EQ(k->channels, 4);
    EXPECT_EQ(k->samples, (std::vector<std::uint16_t>{10, 20, 30, 0, 40, 50, 60, 255}));
}

TEST(ImageCodec, JpegGreyRgbAndAdobeCmykDecode)
{
    const int w = 16, h = 8;
    Result<Image> rgb = readImage(saveBytes("rgb.jpg", jpegOf(w, h, 3, solid(w * h, {200, 100, 50}))));
    ASSERT_TRUE(rgb.ok()) << rgb.error().message();
    ASSERT_EQ(rgb->width, w);
    ASSERT_EQ(rgb->height, h);
    for (const glm::vec4& p : rgb->pixels)
    {
        EXPECT_NEAR(p.r * 255.0f, 200.0f, 2.0f);
        EXPECT_NEAR(p.g * 255.0f, 100.0f, 2.0f);
        EXPECT_NEAR(p.b * 255.0f, 50.0f, 2.0f);
        EXPECT_EQ(p.a, 1.0f);
    }

    const Bytes grey = jpegOf(w, h, 1, solid(w * h, {77}));
    Result<DecodedImage> g = decodeImage(grey.data(), grey.size(), 64, 4096);
    ASSERT_TRUE(g.ok()) << g.error().message();
    EXPECT_EQ(g->channels, 1);
    for (std::uint16_t s : g->samples)
        EXPECT_NEAR(s, 77, 1);

    // Adobe CMYK stores 255 - ink: cyan 0, magenta and yellow full, black 0 is red.
    const Bytes cmyk = jpegOf(w, h, 4, solid(w * h, {255, 0, 0, 255}));
    Result<DecodedImage> c = decodeImage(cmyk.data(), cmyk.size(), 64, 4096);
    ASSERT_TRUE(c.ok()) << c.error().message();
    ASSERT_EQ(c->channels, 3);
    for (std::size_t i = 0; i < c->samples.size(); i += 3)
    {
        EXPECT_NEAR(c->samples[i], 255, 3);
        EXPECT_NEAR(c->samples[i + 1], 0, 3);
        EXPECT_NEAR(c->samples[i + 2], 0, 3);
    }
}

TEST(ImageCodec, SizeLimitIsCheckedBeforeThePixels)
{
    const Bytes png = handMadePng(300, 2, 8, 0, Bytes(2 * 301, 0));
    Result<DecodedImage> wide = decodeImage(png.data(), png.size(), 256, 1 << 20);
    ASSERT_FALSE(wide.ok());
    EXPECT_NE(wide.error().reason.find("300x2 pixels is larger than the limit (256 per side"), std::string::npos)
        << wide.error().reason;
    Result<DecodedImage> many = decodeImage(png.data(), png.size(), 1024, 599);
    ASSERT_FALSE(many.ok());
    EXPECT_NE(many.error().reason.find("599 pixels"), std::string::npos) << many.error().reason;
    EXPECT_TRUE(decodeImage(png.data(), png.size(), 300, 600).ok());

    const Bytes jpeg = jpegOf(40, 30, 1, Bytes(40 * 30, 9));
    Result<DecodedImage> j = decodeImage(jpeg.data(), jpeg.size(), 32, 1 << 20);
    ASSERT_FALSE(j.ok());
    EXPECT_NE(j.error().reason.find("40x30 pixels is larger"), std::string::npos) << j.error().reason;
}

TEST(ImageCodec, BrokenFilesAreNamedAndNothingIsReturned)
{
    const Bytes png = handMadePng(8, 8, 8, 0, Bytes(8 * 9, 128));
    const Bytes truncated(png.begin(), png.begin() + std::ptrdiff_t(png.size() - 20));
    Result<Image> r = readImage(saveBytes("truncated.png", truncated));
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().file, codecOutDir() + "/truncated.png");
    EXPECT_NE(r.error().reason.find("cannot decode PNG"), std::string::npos) << r.error().reason;

    Bytes badCrc = png;
    badCrc[29] ^= 0xFF; // IHDR's CRC
    Result<DecodedImage> crc = decodeImage(badCrc.data(), badCrc.size(), 64, 4096);
    ASSERT_FALSE(crc.ok());
    EXPECT_NE(crc.error().reason.find("CRC"), std::string::npos) << crc.error().reason;

    const Bytes jpeg = jpegOf(16, 16, 3, solid(256, {1, 2, 3}));
    const Bytes cut(jpeg.begin(), jpeg.begin() + 40);
    Result<DecodedImage> j = decodeImage(cut.data(), cut.size(), 64, 4096);
    ASSERT_FALSE(j.ok());
    EXPECT_NE(j.error().reason.find("cannot decode JPEG"), std::string::npos) << j.error().reason;

    const std::uint8_t text[] = "GIF89a";
    Result<DecodedImage> other = decodeImage(text, sizeof(text), 64, 4096);
    ASSERT_FALSE(other.ok());
    EXPECT_NE(other.error().reason.find("not an image"), std::string::npos) << other.error().reason;
}

TEST(ImageCodec, EncodedPngDecodesToTheSameBytes)
{
    for (int channels = 1; channels <= 4; ++channels)
    {
        Bytes samples(std::size_t(5 * 3 * channels));
        for (std::size_t i = 0; i < samples.size(); ++i)
            samples[i] = std::uint8_t(i * 37 + 11);
        Result<Bytes> png = encodePng(samples.data(), 5, 3, channels, 9);
        ASSERT_TRUE(png.ok()) << png.error().message();
        Result<DecodedImage> back = decodeImage(png->data(), png->size(), 64, 4096);
        ASSERT_TRUE(back.ok()) << back.error().message();
        EXPECT_EQ(back->channels, channels);
        EXPECT_EQ(back->bits, 8);
        EXPECT_EQ(back->samples, std::vector<std::uint16_t>(samples.begin(), samples.end()));
    }
    EXPECT_FALSE(encodePng(nullptr, 0, 3, 4, 6).ok());
    EXPECT_FALSE(encodePng(nullptr, 3, 3, 5, 6).ok());
}
