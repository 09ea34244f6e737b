// ChunkCodec: the bytes of fields, arrays and flags, and the errors hostile bytes give (count
// limits, counts past the end, record checks, unknown flags), each with its element.
#include "TreeLod/ChunkCodec.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

namespace TreeLod
{
    namespace
    {
        using Bytes = std::vector<std::uint8_t>;

        struct Level
        {
            std::uint32_t first = 0;
            float scale = 0.0f;
            glm::vec3 centre{0.0f};
        };

        constexpr ArrayLayout LEVELS{4 + 4 + 12, 1, 1, 3, "levels"};
        constexpr ArrayLayout WORDS{4, 16};

        constexpr auto levelFields = [](auto& s, auto& l) { s.fields(l.first, l.scale, l.centre); };
        constexpr auto wordField = [](auto& s, auto& v) { s.fields(v); };

        /// flags, then LEVELS, then WORDS: a small chunk in the kit's layouts.
        Bytes encode(const std::vector<Level>& levels, const std::vector<std::uint32_t>& words, std::uint32_t flags = 0)
        {
            ByteWriter w;
            w.u32(flags);
            writeArray(w, levels, LEVELS, levelFields);
            writeArray(w, words, WORDS, wordField);
            return w.take();
        }

        struct Decoded
        {
            std::vector<Level> levels;
            std::vector<std::uint32_t> words;
            Error error;
        };

        Decoded decode(const Bytes& bytes)
        {
            ByteReader r(bytes.data(), bytes.size(), "file", "chunk");
            Decoded d;
            readFlags(r, 1u);
            r.setElement("chunk, levels");
            readArray(r, d.levels, LEVELS, [](ByteReader& r, Level& l, std::uint32_t i) {
                levelFields(r, l);
                if (l.scale < 0.0f)
                {
                    r.setElement("chunk, level " + std::to_string(i));
                    r.failHere("negative scale");
                }
            });
            r.setElement("chunk, words");
            readArray(r, d.words, WORDS, wordField);
            if (!r.ok())
                d.error = r.error();
            else if (r.remaining() != 0)
                d.error = Error{"file", "chunk", "trailing"};
            return d;
        }

        void putU32(Bytes& b, std::size_t at, std::uint32_t v)
        {
            for (int i = 0; i < 4; ++i)
                b[at + i] = std::uint8_t(v >> (8 * i));
        }

        const std::vector<Level> twoLevels = {{7, 1.5f, {1, 2, 3}}, {9, 0.25f, {-1, 0, 4}}};
    }

    TEST(ChunkCodec, FieldsAreLittleEndianByTheirType)
    {
        ByteWriter w;
        w.fields(std::uint8_t(1), std::uint16_t(0x0302), std::uint32_t(0x07060504), std::int32_t(-2),
                 std::uint64_t(0x0f0e0d0c0b0a0908ull), 1.0f, glm::vec2(2.0f, -2.0f));
        const Bytes expected = {1,    2,    3,    4,    5,    6,    7,    0xfe, 0xff, 0xff, 0xff, 8,    9,
                                10,   11,   12,   13,   14,   15,   0,    0,    0x80, 0x3f, 0,    0,    0,
                                0x40, 0,    0,    0,    0xc0};
        EXPECT_EQ(w.data(), expected);

        ByteReader r(w.data().data(), w.size(), "", "");
        std::uint8_t a = 0;
        std::uint16_t b = 0;
        std::uint32_t c = 0;
        std::int32_t d = 0;
        std::uint64_t e = 0;
        float f = 0.0f;
        glm::vec2 g(0.0f);
        r.fields(a, b, c, d, e, f, g);
        ASSERT_TRUE(r.ok());
        EXPECT_EQ(r.remaining(), 0u);
        EXPECT_EQ(a, 1);
        EXPECT_EQ(b, 0x0302);
        EXPECT_EQ(c, 0x07060504u);
        EXPECT_EQ(d, -2);
        EXPECT_EQ(e, 0x0f0e0d0c0b0a0908ull);
        EXPECT_EQ(f, 1.0f);
        EXPECT_EQ(g, glm::vec2(2.0f, -2.0f));
    }

