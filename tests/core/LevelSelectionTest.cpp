// Budgeted level selection (LevelSelection.h) and the cost calibration file (LevelCosts.h):
// budget 0 draws the reference, budget 1 the cheapest level, a level's worst view bounds it too,
// bad budgets are refused, runs are merged to the Forest's level limit; within the cost slack the
// plan draws fewer and smaller switches, and without slack the cheapest level at every sample;
// costs interpolate in log-log and a calibration made on another renderer is not reused.
#include "TreeLod/AtomicFile.h"
#include "TreeLod/LevelSelection.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <random>
#include <string>
#include <unistd.h>

namespace TreeLod
{
    namespace
    {
        ErrorCurveLevel curve(const std::string& technique, std::uint32_t level, std::vector<float> flip)
        {
            ErrorCurveLevel c;
            c.technique = technique;
            c.techniqueLevel = level;
            c.flip = flip;
            c.flipMax = flip;
            c.rmse = flip;
            return c;
        }

        LevelCost cost(const std::string& technique, std::uint32_t level, std::vector<float> ms)
        {
            LevelCost c;
            c.technique = technique;
            c.techniqueLevel = level;
            c.heightsPx = {16.0f, 64.0f, 256.0f};
            c.msPerTree = ms;
            return c;
        }

        /// Heights 16, 64, 256 px. The mesh: 0.05 everywhere, the dearest. "lodf" 1: 0.06 at every
        /// height, half the mesh's cost. "impostor": 0.06 at 16 px, 0.30 at 256, nearly free.
        struct Fixture
        {
            ErrorCurves curves;
            std::vector<LevelCost> costs;
            Fixture()
            {
                curves.heightsPx = {16.0f, 64.0f, 256.0f};
                curves.views = 1;
                curves.referenceSamples = 4;
                curves.levels = {curve("mesh", 0, {0.05f, 0.05f, 0.05f}), curve("lodf", 1, {0.06f, 0.06f, 0.06f}),
                                 curve("impostor", 0, {0.06f, 0.18f, 0.30f})};
                costs = {cost("mesh", 0, {1.0f, 2.0f, 8.0f}), cost("lodf", 1, {0.5f, 1.0f, 4.0f}),
                         cost("impostor", 0, {0.001f, 0.004f, 0.016f})};
            }
        };
    }

    TEST(LevelSelection, budgetZeroDrawsTheReferenceAndOneTheCheapest)
    {
        Fixture f;
        Result<std::vector<LevelChoice>> zero = chooseLevels(f.curves, f.costs, 0.0f);
        ASSERT_TRUE(zero) << zero.error().message();
        ASSERT_EQ(zero->size(), 1u);
        EXPECT_EQ(zero->front().curveLevel, 0u);
        EXPECT_EQ(zero->front().minHeightPx, 0.0f);

        Result<std::vector<LevelChoice>> one = chooseLevels(f.curves, f.costs, 1.0f);
        ASSERT_TRUE(one);
        ASSERT_EQ(one->size(), 1u);
        EXPECT_EQ(one->front().curveLevel, 2u);
    }

    TEST(LevelSelection, theCheapestLevelWithinTheBudgetAtEachHeight)
    {
        Fixture f;
        // 0.02 over the mesh: lodf (0.06) everywhere it is cheaper; the impostor only where its
        // error is at most 0.07: below 16 * 2^(1/12) px (0.06 at 16, +0.12 per octave... to 64).
        Result<std::vector<LevelChoice>> runs = chooseLevels(f.curves, f.costs, 0.02f);
        ASSERT_TRUE(runs) << runs.error().message();
        ASSERT_EQ(runs->size(), 2u);
        EXPECT_EQ((*runs)[0].curveLevel, 1u);
        EXPECT_EQ((*runs)[1].curveLevel, 2u);
        EXPECT_GT((*runs)[0].minHeightPx, 14.0f);
        EXPECT_LT((*runs)[0].minHeightPx, 19.0f);
        EXPECT_FLOAT_EQ((*runs)[0].flip, 0.06f);
        EXPECT_EQ((*runs)[1].minHeightPx, 0.0f);
        EXPECT_LE((*runs)[1].flip, 0.07f + 1e-6f);

        // Below 0.01 lodf is not allowed: the mesh near, the impostor nowhere above 16 px.
        Result<std::vector<LevelChoice>> tight = chooseLevels(f.curves, f.costs, 0.005f);
        ASSERT_TRUE(tight);
        EXPECT_EQ(tight->front().curveLevel, 0u);

        // A level without a cost is never chosen.
        std::vector<LevelCost> noLodf = {f.costs[0], f.costs[2]};
        Result<std::vector<LevelChoice>> without = chooseLevels(f.curves, noLodf, 0.02f);
        ASSERT_TRUE(without);
        for (const LevelChoice& c : *without)
            EXPECT_NE(c.curveLevel, 1u);
    }

    TEST(LevelSelection, aLevelDearerThanTheMeshWhereItIsDrawnLargeStepsAside)
    {
        // LoDF within the budget everywhere, half the mesh's cost when small but 9 ms against the
        // mesh's 8 at 256 px (as at 1280x720, where its full level costs more than the mesh): the
        // plan draws it where it pays and the mesh above.
        Fixture f;
        f.costs[1] = cost("lodf", 1, {0.5f, 1.0f, 9.0f});
        Result<std::vector<LevelChoice>> plan = chooseLevels(f.curves, f.costs, 0.02f);
        ASSERT_TRUE(plan) << plan.error().message();
        EXPECT_EQ((*plan)[choiceAt(*plan, 256.0f)].curveLevel, 0u) << "the mesh, cheaper there";
        EXPECT_EQ((*plan)[choiceAt(*plan, 4096.0f)].curveLevel, 0u);
        EXPECT_EQ((*plan)[choiceAt(*plan, 64.0f)].curveLevel, 1u) << "LoDF, half the mesh's cost there";
    }

