// WindModel (the CPU side of the wind): calm is an exact zero, the base stays put, the offset
// scales with the tree, a gale is bounded, the phases keep their precision near 1e6 s, and bad
// parameters are refused by name.
#include "TreeLod/WindModel.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace TreeLod
{
    namespace
    {
        WindParameters breeze(float strength)
        {
            WindParameters wind;
            wind.direction = {0.6f, 0.8f};
            wind.strength = strength;
            return wind;
        }

        glm::vec3 offsetOf(const WindParameters& wind, double seconds, const glm::vec3& p, float height,
                           const glm::vec3& base = glm::vec3(3.0f, 0.0f, -7.0f), bool leaf = true)
        {
            const glm::vec2 d = glm::normalize(wind.direction);
            return WindModel::offset(wind, WindPhases::at(seconds), p, height, glm::vec3(d.x, 0.0f, d.y), d, base, leaf);
        }
    }

    TEST(WindModel, calmIsExactlyStillAndTheBaseStaysPut)
    {
        for (const glm::vec3 p : {glm::vec3(0.0f, 5.0f, 0.0f), glm::vec3(2.0f, 9.0f, -1.0f)})
            EXPECT_EQ(offsetOf(breeze(0.0f), 12.5, p, 10.0f), glm::vec3(0.0f));
        EXPECT_EQ(offsetOf(breeze(1.0f), 12.5, glm::vec3(1.0f, 0.0f, 1.0f), 10.0f), glm::vec3(0.0f)) << "eta = 0";
        EXPECT_EQ(offsetOf(breeze(1.0f), 12.5, glm::vec3(1.0f, -2.0f, 1.0f), 10.0f), glm::vec3(0.0f)) << "roots";
        EXPECT_EQ(offsetOf(breeze(1.0f), 12.5, glm::vec3(1.0f, 5.0f, 1.0f), 0.0f), glm::vec3(0.0f)) << "no height";
    }

    TEST(WindModel, theTopMovesDownwindMoreThanTheMiddle)
    {
        const WindParameters wind = breeze(1.5f);
        const glm::vec3 along(0.6f, 0.0f, 0.8f);
        for (double t = 0.0; t < 20.0; t += 0.37)
        {
            const glm::vec3 top = offsetOf(wind, t, glm::vec3(0.0f, 10.0f, 0.0f), 10.0f);
            const glm::vec3 middle = offsetOf(wind, t, glm::vec3(0.0f, 5.0f, 0.0f), 10.0f);
            EXPECT_GT(glm::dot(top, along), 0.0f) << t;
            EXPECT_GT(glm::dot(top, along), glm::dot(middle, along)) << t;
            EXPECT_LT(top.y, 0.0f + 0.004f * 10.0f) << "the arc keeps its length: the top sinks";
        }
    }

    // A 0.5 m and a 500 m tree: the offset of the same relative point scales with the tree.
    TEST(WindModel, offsetScalesWithTheTree)
    {
        const WindParameters wind = breeze(2.0f);
        const glm::vec3 p(0.3f, 0.8f, -0.2f);
        const glm::vec3 unit = offsetOf(wind, 4.2, p, 1.0f);
        for (float height : {0.5f, 500.0f})
        {
            const glm::vec3 scaled = offsetOf(wind, 4.2, p * height, height);
            for (int i = 0; i < 3; ++i)
                EXPECT_NEAR(scaled[i], unit[i] * height, 1e-4f * height) << height;
        }
    }

    TEST(WindModel, aGaleIsBounded)
    {
        for (float strength : {10.0f, 1.0e6f, std::numeric_limits<float>::max()})
            for (double t = 0.0; t < 10.0; t += 0.9)
            {
                const glm::vec3 o = offsetOf(breeze(strength), t, glm::vec3(4.0f, 10.0f, 0.0f), 10.0f);
                EXPECT_TRUE(std::isfinite(o.x) && std::isfinite(o.y) && std::isfinite(o.z)) << strength;
                EXPECT_LT(glm::length(o), 0.25f * 10.0f) << strength;
            }
    }

    // Near 1e6 s the phases step as they do near 0: nothing lost to single precision.
    TEST(WindModel, phasesKeepTheirPrecisionNearAMillionSeconds)
    {
        const double dt = 1.0 / 60.0;
        for (double t0 : {0.0, 1.0e6, 3.0e7})
        {
            const WindPhases a = WindPhases::at(t0), b = WindPhases::at(t0 + dt);
            for (const auto& [pa, pb, rate] : {std::tuple(a.gust, b.gust, WindModel::GUST_RATE),
                                               std::tuple(a.sway, b.sway, WindModel::SWAY_RATE),
                                               std::tuple(a.branch, b.branch, WindModel::BRANCH_RATE),
                                               std::tuple(a.leaf, b.leaf, WindModel::LEAF_RATE)})
            {
                EXPECT_GE(pa, 0.0f);
                EXPECT_LT(pa, 6.2832f);
                const double step = std::remainder(double(pb) - double(pa), 2.0 * 3.141592653589793);
                EXPECT_NEAR(step, rate * dt, 1e-5) << t0;
            }
        }
        const WindPhases nan = WindPhases::at(std::nan(""));
        EXPECT_EQ(nan.gust, 0.0f);
    }

    TEST(WindModel, badParametersAreNamed)
    {
        EXPECT_TRUE(breeze(1.0f).validate().ok());
        auto reason = [](WindParameters w) { return w.validate().ok() ? std::string("accepted") : w.validate().error().message(); };
        WindParameters w = breeze(std::nanf(""));
        EXPECT_NE(reason(w).find("wind.strength"), std::string::npos);
        w = breeze(-0.5f);
        EXPECT_NE(reason(w).find("wind.strength"), std::string::npos);
        w = breeze(1.0f);
        w.direction = {0.0f, 0.0f};
        EXPECT_NE(reason(w).find("wind.direction"), std::string::npos);
        w = breeze(1.0f);
        w.gustiness = -0.1f;
        EXPECT_NE(reason(w).find("wind.gustiness"), std::string::npos);
        w = breeze(1.0f);
        w.gustWavelength = 0.0f;
        EXPECT_NE(reason(w).find("wind.gustWavelength"), std::string::npos);
    }
}
