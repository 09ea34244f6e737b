#include "TreeLod/LevelSelection.h"

#include <cmath>
#include <limits>

namespace TreeLod
{
    float selectionHeight(std::size_t k)
    {
        return std::exp2(float(SELECTION_OCTAVES) - float(k) / SELECTION_SAMPLES_PER_OCTAVE);
    }

    std::size_t selectionSample(float heightPx)
    {
        if (!(heightPx > 0.0f) || !std::isfinite(heightPx))
            return heightPx == std::numeric_limits<float>::infinity() ? 0 : SELECTION_SAMPLES - 1;
        const float k = std::round((float(SELECTION_OCTAVES) - std::log2(heightPx)) * SELECTION_SAMPLES_PER_OCTAVE);
        return std::size_t(std::clamp(k, 0.0f, float(SELECTION_SAMPLES - 1)));
    }

    namespace
    {
        /// Each curve level's cost, or null.
        std::vector<const LevelCost*> costsOf(const ErrorCurves& curves, const std::vector<LevelCost>& costs)
        {
            std::vector<const LevelCost*> costOf(curves.levels.size(), nullptr);
            for (std::size_t l = 0; l < curves.levels.size(); ++l)
            {
                const ErrorCurveLevel& level = curves.levels[l];
                const int c = findLevelCost(costs, level.technique, level.techniqueLevel, level.lowRes);
                if (c >= 0)
                    costOf[l] = &costs[std::size_t(c)];
            }
            return costOf;
        }

        Result<int> checkBudget(const ErrorCurves& curves, float budget, const char* what)
        {
            if (!(std::isfinite(budget) && budget >= 0.0f && budget <= 1.0f))
                return fail("", what, std::to_string(budget) + " is not a number in [0, 1]");
            const int reference = curves.find(LEVEL_SELECTION_REFERENCE, 0, false);
            if (reference < 0)
                return fail("", "error curves",
                            std::string("no curve of the reference '") + LEVEL_SELECTION_REFERENCE + "'");
            return reference;
        }
    }

