// What the scene script's source files share (private to TreeLodScript).
#pragma once

#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

namespace TreeLod::SceneScriptDetail
{
    constexpr double PI = 3.14159265358979323846;
    constexpr std::uint32_t MAX_TREES = 10000000;
    /// Exclusion areas of all placements together: freeArea() tests 512 x 512 points against
    /// each of its placement's, and every drawn tree is tested against them.
    constexpr std::size_t MAX_EXCLUSIONS = 64;

    inline std::string formatNumber(double v)
    {
        std::ostringstream out;
        out << v;
        return out.str();
    }
}
