// What the scene script's source files share (private to TreeLodScript).
#pragma once

#include <cstdint>
#include <sstream>
#include <string>

namespace TreeLod::SceneScriptDetail
{
    constexpr double PI = 3.14159265358979323846;
    constexpr std::uint32_t MAX_TREES = 10000000;

    inline std::string formatNumber(double v)
    {
        std::ostringstream out;
        out << v;
        return out.str();
    }
}
