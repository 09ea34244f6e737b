// FrameBudgetController: the error budget under a frame budget, stepped along frameBudgetLadder()
// from measured predictions and reported frame times, without a GPU.
#include "TreeLod/FrameBudgetController.h"
#include "TreeLod/LevelSelection.h"

#include <gtest/gtest.h>

#include <cmath>

namespace TreeLod
{
    namespace
    {
        /// Predicted ms per ladder step: `finest` at step 0, halving each step (coarser is cheaper).
        std::vector<double> halving(double finest)
        {
            std::vector<double> ms;
            for (std::size_t s = 0; s < frameBudgetLadder().size(); ++s)
                ms.push_back(finest / std::pow(2.0, double(s)));
            return ms;
        }

        std::size_t stepOf(float budget) { return FrameBudgetController::ladderStepOf(budget); }
    }

    TEST(FrameBudgetController, withoutAFrameBudgetTheUsersBudgetHolds)
    {
        FrameBudgetController c(DEFAULT_ERROR_BUDGET);
        EXPECT_EQ(c.getErrorBudget(), DEFAULT_ERROR_BUDGET);
        c.setErrorBudget(0.02f);
        EXPECT_EQ(c.getErrorBudget(), 0.02f);
        EXPECT_EQ(c.getUserErrorBudget(), 0.02f);
        c.notifyFrameTime(100.0f); // ignored: no frame budget
        c.measure(halving(1000.0));
        EXPECT_TRUE(std::isnan(c.getPendingErrorBudget())) << "no frame budget: nothing to apply";
        EXPECT_EQ(c.getFrameTimeRatio(), 1.0);
    }

    TEST(FrameBudgetController, choosesTheFinestStepWithinTheBudgetAndAppliesItOnCommit)
    {
        FrameBudgetController c(0.04f);
        EXPECT_FALSE(c.setFrameBudgetMs(20.0f));
        // 1000 ms at the reference, halving per step: 15.6 ms at step 6 is the first within 20 ms.
        const double inUse = c.measure(halving(1000.0));
        EXPECT_DOUBLE_EQ(inUse, 1000.0 / std::pow(2.0, double(stepOf(0.04f)))) << "the prediction for the step in use";
        const float pending = c.getPendingErrorBudget();
        EXPECT_EQ(pending, frameBudgetLadder()[6]);
        EXPECT_EQ(c.getErrorBudget(), 0.04f) << "nothing changes until the plan is made";
        c.setErrorBudgetInUse(pending);
        c.commitPending(true);
        EXPECT_EQ(c.getErrorBudget(), frameBudgetLadder()[6]);
        EXPECT_TRUE(std::isnan(c.getPendingErrorBudget()));

        // Finer only with margin: step 5 predicted at 0.9 x the budget stays coarse (hysteresis 0.85).
        std::vector<double> near = halving(1000.0);
        near[5] = 0.9 * 20.0;
        c.measure(near);
        EXPECT_TRUE(std::isnan(c.getPendingErrorBudget())) << "within the budget but not within its margin";
        near[5] = 0.8 * 20.0;
        c.measure(near);
        EXPECT_EQ(c.getPendingErrorBudget(), frameBudgetLadder()[5]);

        // Planning failed: the step in use stays and nothing is pending.
        c.commitPending(false);
        EXPECT_TRUE(std::isnan(c.getPendingErrorBudget()));
        EXPECT_EQ(c.getErrorBudget(), frameBudgetLadder()[6]);
    }

    TEST(FrameBudgetController, reportedFramesScaleThePredictionRisingAtOnceFallingSlowly)
    {
        FrameBudgetController c(0.04f);
        c.setFrameBudgetMs(20.0f);
        const std::vector<double> model = halving(1000.0);
        c.measure(model); // plans step 6: 15.625 ms predicted
        c.setErrorBudgetInUse(c.getPendingErrorBudget());
        c.commitPending(true);
        for (int f = 0; f < 4; ++f)
            c.notifyFrameTime(31.25f); // twice the prediction
        c.notifyFrameTime(std::nanf(""));  // ignored
        c.notifyFrameTime(-1.0f);          // ignored
        c.measure(model);
        EXPECT_DOUBLE_EQ(c.getFrameTimeRatio(), 2.0) << "a slower frame raises the ratio at once";
        EXPECT_EQ(c.getPendingErrorBudget(), frameBudgetLadder()[7]) << "twice as slow: one step coarser";
        c.setErrorBudgetInUse(c.getPendingErrorBudget());
        c.commitPending(true);

        // Frames at the unscaled prediction of step 7 (7.8125 ms): measured / predicted = 1; the
        // ratio falls a quarter of the way, to 1.75.
        c.notifyFrameTime(7.8125f);
        c.measure(model);
        EXPECT_DOUBLE_EQ(c.getFrameTimeRatio(), 1.75);
    }

    TEST(FrameBudgetController, switchingTheFrameBudgetOffAsksForTheUsersBudgetAgain)
    {
        FrameBudgetController c(0.02f);
        c.setFrameBudgetMs(10.0f);
        c.measure(halving(1000.0));
        c.setErrorBudgetInUse(c.getPendingErrorBudget());
        c.commitPending(true);
        EXPECT_NE(c.getErrorBudget(), 0.02f);
        EXPECT_TRUE(c.setFrameBudgetMs(0.0f)) << "off: plan the user's budget again";
        EXPECT_FALSE(c.isActive());
        EXPECT_EQ(c.getUserErrorBudget(), 0.02f);
        EXPECT_FALSE(c.setFrameBudgetMs(0.0f)) << "already off";
        EXPECT_EQ(c.getFrameTimeRatio(), 1.0) << "the model starts afresh";
    }

    TEST(FrameBudgetController, aBudgetOffTheLadderTakesTheFirstChoiceAndViewerFramesCountByInterval)
    {
        FrameBudgetController c(0.033f);
        EXPECT_EQ(FrameBudgetController::ladderStepOf(0.033f), FrameBudgetController::OFF_LADDER);
        c.setFrameBudgetMs(1e6f);
        c.measure(halving(1000.0));
        EXPECT_EQ(c.getPendingErrorBudget(), 0.0f) << "everything fits: the reference";

        unsigned measured = 0;
        for (int f = 0; f < 24; ++f)
            measured += c.countViewerFrame(8);
        EXPECT_EQ(measured, 3u);
    }
}
