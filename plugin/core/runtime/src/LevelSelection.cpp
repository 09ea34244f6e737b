#include "TreeLod/LevelSelection.h"

#include <cmath>
#include <limits>

namespace TreeLod
{
    Result<std::vector<LevelChoice>> chooseLevels(const ErrorCurves& curves, const std::vector<LevelCost>& costs,
                                                  float errorBudget, std::size_t maxRuns)
    {
        if (!(std::isfinite(errorBudget) && errorBudget >= 0.0f && errorBudget <= 1.0f))
            return fail("", "error budget", std::to_string(errorBudget) + " is not a number in [0, 1]");
        if (maxRuns == 0)
            return fail("", "error budget", "no level may be used (maxRuns 0)");
        const int reference = curves.find(LEVEL_SELECTION_REFERENCE, 0, false);
        if (reference < 0)
            return fail("", "error curves", std::string("no curve of the reference '") + LEVEL_SELECTION_REFERENCE + "'");

        // Each curve level's cost, or null (not a candidate; the reference stays allowed).
        std::vector<const LevelCost*> costOf(curves.levels.size(), nullptr);
        bool anyCost = false;
        for (std::size_t l = 0; l < curves.levels.size(); ++l)
        {
            const ErrorCurveLevel& level = curves.levels[l];
            const int c = findLevelCost(costs, level.technique, level.techniqueLevel, level.lowRes);
            if (c >= 0)
            {
                costOf[l] = &costs[std::size_t(c)];
                anyCost = true;
            }
        }
        if (!anyCost)
            return fail("", "level costs", "no level of the error curves has a calibrated cost");

        struct Run
        {
            std::size_t level = 0;
            std::size_t samples = 0;
            float lowestHeight = 0.0f; ///< of its samples
            float flip = 0.0f;
        };
        std::vector<Run> runs;
        constexpr int SAMPLES_PER_OCTAVE = 4, OCTAVES = 13; // 8192 px down to 1 px
        for (int k = 0; k <= OCTAVES * SAMPLES_PER_OCTAVE; ++k)
        {
            const float h = std::exp2(float(OCTAVES) - float(k) / SAMPLES_PER_OCTAVE);
            const float allowed = curves.flipAt(std::size_t(reference), h) + errorBudget;
            std::size_t best = std::size_t(reference);
            float bestCost = costOf[best] ? costOf[best]->msAt(h) : std::numeric_limits<float>::infinity();
            float bestFlip = curves.flipAt(best, h);
            if (errorBudget > 0.0f)
                for (std::size_t l = 0; l < curves.levels.size(); ++l)
                {
                    if (!costOf[l] || l == std::size_t(reference))
                        continue;
                    const float flip = curves.flipAt(l, h);
                    const float cost = costOf[l]->msAt(h);
                    if (flip <= allowed && (cost < bestCost || (cost == bestCost && flip < bestFlip)))
                    {
                        best = l;
                        bestCost = cost;
                        bestFlip = flip;
                    }
                }
            if (runs.empty() || runs.back().level != best)
                runs.push_back(Run{best, 0, h, 0.0f});
            Run& run = runs.back();
            ++run.samples;
            run.lowestHeight = h;
            run.flip = std::max(run.flip, bestFlip);
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
            for (int k = 0; k <= OCTAVES * SAMPLES_PER_OCTAVE; ++k) // its error over the heights it gains
            {
                const float h = std::exp2(float(OCTAVES) - float(k) / SAMPLES_PER_OCTAVE);
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
}