    Result<std::vector<LevelChoice>> chooseLevels(const ErrorCurves& curves, const std::vector<LevelCost>& costs,
                                                  float errorBudget, std::size_t maxRuns, float costSlack)
    {
        Result<int> reference = checkBudget(curves, errorBudget, "error budget");
        if (!reference)
            return reference.error();
        if (maxRuns == 0)
            return fail("", "error budget", "no level may be used (maxRuns 0)");
        if (!(std::isfinite(costSlack) && costSlack >= 0.0f))
            return fail("", "cost slack", std::to_string(costSlack) + " is not a finite number >= 0");

        // Each curve level's cost, or null (not a candidate; the reference stays allowed).
        const std::vector<const LevelCost*> costOf = costsOf(curves, costs);
        if (std::find_if(costOf.begin(), costOf.end(), [](const LevelCost* c) { return c != nullptr; }) == costOf.end())
            return fail("", "level costs", "no level of the error curves has a calibrated cost");

        // Per sample, the candidates: the cheapest allowed level (ties: the smaller FLIP) first,
        // then the other allowed levels that cost less than (1 + costSlack) times it.
        const std::size_t ref = std::size_t(*reference);
        auto msOf = [&](std::size_t l, float h) { return costOf[l] ? costOf[l]->msAt(h) : 0.0f; };
        std::vector<std::vector<std::size_t>> candidates(SELECTION_SAMPLES);
        for (std::size_t k = 0; k < SELECTION_SAMPLES; ++k)
        {
            const float h = selectionHeight(k);
            const float allowed = curves.flipAt(ref, h) + errorBudget;
            const float allowedWorst = curves.flipMaxAt(ref, h) + WORST_VIEW_BUDGET_FACTOR * errorBudget;
            auto isAllowed = [&](std::size_t l) {
                return l == ref ||
                       (costOf[l] && curves.flipAt(l, h) <= allowed && curves.flipMaxAt(l, h) <= allowedWorst);
            };
            std::size_t best = ref;
            float bestCost = costOf[best] ? costOf[best]->msAt(h) : std::numeric_limits<float>::infinity();
            float bestFlip = curves.flipAt(best, h);
            if (errorBudget > 0.0f)
                for (std::size_t l = 0; l < curves.levels.size(); ++l)
                {
                    if (l == ref || !isAllowed(l))
                        continue;
                    const float flip = curves.flipAt(l, h);
                    const float cost = costOf[l]->msAt(h);
                    if (cost < bestCost || (cost == bestCost && flip < bestFlip))
                    {
                        best = l;
                        bestCost = cost;
                        bestFlip = flip;
                    }
                }
            candidates[k].push_back(best);
            if (errorBudget > 0.0f && costSlack > 0.0f && std::isfinite(bestCost))
                for (std::size_t l = 0; l < curves.levels.size(); ++l)
                    if (l != best && costOf[l] && isAllowed(l) && costOf[l]->msAt(h) < (1.0f + costSlack) * bestCost)
                        candidates[k].push_back(l);
        }

        // The path near to far through the candidates whose switches show least (Viterbi): at a
        // switch between samples k - 1 and k, at the height halfway between them (the run
        // boundary), the switch FLIP of the two levels plus LEVEL_SWITCH_PENALTY; without
        // measured switch FLIP, flip(a) + flip(b), a conservative stand-in (each image is that far
        // from the reference's; every measured switch FLIP of the test oak is below it). Ties:
        // the smaller summed cost.
        auto switchCost = [&](std::size_t a, std::size_t b, float h) {
            const float shown = curves.hasSwitchFlip() ? curves.switchFlipAt(a, b, h)
                                                       : curves.flipAt(a, h) + curves.flipAt(b, h);
            return double(shown) + double(LEVEL_SWITCH_PENALTY);
        };
        struct Step
        {
            double switches = 0.0, ms = 0.0;
            std::size_t from = 0; ///< index into the previous sample's candidates
            bool better(const Step& other) const
            {
                return switches < other.switches || (switches == other.switches && ms < other.ms);
            }
        };
        std::vector<std::vector<Step>> steps(SELECTION_SAMPLES);
        constexpr int SAMPLES_PER_OCTAVE = SELECTION_SAMPLES_PER_OCTAVE;
        for (std::size_t k = 0; k < SELECTION_SAMPLES; ++k)
        {
            const float h = selectionHeight(k);
            const float boundary = h * std::exp2(0.5f / SAMPLES_PER_OCTAVE);
            for (const std::size_t b : candidates[k])
            {
                Step step{0.0, double(msOf(b, h)), 0};
                if (k > 0)
                {
                    step.switches = std::numeric_limits<double>::infinity();
                    for (std::size_t i = 0; i < candidates[k - 1].size(); ++i)
                    {
                        const std::size_t a = candidates[k - 1][i];
                        const Step& before = steps[k - 1][i];
                        const Step through{before.switches + (a == b ? 0.0 : switchCost(a, b, boundary)),
                                           before.ms + double(msOf(b, h)), i};
                        if (through.better(step))
                            step = through;
                    }
                }
                steps[k].push_back(step);
            }
        }
        std::vector<std::size_t> path(SELECTION_SAMPLES);
        std::size_t at = 0;
        for (std::size_t i = 1; i < steps.back().size(); ++i)
            if (steps.back()[i].better(steps.back()[at]))
                at = i;
        for (std::size_t k = SELECTION_SAMPLES; k-- > 0;)
        {
            path[k] = candidates[k][at];
            at = steps[k][at].from;
        }

        struct Run
        {
            std::size_t level = 0;
            std::size_t samples = 0;
            float lowestHeight = 0.0f; ///< of its samples
            float flip = 0.0f;
        };
        std::vector<Run> runs;
        for (std::size_t k = 0; k < SELECTION_SAMPLES; ++k)
        {
            const float h = selectionHeight(k);
            if (runs.empty() || runs.back().level != path[k])
                runs.push_back(Run{path[k], 0, h, 0.0f});
            Run& run = runs.back();
            ++run.samples;
            run.lowestHeight = h;
            run.flip = std::max(run.flip, curves.flipAt(path[k], h));
        }

        // Too many runs: the shortest joins its finer (nearer) neighbour.
        while (runs.size() > maxRuns)
        {
            std::size_t shortest = 0;
            for (std::size_t r = 1; r < runs.size(); ++r)
                if (runs[r].samples < runs[shortest].samples)
                    shortest = r;
            const std::size_t into = shortest == 0 ? 1 : shortest - 1;
            Run& keep = runs[into];
            const Run& gone = runs[shortest];
            keep.samples += gone.samples;
            keep.lowestHeight = std::min(keep.lowestHeight, gone.lowestHeight);
            for (std::size_t k = 0; k < SELECTION_SAMPLES; ++k) // its error over the heights it gains
            {
                const float h = selectionHeight(k);
                if (h >= gone.lowestHeight && h < gone.lowestHeight * std::exp2(float(gone.samples) / SAMPLES_PER_OCTAVE))
                    keep.flip = std::max(keep.flip, curves.flipAt(keep.level, h));
            }
            runs.erase(runs.begin() + std::ptrdiff_t(shortest));
            for (std::size_t r = 1; r < runs.size(); ++r) // neighbours of one level join
                if (runs[r].level == runs[r - 1].level)
                {
                    runs[r - 1].samples += runs[r].samples;
                    runs[r - 1].lowestHeight = runs[r].lowestHeight;
                    runs[r - 1].flip = std::max(runs[r - 1].flip, runs[r].flip);
                    runs.erase(runs.begin() + std::ptrdiff_t(r));
                    break;
                }
        }

        // A run is drawn down to halfway (in log height) to the next run's first sample.
        std::vector<LevelChoice> choices;
        for (std::size_t r = 0; r < runs.size(); ++r)
        {
            const bool last = r + 1 == runs.size();
            const float boundary = last ? 0.0f : runs[r].lowestHeight * std::exp2(-0.5f / SAMPLES_PER_OCTAVE);
            choices.push_back(LevelChoice{runs[r].level, boundary, runs[r].flip});
        }
        return choices;
    }