    TEST(LevelSelection, occlusionScalesTheHeightAsFarAsTheBudgetOverTheVisibleShareAllows)
    {
        Fixture f;
        Result<std::vector<LevelChoice>> plan = chooseLevels(f.curves, f.costs, 0.02f);
        ASSERT_TRUE(plan) << plan.error().message();
        const std::size_t ref = 0;
        // Whether the plan drawn at h * s keeps every sampled height within errorBudget / v (or no
        // worse than the plan's own level there).
        auto holds = [&](float s, float v) {
            const float budget = std::min(1.0f, 0.02f / v);
            for (std::size_t j = 0; j < SELECTION_SAMPLES; ++j)
            {
                const float h = selectionHeight(j);
                const std::size_t own = (*plan)[choiceAt(*plan, h)].curveLevel;
                const std::size_t level = (*plan)[choiceAt(*plan, h * s)].curveLevel;
                if (f.curves.flipAt(level, h) >
                    std::max(f.curves.flipAt(ref, h) + budget, f.curves.flipAt(own, h)) + 1e-6f)
                    return false;
            }
            return true;
        };
        EXPECT_EQ(occlusionHeightScale(f.curves, *plan, 0.02f, 1.0f), 1.0f);
        float previous = 1.0f;
        // Visible shares whose budgets put no level's limit on a sampled height (no ties).
        for (const float v : {0.6f, 0.3f, 0.15f})
        {
            const float s = occlusionHeightScale(f.curves, *plan, 0.02f, v);
            // Less visible, at most as fine; within the budget, and the next quarter octave is not.
            EXPECT_LT(s, 1.0f) << "v " << v;
            EXPECT_LE(s, previous) << "v " << v;
            EXPECT_TRUE(holds(s, v)) << "v " << v << ", s " << s;
            EXPECT_FALSE(holds(s * std::exp2(-1.0f / SELECTION_SAMPLES_PER_OCTAVE), v)) << "v " << v << ", s " << s;
            previous = s;
        }
        // The impostor's curve grows 0.06 per octave from 0.06 at 16 px; the plan draws it below
        // 19.03 px (2^4.25). At v = 0.6 (0.033 allowed) it may be drawn up to 20.9 px: the sample at
        // 19.03 px may draw it, the one at 22.6 px may not, so s = 2^-0.25.
        EXPECT_NEAR(occlusionHeightScale(f.curves, *plan, 0.02f, 0.6f), std::exp2(-0.25f), 1e-6f);
        // Nothing to scale: no plan, a bad budget or visibility.
        EXPECT_EQ(occlusionHeightScale(f.curves, {}, 0.02f, 0.5f), 1.0f);
        EXPECT_EQ(occlusionHeightScale(f.curves, *plan, NAN, 0.5f), 1.0f);
        EXPECT_EQ(occlusionHeightScale(f.curves, *plan, 0.02f, 0.0f), 1.0f);
        EXPECT_EQ(occlusionHeightScale(f.curves, *plan, 0.02f, NAN), 1.0f);
    }

    TEST(LevelSelection, aLevelWhoseWorstViewFailsIsNotChosen)
    {
        // The impostor's mean is within 0.02 below 16 px; its worst view (the mesh's is 0.05) may
        // add WORST_VIEW_BUDGET_FACTOR * 0.02 = 0.08.
        for (const float worstAdded : {0.07f, 0.09f})
        {
            Fixture f;
            f.curves.levels[2].flipMax = {0.05f + worstAdded, 0.6f, 0.7f};
            Result<std::vector<LevelChoice>> runs = chooseLevels(f.curves, f.costs, 0.02f);
            ASSERT_TRUE(runs) << runs.error().message();
            const bool impostor = runs->back().curveLevel == 2u;
            EXPECT_EQ(impostor, worstAdded < WORST_VIEW_BUDGET_FACTOR * 0.02f) << "worst view +" << worstAdded;
            if (!impostor)
            {
                EXPECT_EQ(runs->size(), 1u) << "lodf at every height";
            }
        }
        // Budget 1 still draws the cheapest, whatever its worst view.
        Fixture f;
        f.curves.levels[2].flipMax = {1.0f, 1.0f, 1.0f};
        Result<std::vector<LevelChoice>> one = chooseLevels(f.curves, f.costs, 1.0f);
        ASSERT_TRUE(one);
        EXPECT_EQ(one->back().curveLevel, 2u);
    }

    TEST(LevelSelection, runsAreMergedToTheLimit)
    {
        Fixture f;
        // Costs that alternate between lodf and the mesh every few samples.
        f.curves.heightsPx = {1.0f, 2.0f, 4.0f, 8.0f, 16.0f, 32.0f, 64.0f, 128.0f, 256.0f, 512.0f, 1024.0f};
        const std::size_t n = f.curves.heightsPx.size();
        f.curves.levels = {curve("mesh", 0, std::vector<float>(n, 0.05f)), curve("lodf", 1, std::vector<float>(n, 0.05f))};
        f.costs[0].heightsPx = f.curves.heightsPx;
        f.costs[1].heightsPx = f.curves.heightsPx;
        f.costs[0].msPerTree.assign(n, 1.0f);
        f.costs[1].msPerTree.clear();
        for (std::size_t i = 0; i < n; ++i)
            f.costs[1].msPerTree.push_back(i % 2 ? 0.5f : 2.0f);
        Result<std::vector<LevelChoice>> many = chooseLevels(f.curves, f.costs, 0.01f);
        ASSERT_TRUE(many);
        EXPECT_GT(many->size(), 4u);
        Result<std::vector<LevelChoice>> few = chooseLevels(f.curves, f.costs, 0.01f, 3);
        ASSERT_TRUE(few);
        EXPECT_LE(few->size(), 3u);
        for (std::size_t r = 1; r < few->size(); ++r)
        {
            EXPECT_NE((*few)[r].curveLevel, (*few)[r - 1].curveLevel) << "neighbours of one level are one run";
            EXPECT_LT((*few)[r].minHeightPx, (*few)[r - 1].minHeightPx);
        }
        EXPECT_EQ(few->back().minHeightPx, 0.0f);
    }

