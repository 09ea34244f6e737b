// WindModel: one wind for every level of every tree, evaluated the same way here (tests, the
// reference) and in every technique's vertex programs (materials/GLSL/TreeLodWind.glsl).
//
// A point p of a tree (the tree's own frame: y up, base at the origin, its own units) of height H
// moves by windOffset(p):
//   - gusts: force F = S (1 + G sin(phase_gust - k (P . D))), a front of wavelength 2 pi / k running
//     along the wind over the forest (P: the tree's base in world units, D: the wind's direction);
//   - trunk bending, growing with height: bend b = B tanh(F / F_B) (1 + 0.25 sin(phase_sway + h)),
//     offset H b eta^2 along D and -(2/3) H b^2 eta^3 down (the arc keeps its length to first
//     order), eta = p.y / H clamped to [0, 1];
//   - branch sway, growing with the distance from the trunk's axis and with height: amplitude
//     A H tanh(F / F_A) rho eta, with phase phase_branch + h + 2 pi (p / H) . K, a smooth field
//     over the crown, so that a coarse level's pieces move as the branches they stand for;
//   - leaf flutter (leaf vertices of the mesh and LoDF only): vertical, amplitude L H tanh(F) eta,
//     phase per vertex.
// h = 2 pi fract(P.xz . (0.1031, 0.0717)) is the tree's own phase. Every term is 0 at S = 0 (an
// exact zero: the programs then draw what they drew without wind), and bounded at any S by the
// tanh. Deviation from a skeleton-driven model (branch anchors and hierarchy levels per vertex):
// the branch phase is a field of the rest position, which every representation has without a
// package change; neighbouring branches sway nearly in phase.
//
// Time: the phases are computed here in double precision and reduced modulo 2 pi (WindPhases), so
// a clock near 1e6 s loses nothing in the programs' single-precision sines.
#pragma once

#include "TreeLod/Result.h"

#include <glm/glm.hpp>

#include <string>

namespace TreeLod
{
    /// The wind of a scene (world units: metres).
    struct WindParameters
    {
        glm::vec2 direction{1.0f, 0.0f}; ///< horizontal (x, z), any length > 0
        float strength = 0.0f;           ///< S >= 0: 0 calm, 1 a fresh breeze, 3 a gale
        float gustiness = 0.5f;          ///< G in [0, 1]
        float gustWavelength = 60.0f;    ///< metres between gust fronts (> 0)

        /// Unset values named in the message ("wind.strength must be ..."); NaN and infinities
        /// refused.
        Result<void> validate() const;
        bool calm() const { return strength == 0.0f; }
    };

    /// The oscillators' phases at a time, each in [0, 2 pi).
    struct WindPhases
    {
        float gust = 0.0f, sway = 0.0f, branch = 0.0f, leaf = 0.0f;
        /// At `seconds` (any finite value: reduced in double precision).
        static WindPhases at(double seconds);
    };

    struct WindModel
    {
        static constexpr float BEND_MAX = 0.12f;    ///< B: the trunk's largest bend (offset / height at the top)
        static constexpr float BEND_FORCE = 2.0f;   ///< F_B
        static constexpr float BRANCH_MAX = 0.03f;  ///< A
        static constexpr float BRANCH_FORCE = 1.5f; ///< F_A
        static constexpr float FLUTTER_MAX = 0.004f; ///< L
        /// Angular frequencies (rad/s) of the gusts, the trunk's sway, the branches, the leaves.
        static constexpr double GUST_RATE = 0.9, SWAY_RATE = 2.2, BRANCH_RATE = 5.3, LEAF_RATE = 23.0;

        /// The offset of `point` (the tree's frame) of a tree of `height` whose base stands at
        /// `treeBase` (world), the wind's direction `along` given in the tree's frame (unit,
        /// horizontal) and `worldDirection` in the world's (unit, x z). `leaf`: add the flutter.
        static glm::vec3 offset(const WindParameters& wind, const WindPhases& phases, const glm::vec3& point,
                                float height, const glm::vec3& along, const glm::vec2& worldDirection,
                                const glm::vec3& treeBase, bool leaf);
    };
}
