// LevelTransition.h: the band's end, the coarse share across it, and the per-tree pattern shift
// that the Forest's shaders and the tree objects share.
#include "TreeLod/LevelTransition.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <set>

namespace TreeLod
{
    TEST(LevelTransition, aBandEndsAtOnePlusItsLengthWithinTheLowerHalfOfItsLevel)
    {
        const float inf = std::numeric_limits<float>::infinity();
        EXPECT_EQ(transitionBandEnd(0.0f, inf), 1.0f) << "length 0: no band";
        EXPECT_EQ(transitionBandEnd(std::nanf(""), inf), 1.0f);
        EXPECT_FLOAT_EQ(transitionBandEnd(0.2f, inf), 1.2f) << "the finest level's range is unbounded";
        EXPECT_FLOAT_EQ(transitionBandEnd(0.2f, 2.0f), 1.2f);
        EXPECT_FLOAT_EQ(transitionBandEnd(0.2f, 1.21f), 1.1f) << "at most the square root of the level's range";
        EXPECT_EQ(transitionBandEnd(0.2f, 1.0f), 1.0f) << "a level of no range has no band";
        EXPECT_EQ(transitionBandEnd(0.2f, 0.5f), 1.0f);
    }

    TEST(LevelTransition, theCoarseShareRunsFromOneAtTheSwitchToZeroAtTheBandsEnd)
    {
        EXPECT_FLOAT_EQ(transitionCoarseShare(1.0f, 1.2f), 1.0f);
        EXPECT_NEAR(transitionCoarseShare(1.1f, 1.2f), 0.5f, 1e-6f);
        EXPECT_NEAR(transitionCoarseShare(1.15f, 1.2f), 0.25f, 1e-6f);
        EXPECT_EQ(transitionCoarseShare(1.2f, 1.2f), 0.0f);
        EXPECT_EQ(transitionCoarseShare(3.0f, 1.2f), 0.0f);
        EXPECT_EQ(transitionCoarseShare(0.5f, 1.2f), 1.0f) << "past the switch: the coarse level whole";
        EXPECT_EQ(transitionCoarseShare(1.1f, 1.0f), 0.0f) << "no band";
        EXPECT_EQ(transitionCoarseShare(std::nanf(""), 1.2f), 0.0f);
        // Monotonic across the band, and the two draws' masks complement at every threshold.
        float last = 1.0f;
        for (int i = 0; i <= 100; ++i)
        {
            const float share = transitionCoarseShare(1.0f + 0.2f * float(i) / 100.0f, 1.2f);
            EXPECT_LE(share, last);
            last = share;
            for (int k = 0; k < 64; ++k)
            {
                const float dither = (float(k) + 0.5f) / 64.0f;
                if (share > 0.0f)
                    EXPECT_NE(transitionKeeps(share, dither), transitionKeeps(-share, dither));
                else
                    EXPECT_TRUE(transitionKeeps(0.0f, dither)) << "outside the band: one level, whole";
            }
        }
    }

    TEST(LevelTransition, thePatternShiftHashesTheQuarterMetreCell)
    {
        // TreeLodTransition.glsl's transitionOf: cells floor(4 p) + 2^24, hashed in 32-bit integers.
        EXPECT_EQ(transitionPatternShift({1.3f, -2.6f, 1000.1f}), 26.0f / 64.0f);
        EXPECT_EQ(transitionPatternShift({0.0f, 0.0f, 0.0f}), 0.0f);
        EXPECT_EQ(transitionPatternShift({0.01f, 0.02f, 0.24f}), transitionPatternShift({0.0f, 0.0f, 0.0f}))
            << "one cell, one shift";
        const float nan = std::nanf(""), inf = std::numeric_limits<float>::infinity();
        for (const glm::vec3& odd : {glm::vec3(nan, 0.0f, 0.0f), glm::vec3(inf, -inf, 1e30f)})
        {
            const float shift = transitionPatternShift(odd);
            EXPECT_GE(shift, 0.0f);
            EXPECT_LT(shift, 1.0f);
        }
        // Trees spread over a forest get every one of the 64 shifts.
        std::mt19937 rng(7);
        std::uniform_real_distribution<float> u(-500.0f, 500.0f);
        std::set<float> shifts;
        for (int i = 0; i < 2000; ++i)
        {
            const float shift = transitionPatternShift({u(rng), 0.0f, u(rng)});
            EXPECT_EQ(shift * 64.0f, std::floor(shift * 64.0f)) << "a multiple of 1/64";
            shifts.insert(shift);
        }
        EXPECT_EQ(shifts.size(), 64u);
    }
}