    TEST(LevelSelection, badBudgetsAndCurvesAreRefused)
    {
        Fixture f;
        for (const float budget : {-0.01f, std::nanf(""), 1.5f, INFINITY})
        {
            Result<std::vector<LevelChoice>> r = chooseLevels(f.curves, f.costs, budget);
            ASSERT_FALSE(r) << budget;
            EXPECT_NE(r.error().message().find("error budget"), std::string::npos) << r.error().message();
        }
        ErrorCurves noMesh = f.curves;
        noMesh.levels.erase(noMesh.levels.begin());
        Result<std::vector<LevelChoice>> r = chooseLevels(noMesh, f.costs, 0.02f);
        ASSERT_FALSE(r);
        EXPECT_NE(r.error().message().find("mesh"), std::string::npos) << r.error().message();
        r = chooseLevels(f.curves, {}, 0.02f);
        ASSERT_FALSE(r);
        EXPECT_NE(r.error().message().find("cost"), std::string::npos) << r.error().message();
    }

    namespace
    {
        /// The levels of `choices` at each selection sample.
        std::vector<std::size_t> perSample(const std::vector<LevelChoice>& choices)
        {
            std::vector<std::size_t> levels;
            for (std::size_t k = 0; k < SELECTION_SAMPLES; ++k)
                levels.push_back(choices[choiceAt(choices, selectionHeight(k))].curveLevel);
            return levels;
        }

        /// LevelSelection.h's rule without switches, written from its comment: at each sample the
        /// cheapest allowed level (ties: the smaller FLIP; the reference "mesh", level 0 here, always
        /// allowed).
        std::vector<std::size_t> cheapestAllowed(const ErrorCurves& curves, const std::vector<LevelCost>& costs,
                                                 float budget)
        {
            std::vector<std::size_t> levels;
            for (std::size_t k = 0; k < SELECTION_SAMPLES; ++k)
            {
                const float h = selectionHeight(k);
                std::size_t best = 0;
                for (std::size_t l = 1; l < curves.levels.size() && budget > 0.0f; ++l)
                {
                    const bool allowed =
                        curves.flipAt(l, h) <= curves.flipAt(0, h) + budget &&
                        curves.flipMaxAt(l, h) <= curves.flipMaxAt(0, h) + WORST_VIEW_BUDGET_FACTOR * budget;
                    const float cost = costs[l].msAt(h), bestCost = costs[best].msAt(h);
                    const bool finer = cost == bestCost && curves.flipAt(l, h) < curves.flipAt(best, h);
                    if (allowed && (cost < bestCost || finer))
                        best = l;
                }
                levels.push_back(best);
            }
            return levels;
        }

        /// What the switches of a plan (levels per sample) show: switch FLIP plus the penalty each.
        double switchesShown(const ErrorCurves& curves, const std::vector<std::size_t>& levels)
        {
            double shown = 0.0;
            for (std::size_t k = 1; k < levels.size(); ++k)
                if (levels[k] != levels[k - 1])
                {
                    const float boundary = selectionHeight(k) * std::exp2(0.5f / SELECTION_SAMPLES_PER_OCTAVE);
                    shown += double(curves.switchFlipAt(levels[k - 1], levels[k], boundary)) +
                             double(LEVEL_SWITCH_PENALTY);
                }
            return shown;
        }

        std::size_t switchCount(const std::vector<std::size_t>& levels)
        {
            std::size_t n = 0;
            for (std::size_t k = 1; k < levels.size(); ++k)
                n += levels[k] != levels[k - 1];
            return n;
        }

        /// Heights 8..512 px (one an octave); the mesh (0.05, dear) and two levels "lodf" 1 and 2.
        struct SwitchFixture
        {
            ErrorCurves curves;
            std::vector<LevelCost> costs;
            SwitchFixture(std::vector<float> flip1, std::vector<float> flip2, std::vector<float> ms1,
                          std::vector<float> ms2)
            {
                curves.heightsPx = {8.0f, 16.0f, 32.0f, 64.0f, 128.0f, 256.0f, 512.0f};
                curves.views = 1;
                curves.referenceSamples = 4;
                curves.levels = {curve("mesh", 0, std::vector<float>(7, 0.05f)), curve("lodf", 1, flip1),
                                 curve("lodf", 2, flip2)};
                costs = {cost("mesh", 0, {}), cost("lodf", 1, {}), cost("lodf", 2, {})};
                for (LevelCost& c : costs)
                    c.heightsPx = curves.heightsPx;
                costs[0].msPerTree.assign(7, 4.0f);
                costs[1].msPerTree = std::move(ms1);
                costs[2].msPerTree = std::move(ms2);
            }
            /// Switch FLIP mesh-lodf 1, mesh-lodf 2, lodf 1-lodf 2, the same at every height.
            void setSwitches(float mesh1, float mesh2, float between)
            {
                curves.switchFlip = {std::vector<float>(7, mesh1), std::vector<float>(7, mesh2),
                                     std::vector<float>(7, between)};
            }
        };
    }