    std::size_t choiceAt(const std::vector<LevelChoice>& choices, float heightPx)
    {
        for (std::size_t r = 0; r < choices.size(); ++r)
            if (heightPx >= choices[r].minHeightPx)
                return r;
        return choices.empty() ? 0 : choices.size() - 1;
    }

    Result<std::vector<std::size_t>> chooseShadowLevels(const ErrorCurves& curves, const std::vector<LevelCost>& costs,
                                                        const std::vector<LevelChoice>& choices, float shadowBudget)
    {
        Result<int> reference = checkBudget(curves, shadowBudget, "shadow error budget");
        if (!reference)
            return reference.error();
        const std::vector<const LevelCost*> costOf = costsOf(curves, costs);
        for (const LevelChoice& choice : choices)
            if (choice.curveLevel >= curves.levels.size())
                return fail("", "level choices", "curve level " + std::to_string(choice.curveLevel) + " of " +
                                                     std::to_string(curves.levels.size()));
        std::vector<std::size_t> shadow(choices.size());
        for (std::size_t r = 0; r < choices.size(); ++r)
        {
            // Run r's sampled heights: those that choiceAt gives r for.
            std::vector<float> heights;
            for (std::size_t k = 0; k < SELECTION_SAMPLES; ++k)
                if (choiceAt(choices, selectionHeight(k)) == r)
                    heights.push_back(selectionHeight(k));
            shadow[r] = r;
            double bestCost = std::numeric_limits<double>::infinity();
            for (std::size_t c = r; c < choices.size(); ++c)
            {
                const std::size_t level = choices[c].curveLevel;
                const LevelCost* cost = costOf[level];
                if (!cost && c != r)
                    continue;
                double total = 0.0;
                bool within = true;
                for (const float h : heights)
                {
                    total += cost ? cost->msAt(h) : 0.0;
                    within &= curves.flipAt(level, h) <= curves.flipAt(std::size_t(*reference), h) + shadowBudget;
                }
                if ((c == r || within) && total < bestCost)
                {
                    shadow[r] = c;
                    bestCost = total;
                }
            }
        }
        return shadow;
    }

