#include "TreeLod/LevelSelection.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <optional>
#include <set>

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
                                                  float errorBudget, std::size_t maxRuns, float costSlack,
                                                  const std::vector<bool>& excluded)
    {
        Result<int> reference = checkBudget(curves, errorBudget, "error budget");
        if (!reference)
            return reference.error();
        if (maxRuns == 0)
            return fail("", "error budget", "no level may be used (maxRuns 0)");
        if (!(std::isfinite(costSlack) && costSlack >= 0.0f))
            return fail("", "cost slack", std::to_string(costSlack) + " is not a finite number >= 0");

        // Each curve level's cost, or null (not a candidate; the reference stays allowed unless excluded).
        const std::vector<const LevelCost*> costOf = costsOf(curves, costs);
        if (std::find_if(costOf.begin(), costOf.end(), [](const LevelCost* c) { return c != nullptr; }) == costOf.end())
            return fail("", "level costs", "no level of the error curves has a calibrated cost");
        auto isExcluded = [&](std::size_t l) { return l < excluded.size() && excluded[l]; };

        // Per sample, the candidates: the cheapest allowed level (ties: the smaller FLIP) first,
        // then the other allowed levels that cost less than (1 + costSlack) times it. Where no
        // level left is allowed (the reference excluded), the one with the least FLIP, alone.
        const std::size_t ref = std::size_t(*reference);
        const bool referenceOpen = !isExcluded(ref);
        auto msOf = [&](std::size_t l, float h) { return costOf[l] ? costOf[l]->msAt(h) : 0.0f; };
        std::vector<std::vector<std::size_t>> candidates(SELECTION_SAMPLES);
        std::vector<bool> overBudget(SELECTION_SAMPLES, false);
        constexpr std::size_t NONE = std::numeric_limits<std::size_t>::max();
        for (std::size_t k = 0; k < SELECTION_SAMPLES; ++k)
        {
            const float h = selectionHeight(k);
            const float allowed = curves.flipAt(ref, h) + errorBudget;
            const float allowedWorst = curves.flipMaxAt(ref, h) + WORST_VIEW_BUDGET_FACTOR * errorBudget;
            auto isAllowed = [&](std::size_t l) {
                return !isExcluded(l) &&
                       (l == ref ||
                        (costOf[l] && curves.flipAt(l, h) <= allowed && curves.flipMaxAt(l, h) <= allowedWorst));
            };
            std::size_t best = NONE;
            float bestCost = std::numeric_limits<float>::infinity();
            float bestFlip = std::numeric_limits<float>::infinity();
            if (referenceOpen)
            {
                best = ref;
                bestCost = costOf[best] ? costOf[best]->msAt(h) : std::numeric_limits<float>::infinity();
                bestFlip = curves.flipAt(best, h);
            }
            if (errorBudget > 0.0f || !referenceOpen)
                for (std::size_t l = 0; l < curves.levels.size(); ++l)
                {
                    if (l == ref || !isAllowed(l))
                        continue;
                    const float flip = curves.flipAt(l, h);
                    const float cost = costOf[l]->msAt(h);
                    if (best == NONE || cost < bestCost || (cost == bestCost && flip < bestFlip))
                    {
                        best = l;
                        bestCost = cost;
                        bestFlip = flip;
                    }
                }
            if (best == NONE)
            {
                overBudget[k] = true;
                for (std::size_t l = 0; l < curves.levels.size(); ++l)
                {
                    if (isExcluded(l) || !costOf[l])
                        continue;
                    const float flip = curves.flipAt(l, h);
                    const float cost = costOf[l]->msAt(h);
                    if (best == NONE || flip < bestFlip || (flip == bestFlip && cost < bestCost))
                    {
                        best = l;
                        bestCost = cost;
                        bestFlip = flip;
                    }
                }
                if (best == NONE)
                    return fail("", "level choices", "every level with a cost is excluded");
            }
            candidates[k].push_back(best);
            if (errorBudget > 0.0f && costSlack > 0.0f && std::isfinite(bestCost) && !overBudget[k])
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
            bool overBudget = false;
        };
        std::vector<Run> runs;
        for (std::size_t k = 0; k < SELECTION_SAMPLES; ++k)
        {
            const float h = selectionHeight(k);
            if (runs.empty() || runs.back().level != path[k])
                runs.push_back(Run{path[k], 0, h, 0.0f});
            Run& run = runs.back();
            ++run.samples;
            run.overBudget = run.overBudget || overBudget[k];
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
            keep.overBudget = keep.overBudget || gone.overBudget;
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
                    runs[r - 1].overBudget = runs[r - 1].overBudget || runs[r].overBudget;
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
            choices.push_back(LevelChoice{runs[r].level, boundary, runs[r].flip, !runs[r].overBudget});
        }
        return choices;
    }

    std::uint64_t planGpuBytes(const std::vector<MemoryPlanSpecies>& species,
                               const std::vector<std::vector<LevelChoice>>& plans)
    {
        // Per resource key, the union of its species' levels (one asset, one set of curves).
        std::map<const void*, std::pair<const ErrorCurves*, std::vector<std::size_t>>> byKey;
        for (std::size_t s = 0; s < species.size() && s < plans.size(); ++s)
        {
            if (!species[s].curves)
                continue;
            const void* key = species[s].resourceKey ? species[s].resourceKey : &species[s];
            auto& entry = byKey[key];
            entry.first = species[s].curves;
            for (const LevelChoice& choice : plans[s])
                entry.second.push_back(choice.curveLevel);
        }
        std::uint64_t bytes = 0;
        for (const auto& [key, entry] : byKey)
            bytes += entry.first->gpuBytes(entry.second);
        return bytes;
    }

    namespace
    {
        std::string megabytes(std::uint64_t bytes)
        {
            char text[32];
            std::snprintf(text, sizeof(text), "%.2f MB", double(bytes) / 1e6);
            return text;
        }

        /// A plan's cost and its FLIP over the error budget, summed over the samples by weight.
        struct PlanScore
        {
            double ms = 0.0, excess = 0.0;
        };

        PlanScore scorePlan(const MemoryPlanSpecies& species, const std::vector<LevelChoice>& plan, float errorBudget,
                            std::size_t reference)
        {
            const ErrorCurves& curves = *species.curves;
            const std::vector<const LevelCost*> costOf = costsOf(curves, *species.costs);
            double total = 0.0;
            for (std::uint32_t w : species.weights)
                total += w;
            PlanScore score;
            for (std::size_t k = 0; k < SELECTION_SAMPLES; ++k)
            {
                const double weight = total > 0.0 ? (k < species.weights.size() ? species.weights[k] : 0.0) : 1.0;
                if (weight == 0.0)
                    continue;
                const float h = selectionHeight(k);
                const std::size_t level = plan[choiceAt(plan, h)].curveLevel;
                score.ms += weight * (costOf[level] ? double(costOf[level]->msAt(h)) : 0.0);
                score.excess +=
                    weight * std::max(0.0, double(curves.flipAt(level, h)) - double(curves.flipAt(reference, h)) -
                                               double(errorBudget));
            }
            return score;
        }
    }

    namespace
    {
        /// The plan from the smallest one up: each species starts with its level of fewest bytes
        /// alone; while the budget allows, the level that removes most FLIP over the error budget
        /// (then most cost) per byte it adds joins its species' candidates.
        Result<MemoryPlan> planUpFromSmallest(const std::vector<MemoryPlanSpecies>& species,
                                              const std::vector<std::size_t>& references, float errorBudget,
                                              std::uint64_t memoryBudget, std::size_t maxRuns)
        {
            MemoryPlan plan;
            plan.memoryBinds = true;
            std::string smallest;
            for (std::size_t s = 0; s < species.size(); ++s)
            {
                const ErrorCurves& curves = *species[s].curves;
                const std::vector<const LevelCost*> costOf = costsOf(curves, *species[s].costs);
                std::size_t least = references[s];
                for (std::size_t l = 0; l < curves.levels.size(); ++l)
                    if (costOf[l] && (!costOf[least] || curves.gpuBytes({l}) < curves.gpuBytes({least})))
                        least = l;
                std::vector<bool> excluded(curves.levels.size(), true);
                excluded[least] = false;
                Result<std::vector<LevelChoice>> choices =
                    chooseLevels(curves, *species[s].costs, errorBudget, maxRuns, LEVEL_SWITCH_COST_SLACK, excluded);
                if (!choices)
                    return Error{"", "species " + std::to_string(s) + " " + choices.error().element,
                                 choices.error().reason};
                plan.excluded.push_back(std::move(excluded));
                plan.choices.push_back(std::move(*choices));
                const ErrorCurveLevel& level = curves.levels[least];
                smallest += std::string(s ? "; " : "") + "species " + std::to_string(s) + ": " + level.technique +
                            " " + std::to_string(level.techniqueLevel) + (level.lowRes ? " low-res " : " ") +
                            megabytes(curves.gpuBytes({least}));
            }
            plan.gpuBytes = planGpuBytes(species, plan.choices);
            if (plan.gpuBytes > memoryBudget)
                return fail("", "memory budget",
                            megabytes(memoryBudget) + " is below the smallest plan, " + megabytes(plan.gpuBytes) +
                                " (" + smallest + ")");
            for (;;)
            {
                std::size_t bestSpecies = 0;
                std::vector<bool> bestExcluded;
                std::vector<LevelChoice> bestChoices;
                std::uint64_t bestBytes = 0;
                double bestGain = 0.0;
                bool bestReducesError = false;
                for (std::size_t s = 0; s < species.size(); ++s)
                {
                    const ErrorCurves& curves = *species[s].curves;
                    const PlanScore now = scorePlan(species[s], plan.choices[s], errorBudget, references[s]);
                    for (std::size_t l = 0; l < curves.levels.size(); ++l)
                    {
                        if (!plan.excluded[s][l])
                            continue;
                        std::vector<bool> excluded = plan.excluded[s];
                        excluded[l] = false;
                        Result<std::vector<LevelChoice>> trial = chooseLevels(
                            curves, *species[s].costs, errorBudget, maxRuns, LEVEL_SWITCH_COST_SLACK, excluded);
                        if (!trial)
                            continue;
                        std::vector<std::vector<LevelChoice>> plans = plan.choices;
                        plans[s] = *trial;
                        const std::uint64_t bytes = planGpuBytes(species, plans);
                        if (bytes > memoryBudget)
                            continue;
                        const PlanScore after = scorePlan(species[s], *trial, errorBudget, references[s]);
                        const bool reducesError = now.excess - after.excess > 1e-9;
                        const double gain = reducesError ? now.excess - after.excess : now.ms - after.ms;
                        if (!(gain > 1e-12) || (bestReducesError && !reducesError))
                            continue;
                        const double perByte = gain / double(std::max<std::uint64_t>(bytes - std::min(bytes, plan.gpuBytes), 1));
                        if ((reducesError && !bestReducesError) || perByte > bestGain)
                        {
                            bestSpecies = s;
                            bestExcluded = std::move(excluded);
                            bestChoices = std::move(*trial);
                            bestBytes = bytes;
                            bestGain = perByte;
                            bestReducesError = reducesError;
                        }
                    }
                }
                if (bestExcluded.empty())
                    return plan;
                plan.excluded[bestSpecies] = std::move(bestExcluded);
                plan.choices[bestSpecies] = std::move(bestChoices);
                plan.gpuBytes = bestBytes;
            }
        }
    }

    Result<MemoryPlan> chooseLevelsWithinMemory(const std::vector<MemoryPlanSpecies>& species, float errorBudget,
                                                std::uint64_t memoryBudget, std::size_t maxRuns)
    {
        MemoryPlan plan;
        std::vector<std::size_t> references;
        for (std::size_t s = 0; s < species.size(); ++s)
        {
            const std::string element = "species " + std::to_string(s);
            const MemoryPlanSpecies& one = species[s];
            if (!one.curves || !one.costs)
                return fail("", element, "no error curves or level costs");
            if (memoryBudget > 0 && !one.curves->hasGpuBytes())
                return fail("", element,
                            "its error curves hold no GPU bytes (measured by an older build): measure them again "
                            "(treelod bake --error-curves) to plan within a memory budget");
            Result<int> reference = checkBudget(*one.curves, errorBudget, "error budget");
            if (!reference)
                return Error{"", element + " " + reference.error().element, reference.error().reason};
            references.push_back(std::size_t(*reference));
            plan.excluded.emplace_back(one.curves->levels.size(), false);
            Result<std::vector<LevelChoice>> choices = chooseLevels(*one.curves, *one.costs, errorBudget, maxRuns);
            if (!choices)
                return Error{"", element + " " + choices.error().element, choices.error().reason};
            plan.choices.push_back(std::move(*choices));
        }
        plan.gpuBytes = planGpuBytes(species, plan.choices);

        while (memoryBudget > 0 && plan.gpuBytes > memoryBudget)
        {
            // Moves: one level of a plan out, or every level of its technique (levels of one
            // technique share resources: one alone may free nothing).
            struct Move
            {
                std::size_t species = 0;
                std::vector<bool> excluded;
                std::vector<LevelChoice> choices;
                std::uint64_t bytes = 0;
                int tier = 2;       ///< 0: keeps the error budget; 1: adds FLIP over it
                double ratio = 0.0; ///< bytes saved per ms added (tier 0) or per FLIP added (tier 1)
            };
            std::optional<Move> best;
            for (std::size_t s = 0; s < species.size(); ++s)
            {
                const ErrorCurves& curves = *species[s].curves;
                const PlanScore now = scorePlan(species[s], plan.choices[s], errorBudget, references[s]);
                std::set<std::vector<bool>> tried;
                for (const LevelChoice& choice : plan.choices[s])
                    for (const bool wholeTechnique : {false, true})
                    {
                        std::vector<bool> excluded = plan.excluded[s];
                        for (std::size_t l = 0; l < curves.levels.size(); ++l)
                            if (l == choice.curveLevel ||
                                (wholeTechnique &&
                                 curves.levels[l].technique == curves.levels[choice.curveLevel].technique))
                                excluded[l] = true;
                        if (!tried.insert(excluded).second)
                            continue;
                        Result<std::vector<LevelChoice>> trial =
                            chooseLevels(curves, *species[s].costs, errorBudget, maxRuns, LEVEL_SWITCH_COST_SLACK,
                                         excluded);
                        if (!trial)
                            continue; // nothing left to draw
                        std::vector<std::vector<LevelChoice>> plans = plan.choices;
                        plans[s] = *trial;
                        const std::uint64_t bytes = planGpuBytes(species, plans);
                        if (bytes >= plan.gpuBytes)
                            continue;
                        const PlanScore after = scorePlan(species[s], *trial, errorBudget, references[s]);
                        const double saved = double(plan.gpuBytes - bytes);
                        const double addedError = after.excess - now.excess;
                        Move move{s, std::move(excluded), std::move(*trial), bytes, addedError > 1e-9 ? 1 : 0, 0.0};
                        move.ratio = move.tier == 0 ? saved / std::max(after.ms - now.ms, 1e-9) : saved / addedError;
                        if (!best || move.tier < best->tier || (move.tier == best->tier && move.ratio > best->ratio))
                            best = std::move(move);
                    }
            }
            if (!best)
            {
                // Taking levels out got stuck (each way out draws a larger level instead): plan up
                // from the smallest plan instead.
                Result<MemoryPlan> up = planUpFromSmallest(species, references, errorBudget, memoryBudget, maxRuns);
                if (!up)
                    return up.error();
                plan = std::move(*up);
                break;
            }
            plan.excluded[best->species] = std::move(best->excluded);
            plan.choices[best->species] = std::move(best->choices);
            plan.gpuBytes = best->bytes;
            plan.memoryBinds = true;
        }
        for (const std::vector<LevelChoice>& choices : plan.choices)
            for (const LevelChoice& choice : choices)
                plan.withinErrorBudget = plan.withinErrorBudget && choice.withinBudget;
        return plan;
    }

    float occlusionHeightScale(const ErrorCurves& curves, const std::vector<LevelChoice>& choices, float errorBudget,
                               float visibility, int maxOctaves)
    {
        const int reference = curves.find(LEVEL_SELECTION_REFERENCE, 0, false);
        if (choices.empty() || reference < 0 || !(visibility > 0.0f && visibility < 1.0f) ||
            !(errorBudget >= 0.0f && errorBudget <= 1.0f))
            return 1.0f;
        const std::size_t ref = std::size_t(reference);
        const float budget = std::min(1.0f, errorBudget / visibility);
        float scale = 1.0f;
        for (int k = 1; k <= maxOctaves * SELECTION_SAMPLES_PER_OCTAVE; ++k)
        {
            const float s = std::exp2(-float(k) / SELECTION_SAMPLES_PER_OCTAVE);
            for (std::size_t j = 0; j < SELECTION_SAMPLES; ++j)
            {
                const float h = selectionHeight(j);
                const std::size_t own = choices[choiceAt(choices, h)].curveLevel;
                const std::size_t level = choices[choiceAt(choices, h * s)].curveLevel;
                if (level == own)
                    continue;
                const float allowed = std::max(curves.flipAt(ref, h) + budget, curves.flipAt(own, h));
                const float allowedWorst = std::max(curves.flipMaxAt(ref, h) + WORST_VIEW_BUDGET_FACTOR * budget,
                                                    curves.flipMaxAt(own, h));
                if (curves.flipAt(level, h) > allowed || curves.flipMaxAt(level, h) > allowedWorst)
                    return scale;
            }
            scale = s;
        }
        return scale;
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