    TEST(LevelSelection, withoutSlackTheCheapestAllowedLevelAtEverySample)
    {
        // Random curves and costs: slack 0 gives the plan of the cheapest allowed level at every
        // sample; the default slack a plan whose switches show no more, within the slack's cost.
        std::mt19937 random(7);
        std::uniform_real_distribution<float> unit(0.0f, 1.0f);
        std::size_t fewer = 0;
        for (int trial = 0; trial < 40; ++trial)
        {
            ErrorCurves curves;
            curves.heightsPx = {8.0f, 16.0f, 32.0f, 64.0f, 128.0f, 256.0f, 512.0f};
            curves.views = 1;
            curves.referenceSamples = 4;
            std::vector<LevelCost> costs;
            for (std::uint32_t l = 0; l < 5; ++l)
            {
                std::vector<float> flip;
                for (std::size_t h = 0; h < 7; ++h)
                    flip.push_back(0.02f + 0.2f * unit(random));
                ErrorCurveLevel c = curve(l == 0 ? "mesh" : "lodf", l, flip);
                for (float& v : c.flipMax)
                    v = std::min(1.0f, v + 0.1f * unit(random));
                curves.levels.push_back(c);
                std::vector<float> ms;
                for (int h = 0; h < 3; ++h)
                    ms.push_back(0.2f + unit(random));
                costs.push_back(cost(l == 0 ? "mesh" : "lodf", l, ms));
            }
            for (std::size_t p = 0; p < ErrorCurves::switchPairs(5); ++p)
            {
                curves.switchFlip.emplace_back();
                for (std::size_t h = 0; h < 7; ++h)
                    curves.switchFlip.back().push_back(0.3f * unit(random));
            }
            for (const float budget : {0.0f, 0.01f, 0.04f, 0.1f, 1.0f})
            {
                Result<std::vector<LevelChoice>> exact = chooseLevels(curves, costs, budget, SELECTION_SAMPLES, 0.0f);
                ASSERT_TRUE(exact) << exact.error().message();
                const std::vector<std::size_t> cheapest = cheapestAllowed(curves, costs, budget);
                ASSERT_EQ(perSample(*exact), cheapest) << "trial " << trial << " budget " << budget;

                Result<std::vector<LevelChoice>> slack = chooseLevels(curves, costs, budget, SELECTION_SAMPLES);
                ASSERT_TRUE(slack) << slack.error().message();
                const std::vector<std::size_t> levels = perSample(*slack);
                EXPECT_LE(switchesShown(curves, levels), switchesShown(curves, cheapest) + 1e-9)
                    << "trial " << trial << " budget " << budget;
                for (std::size_t k = 0; k < SELECTION_SAMPLES; ++k)
                {
                    const float h = selectionHeight(k);
                    EXPECT_LE(costs[levels[k]].msAt(h), (1.0f + LEVEL_SWITCH_COST_SLACK) * costs[cheapest[k]].msAt(h))
                        << "trial " << trial << " budget " << budget << " sample " << k;
                }
                fewer += switchCount(levels) < switchCount(cheapest);
            }
        }
        EXPECT_GT(fewer, 0u) << "the slack never saved a switch";
    }

    TEST(LevelSelection, aCheapestLevelThatAlternatesWithinTheSlackBecomesOneRun)
    {
        // lodf 1 and 2 both within the budget everywhere; lodf 2 costs 4 % less, then 4 % more,
        // octave by octave, than lodf 1.
        SwitchFixture f(std::vector<float>(7, 0.06f), std::vector<float>(7, 0.065f), std::vector<float>(7, 1.0f),
                        {0.96f, 1.04f, 0.96f, 1.04f, 0.96f, 1.04f, 0.96f});
        f.setSwitches(0.2f, 0.2f, 0.1f);
        Result<std::vector<LevelChoice>> exact = chooseLevels(f.curves, f.costs, 0.02f, 16, 0.0f);
        ASSERT_TRUE(exact) << exact.error().message();
        EXPECT_GE(exact->size(), 6u) << "the cheapest alternates";

        Result<std::vector<LevelChoice>> plan = chooseLevels(f.curves, f.costs, 0.02f);
        ASSERT_TRUE(plan) << plan.error().message();
        ASSERT_EQ(plan->size(), 1u);
        // No switch either way: the one of the smaller summed cost.
        double ms1 = 0.0, ms2 = 0.0;
        for (std::size_t k = 0; k < SELECTION_SAMPLES; ++k)
        {
            ms1 += f.costs[1].msAt(selectionHeight(k));
            ms2 += f.costs[2].msAt(selectionHeight(k));
        }
        ASSERT_NE(ms1, ms2);
        EXPECT_EQ(plan->front().curveLevel, ms1 < ms2 ? 1u : 2u) << ms1 << " " << ms2;
    }

    TEST(LevelSelection, withinTheSlackTheLevelWithTheSmallerSwitchToItsNeighbour)
    {
        // Near (above 64 px) only the mesh is within the budget; far, lodf 1 and lodf 2 are, lodf 2
        // 5 % dearer (within the slack).
        const std::vector<float> farOnly{0.06f, 0.06f, 0.06f, 0.06f, 0.5f, 0.5f, 0.5f};
        SwitchFixture f(farOnly, farOnly, std::vector<float>(7, 1.0f), std::vector<float>(7, 1.05f));
        auto farLevel = [&](float slack) {
            Result<std::vector<LevelChoice>> plan = chooseLevels(f.curves, f.costs, 0.02f, 16, slack);
            EXPECT_TRUE(plan) << plan.error().message();
            EXPECT_EQ(plan->size(), 2u);
            EXPECT_EQ(plan->front().curveLevel, 0u);
            return plan->back().curveLevel;
        };
        f.setSwitches(0.3f, 0.05f, 0.4f); // the mesh to lodf 2 shows least
        EXPECT_EQ(farLevel(LEVEL_SWITCH_COST_SLACK), 2u);
        EXPECT_EQ(farLevel(0.0f), 1u); // the cheapest
        f.setSwitches(0.05f, 0.3f, 0.4f); // the mesh to lodf 1
        EXPECT_EQ(farLevel(LEVEL_SWITCH_COST_SLACK), 1u);
        // 2 % dearer than lodf 1 is not within a slack of 1 %.
        f.setSwitches(0.3f, 0.05f, 0.4f);
        EXPECT_EQ(farLevel(0.01f), 1u);

        // Without switch FLIP (curves of version 1): flip(mesh) + flip(level) stands in, so the
        // level nearer the reference wins within the slack.
        f.curves.switchFlip.clear();
        f.curves.levels[2].flip = {0.055f, 0.055f, 0.055f, 0.055f, 0.5f, 0.5f, 0.5f};
        EXPECT_EQ(farLevel(LEVEL_SWITCH_COST_SLACK), 2u);
        EXPECT_EQ(farLevel(0.0f), 1u);

        for (const float bad : {-0.1f, std::nanf(""), INFINITY})
        {
            Result<std::vector<LevelChoice>> r = chooseLevels(f.curves, f.costs, 0.02f, 16, bad);
            ASSERT_FALSE(r) << bad;
            EXPECT_NE(r.error().message().find("cost slack"), std::string::npos) << r.error().message();
        }
    }

