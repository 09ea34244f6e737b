// WindModel: the CPU side of the wind (WindModel.h); materials/GLSL/TreeLodWind.glsl is the same
// arithmetic, term for term.
#include "TreeLod/WindModel.h"

#include <cmath>

namespace TreeLod
{
    namespace
    {
        constexpr double TWO_PI = 6.283185307179586;

        float phaseAt(double rate, double seconds) { return float(std::fmod(std::fmod(rate * seconds, TWO_PI) + TWO_PI, TWO_PI)); }
        float fract(float v) { return v - std::floor(v); }
        std::string number(float v) { return std::to_string(v); }
    }

    Result<void> WindParameters::validate() const
    {
        if (!std::isfinite(direction.x) || !std::isfinite(direction.y) || glm::dot(direction, direction) <= 0.0f)
            return fail("", "wind.direction", "must be a finite non-zero horizontal vector, got (" + number(direction.x) +
                                                  ", " + number(direction.y) + ")");
        if (!(strength >= 0.0f) || !std::isfinite(strength))
            return fail("", "wind.strength", "must be finite and >= 0, got " + number(strength));
        if (!(gustiness >= 0.0f && gustiness <= 1.0f))
            return fail("", "wind.gustiness", "must be in [0, 1], got " + number(gustiness));
        if (!(gustWavelength > 0.0f) || !std::isfinite(gustWavelength))
            return fail("", "wind.gustWavelength", "must be finite and > 0 metres, got " + number(gustWavelength));
        return {};
    }

    WindPhases WindPhases::at(double seconds)
    {
        if (!std::isfinite(seconds))
            seconds = 0.0;
        return {phaseAt(WindModel::GUST_RATE, seconds), phaseAt(WindModel::SWAY_RATE, seconds),
                phaseAt(WindModel::BRANCH_RATE, seconds), phaseAt(WindModel::LEAF_RATE, seconds)};
    }

    glm::vec3 WindModel::offset(const WindParameters& wind, const WindPhases& phases, const glm::vec3& point, float height,
                                const glm::vec3& along, const glm::vec2& worldDirection, const glm::vec3& treeBase, bool leaf)
    {
        if (!(height > 0.0f) || wind.strength == 0.0f)
            return glm::vec3(0.0f);
        const float twoPi = float(TWO_PI);
        const glm::vec2 base(treeBase.x, treeBase.z);
        const float k = twoPi / wind.gustWavelength;
        const float force = wind.strength * (1.0f + wind.gustiness * std::sin(phases.gust - k * glm::dot(base, worldDirection)));
        const float treePhase = twoPi * fract(glm::dot(base, glm::vec2(0.1031f, 0.0717f)));
        const float eta = glm::clamp(point.y / height, 0.0f, 1.0f);

        const float bend = BEND_MAX * std::tanh(force / BEND_FORCE) * (1.0f + 0.25f * std::sin(phases.sway + treePhase));
        glm::vec3 result = along * (height * bend * eta * eta);
        result.y -= (2.0f / 3.0f) * height * bend * bend * eta * eta * eta;

        const float rho = glm::clamp(glm::length(glm::vec2(point.x, point.z)) / (0.5f * height), 0.0f, 1.0f);
        const float sway = BRANCH_MAX * height * std::tanh(force / BRANCH_FORCE) * rho * eta;
        const float branchPhase = phases.branch + treePhase + twoPi * glm::dot(point / height, glm::vec3(0.9f, 0.7f, 1.1f));
        result += sway * (along * std::sin(branchPhase) + glm::vec3(0.0f, 0.5f * std::cos(branchPhase), 0.0f));

        if (leaf)
        {
            const float flutter = FLUTTER_MAX * height * std::tanh(force) * eta;
            const float leafPhase = phases.leaf + twoPi * fract(glm::dot(point / height, glm::vec3(13.1f, 17.3f, 11.7f)));
            result.y += flutter * std::sin(leafPhase);
        }
        return result;
    }
}
