// LevelSelection: each tree's level chosen from two measured things (docs/forest.md, "Budgeted
// levels"): the asset's error curves (ErrorCurves.h, baked) and the levels' costs on this
// machine (LevelCosts.h, calibrated). For an error budget e, at each screen height h the
// cheapest level whose error is within e of the polygonal reference's own error at h:
//     allowed(L, h)  <=>  flip(L, h) <= flip(mesh, h) + e        (mesh always allowed)
// and the result, sampled at 4 heights per octave from 1 to 8192 px, is merged into runs of one
// level: near to far, each with the smallest height it is drawn at. A budget of 0 draws the
// reference itself; a budget of 1 the cheapest level everywhere. A level without a cost is not a
// candidate.
#pragma once

#include "TreeLod/ErrorCurves.h"
#include "TreeLod/LevelCosts.h"
#include "TreeLod/Result.h"

#include <cstddef>
#include <vector>

namespace TreeLod
{
    /// The technique whose curve is the floor of every budget (TechniqueRegistry's REFERENCE_TECHNIQUE).
    constexpr const char* LEVEL_SELECTION_REFERENCE = "mesh";

    /// One run of the selection: curves.levels[curveLevel] while the tree is >= minHeightPx tall.
    struct LevelChoice
    {
        std::size_t curveLevel = 0;
        float minHeightPx = 0.0f; ///< the last run's is 0
        float flip = 0.0f;        ///< the curve's largest FLIP over the run's sampled heights
    };

    /// Runs near to far, at most `maxRuns` (the shortest runs, counted in samples, are merged into
    /// the finer neighbour until they fit). Errors: a budget that is not finite or not in [0, 1];
    /// curves without the reference level or with no level that has a cost.
    Result<std::vector<LevelChoice>> chooseLevels(const ErrorCurves& curves, const std::vector<LevelCost>& costs,
                                                  float errorBudget, std::size_t maxRuns = 16);
}
