// LevelSelection: each tree's level chosen from two measured things (docs/forest.md, "Budgeted
// levels"): the asset's error curves (ErrorCurves.h, baked) and the levels' costs on this
// machine (LevelCosts.h, calibrated). For an error budget e, at each screen height h the levels
// whose error is within e of the polygonal reference's own error at h are allowed:
//     allowed(L, h)  <=>  flip(L, h) <= flip(mesh, h) + e        (mesh always allowed)
//                    and  flipMax(L, h) <= flipMax(mesh, h) + WORST_VIEW_BUDGET_FACTOR e
// at 4 heights per octave from 1 to 8192 px. Each run boundary of the plan is a switch a
// moving tree shows (a pop), so among the allowed levels that cost less than (1 + costSlack)
// times the cheapest at each sample, the plan is the sequence near to far whose switches show
// least: the sum over switches of the measured FLIP between the two levels at the switch height
// (ErrorCurves::switchFlipAt; flip(a) + flip(b) where the curves have none) plus
// LEVEL_SWITCH_PENALTY, so fewer switches win; ties go to the smaller summed cost. A shortest
// path over the samples (the Viterbi algorithm: Viterbi 1967, IEEE Trans. Inf. Theory 13(2));
// with a slack of 0, the cheapest allowed level at each sample.
// The result is merged into runs of one level: near to far, each with the smallest height it is
// drawn at. A budget of 0 draws the reference itself; a budget of 1 the cheapest level (within
// the slack) everywhere.
// A level without a cost is not a candidate.
// Shadow casters (chooseShadowLevels) get their own, coarser budget: each run's casters draw the
// cheapest of its level and the coarser runs' levels within that budget over the run's heights.
// A memory budget (chooseLevelsWithinMemory) bounds the GPU bytes of the levels the plans of all
// budgeted species hold (ErrorCurves::gpuBytes, measured with the curves): while the plans hold
// more, the level whose exclusion saves most bytes is taken out of its species' candidates, first
// among those whose exclusion keeps the error budget (most bytes per millisecond the plan adds),
// then among the others (most bytes per FLIP over the budget added). Where every way out draws a
// larger level instead, the plan is built up from the smallest one (each species' level of fewest
// bytes alone), adding the level that removes most FLIP over the error budget (then most cost)
// per byte while the bytes fit. A greedy search, not an optimum: the plan says which budget bound.
// A frame budget (chooseFrameBudgetStep) picks the finest error budget of a ladder whose plans'
// predicted cost, the visible trees counted by height (HeightHistogram) times each level's
// LevelCost::msAt, fits: a model of this machine's calibrated costs, not a timer.
#pragma once

