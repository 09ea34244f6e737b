// FrameBudgetController: the error budget a Forest plans its budgeted species with, in one place:
// the budget the user set (setErrorBudget), the one in use, and what a frame budget makes of it.
// Under a frame budget the Forest measures, every few viewer frames, the predicted cost of the
// visible trees at each step of frameBudgetLadder() (LevelSelection.h). The controller scales the
// prediction by the frame times reported since the last measurement (measured / predicted, within
// [0.1, 10]: it rises at once, so frames over the model go coarser in the next plan, and falls a
// quarter of the way to each lower ratio) and picks the finest step within the budget, with
// chooseFrameBudgetStep's hysteresis. The Forest applies that step before its next viewer frame
// culls. No Ogre: tested without a GPU.
#pragma once

#include <cstddef>
#include <limits>
#include <vector>

namespace TreeLod
{
    class FrameBudgetController
    {
    public:
        /// The ladder step of a budget that is none of the ladder's: the first measurement takes
        /// whatever step it chooses.
        static constexpr std::size_t OFF_LADDER = std::numeric_limits<std::size_t>::max();

        explicit FrameBudgetController(float errorBudget);

        /// The user's budget (mean FLIP, [0, 1], checked by the caller): in use from now, and the
        /// step a frame budget starts from.
        void setErrorBudget(float budget);
        /// The budget the plan uses now (the user's, or a ladder step under a frame budget).
        float getErrorBudget() const { return mErrorBudget; }
        float getUserErrorBudget() const { return mUserErrorBudget; }
        /// Record that the plan now uses `budget` (the Forest replanned with it).
        void setErrorBudgetInUse(float budget) { mErrorBudget = budget; }

        /// Milliseconds per frame, >= 0 (0: none; checked by the caller). Starts the model afresh.
        /// True when this switched a frame budget off: the user's budget should be planned again.
        bool setFrameBudgetMs(float milliseconds);
        float getFrameBudgetMs() const { return mFrameBudgetMs; }
        bool isActive() const { return mFrameBudgetMs > 0.0f; }

        /// A frame's time as the application measured it (ignored without a frame budget, or when
        /// not finite and positive).
        void notifyFrameTime(float milliseconds);
        /// Counts a viewer frame: true every `interval`-th (the first included), when the Forest
        /// measures.
        bool countViewerFrame(unsigned interval) { return mViewerFrames++ % interval == 0; }
        /// A measurement: the model's predicted milliseconds per ladder step (finest first).
        /// Returns the scaled prediction for the step in use (ForestStats::predictedMilliseconds).
        double measure(std::vector<double> predictedMs);

        /// The ladder budget the last measurement chose, when it differs from the one in use; NaN
        /// when there is nothing to apply.
        float getPendingErrorBudget() const;
        /// The pending budget was planned (`applied`) or planning it failed (the step in use stays).
        void commitPending(bool applied);

        /// measured / predicted frame time, the scale of the model's predictions.
        double getFrameTimeRatio() const { return mFrameTimeRatio; }

        /// The frameBudgetLadder() step that is `budget`, or OFF_LADDER.
        static std::size_t ladderStepOf(float budget);

    private:
        float mErrorBudget;
        float mUserErrorBudget;
        float mFrameBudgetMs = 0.0f;
        std::size_t mStep;       ///< frameBudgetLadder() step in use, or OFF_LADDER
        std::size_t mWantedStep; ///< the last measurement's choice
        unsigned mViewerFrames = 0;
        double mFrameTimeRatio = 1.0;
        double mReportedMs = 0.0; ///< frame times reported since the last measurement
        unsigned mReportedFrames = 0;
        double mPlanPredictedMs = 0.0; ///< the unscaled prediction for the plan those frames drew
    };
}