    TEST(LevelSelection, shadowCastersTakeTheCheapestCoarserLevelWithinTheirBudget)
    {
        Fixture f;
        // The view: the mesh from 64 px, lodf from 16 px, the impostor below.
        const std::vector<LevelChoice> view{{0, 64.0f, 0.05f}, {1, 16.0f, 0.06f}, {2, 0.0f, 0.06f}};

        // 0.005: nothing coarser is within it; each run keeps its level.
        Result<std::vector<std::size_t>> same = chooseShadowLevels(f.curves, f.costs, view, 0.005f);
        ASSERT_TRUE(same) << same.error().message();
        EXPECT_EQ(*same, (std::vector<std::size_t>{0u, 1u, 2u}));
        // 0.02: the mesh's casters draw lodf (0.06 <= 0.05 + 0.02, half the cost), never a finer level.
        Result<std::vector<std::size_t>> coarser = chooseShadowLevels(f.curves, f.costs, view, 0.02f);
        ASSERT_TRUE(coarser);
        EXPECT_EQ(*coarser, (std::vector<std::size_t>{1u, 1u, 2u}));
        // 1: the impostor everywhere.
        Result<std::vector<std::size_t>> cheapest = chooseShadowLevels(f.curves, f.costs, view, 1.0f);
        ASSERT_TRUE(cheapest);
        EXPECT_EQ(*cheapest, (std::vector<std::size_t>{2u, 2u, 2u}));
        for (const float bad : {-0.1f, std::nanf(""), 2.0f})
        {
            Result<std::vector<std::size_t>> r = chooseShadowLevels(f.curves, f.costs, view, bad);
            ASSERT_FALSE(r) << bad;
            EXPECT_NE(r.error().message().find("shadow error budget"), std::string::npos) << r.error().message();
        }
    }

    // A transition's double draw: a tree within 1 + t of a run's smallest height also pays for the
    // next run's level, over the share of each sample's quarter-octave bin the band covers.
    TEST(LevelSelection, aTransitionAddsTheCoarseLevelsCostOverItsBand)
    {
        Fixture f;
        std::vector<LevelChoice> plan(2);
        plan[0].curveLevel = 0; // the mesh down to 64 px
        plan[0].minHeightPx = 64.0f;
        plan[1].curveLevel = 2; // the impostor below
        const std::vector<float> hard = planCostPerTree(f.curves, f.costs, plan);
        EXPECT_EQ(planCostPerTree(f.curves, f.costs, plan, 0.0f), hard);
        // 2^(1/4) - 1: the band [64, 76.1) px is the upper half of 64's bin and the lower half of 76.1's.
        const float t = std::exp2(0.25f) - 1.0f;
        const std::vector<float> faded = planCostPerTree(f.curves, f.costs, plan, t);
        const std::size_t at64 = selectionSample(64.0f), above = at64 - 1;
        const auto impostor = [&](float h) { return f.costs[2].msAt(h); };
        EXPECT_NEAR(faded[at64] - hard[at64], 0.5f * impostor(64.0f), 1e-5f);
        EXPECT_NEAR(faded[above] - hard[above], 0.5f * impostor(selectionHeight(above)), 1e-5f);
        for (std::size_t k = 0; k < SELECTION_SAMPLES; ++k)
            if (k != at64 && k != above)
                EXPECT_EQ(faded[k], hard[k]) << selectionHeight(k) << " px: outside the band";
        // A band stops at half of its run's range: the impostor from 64 to 70 px fades into LoDF
        // over half of log2(70 / 64) octaves (0.26 of the bin at 64 px), not the octave t = 1 asks.
        std::vector<LevelChoice> three(3);
        three[0] = LevelChoice{0, 70.0f, 0.0f};
        three[1] = LevelChoice{2, 64.0f, 0.0f};
        three[2] = LevelChoice{1, 0.0f, 0.0f};
        const std::vector<float> long3 = planCostPerTree(f.curves, f.costs, three, 1.0f);
        const std::vector<float> hard3 = planCostPerTree(f.curves, f.costs, three);
        EXPECT_NEAR(long3[at64] - hard3[at64], 0.5 * std::log2(70.0 / 64.0) * SELECTION_SAMPLES_PER_OCTAVE * f.costs[1].msAt(64.0f),
                    1e-4);
        // Runs below the transitions' smallest height switch hard.
        EXPECT_EQ(planCostPerTree(f.curves, f.costs, plan, t, 65.0f), hard);
        // Above 70 px the mesh fades into the impostor for a whole octave: nearly free.
        for (std::size_t k = 0; k < at64; ++k)
            EXPECT_LT(long3[k] - hard3[k], 0.05f) << selectionHeight(k) << " px";
    }