#include "TreeLod/ErrorCurves.h"
#include "TreeLod/LevelCosts.h"
#include "TreeLod/Result.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace TreeLod
{
    /// The technique whose curve is the floor of every budget (TechniqueRegistry's REFERENCE_TECHNIQUE).
    constexpr const char* LEVEL_SELECTION_REFERENCE = "mesh";

    /// The error budget the Forest starts with (Forest::setErrorBudget, scene scripts' "lod" maxError):
    /// the FLIP a level may add over the polygonal tree's own, per pixel of the tree (ErrorCurves.h).
    /// A scene's mean over the frame adds less (sky, ground, trees hidden behind trees): at 0.04 the
    /// three benchmark scenes stay within the project's margin of 0.02 (docs/measurements.md,
    /// "Budgeted auto").
    constexpr float DEFAULT_ERROR_BUDGET = 0.04f;
    /// What the project holds auto to over a whole frame: its mean FLIP against the supersampled
    /// reference at most the polygonal tree's own (one sample a pixel) plus this. The bench reports
    /// the error a run uses against it (bench.md, "Error used").
    constexpr float SCENE_ERROR_MARGIN = 0.02f;
    /// A level's worst view (the view from above among them) may add at most this many times the
    /// budget over the reference's worst view: the mean is over the side views, and a level that
    /// fails from above (a camera-facing quad seen from 30-40 degrees up) loses in a scene seen
    /// from above though its side views are within the budget.
    constexpr float WORST_VIEW_BUDGET_FACTOR = 4.0f;
    /// The shadow casters' error budget the Forest starts with (Forest::setShadowErrorBudget): coarser
    /// than the view's, as a shadow shows a tree's outline blurred and from one side (four times it,
    /// as when both were measured over a square about half background).
    constexpr float DEFAULT_SHADOW_ERROR_BUDGET = 0.16f;

    /// The cost a plan may add at a height to draw fewer or smaller switches (chooseLevels): a tenth
    /// of the cheapest allowed level's. Within what the costs can tell apart: they are a model
    /// (on llvmpipe it predicts 2.2x the measured time, docs/forest.md) and two runs of one bench
    /// differ by up to 20 % in median frame time (docs/measurements.md, "Transitions").
    constexpr float LEVEL_SWITCH_COST_SLACK = 0.1f;
    /// What a switch counts besides the FLIP it shows: between plans whose switches show as much,
    /// the one with fewer switches wins; small against a switch between different levels (0.07 and
    /// more between two levels of the test oak, docs/measurements.md "Error curves at bake time").
    constexpr float LEVEL_SWITCH_PENALTY = 0.01f;

    /// The heights the selection samples: 4 per octave from 8192 px (sample 0) down to 1 px.
    constexpr int SELECTION_SAMPLES_PER_OCTAVE = 4;
    constexpr int SELECTION_OCTAVES = 13;
    constexpr std::size_t SELECTION_SAMPLES = SELECTION_OCTAVES * SELECTION_SAMPLES_PER_OCTAVE + 1;
    /// Height of sample k (< SELECTION_SAMPLES), pixels.
    float selectionHeight(std::size_t k);
    /// The sample nearest `heightPx` in log2 (clamped to the range; non-finite or <= 0: the last).
    std::size_t selectionSample(float heightPx);

    /// One run of the selection: curves.levels[curveLevel] while the tree is >= minHeightPx tall.
    struct LevelChoice
    {
        std::size_t curveLevel = 0;
        float minHeightPx = 0.0f; ///< the last run's is 0
        float flip = 0.0f;        ///< the curve's largest FLIP over the run's sampled heights
        /// False where, at some sampled height of the run, no level left allowed the error budget
        /// (chooseLevels' `excluded` took them) and the run draws the least FLIP there instead.
        bool withinBudget = true;
    };

    /// Runs near to far, at most `maxRuns` (the shortest runs, counted in samples, are merged into
    /// the finer neighbour until they fit); `costSlack` as above (0: the cheapest level at each
    /// sample). `excluded` (one flag per curve level; shorter: the rest kept) takes levels out,
    /// the reference too: where no level left is allowed, the one with the least FLIP is drawn
    /// (LevelChoice::withinBudget false). Errors: a budget that is not finite or not in [0, 1];
    /// a slack that is not finite or below 0; curves without the reference level or with no
    /// level that has a cost; every level with a cost excluded.
    Result<std::vector<LevelChoice>> chooseLevels(const ErrorCurves& curves, const std::vector<LevelCost>& costs,
                                                  float errorBudget, std::size_t maxRuns = 16,
                                                  float costSlack = LEVEL_SWITCH_COST_SLACK,
                                                  const std::vector<bool>& excluded = {});

    /// The run of `choices` drawn at `heightPx` (the first whose minHeightPx it reaches).
    std::size_t choiceAt(const std::vector<LevelChoice>& choices, float heightPx);

    /// Occlusion (ForestOcclusion.h): a tree of which only the share `visibility` is visible adds that
    /// share of its level's error to the frame, so its plan may spend errorBudget / visibility. The
    /// factor s <= 1 on its height on screen that spends it with the levels of `choices` (planned for
    /// `errorBudget`): the smallest s = 2^(-k / SELECTION_SAMPLES_PER_OCTAVE), k at most
    /// `maxOctaves` octaves, such that for every k' <= k and every sample height h the level the plan
    /// draws at h s is allowed at h for min(1, errorBudget / visibility) (chooseLevels' test), or is
    /// no worse there than the level it draws at h. 1 for a visibility of 1 (or more), curves without
    /// the reference, a budget that is not in [0, 1] or a visibility that is not > 0.
    float occlusionHeightScale(const ErrorCurves& curves, const std::vector<LevelChoice>& choices, float errorBudget,
                               float visibility, int maxOctaves = 5);

    /// One species of a memory plan (chooseLevelsWithinMemory).
    struct MemoryPlanSpecies
    {
        const ErrorCurves* curves = nullptr;          ///< with GPU bytes (ErrorCurves::hasGpuBytes)
        const std::vector<LevelCost>* costs = nullptr;
        /// Trees at each selection sample (HeightHistogram::counts), weighing where the plan's added
        /// cost and error count; empty or all 0: every sample alike.
        std::vector<std::uint32_t> weights;
        /// Species with one key draw one asset's resources: its bytes are counted once for them.
        const void* resourceKey = nullptr;
    };

    struct MemoryPlan
    {
        std::vector<std::vector<LevelChoice>> choices; ///< per species, as chooseLevels
        std::vector<std::vector<bool>> excluded;       ///< per species, per curve level: taken out
        std::uint64_t gpuBytes = 0;                    ///< of the plans' levels
        bool memoryBinds = false;      ///< levels were excluded to fit the memory budget
        bool withinErrorBudget = true; ///< every run of every plan within the error budget
    };

    /// The plans of `species` within `errorBudget` whose levels hold at most `memoryBudget` GPU
    /// bytes (0: no limit), as above. Errors: chooseLevels'; a species without curves, costs or
    /// measured GPU bytes (under a memory budget); a memory budget below the smallest plan, naming
    /// the budget and that plan (each species' level with the fewest bytes).
    Result<MemoryPlan> chooseLevelsWithinMemory(const std::vector<MemoryPlanSpecies>& species, float errorBudget,
                                                std::uint64_t memoryBudget, std::size_t maxRuns = 16);

    /// GPU bytes of the levels of `plans` (one per species of `species`), each resource once per key.
    std::uint64_t planGpuBytes(const std::vector<MemoryPlanSpecies>& species,
                               const std::vector<std::vector<LevelChoice>>& plans);

    /// Shadow casters' levels: for each run r of `choices`, the index (>= r) of the run whose level
    /// its casters draw: the cheapest over run r's sampled heights among run r's own level and the
    /// coarser runs' levels whose FLIP stays within `shadowBudget` of the reference's at every one
    /// of those heights (run r's own when none is cheaper). Errors as chooseLevels.
    Result<std::vector<std::size_t>> chooseShadowLevels(const ErrorCurves& curves, const std::vector<LevelCost>& costs,
                                                        const std::vector<LevelChoice>& choices, float shadowBudget);

    /// Milliseconds per tree a plan costs at each selection sample height: the cost of the level
    /// `choices` draws there (LevelCost::msAt; 0 for a level without a cost). With level
    /// transitions of length `transition` (ForestInstances.h, "Transitions") a tree within 1 + t of
    /// a run's smallest height also draws the next run's level: each sample adds that level's cost
    /// times the share of its bin (a quarter octave about it) the band covers; runs whose smallest
    /// height is below `transitionMinHeightPx` switch hard (Forest::setLodTransition).
    std::vector<float> planCostPerTree(const ErrorCurves& curves, const std::vector<LevelCost>& costs,
                                       const std::vector<LevelChoice>& choices, float transition = 0.0f,
                                       float transitionMinHeightPx = 0.0f);

    /// Visible trees of one species counted by height on screen, at the nearest selection sample.
    struct HeightHistogram
    {
        std::vector<std::uint32_t> counts = std::vector<std::uint32_t>(SELECTION_SAMPLES, 0u);
        void add(float heightPx) { ++counts[selectionSample(heightPx)]; }
        void clear() { std::fill(counts.begin(), counts.end(), 0u); }
        /// Sum of count x msPerTree (planCostPerTree's).
        double milliseconds(const std::vector<float>& msPerTree) const;
    };

    /// The error budgets a frame budget chooses among, finest first (0: the reference).
    const std::vector<float>& frameBudgetLadder();

    /// The step of the ladder a frame budget takes, from `predictedMs` (one per step, finest first)
    /// and the step in use: the finest step predicted within `frameBudgetMs`; but a step finer than
    /// `current` only where it is predicted within `finerMargin` x the budget (hysteresis: a frame
    /// near the budget does not flip between two steps). The coarsest step when none fits.
    std::size_t chooseFrameBudgetStep(const std::vector<double>& predictedMs, double frameBudgetMs,
                                      std::size_t current, double finerMargin = 0.85);
}