    TEST(ChunkCodec, ArraysStoreCountPaddingAndRecords)
    {
        const Bytes bytes = encode(twoLevels, {5, 6});
        // flags 4, levels 4 + 2 x 20, words: count at 48, padding to 64, 2 x 4.
        ASSERT_EQ(bytes.size(), 72u);
        EXPECT_EQ(bytes[4], 2);
        EXPECT_EQ(bytes[8], 7);
        EXPECT_EQ(bytes[48], 2);
        for (std::size_t i = 52; i < 64; ++i)
            EXPECT_EQ(bytes[i], 0) << i;
        EXPECT_EQ(bytes[64], 5);
        EXPECT_EQ(bytes[68], 6);

        const Decoded d = decode(bytes);
        ASSERT_TRUE(d.error.reason.empty()) << d.error.message();
        ASSERT_EQ(d.levels.size(), 2u);
        EXPECT_EQ(d.levels[1].first, 9u);
        EXPECT_EQ(d.levels[1].scale, 0.25f);
        EXPECT_EQ(d.levels[1].centre, glm::vec3(-1, 0, 4));
        EXPECT_EQ(d.words, (std::vector<std::uint32_t>{5, 6}));

        // An empty array still pads to its alignment.
        EXPECT_EQ(encode(twoLevels, {}).size(), 64u);
        EXPECT_TRUE(decode(encode(twoLevels, {})).error.reason.empty());
    }

    TEST(ChunkCodec, CountOutsideTheLimitsIsRefusedWithTheStandardText)
    {
        EXPECT_EQ(LEVELS.countProblem(0), "0 levels (1 to 3 needed)");
        EXPECT_EQ(LEVELS.countProblem(3), "");
        EXPECT_EQ(LEVELS.countProblem(4), "4 levels (1 to 3 needed)");
        EXPECT_EQ(WORDS.countProblem(0xffffffffull), "");

        const Decoded none = decode(encode({}, {}));
        EXPECT_EQ(none.error.file, "file");
        EXPECT_EQ(none.error.element, "chunk, levels");
        EXPECT_EQ(none.error.reason, "0 levels (1 to 3 needed)");

        const std::vector<Level> four(4);
        EXPECT_EQ(decode(encode(four, {})).error.reason, "4 levels (1 to 3 needed)");
    }

    TEST(ChunkCodec, CountPastTheBytesIsRefusedBeforeAllocating)
    {
        Bytes bytes = encode(twoLevels, {5, 6});
        putU32(bytes, 48, 0x40000000u); // a billion words
        const Decoded d = decode(bytes);
        EXPECT_EQ(d.error.element, "chunk, words");
        EXPECT_EQ(d.error.reason, "count 1073741824 at offset 48 needs 4294967296 bytes, chunk has 20 left");
        EXPECT_TRUE(d.words.empty());

        // Every prefix is refused, none reads past its end.
        const Bytes good = encode(twoLevels, {5, 6});
        for (std::size_t size = 0; size < good.size(); ++size)
            EXPECT_FALSE(decode(Bytes(good.begin(), good.begin() + std::ptrdiff_t(size))).error.reason.empty())
                << size;
    }

    TEST(ChunkCodec, RecordCheckNamesTheRecordAndStopsTheReading)
    {
        std::vector<Level> levels = twoLevels;
        levels[0].scale = -1.0f;
        levels[1].scale = -2.0f;
        const Decoded d = decode(encode(levels, {5}));
        EXPECT_EQ(d.error.element, "chunk, level 0");
        EXPECT_EQ(d.error.reason, "negative scale");
        EXPECT_TRUE(d.words.empty()) << "arrays after a failure are not read";
    }

    TEST(ChunkCodec, UnknownFlagsAreRefused)
    {
        EXPECT_TRUE(decode(encode(twoLevels, {}, 1u)).error.reason.empty());
        const Decoded d = decode(encode(twoLevels, {}, 6u));
        EXPECT_EQ(d.error.element, "chunk");
        EXPECT_EQ(d.error.reason, "unknown flags 6");

        // checkFlags names the element current when it is called.
        const Bytes bytes = {3, 0, 0, 0};
        ByteReader r(bytes.data(), bytes.size(), "file", "chunk");
        const std::uint32_t flags = r.u32();
        r.setElement("chunk 'classic'");
        EXPECT_EQ(checkFlags(r, flags, 1u), 3u);
        EXPECT_EQ(r.error().element, "chunk 'classic'");
        EXPECT_EQ(r.error().reason, "unknown flags 3");
    }

    TEST(ChunkCodec, ReadingAfterAFailureChangesNothing)
    {
        const Bytes bytes = {1, 0};
        ByteReader r(bytes.data(), bytes.size(), "file", "chunk");
        readFlags(r, 0u);
        ASSERT_FALSE(r.ok());
        const Error first = r.error();
        std::vector<std::uint32_t> words = {42};
        r.setElement("chunk, words");
        EXPECT_FALSE(readArray(r, words, WORDS, wordField));
        EXPECT_EQ(words, (std::vector<std::uint32_t>{42}));
        EXPECT_EQ(r.error().element, first.element);
        EXPECT_EQ(r.error().reason, "truncated: needs 4 bytes at offset 0, chunk has 2");
    }
}