    TEST(LevelSelection, aFrameBudgetTakesTheFinestStepPredictedWithinIt)
    {
        Fixture f;
        EXPECT_EQ(selectionSample(8192.0f), 0u);
        EXPECT_EQ(selectionSample(1.0f), SELECTION_SAMPLES - 1);
        EXPECT_EQ(selectionSample(0.0f), SELECTION_SAMPLES - 1);
        EXPECT_EQ(selectionSample(std::nanf("")), SELECTION_SAMPLES - 1);
        EXPECT_EQ(selectionSample(1e9f), 0u);
        EXPECT_FLOAT_EQ(selectionHeight(selectionSample(64.0f)), 64.0f);

        // 10 trees at 64 px, 100 at 16 px: the mesh plan costs 10 x 2 + 100 x 1 ms.
        HeightHistogram trees;
        for (int i = 0; i < 10; ++i)
            trees.add(64.0f);
        for (int i = 0; i < 100; ++i)
            trees.add(16.0f);
        std::vector<double> predicted;
        for (const float budget : frameBudgetLadder())
        {
            Result<std::vector<LevelChoice>> plan = chooseLevels(f.curves, f.costs, budget);
            ASSERT_TRUE(plan);
            predicted.push_back(trees.milliseconds(planCostPerTree(f.curves, f.costs, *plan)));
        }
        EXPECT_NEAR(predicted.front(), 120.0, 1e-3);
        EXPECT_LT(predicted.back(), 0.2);
        for (std::size_t s = 1; s < predicted.size(); ++s)
            EXPECT_LE(predicted[s], predicted[s - 1] + 1e-9) << "a larger budget never costs more here";

        EXPECT_EQ(chooseFrameBudgetStep(predicted, 1000.0, 5), 0u) << "everything fits: the reference";
        EXPECT_EQ(chooseFrameBudgetStep(predicted, 1e-6, 0), predicted.size() - 1) << "nothing fits: the coarsest";
        const std::size_t fits = chooseFrameBudgetStep(predicted, 70.0, predicted.size() - 1, 1.0);
        EXPECT_LE(predicted[fits], 70.0);
        EXPECT_TRUE(fits == 0 || predicted[fits - 1] > 70.0);
        // Hysteresis: from a coarser step, a finer one is taken only well within the budget.
        EXPECT_EQ(chooseFrameBudgetStep({100.0, 10.0}, 105.0, 1, 0.85), 1u);
        EXPECT_EQ(chooseFrameBudgetStep({100.0, 10.0}, 105.0, 0, 0.85), 0u) << "already there: it stays";
        EXPECT_EQ(chooseFrameBudgetStep({100.0, 10.0}, 120.0, 1, 0.85), 0u);
        EXPECT_EQ(chooseFrameBudgetStep({}, 10.0, 0), 0u);
    }

    TEST(LevelSelection, excludedLevelsAreNotCandidatesAndTheLeastFlipStandsInForTheReference)
    {
        Fixture f;
        // Without the impostor, lodf everywhere (within 0.02 of the mesh at every height).
        Result<std::vector<LevelChoice>> noImpostor =
            chooseLevels(f.curves, f.costs, 0.02f, 16, LEVEL_SWITCH_COST_SLACK, {false, false, true});
        ASSERT_TRUE(noImpostor) << noImpostor.error().message();
        ASSERT_EQ(noImpostor->size(), 1u);
        EXPECT_EQ(noImpostor->front().curveLevel, 1u);
        EXPECT_TRUE(noImpostor->front().withinBudget);

        // Without the mesh and lodf, at 0.005 nothing is allowed above 16 px: the impostor is drawn
        // anyway, outside the budget; an empty or short mask excludes nothing.
        Result<std::vector<LevelChoice>> onlyImpostor =
            chooseLevels(f.curves, f.costs, 0.005f, 16, LEVEL_SWITCH_COST_SLACK, {true, true});
        ASSERT_TRUE(onlyImpostor) << onlyImpostor.error().message();
        ASSERT_EQ(onlyImpostor->size(), 1u);
        EXPECT_EQ(onlyImpostor->front().curveLevel, 2u);
        EXPECT_FALSE(onlyImpostor->front().withinBudget);
        Result<std::vector<LevelChoice>> all = chooseLevels(f.curves, f.costs, 0.005f, 16, LEVEL_SWITCH_COST_SLACK, {});
        ASSERT_TRUE(all);
        EXPECT_EQ(all->front().curveLevel, 0u);
        EXPECT_TRUE(all->front().withinBudget);

        // Without the mesh, budget 0: the level of least FLIP, lodf, down to 16 px, where the
        // impostor's equals it and costs less; no level is within a budget of 0.
        Result<std::vector<LevelChoice>> zero = chooseLevels(f.curves, f.costs, 0.0f, 16, 0.0f, {true});
        ASSERT_TRUE(zero);
        ASSERT_EQ(zero->size(), 2u);
        EXPECT_EQ((*zero)[0].curveLevel, 1u);
        EXPECT_GT((*zero)[0].minHeightPx, 14.0f);
        EXPECT_LT((*zero)[0].minHeightPx, 19.0f);
        EXPECT_EQ((*zero)[1].curveLevel, 2u);
        EXPECT_FALSE((*zero)[0].withinBudget);
        EXPECT_FALSE((*zero)[1].withinBudget);

        // Everything with a cost excluded: refused.
        Result<std::vector<LevelChoice>> none =
            chooseLevels(f.curves, f.costs, 0.02f, 16, LEVEL_SWITCH_COST_SLACK, {true, true, true});
        ASSERT_FALSE(none);
        EXPECT_NE(none.error().message().find("every level with a cost is excluded"), std::string::npos)
            << none.error().message();
    }

    namespace
    {
        /// The fixture with GPU bytes: the mesh 10 MB, lodf 4 MB, the impostor 1 MB.
        Fixture withBytes()
        {
            Fixture f;
            f.curves.resourceBytes = {10000000, 4000000, 1000000};
            for (std::uint32_t l = 0; l < 3; ++l)
                f.curves.levels[l].resources = {l};
            return f;
        }
    }

