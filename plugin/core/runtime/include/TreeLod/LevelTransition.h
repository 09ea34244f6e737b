// LevelTransition: the arithmetic of a screen-door transition between two levels of one tree,
// shared by the Forest (ForestInstances::cull) and the tree objects (ObjectTransition.h), whose
// shaders draw the masks (materials/GLSL/TreeLodTransition.glsl).
//
// A switch from a level to the next coarser one happens at screen size S (a length: the tree's
// height or projected radius on screen). With transition length t, a tree of screen size s with
// 1 < s / S < end = 1 + t is drawn at both levels: the coarse one keeps the share
// f = (end - s / S) / (end - 1) of the pixels (code f), the fine one the rest (code -f). A band
// takes at most the lower half (in ratio) of its level's own range of screen sizes, so two bands
// never meet and each level is drawn whole somewhere.
#pragma once

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace TreeLod
{
    /// Where a band ends, as a ratio of screen sizes over its switch's (1: no band): 1 + `transition`,
    /// at most the square root of `levelRange`, the fine level's own range of screen sizes (its
    /// largest over its smallest; infinite for the finest level).
    inline float transitionBandEnd(float transition, float levelRange)
    {
        if (!(transition > 0.0f))
            return 1.0f;
        return std::min(1.0f + transition, std::sqrt(std::max(levelRange, 1.0f)));
    }

    /// The coarse level's share f in (0, 1] of a tree at `sizeRatio` (its screen size over the
    /// switch's, >= 1 on the fine side) in a band ending at `end`; 0 outside the band.
    inline float transitionCoarseShare(float sizeRatio, float end)
    {
        if (!(end > 1.0f) || !(sizeRatio < end))
            return 0.0f;
        return std::min((end - sizeRatio) / (end - 1.0f), 1.0f);
    }

    /// What a draw keeps of a tree at screen-door threshold `dither` in [0, 1) (the pattern's
    /// value at the pixel, TreeLodTransition.glsl): code 0 all, f > 0 where dither < f, -f where
    /// dither >= f. The two draws of a transition keep complementary pixels.
    inline bool transitionKeeps(float code, float dither)
    {
        return code > 0.0f ? dither < code : dither >= -code;
    }

    /// The pattern shift of a tree standing at `position` (metres), in [0, 1) in steps of 1/64:
    /// a hash of its quarter-metre cell, so that trees one behind another in transitions do not
    /// drop the same pixels. TreeLodTransition.glsl's transitionOf computes the same in integers.
    inline float transitionPatternShift(const glm::vec3& position)
    {
        const glm::vec3 p = glm::clamp(position * 4.0f, glm::vec3(-1.6e7f), glm::vec3(1.6e7f));
        const auto cell = [](float v) { return std::isfinite(v) ? std::uint32_t(std::int32_t(std::floor(v)) + 16777216) : 0u; };
        const std::uint32_t hash =
            (cell(p.x) * 73856093u) ^ (cell(p.y) * 19349663u) ^ (cell(p.z) * 83492791u);
        return float(hash & 63u) / 64.0f;
    }
}
