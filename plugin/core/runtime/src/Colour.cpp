#include "TreeLod/Colour.h"

namespace TreeLod
{
    // IEC 61966-2-1 piecewise transfer functions.
    float srgbToLinear(float c)
    {
        return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
    }

    float linearToSrgb(float c)
    {
        return c <= 0.0031308f ? c * 12.92f : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
    }
}