    TEST(LevelSelection, aMemoryBudgetTakesOutTheLevelsItCannotHold)
    {
        Fixture f = withBytes();
        const std::vector<MemoryPlanSpecies> one = {MemoryPlanSpecies{&f.curves, &f.costs, {}, nullptr}};
        // Unbudgeted: lodf near, the impostor far, 5 MB; a budget of 5 MB holds it.
        for (const std::uint64_t budget : {std::uint64_t(0), std::uint64_t(5000000)})
        {
            Result<MemoryPlan> plan = chooseLevelsWithinMemory(one, 0.02f, budget);
            ASSERT_TRUE(plan) << plan.error().message();
            EXPECT_EQ(plan->gpuBytes, 5000000u);
            EXPECT_FALSE(plan->memoryBinds);
            EXPECT_TRUE(plan->withinErrorBudget);
            ASSERT_EQ(plan->choices.size(), 1u);
            EXPECT_EQ(plan->choices[0].size(), 2u);
        }
        // 4.5 MB: the impostor goes (lodf alone keeps the error budget, at a higher cost).
        Result<MemoryPlan> tighter = chooseLevelsWithinMemory(one, 0.02f, 4500000);
        ASSERT_TRUE(tighter) << tighter.error().message();
        EXPECT_EQ(tighter->gpuBytes, 4000000u);
        EXPECT_TRUE(tighter->memoryBinds);
        EXPECT_TRUE(tighter->withinErrorBudget);
        ASSERT_EQ(tighter->choices[0].size(), 1u);
        EXPECT_EQ(tighter->choices[0][0].curveLevel, 1u);
        EXPECT_EQ(tighter->excluded[0], (std::vector<bool>{false, false, true}));
        // 2 MB: taking lodf out brings the mesh in, so the plan is built up from the smallest: the
        // impostor alone, over the error budget near, and said so.
        Result<MemoryPlan> small = chooseLevelsWithinMemory(one, 0.02f, 2000000);
        ASSERT_TRUE(small) << small.error().message();
        EXPECT_EQ(small->gpuBytes, 1000000u);
        EXPECT_TRUE(small->memoryBinds);
        EXPECT_FALSE(small->withinErrorBudget);
        ASSERT_EQ(small->choices[0].size(), 1u);
        EXPECT_EQ(small->choices[0][0].curveLevel, 2u);
        // Below the smallest plan: refused, naming the budget and that plan.
        Result<MemoryPlan> tiny = chooseLevelsWithinMemory(one, 0.02f, 500000);
        ASSERT_FALSE(tiny);
        EXPECT_EQ(tiny.error().message(),
                  "memory budget: 0.50 MB is below the smallest plan, 1.00 MB (species 0: impostor 0 1.00 MB)");
    }

    TEST(LevelSelection, aMemoryBudgetSharesResourcesAndNeedsMeasuredBytes)
    {
        Fixture f = withBytes();
        Fixture g = withBytes();
        // Two species of one asset hold its levels once: 5 MB for both; two assets 10 MB.
        const std::vector<MemoryPlanSpecies> shared = {MemoryPlanSpecies{&f.curves, &f.costs, {}, &f},
                                                       MemoryPlanSpecies{&f.curves, &f.costs, {}, &f}};
        Result<MemoryPlan> one = chooseLevelsWithinMemory(shared, 0.02f, 6000000);
        ASSERT_TRUE(one) << one.error().message();
        EXPECT_EQ(one->gpuBytes, 5000000u);
        EXPECT_FALSE(one->memoryBinds);
        const std::vector<MemoryPlanSpecies> two = {MemoryPlanSpecies{&f.curves, &f.costs, {}, &f},
                                                    MemoryPlanSpecies{&g.curves, &g.costs, {}, &g}};
        Result<MemoryPlan> both = chooseLevelsWithinMemory(two, 0.02f, 6000000);
        ASSERT_TRUE(both) << both.error().message();
        EXPECT_LE(both->gpuBytes, 6000000u);
        EXPECT_TRUE(both->memoryBinds);
        EXPECT_EQ(planGpuBytes(two, both->choices), both->gpuBytes);

        // Curves without GPU bytes cannot be planned within a memory budget, but can without.
        Fixture old;
        const std::vector<MemoryPlanSpecies> unmeasured = {MemoryPlanSpecies{&old.curves, &old.costs, {}, nullptr}};
        EXPECT_TRUE(chooseLevelsWithinMemory(unmeasured, 0.02f, 0));
        Result<MemoryPlan> refused = chooseLevelsWithinMemory(unmeasured, 0.02f, 1000000);
        ASSERT_FALSE(refused);
        EXPECT_NE(refused.error().message().find("species 0: its error curves hold no GPU bytes"), std::string::npos)
            << refused.error().message();
    }

    TEST(LevelCosts, costsInterpolateInLogLog)
    {
        const LevelCost c = cost("lodf", 1, {1.0f, 4.0f, 64.0f});
        EXPECT_FLOAT_EQ(c.msAt(16.0f), 1.0f);
        EXPECT_FLOAT_EQ(c.msAt(4.0f), 1.0f) << "below the first height: the first value";
        EXPECT_NEAR(c.msAt(32.0f), 2.0f, 1e-4f) << "halfway in log between 1 and 4";
        EXPECT_NEAR(c.msAt(128.0f), 16.0f, 1e-3f);
        EXPECT_NEAR(c.msAt(512.0f), 256.0f, 1e-2f) << "the last slope (area) extrapolated";
        const LevelCost falling = cost("x", 0, {1.0f, 2.0f, 1.0f});
        EXPECT_FLOAT_EQ(falling.msAt(1024.0f), 1.0f) << "never a falling extrapolation";
        EXPECT_TRUE(std::isfinite(c.msAt(std::nanf(""))));
        EXPECT_TRUE(std::isfinite(c.msAt(INFINITY)));
    }

