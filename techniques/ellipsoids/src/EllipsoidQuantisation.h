// The quantisation both ellipsoid chunks share (EllipsoidTreeData.h, EllipsoidLineData.h): a value
// in [0, 1] as u16, a length on a log2 scale as u16 (`unit` * 2^[log2Min, log2Min + log2Span]),
// and the finite-vector test and number text their validation uses.
#pragma once

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

namespace TreeLod
{
    namespace EllipsoidQuantisation
    {
        inline bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

        inline std::string text(float v) { return std::to_string(v); }

        /// t clamped to [0, 1] (NaN as 0), in 65535 steps.
        inline std::uint16_t unit(float t)
        {
            return std::uint16_t(std::lround(std::clamp(std::isfinite(t) ? t : 0.0f, 0.0f, 1.0f) * 65535.0f));
        }

        /// A length (metres; not finite or <= 0 as the scale's bottom) on the log scale.
        inline std::uint16_t logLength(float length, float scaleUnit, float log2Min, float log2Span)
        {
            const float l = std::log2(std::max(std::isfinite(length) ? length : 0.0f, 1e-30f) / scaleUnit);
            return unit((l - log2Min) / log2Span);
        }

        inline float lengthFromCode(std::uint16_t q, float scaleUnit, float log2Min, float log2Span)
        {
            return scaleUnit * std::exp2(log2Span * float(q) / 65535.0f + log2Min);
        }
    }
}
