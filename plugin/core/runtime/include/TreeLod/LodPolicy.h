// LodPolicy: how the species of a forest scene choose their levels, as one value. It is parsed
// once where a user writes it (a scene script's choice, `--techniques`, the browser's controls) and
// passed down as a value:
//   ""         Script   each species as its script says (distance bands, or "auto")
//   "auto"     Auto     budgeted auto at the script's error budget (docs/forest.md)
//   "auto@E"   Auto     budgeted auto at error budget E, the mean FLIP allowed, in [0, 1]
//   "auto~MS"  Auto     budgeted auto under a frame budget of MS milliseconds, in (0, 1e6]
//   any other  Fixed    every species drawn by that one technique or measurement baseline
// Any of them + "+fadeT": level transitions of length T in [0, 1] (Forest::setLodTransition; 0:
// hard switches), else the script's ("auto+fade0", "impostor+fade0.2", "+fade0.1"); and + "+memMB":
// a memory budget of MB megabytes (10^6 bytes) for budgeted auto (Forest::setMemoryBudget; 0:
// none), else the script's ("auto+mem40", "auto@0.02+mem40+fade0.2"); and + "+occB": occlusion
// between the trees off (0) or on (1) (Forest::setOcclusion), else the script's ("auto+occ0").
#pragma once

#include "TreeLod/Result.h"

#include <limits>
#include <string>

namespace TreeLod
{
    struct LodPolicy
    {
        enum class Mode
        {
            Script,
            Auto,
            Fixed
        };

        Mode mode = Mode::Script;
        std::string technique; ///< Fixed: the technique or baseline every species is drawn with
        /// Auto: mean FLIP allowed, [0, 1]; NaN: the script's (or the Forest's default).
        float errorBudget = std::numeric_limits<float>::quiet_NaN();
        /// Auto: frame time the error budget follows, milliseconds; NaN: none.
        float frameBudgetMs = std::numeric_limits<float>::quiet_NaN();
        /// Forest::setLodTransition, [0, 1]; NaN: the script's.
        float transition = std::numeric_limits<float>::quiet_NaN();
        /// Forest::setMemoryBudget in megabytes (10^6 bytes), >= 0 (0: none); NaN: the script's.
        float memoryBudgetMB = std::numeric_limits<float>::quiet_NaN();
        /// Forest::setOcclusion: 0 off, 1 on; NaN: the script's.
        float occlusion = std::numeric_limits<float>::quiet_NaN();

        static LodPolicy scriptChoice() { return {}; }
        static LodPolicy automatic(float errorBudget = std::numeric_limits<float>::quiet_NaN(),
                                   float frameBudgetMs = std::numeric_limits<float>::quiet_NaN());
        static LodPolicy fixed(std::string technique);

        /// `text` as in the table above. An "auto@" or "auto~" with a number out of range, or not a
        /// number, is an error naming `element`. A fixed technique is not checked here (the
        /// technique registry knows the names).
        static Result<LodPolicy> parse(const std::string& text, const std::string& element = "technique");
        /// The text parse reads back ("auto@0.05", "<technique>", "", "auto+fade0").
        std::string toString() const;

        bool isAuto() const { return mode == Mode::Auto; }
        bool operator==(const LodPolicy& other) const;
        bool operator!=(const LodPolicy& other) const { return !(*this == other); }
    };
}