    TEST(LevelCosts, aCalibrationFromAnotherRendererIsNotReused)
    {
        const std::string dir = testing::TempDir() + "/treelod-costs-" + std::to_string(::getpid());
        std::filesystem::create_directories(dir);
        const std::string renderer = "OpenGL 3+ Rendering Subsystem | llvmpipe (LLVM 15.0.6, 256 bits) | 4.5.0.0";
        const std::string other = "OpenGL 3+ Rendering Subsystem | NVIDIA H200/PCIe/SSE2 | 4.6.0.0";
        EXPECT_NE(costCalibrationPath(dir, renderer), costCalibrationPath(dir, other));

        CostCalibration calibration;
        calibration.renderer = renderer;
        calibration.assets["0123456789abcdef"] = {cost("lodf", 1200, {0.5f, 1.0f, 4.0f}), cost("impostor", 0, {0.0f, 0.01f, 0.1f})};
        const std::string path = costCalibrationPath(dir, renderer);
        ASSERT_TRUE(writeCostCalibration(path, calibration));
        Result<CostCalibration> read = readCostCalibration(path, renderer);
        ASSERT_TRUE(read) << read.error().message();
        const std::vector<LevelCost>* levels = read->find("0123456789abcdef");
        ASSERT_NE(levels, nullptr);
        ASSERT_EQ(levels->size(), 2u);
        EXPECT_EQ(findLevelCost(*levels, "lodf", 1200, false), 0);
        EXPECT_EQ((*levels)[0].msPerTree, (std::vector<float>{0.5f, 1.0f, 4.0f}));
        EXPECT_EQ(read->find("fedcba9876543210"), nullptr);

        // The same file read for another renderer (copied, renamed by hand): refused, naming both.
        Result<CostCalibration> foreign = readCostCalibration(path, other);
        ASSERT_FALSE(foreign);
        EXPECT_NE(foreign.error().message().find(path), std::string::npos);
        EXPECT_NE(foreign.error().message().find("NVIDIA"), std::string::npos) << foreign.error().message();

        // Damaged files: errors naming the file and the element.
        const std::string bad = dir + "/bad.json";
        for (const std::string& text :
             {std::string("not json"), std::string(R"({"renderer": "r", "version": 1, "assets": {"k": [{"technique": "lodf", "level": 1, "heightsPx": [16, 8], "msPerTree": [1, 2]}]}})"),
              std::string(R"({"renderer": "r", "version": 1, "assets": {"k": [{"technique": "lodf", "level": 1, "heightsPx": [16], "msPerTree": [-1]}]}})"),
              std::string(R"({"renderer": "r", "version": 9, "assets": {}})")})
        {
            ASSERT_TRUE(writeFileAtomic(bad, std::vector<std::uint8_t>(text.begin(), text.end())));
            Result<CostCalibration> r = readCostCalibration(bad, "r");
            ASSERT_FALSE(r) << text;
            EXPECT_NE(r.error().message().find(bad), std::string::npos) << r.error().message();
        }
        std::filesystem::remove_all(dir);
    }

    TEST(LevelCosts, textureSamplingDecidesDecodingAtLoadAndRoundTripsThroughTheFile)
    {
        // llvmpipe-like: compressed sampling 1.8x the decoded one decodes at load; a GPU's (equal, or
        // compressed faster) does not; within the margin (1.05x) neither noise nor rounding decodes.
        TextureSamplingCost software{9.0, 5.0};
        EXPECT_TRUE(software.decodeAtLoad());
        EXPECT_FALSE((TextureSamplingCost{1.0, 1.0}).decodeAtLoad());
        EXPECT_FALSE((TextureSamplingCost{0.8, 1.0}).decodeAtLoad());
        EXPECT_FALSE((TextureSamplingCost{1.05, 1.0}).decodeAtLoad());
        EXPECT_TRUE((TextureSamplingCost{1.2, 1.0}).decodeAtLoad());
        EXPECT_FALSE((TextureSamplingCost{0.0, 0.0}).decodeAtLoad()) << "nothing measured: as stored";

        const std::string dir = testing::TempDir() + "/treelod-sampling-" + std::to_string(::getpid());
        std::filesystem::create_directories(dir);
        const std::string path = costCalibrationPath(dir, "r");
        CostCalibration calibration;
        calibration.renderer = "r";
        ASSERT_TRUE(writeCostCalibration(path, calibration));
        Result<CostCalibration> read = readCostCalibration(path, "r");
        ASSERT_TRUE(read) << read.error().message();
        EXPECT_FALSE(read->hasTextureSampling) << "a file without it is measured again";
        calibration.hasTextureSampling = true;
        calibration.textureSampling = software;
        ASSERT_TRUE(writeCostCalibration(path, calibration));
        read = readCostCalibration(path, "r");
        ASSERT_TRUE(read) << read.error().message();
        ASSERT_TRUE(read->hasTextureSampling);
        EXPECT_DOUBLE_EQ(read->textureSampling.compressedMs, 9.0);
        EXPECT_DOUBLE_EQ(read->textureSampling.decodedMs, 5.0);
        EXPECT_TRUE(read->textureSampling.decodeAtLoad());

        for (const std::string& text :
             {std::string(R"({"renderer": "r", "version": 1, "assets": {}, "textureSampling": {"compressedMs": 1}})"),
              std::string(R"({"renderer": "r", "version": 1, "assets": {}, "textureSampling": {"compressedMs": -1, "decodedMs": 1}})"),
              std::string(R"({"renderer": "r", "version": 1, "assets": {}, "textureSampling": 3})")})
        {
            ASSERT_TRUE(writeFileAtomic(path, std::vector<std::uint8_t>(text.begin(), text.end())));
            Result<CostCalibration> r = readCostCalibration(path, "r");
            ASSERT_FALSE(r) << text;
            EXPECT_NE(r.error().message().find(path), std::string::npos) << r.error().message();
            EXPECT_NE(r.error().message().find("textureSampling"), std::string::npos) << r.error().message();
        }
        std::filesystem::remove_all(dir);
    }
}
