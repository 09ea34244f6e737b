// Colour: sRGB <-> linear transfer (IEC 61966-2-1) and 8-bit packing, the one place the CPU side
// converts colours (bake, reference renderer, metrics, the Ogre renderer's supersampling).
// GLSL shaders keep their own copies of the formulas.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

namespace TreeLod
{
    /// sRGB-encoded value in [0, 1] to linear (the piecewise IEC 61966-2-1 curve), per channel.
    float srgbToLinear(float c);

    /// Linear value to sRGB encoding, per channel; not clamped (values above 1 give above 1).
    float linearToSrgb(float c);

    /// srgbToLinear(b / 255), from a 256-entry table.
    inline float srgbByteToLinear(std::uint8_t b)
    {
        static const std::array<float, 256> table = [] {
            std::array<float, 256> t{};
            for (int i = 0; i < 256; ++i)
                t[std::size_t(i)] = srgbToLinear(float(i) / 255.0f);
            return t;
        }();
        return table[b];
    }

    /// A byte as a [0, 1] value: b / 255.
    inline float byteToUnit(std::uint8_t b) { return float(b) / 255.0f; }

    /// A [0, 1] value as a byte: round(clamp(v, 0, 1) * 255).
    inline std::uint8_t unitToByte(float v) { return std::uint8_t(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); }

    /// A linear value as an sRGB byte: unitToByte(linearToSrgb(c)), so values outside [0, 1] give 0 or 255.
    inline std::uint8_t linearToSrgbByte(float c) { return unitToByte(linearToSrgb(c)); }
}
