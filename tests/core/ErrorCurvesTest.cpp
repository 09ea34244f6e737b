// The "error-curves" chunk: what is encoded decodes to the same values, flipAt and switchFlipAt
// interpolate in log2(height) and clamp, version 1 still decodes (switch data unknown), and every
// broken value or byte is refused naming the element. The
// descriptor is registered by TreeLodRuntime itself, whatever the program references.
#include "TreeLod/ErrorCurves.h"
#include "TreeLod/TechniqueDescriptor.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <limits>

namespace TreeLod
{
    namespace
    {
        ErrorCurveLevel level(const std::string& technique, std::uint32_t techniqueLevel, bool lowRes,
                              std::vector<float> flip)
        {
            ErrorCurveLevel l;
            l.technique = technique;
            l.techniqueLevel = techniqueLevel;
            l.lowRes = lowRes;
            l.flipMax = flip;
            for (float& v : l.flipMax)
                v = std::min(1.0f, v + 0.125f);
            l.rmse = flip;
            for (float& v : l.rmse)
                v *= 0.5f;
            l.flip = std::move(flip);
            return l;
        }

        /// Three heights an octave pair apart, values exact in binary so interpolation is exact.
        ErrorCurves sample()
        {
            ErrorCurves c;
            c.heightsPx = {8.0f, 32.0f, 128.0f};
            c.views = 6;
            c.referenceSamples = 4;
            c.levels = {level("mesh", 0, false, {0.0625f, 0.03125f, 0.015625f}),
                        level("lodf", 0, false, {0.5f, 0.25f, 0.125f}),
                        level("lodf", 1200, false, {0.75f, 0.5f, 0.25f}),
                        level("billboard-cloud", 1, true, {1.0f, 0.875f, 0.5f}),
                        level("impostor", 0, false, {0.875f, 0.75f, 0.625f})};
            // Pair p: p / 16 at 8 px, p / 32 at 32 px, p / 64 at 128 px.
            for (std::size_t p = 0; p < ErrorCurves::switchPairs(c.levels.size()); ++p)
                c.switchFlip.push_back({float(p) / 16.0f, float(p) / 32.0f, float(p) / 64.0f});
            // The mesh's buffer, LoDF's vertex and index buffers (both levels), the cloud's and the
            // impostor's textures.
            c.resourceBytes = {1000000, 250000, 40000, 8000, 2000};
            const std::vector<std::vector<std::uint32_t>> resources = {{0}, {1, 2}, {1, 2}, {3}, {4}};
            for (std::size_t l = 0; l < c.levels.size(); ++l)
                c.levels[l].resources = resources[l];
            return c;
        }

        /// The bytes of the resource section of sample(): the count, 5 sizes, 5 lists.
        constexpr std::size_t SAMPLE_RESOURCE_BYTES = 4 + 5 * 8 + 4 * 5 + 4 * 7;

        /// `c` without GPU bytes (as decoded from versions 1 and 2).
        ErrorCurves withoutGpuBytes(ErrorCurves c)
        {
            c.resourceBytes.clear();
            for (ErrorCurveLevel& level : c.levels)
                level.resources.clear();
            return c;
        }

        /// The bytes of `c` as version 2 wrote them: the version 3 layout ends with the resource
        /// section, which for curves without GPU bytes is one u32 of 0.
        std::vector<std::uint8_t> versionTwoBytes(const ErrorCurves& c)
        {
            std::vector<std::uint8_t> bytes = encodeErrorCurves(withoutGpuBytes(c));
            EXPECT_EQ(std::vector<std::uint8_t>(bytes.end() - 4, bytes.end()), std::vector<std::uint8_t>(4, 0));
            bytes.resize(bytes.size() - 4);
            return bytes;
        }

        /// The bytes of `c` as version 1 wrote them: version 2's less its switch section, which for
        /// curves without switch data is one u32 of 0.
        std::vector<std::uint8_t> versionOneBytes(ErrorCurves c)
        {
            c.switchFlip.clear();
            std::vector<std::uint8_t> bytes = versionTwoBytes(c);
            EXPECT_EQ(std::vector<std::uint8_t>(bytes.end() - 4, bytes.end()), std::vector<std::uint8_t>(4, 0));
            bytes.resize(bytes.size() - 4);
            return bytes;
        }

