#include "TreeLod/FrameBudgetController.h"

#include "TreeLod/LevelSelection.h"

#include <algorithm>
#include <cmath>

namespace TreeLod
{
    FrameBudgetController::FrameBudgetController(float errorBudget)
        : mErrorBudget(errorBudget), mUserErrorBudget(errorBudget), mStep(ladderStepOf(errorBudget)), mWantedStep(mStep)
    {
    }

    std::size_t FrameBudgetController::ladderStepOf(float budget)
    {
        const std::vector<float>& ladder = frameBudgetLadder();
        const auto step = std::find(ladder.begin(), ladder.end(), budget);
        return step == ladder.end() ? OFF_LADDER : std::size_t(step - ladder.begin());
    }

    void FrameBudgetController::setErrorBudget(float budget)
    {
        mErrorBudget = mUserErrorBudget = budget;
        mStep = mWantedStep = ladderStepOf(budget);
    }

    bool FrameBudgetController::setFrameBudgetMs(float milliseconds)
    {
        const bool off = milliseconds == 0.0f && isActive();
        mFrameBudgetMs = milliseconds;
        mStep = mWantedStep = ladderStepOf(mErrorBudget);
        mViewerFrames = 0;
        mFrameTimeRatio = 1.0;
        mReportedMs = 0.0;
        mReportedFrames = 0;
        mPlanPredictedMs = 0.0;
        return off;
    }

    void FrameBudgetController::notifyFrameTime(float milliseconds)
    {
        if (isActive() && std::isfinite(milliseconds) && milliseconds > 0.0f)
        {
            mReportedMs += double(milliseconds);
            ++mReportedFrames;
        }
    }

    double FrameBudgetController::measure(std::vector<double> predictedMs)
    {
        if (predictedMs.empty())
            return 0.0;
        if (mReportedFrames > 0 && mPlanPredictedMs > 0.0)
        {
            const double ratio = std::clamp(mReportedMs / mReportedFrames / mPlanPredictedMs, 0.1, 10.0);
            mFrameTimeRatio = ratio > mFrameTimeRatio ? ratio : mFrameTimeRatio + 0.25 * (ratio - mFrameTimeRatio);
        }
        mReportedMs = 0.0;
        mReportedFrames = 0;
        for (double& ms : predictedMs)
            ms *= mFrameTimeRatio;
        const double inUse = predictedMs[std::min(mStep, predictedMs.size() - 1)];
        mWantedStep = chooseFrameBudgetStep(predictedMs, double(mFrameBudgetMs), mStep);
        mPlanPredictedMs = predictedMs[mWantedStep] / mFrameTimeRatio;
        return inUse;
    }

    float FrameBudgetController::getPendingErrorBudget() const
    {
        if (!isActive() || mWantedStep == mStep || mWantedStep == OFF_LADDER)
            return std::numeric_limits<float>::quiet_NaN();
        return frameBudgetLadder()[mWantedStep];
    }

    void FrameBudgetController::commitPending(bool applied)
    {
        if (applied)
            mStep = mWantedStep;
        else
            mWantedStep = mStep;
    }
}