    std::vector<float> planCostPerTree(const ErrorCurves& curves, const std::vector<LevelCost>& costs,
                                       const std::vector<LevelChoice>& choices, float transition,
                                       float transitionMinHeightPx)
    {
        const std::vector<const LevelCost*> costOf = costsOf(curves, costs);
        auto msAt = [&](std::size_t level, float h) {
            return level < costOf.size() && costOf[level] ? costOf[level]->msAt(h) : 0.0f;
        };
        std::vector<float> ms(SELECTION_SAMPLES, 0.0f);
        if (choices.empty())
            return ms;
        constexpr double BIN = 1.0 / SELECTION_SAMPLES_PER_OCTAVE; // a sample's bin, octaves
        for (std::size_t k = 0; k < SELECTION_SAMPLES; ++k)
        {
            const float h = selectionHeight(k);
            ms[k] = msAt(choices[choiceAt(choices, h)].curveLevel, h);
            if (!(transition > 0.0f))
                continue;
            // The bands above each run's smallest height (at most the lower half of the run's
            // range, as ForestInstances::cull draws them), in octaves, against this sample's bin.
            const double lo = std::log2(double(h)) - 0.5 * BIN, hi = lo + BIN;
            for (std::size_t r = 0; r + 1 < choices.size(); ++r)
            {
                if (!(choices[r].minHeightPx > 0.0f) || choices[r].minHeightPx < transitionMinHeightPx)
                    continue;
                double length = std::log2(1.0 + double(transition));
                if (r > 0)
                    length = std::min(length, 0.5 * std::log2(double(choices[r - 1].minHeightPx) /
                                                               double(choices[r].minHeightPx)));
                const double start = std::log2(double(choices[r].minHeightPx));
                const double overlap = std::min(hi, start + length) - std::max(lo, start);
                if (overlap > 0.0)
                    ms[k] += float(overlap / BIN) * msAt(choices[r + 1].curveLevel, h);
            }
        }
        return ms;
    }

    double HeightHistogram::milliseconds(const std::vector<float>& msPerTree) const
    {
        double ms = 0.0;
        for (std::size_t k = 0; k < counts.size() && k < msPerTree.size(); ++k)
            ms += double(counts[k]) * double(msPerTree[k]);
        return ms;
    }

    const std::vector<float>& frameBudgetLadder()
    {
        static const std::vector<float> ladder{0.0f, 0.005f, 0.01f, 0.02f, 0.03f, 0.04f,
                                               0.05f, 0.08f, 0.12f, 0.2f, 0.35f, 1.0f};
        return ladder;
    }

    std::size_t chooseFrameBudgetStep(const std::vector<double>& predictedMs, double frameBudgetMs,
                                      std::size_t current, double finerMargin)
    {
        if (predictedMs.empty())
            return 0;
        current = std::min(current, predictedMs.size() - 1);
        for (std::size_t step = 0; step < predictedMs.size(); ++step)
        {
            const double limit = step < current ? finerMargin * frameBudgetMs : frameBudgetMs;
            if (predictedMs[step] <= limit)
                return step;
        }
        return predictedMs.size() - 1;
    }
}