        std::string decodeError(const std::vector<std::uint8_t>& bytes,
                                std::uint32_t formatVersion = ERROR_CURVES_FORMAT_VERSION)
        {
            Result<ErrorCurves> decoded = decodeErrorCurves(bytes, "tree.treelod", formatVersion);
            return decoded ? std::string() : decoded.error().message();
        }

        std::string validateError(const ErrorCurves& curves)
        {
            Result<void> valid = validateErrorCurves(curves, "tree.treelod");
            return valid ? std::string() : valid.error().message();
        }

        void putU32(std::vector<std::uint8_t>& b, std::size_t at, std::uint32_t v)
        {
            for (int i = 0; i < 4; ++i)
                b[at + i] = std::uint8_t(v >> (8 * i));
        }

        void putF32(std::vector<std::uint8_t>& b, std::size_t at, float v)
        {
            std::uint32_t bits;
            std::memcpy(&bits, &v, 4);
            putU32(b, at, bits);
        }

        bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }
    }

    TEST(ErrorCurves, roundTripKeepsEveryValue)
    {
        const ErrorCurves c = sample();
        ASSERT_TRUE(validateErrorCurves(c, "tree").ok()) << validateError(c);
        const std::vector<std::uint8_t> bytes = encodeErrorCurves(c);
        // 16 header + 12 heights + per level: 4 + name + 8 + 36; the pair count, 10 pairs of 3 heights.
        EXPECT_EQ(bytes.size(), 16u + 12u + 5u * 48u + 4u + 4u + 4u + 15u + 8u + 4u + 10u * 12u + SAMPLE_RESOURCE_BYTES);
        Result<ErrorCurves> decoded = decodeErrorCurves(bytes, "tree");
        ASSERT_TRUE(decoded.ok()) << decoded.error().message();
        EXPECT_EQ(decoded->heightsPx, c.heightsPx);
        EXPECT_EQ(decoded->views, 6u);
        EXPECT_EQ(decoded->referenceSamples, 4u);
        ASSERT_EQ(decoded->levels.size(), c.levels.size());
        for (std::size_t i = 0; i < c.levels.size(); ++i)
        {
            EXPECT_EQ(decoded->levels[i].technique, c.levels[i].technique);
            EXPECT_EQ(decoded->levels[i].techniqueLevel, c.levels[i].techniqueLevel);
            EXPECT_EQ(decoded->levels[i].lowRes, c.levels[i].lowRes);
            EXPECT_EQ(decoded->levels[i].flip, c.levels[i].flip);
            EXPECT_EQ(decoded->levels[i].flipMax, c.levels[i].flipMax);
            EXPECT_EQ(decoded->levels[i].rmse, c.levels[i].rmse);
        }
        EXPECT_EQ(decoded->switchFlip, c.switchFlip);
        EXPECT_TRUE(decoded->hasSwitchFlip());
        EXPECT_EQ(decoded->resourceBytes, c.resourceBytes);
        for (std::size_t i = 0; i < c.levels.size(); ++i)
            EXPECT_EQ(decoded->levels[i].resources, c.levels[i].resources);
        EXPECT_TRUE(decoded->hasGpuBytes());
        EXPECT_EQ(encodeErrorCurves(decoded.value()), bytes); // deterministic

        // Curves without switch data (as decoded from version 1) encode as version 2 with 0 pairs.
        ErrorCurves none = c;
        none.switchFlip.clear();
        Result<ErrorCurves> noneDecoded = decodeErrorCurves(encodeErrorCurves(none), "tree");
        ASSERT_TRUE(noneDecoded.ok()) << noneDecoded.error().message();
        EXPECT_TRUE(noneDecoded->switchFlip.empty());
        EXPECT_FALSE(noneDecoded->hasSwitchFlip());
    }

    TEST(ErrorCurves, versionOneStillDecodesWithSwitchDataUnknown)
    {
        const ErrorCurves c = sample();
        const std::vector<std::uint8_t> v1 = versionOneBytes(c);
        EXPECT_EQ(v1.size(), 16u + 12u + 5u * 48u + 4u + 4u + 4u + 15u + 8u); // version 1's size
        Result<ErrorCurves> decoded = decodeErrorCurves(v1, "old.treelod", 1);
        ASSERT_TRUE(decoded.ok()) << decoded.error().message();
        ASSERT_EQ(decoded->levels.size(), c.levels.size());
        for (std::size_t i = 0; i < c.levels.size(); ++i)
            EXPECT_EQ(decoded->levels[i].flip, c.levels[i].flip);
        EXPECT_TRUE(decoded->switchFlip.empty());
        EXPECT_FALSE(decoded->hasSwitchFlip());
        EXPECT_EQ(decoded->switchFlipAt(1, 3, 32.0f), SWITCH_FLIP_UNKNOWN);
        EXPECT_EQ(decoded->switchFlipAt(3, 1, 32.0f), SWITCH_FLIP_UNKNOWN);
        EXPECT_EQ(decoded->switchFlipAt(2, 2, 32.0f), 0.0f); // no switch at all

        // Version 2: switch FLIP, no GPU bytes.
        Result<ErrorCurves> two = decodeErrorCurves(versionTwoBytes(c), "old.treelod", 2);
        ASSERT_TRUE(two.ok()) << two.error().message();
        EXPECT_EQ(two->switchFlip, c.switchFlip);
        EXPECT_FALSE(two->hasGpuBytes());
        EXPECT_EQ(two->gpuBytes({0, 1}), 0u);

        // Each version's bytes read as another are refused; other versions are refused.
        std::string e = decodeError(encodeErrorCurves(c), 1);
        EXPECT_TRUE(contains(e, "tree.treelod: error-curves: " + std::to_string(124 + SAMPLE_RESOURCE_BYTES) +
                                    " trailing bytes"))
            << e;
        e = decodeError(v1, 2);
        EXPECT_TRUE(contains(e, "tree.treelod: error-curves switchFlip: truncated")) << e;
        e = decodeError(versionTwoBytes(c), 3);
        EXPECT_TRUE(contains(e, "tree.treelod: error-curves resources")) << e;
        for (std::uint32_t version : {0u, 4u})
        {
            e = decodeError(encodeErrorCurves(c), version);
            EXPECT_TRUE(contains(e, "error-curves: format version " + std::to_string(version) +
                                        ", this build reads 1..3"))
                << e;
        }

        // The descriptor reads all three (treelod info, TreeAsset::readChunk); "reference" its one version.
        const TechniqueDescriptor* d = findTechniqueDescriptor(ERROR_CURVES_CHUNK);
        ASSERT_NE(d, nullptr);
        EXPECT_TRUE(readsFormatVersion(*d, 1));
        EXPECT_TRUE(readsFormatVersion(*d, 2));
        EXPECT_TRUE(readsFormatVersion(*d, 3));
        EXPECT_FALSE(readsFormatVersion(*d, 4));
        EXPECT_FALSE(readsFormatVersion(*d, 0));
        Result<ChunkSummary> summary = inspectChunk(*d, v1, "old.treelod", 1);
        ASSERT_TRUE(summary.ok()) << summary.error().message();
        EXPECT_TRUE(contains(summary->text, "6 views; FLIP at")) << summary->text; // no switch pairs, no bytes
        Result<ChunkSummary> refused = inspectChunk(*d, v1, "old.treelod", 4);
        ASSERT_FALSE(refused.ok());
        EXPECT_TRUE(contains(refused.error().message(), "old.treelod: error-curves: unsupported format version 4, "
                                                        "this build reads 1..3"))
            << refused.error().message();
        const TechniqueDescriptor* reference = findTechniqueDescriptor("reference");
        ASSERT_NE(reference, nullptr);
        EXPECT_TRUE(readsFormatVersion(*reference, reference->formatVersion));
        EXPECT_FALSE(readsFormatVersion(*reference, reference->formatVersion - 1));
        EXPECT_EQ(readFormatVersions(*d), "1..3");
        EXPECT_EQ(readFormatVersions(*reference), std::to_string(reference->formatVersion));
    }

    TEST(ErrorCurves, switchFlipAtInterpolatesEitherOrder)
    {
        const ErrorCurves c = sample();
        // Pair (1, 3) is index 4 + 1 = 5 (pairs of 0 come first: (0, 1) .. (0, 4)).
        EXPECT_EQ(c.switchPair(0, 1), 0u);
        EXPECT_EQ(c.switchPair(0, 4), 3u);
        EXPECT_EQ(c.switchPair(1, 3), 5u);
        EXPECT_EQ(c.switchPair(3, 4), 9u);
        EXPECT_EQ(c.switchFlipAt(1, 3, 8.0f), 5.0f / 16.0f);
        EXPECT_EQ(c.switchFlipAt(3, 1, 8.0f), 5.0f / 16.0f);
        EXPECT_EQ(c.switchFlipAt(1, 3, 16.0f), 0.5f * (5.0f / 16.0f + 5.0f / 32.0f)); // halfway in log2
        EXPECT_EQ(c.switchFlipAt(1, 3, 4096.0f), 5.0f / 64.0f);                     // clamped
        EXPECT_EQ(c.switchFlipAt(4, 4, 16.0f), 0.0f);
        EXPECT_EQ(c.switchFlipAt(1, 5, 16.0f), SWITCH_FLIP_UNKNOWN); // no level 5

        // Keeping some levels keeps their pairs: levels 1, 3, 4 of the five.
        ErrorCurves kept = c;
        kept.keepLevels({false, true, false, true, true});
        ASSERT_EQ(kept.levels.size(), 3u);
        EXPECT_EQ(kept.levels[1].technique, "billboard-cloud");
        EXPECT_TRUE(kept.hasSwitchFlip());
        EXPECT_TRUE(validateErrorCurves(kept, "kept").ok());
        for (const auto& [a, b] : {std::pair<std::size_t, std::size_t>{0, 1}, {0, 2}, {1, 2}})
        {
            const std::size_t original[] = {1, 3, 4};
            EXPECT_EQ(kept.switchFlipAt(a, b, 16.0f), c.switchFlipAt(original[a], original[b], 16.0f)) << a << b;
        }
    }

    TEST(ErrorCurves, flipAtInterpolatesInLog2HeightAndClamps)
    {
        const ErrorCurves c = sample();
        const std::size_t lodf = 1; // 0.5, 0.25, 0.125 at 8, 32, 128 px
        // At the measured heights: the measured values.
        EXPECT_EQ(c.flipAt(lodf, 8.0f), 0.5f);
        EXPECT_EQ(c.flipAt(lodf, 32.0f), 0.25f);
        EXPECT_EQ(c.flipAt(lodf, 128.0f), 0.125f);
        // 16 px is halfway from 8 to 32 in log2 (3, 4, 5): halfway between the values; 64 likewise.
        EXPECT_EQ(c.flipAt(lodf, 16.0f), 0.375f);
        EXPECT_EQ(c.flipAt(lodf, 64.0f), 0.1875f);
        // A quarter of the way in log2 (2^3.5 is halfway from 8 to 16).
        EXPECT_NEAR(c.flipAt(lodf, float(8.0 * std::sqrt(2.0))), 0.4375f, 1e-6f);
        // Linear in height would give 0.5 - 0.25 * 12 / 24 = 0.375 at 20 px; log2 gives more weight below.
        EXPECT_NEAR(c.flipAt(lodf, 20.0f), 0.5f - 0.25f * float(std::log2(20.0 / 8.0) / 2.0), 1e-6f);
        // Outside the measured range: the end values.
        EXPECT_EQ(c.flipAt(lodf, 1.0f), 0.5f);
        EXPECT_EQ(c.flipAt(lodf, 4096.0f), 0.125f);
        EXPECT_EQ(c.flipAt(lodf, FLT_MAX), 0.125f);
        // Not a height: the first value.
        EXPECT_EQ(c.flipAt(lodf, 0.0f), 0.5f);
        EXPECT_EQ(c.flipAt(lodf, -3.0f), 0.5f);
        EXPECT_EQ(c.flipAt(lodf, std::numeric_limits<float>::quiet_NaN()), 0.5f);
        EXPECT_EQ(c.flipAt(lodf, std::numeric_limits<float>::infinity()), 0.5f);
        // No such level.
        EXPECT_EQ(c.flipAt(99, 16.0f), 0.0f);
    }

    TEST(ErrorCurves, findNamesTheLevelByAllThreeKeys)
    {
        const ErrorCurves c = sample();
        EXPECT_EQ(c.find("mesh", 0, false), 0);
        EXPECT_EQ(c.find("lodf", 0, false), 1);
        EXPECT_EQ(c.find("lodf", 1200, false), 2);
        EXPECT_EQ(c.find("billboard-cloud", 1, true), 3);
        EXPECT_EQ(c.find("billboard-cloud", 1, false), -1);
        EXPECT_EQ(c.find("lodf", 600, false), -1);
        EXPECT_EQ(c.find("reference", 0, false), -1);
    }

    TEST(ErrorCurves, validationNamesTheElement)
    {
        ErrorCurves c = sample();
        c.levels[2].flip[1] = std::numeric_limits<float>::quiet_NaN();
        std::string e = validateError(c);
        EXPECT_TRUE(contains(e, "tree.treelod: error-curves level 2 'lodf' 1200 flip[1]: nan")) << e;

        c = sample();
        c.heightsPx[2] = 32.0f;
        e = validateError(c);
        EXPECT_TRUE(contains(e, "heights[2]: 32 px after 32 px")) << e;

        c = sample();
        c.heightsPx[0] = 0.5f;
        EXPECT_TRUE(contains(validateError(c), "heights[0]: 0.5 px outside [1, 16384]")) << validateError(c);

        c = sample();
        c.switchFlip.clear(); // 5 levels' pairs
        c.levels.push_back(c.levels[2]);
        e = validateError(c);
        EXPECT_TRUE(contains(e, "level 5 'lodf' 1200: the same level as level 2")) << e;
        c.levels.back().lowRes = true; // another level: fine
        EXPECT_EQ(validateError(c), "");

        c = sample();
        c.levels[3].flipMax[0] = 0.5f;
        e = validateError(c);
        EXPECT_TRUE(contains(e, "level 3 'billboard-cloud' 1 low-res flipMax[0]: 0.5 below the mean FLIP 1")) << e;
        c.levels[3].flipMax[0] = 1.0f - 5e-7f; // within the tolerance
        EXPECT_EQ(validateError(c), "");

        c = sample();
        c.levels[1].rmse.pop_back();
        EXPECT_TRUE(contains(validateError(c), "level 1 'lodf' 0 rmse: 2 values for 3 heights")) << validateError(c);

        c = sample();
        c.levels[0].technique = "";
        EXPECT_TRUE(contains(validateError(c), "level 0: technique name of 0 bytes")) << validateError(c);
        c.levels[0].technique = std::string(33, 'x');
        EXPECT_TRUE(contains(validateError(c), "level 0: technique name of 33 bytes")) << validateError(c);
        c.levels[0].technique = "me\nsh";
        EXPECT_TRUE(contains(validateError(c), "level 0: technique name")) << validateError(c);

        c = sample();
        c.views = 0;
        EXPECT_TRUE(contains(validateError(c), "views: 0 views")) << validateError(c);
        c = sample();
        c.levels.clear();
        EXPECT_TRUE(contains(validateError(c), "levels: 0 levels (1..256 allowed)")) << validateError(c);
        c = sample();
        c.heightsPx.assign(65, 1.0f);
        EXPECT_TRUE(contains(validateError(c), "heights: 65 heights (1..64 allowed)")) << validateError(c);

        // Switch data: every value in [0, 1], one per height, one curve per pair (or none).
        c = sample();
        c.switchFlip[c.switchPair(1, 3)][2] = 1.5f;
        e = validateError(c);
        EXPECT_TRUE(contains(e, "tree.treelod: error-curves level 1 'lodf' 0 to level 3 'billboard-cloud' 1 low-res "
                                "switchFlip[2]: 1.5 outside [0, 1]"))
            << e;
        c.switchFlip[c.switchPair(1, 3)][2] = std::numeric_limits<float>::infinity();
        EXPECT_TRUE(contains(validateError(c), "switchFlip[2]: inf outside [0, 1]")) << validateError(c);
        c = sample();
        c.switchFlip[c.switchPair(0, 4)].pop_back();
        e = validateError(c);
        EXPECT_TRUE(contains(e, "level 0 'mesh' 0 to level 4 'impostor' 0 switchFlip: 2 values for 3 heights")) << e;
        c = sample();
        c.switchFlip.pop_back();
        e = validateError(c);
        EXPECT_TRUE(contains(e, "error-curves switchFlip: 9 pairs of levels for 5 levels (0 or 10 needed)")) << e;
        c.switchFlip.clear(); // not measured: fine
        EXPECT_EQ(validateError(c), "");
    }

    TEST(ErrorCurves, decodeRefusesBrokenBytes)
    {
        const std::vector<std::uint8_t> good = encodeErrorCurves(sample());
        ASSERT_EQ(decodeError(good), "");

        // Cut anywhere: refused, never a crash.
        for (std::size_t size = 0; size < good.size(); ++size)
            EXPECT_NE(decodeError({good.begin(), good.begin() + std::ptrdiff_t(size)}), "") << size;
        std::string e = decodeError({good.begin(), good.end() - 1});
        EXPECT_TRUE(contains(e, "tree.treelod: error-curves level 4 'impostor' 0 resources")) << e;
        const std::size_t switchesEnd = good.size() - SAMPLE_RESOURCE_BYTES; // where the resources start
        e = decodeError({good.begin(), good.begin() + std::ptrdiff_t(switchesEnd) - 1});
        EXPECT_TRUE(contains(e, "tree.treelod: error-curves switchFlip: truncated")) << e;
        const std::size_t levelsEnd = switchesEnd - 4 - 10 * 12; // where the switch section starts
        e = decodeError({good.begin(), good.begin() + std::ptrdiff_t(levelsEnd) - 1});
        EXPECT_TRUE(contains(e, "tree.treelod: error-curves level 4 'impostor' 0: truncated")) << e;

        std::vector<std::uint8_t> bytes = good;
        bytes.push_back(0);
        EXPECT_TRUE(contains(decodeError(bytes), "error-curves: 1 trailing bytes")) << decodeError(bytes);

        // Counts over the limits, or more than the bytes hold, refused before allocating.
        bytes = good;
        putU32(bytes, 0, 0xFFFFFFFFu);
        EXPECT_TRUE(contains(decodeError(bytes), "heights: 4294967295 heights (1..64 allowed)")) << decodeError(bytes);
        bytes = good;
        putU32(bytes, 4, 257);
        EXPECT_TRUE(contains(decodeError(bytes), "levels: 257 levels (1..256 allowed)")) << decodeError(bytes);
        bytes = good;
        putU32(bytes, 4, 256);
        e = decodeError(bytes);
        EXPECT_TRUE(contains(e, "levels: truncated: 256 levels of 3 heights need at least")) << e;

        // A NaN height (bytes 16..27 are the heights).
        bytes = good;
        putF32(bytes, 20, std::numeric_limits<float>::quiet_NaN());
        EXPECT_TRUE(contains(decodeError(bytes), "error-curves heights[1]: nan px")) << decodeError(bytes);

        // A technique name longer than 32 bytes (level 0's name length at 28).
        bytes = good;
        putU32(bytes, 28, 40);
        e = decodeError(bytes);
        EXPECT_TRUE(contains(e, "error-curves level 0: string of 40 bytes, at most 32")) << e;

        // Unknown flags (level 0: length 4, "mesh", techniqueLevel, flags at 40).
        bytes = good;
        putU32(bytes, 40, 2);
        e = decodeError(bytes);
        EXPECT_TRUE(contains(e, "error-curves level 0 'mesh' 0: unknown flags 2")) << e;

        // A value outside [0, 1] (level 0's flip[0] at 44).
        bytes = good;
        putF32(bytes, 44, 1.5f);
        EXPECT_TRUE(contains(decodeError(bytes), "level 0 'mesh' 0 flip[0]: 1.5 outside [0, 1]")) << decodeError(bytes);

        // The switch section: a pair count other than 0 or 10, a NaN (pair (0, 2)'s second value).
        bytes = good;
        putU32(bytes, levelsEnd, 9);
        e = decodeError(bytes);
        EXPECT_TRUE(contains(e, "error-curves switchFlip: 9 pairs of levels for 5 levels (0 or 10 needed)")) << e;
        bytes = good;
        putU32(bytes, levelsEnd, 0xFFFFFFFFu);
        EXPECT_NE(decodeError(bytes), "");
        bytes = good;
        putF32(bytes, levelsEnd + 4 + 12 + 4, std::numeric_limits<float>::quiet_NaN());
        e = decodeError(bytes);
        EXPECT_TRUE(contains(e, "error-curves level 0 'mesh' 0 to level 2 'lodf' 1200 switchFlip[1]: nan outside"))
            << e;

        // The resource section: too many resources, an index out of the table, a list out of order.
        bytes = good;
        putU32(bytes, switchesEnd, 5000);
        e = decodeError(bytes);
        EXPECT_TRUE(contains(e, "error-curves resources: 5000 GPU resources (at most 4096)")) << e;
        const std::size_t lists = switchesEnd + 4 + 5 * 8; // mesh's list: count 1, resource 0
        bytes = good;
        putU32(bytes, lists + 4, 7);
        e = decodeError(bytes);
        EXPECT_TRUE(contains(e, "error-curves level 0 'mesh' 0 resources[0]: resource 7 of a table of 5")) << e;
        bytes = good;
        putU32(bytes, lists + 8 + 4, 2); // lodf 0's list {1, 2} becomes {2, 2}
        e = decodeError(bytes);
        EXPECT_TRUE(contains(e, "error-curves level 1 'lodf' 0 resources[1]: resource 2 after 2")) << e;
        bytes = good;
        putU32(bytes, lists, 6);
        EXPECT_NE(decodeError(bytes), "");
    }

    TEST(ErrorCurves, gpuBytesCountEachSharedResourceOnce)
    {
        const ErrorCurves c = sample();
        EXPECT_EQ(c.gpuBytes({0}), 1000000u);
        EXPECT_EQ(c.gpuBytes({1}), 290000u);
        EXPECT_EQ(c.gpuBytes({1, 2}), 290000u); // both LoDF levels draw from the same buffers
        EXPECT_EQ(c.gpuBytes({0, 1, 2, 3, 4}), 1300000u);
        EXPECT_EQ(c.gpuBytes({4, 4, 99}), 2000u); // repeated and out-of-range levels
        EXPECT_EQ(c.gpuBytes({}), 0u);
        // Levels kept keep their resources.
        ErrorCurves kept = c;
        kept.keepLevels({false, true, false, false, true});
        ASSERT_EQ(kept.levels.size(), 2u);
        EXPECT_EQ(kept.gpuBytes({0, 1}), 292000u);
        EXPECT_TRUE(validateErrorCurves(kept, "tree").ok());
        // Resources without a table are refused.
        ErrorCurves broken = withoutGpuBytes(c);
        broken.levels[3].resources = {0};
        EXPECT_TRUE(contains(validateError(broken), "level 3 'billboard-cloud' 1 low-res resources[0]: resource 0 of a "
                                                    "table of 0"))
            << validateError(broken);
    }

    TEST(ErrorCurves, descriptorIsRegisteredAndInspects)
    {
        // Registered with "reference" in TechniqueDescriptor.cpp, so that no static registration
        // can be dropped by the linker.
        const TechniqueDescriptor* d = findTechniqueDescriptor(ERROR_CURVES_CHUNK);
        ASSERT_NE(d, nullptr);
        EXPECT_EQ(d->formatVersion, ERROR_CURVES_FORMAT_VERSION);
        ASSERT_NE(d->inspect, nullptr);
        ASSERT_NE(d->fuzz, nullptr);
        EXPECT_FALSE(d->description.empty());
        EXPECT_EQ(techniqueDescriptors().front().name, "reference");

        const std::vector<std::uint8_t> bytes = encodeErrorCurves(sample());
        Result<ChunkSummary> summary = d->inspect(bytes, "tree.treelod");
        ASSERT_TRUE(summary.ok()) << summary.error().message();
        EXPECT_EQ(summary->text, "5 levels x 3 heights (8-128 px), 6 views, switch FLIP of 10 pairs, GPU bytes of 5 "
                                 "resources; FLIP at 8/128 px: mesh 0.062/0.016 (1.00 MB), "
                                 "lodf 0 0.500/0.125 (0.29 MB), lodf 1200 0.750/0.250 (0.29 MB), billboard-cloud "
                                 "low-res 1.000/0.500 (0.01 MB), impostor 0.875/0.625 (0.00 MB)");
        const nlohmann::json json = nlohmann::json::parse(summary->json, nullptr, false);
        ASSERT_TRUE(json.is_object()) << summary->json;
        EXPECT_EQ(json["levels"], 5);
        EXPECT_EQ(json["heightsPx"], nlohmann::json({8, 32, 128}));
        EXPECT_EQ(json["views"], 6);
        EXPECT_EQ(json["referenceSamples"], 4);
        ASSERT_EQ(json["curves"].size(), 5u);
        EXPECT_EQ(json["curves"][2]["technique"], "lodf");
        EXPECT_EQ(json["curves"][2]["level"], 1200);
        EXPECT_EQ(json["curves"][3]["lowRes"], true);
        EXPECT_EQ(json["curves"][1]["flip"], nlohmann::json({0.5, 0.25, 0.125}));
        EXPECT_EQ(json["curves"][1]["flipMax"], nlohmann::json({0.625, 0.375, 0.25}));
        EXPECT_EQ(json["curves"][1]["rmse"], nlohmann::json({0.25, 0.125, 0.0625}));
        ASSERT_EQ(json["switchFlip"].size(), 10u);
        EXPECT_EQ(json["switchFlip"][5]["levels"], nlohmann::json({1, 3}));
        EXPECT_EQ(json["switchFlip"][5]["flip"], nlohmann::json({0.3125, 0.15625, 0.078125}));
        EXPECT_EQ(json["curves"][1]["gpuBytes"], 290000);
        EXPECT_EQ(json["resourceBytes"], nlohmann::json({1000000, 250000, 40000, 8000, 2000}));

        // Broken: refused naming the package; the fuzz hook never traps on valid or broken bytes.
        Result<ChunkSummary> refused = d->inspect({bytes.begin(), bytes.begin() + 10}, "broken.treelod");
        ASSERT_FALSE(refused.ok());
        EXPECT_TRUE(contains(refused.error().message(), "broken.treelod")) << refused.error().message();
        d->fuzz(bytes);
        d->fuzz({bytes.begin(), bytes.begin() + 10});
    }

    TEST(ErrorCurves, inspectListsAtMostEightLevelsAndShowsThreeHeights)
    {
        ErrorCurves c;
        c.heightsPx = {8, 16, 32, 64, 128, 256, 512};
        c.views = 1;
        c.referenceSamples = 1;
        for (std::uint32_t l = 0; l < 10; ++l)
            c.levels.push_back(level("lodf", l, false, std::vector<float>(7, 0.25f)));
        Result<ChunkSummary> summary = findTechniqueDescriptor(ERROR_CURVES_CHUNK)->inspect(encodeErrorCurves(c), "t");
        ASSERT_TRUE(summary.ok()) << summary.error().message();
        EXPECT_EQ(summary->text.rfind("10 levels x 7 heights (8-512 px), 1 view; FLIP at 32/128/512 px: lodf 0 "
                                      "0.250/0.250/0.250, lodf 1 ",
                                      0),
                  0u)
            << summary->text;
        EXPECT_TRUE(contains(summary->text, "lodf 7 0.250/0.250/0.250, ...")) << summary->text;
        EXPECT_FALSE(contains(summary->text, "lodf 8")) << summary->text;
        EXPECT_EQ(summary->text.find('\n'), std::string::npos);
    }
}
