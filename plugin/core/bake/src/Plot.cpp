// Plot: see Plot.h. Everything is drawn in display-encoded (sRGB) values, blended in that
// space like common 2D plotting libraries do.
#include "TreeLod/Plot.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <limits>

namespace TreeLod
{
    namespace
    {
        // X11 misc-fixed 6x13 ("fixed"), printable ASCII 32..126; public domain
        // ("Public domain font. Share and enjoy.", font-misc-misc). One byte per row,
        // bit 7 = leftmost of the 6 columns; baseline below row 10.
        constexpr int kGlyphW = 6;
        constexpr int kGlyphH = 13;
        // clang-format off
        constexpr std::uint8_t kFont[95][kGlyphH] = {
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}, // space
    {0x00, 0x00, 0x20, 0x20, 0x20, 0x20, 0x20, 0x20, 0x20, 0x00, 0x20, 0x00, 0x00}, // !
    {0x00, 0x00, 0x50, 0x50, 0x50, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}, // "
    {0x00, 0x00, 0x00, 0x50, 0x50, 0xf8, 0x50, 0xf8, 0x50, 0x50, 0x00, 0x00, 0x00}, // #
    {0x00, 0x00, 0x20, 0x78, 0xa0, 0xa0, 0x70, 0x28, 0x28, 0xf0, 0x20, 0x00, 0x00}, // $
    {0x00, 0x00, 0x48, 0xa8, 0x50, 0x10, 0x20, 0x40, 0x50, 0xa8, 0x90, 0x00, 0x00}, // %
    {0x00, 0x00, 0x00, 0x40, 0xa0, 0xa0, 0x40, 0xa0, 0x98, 0x90, 0x68, 0x00, 0x00}, // &
    {0x00, 0x00, 0x20, 0x20, 0x20, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}, // '
    {0x00, 0x10, 0x20, 0x20, 0x40, 0x40, 0x40, 0x40, 0x40, 0x20, 0x20, 0x10, 0x00}, // (
    {0x00, 0x40, 0x20, 0x20, 0x10, 0x10, 0x10, 0x10, 0x10, 0x20, 0x20, 0x40, 0x00}, // )
    {0x00, 0x00, 0x20, 0xa8, 0x70, 0xa8, 0x20, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}, // *
    {0x00, 0x00, 0x00, 0x00, 0x20, 0x20, 0xf8, 0x20, 0x20, 0x00, 0x00, 0x00, 0x00}, // +
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x30, 0x20, 0x40, 0x00}, // ,
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xf8, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}, // -
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x20, 0x70, 0x20, 0x00}, // .
    {0x00, 0x00, 0x08, 0x08, 0x10, 0x10, 0x20, 0x40, 0x40, 0x80, 0x80, 0x00, 0x00}, // /
    {0x00, 0x00, 0x20, 0x50, 0x88, 0x88, 0x88, 0x88, 0x88, 0x50, 0x20, 0x00, 0x00}, // 0
    {0x00, 0x00, 0x20, 0x60, 0xa0, 0x20, 0x20, 0x20, 0x20, 0x20, 0xf8, 0x00, 0x00}, // 1
    {0x00, 0x00, 0x70, 0x88, 0x88, 0x08, 0x10, 0x20, 0x40, 0x80, 0xf8, 0x00, 0x00}, // 2
    {0x00, 0x00, 0xf8, 0x08, 0x10, 0x20, 0x70, 0x08, 0x08, 0x88, 0x70, 0x00, 0x00}, // 3
    {0x00, 0x00, 0x10, 0x10, 0x30, 0x50, 0x50, 0x90, 0xf8, 0x10, 0x10, 0x00, 0x00}, // 4
    {0x00, 0x00, 0xf8, 0x80, 0x80, 0xb0, 0xc8, 0x08, 0x08, 0x88, 0x70, 0x00, 0x00}, // 5
    {0x00, 0x00, 0x70, 0x88, 0x80, 0x80, 0xf0, 0x88, 0x88, 0x88, 0x70, 0x00, 0x00}, // 6
    {0x00, 0x00, 0xf8, 0x08, 0x10, 0x10, 0x20, 0x20, 0x40, 0x40, 0x40, 0x00, 0x00}, // 7
    {0x00, 0x00, 0x70, 0x88, 0x88, 0x88, 0x70, 0x88, 0x88, 0x88, 0x70, 0x00, 0x00}, // 8
    {0x00, 0x00, 0x70, 0x88, 0x88, 0x88, 0x78, 0x08, 0x08, 0x88, 0x70, 0x00, 0x00}, // 9
    {0x00, 0x00, 0x00, 0x00, 0x20, 0x70, 0x20, 0x00, 0x00, 0x20, 0x70, 0x20, 0x00}, // :
    {0x00, 0x00, 0x00, 0x00, 0x20, 0x70, 0x20, 0x00, 0x00, 0x30, 0x20, 0x40, 0x00}, // ;
    {0x00, 0x00, 0x08, 0x10, 0x20, 0x40, 0x80, 0x40, 0x20, 0x10, 0x08, 0x00, 0x00}, // <
    {0x00, 0x00, 0x00, 0x00, 0x00, 0xf8, 0x00, 0x00, 0xf8, 0x00, 0x00, 0x00, 0x00}, // =
    {0x00, 0x00, 0x80, 0x40, 0x20, 0x10, 0x08, 0x10, 0x20, 0x40, 0x80, 0x00, 0x00}, // >
    {0x00, 0x00, 0x70, 0x88, 0x88, 0x08, 0x10, 0x20, 0x20, 0x00, 0x20, 0x00, 0x00}, // ?
    {0x00, 0x00, 0x70, 0x88, 0x88, 0x98, 0xa8, 0xa8, 0xb0, 0x80, 0x78, 0x00, 0x00}, // @
    {0x00, 0x00, 0x20, 0x50, 0x88, 0x88, 0x88, 0xf8, 0x88, 0x88, 0x88, 0x00, 0x00}, // A
    {0x00, 0x00, 0xf0, 0x48, 0x48, 0x48, 0x70, 0x48, 0x48, 0x48, 0xf0, 0x00, 0x00}, // B
    {0x00, 0x00, 0x70, 0x88, 0x80, 0x80, 0x80, 0x80, 0x80, 0x88, 0x70, 0x00, 0x00}, // C
    {0x00, 0x00, 0xf0, 0x48, 0x48, 0x48, 0x48, 0x48, 0x48, 0x48, 0xf0, 0x00, 0x00}, // D
    {0x00, 0x00, 0xf8, 0x80, 0x80, 0x80, 0xf0, 0x80, 0x80, 0x80, 0xf8, 0x00, 0x00}, // E
    {0x00, 0x00, 0xf8, 0x80, 0x80, 0x80, 0xf0, 0x80, 0x80, 0x80, 0x80, 0x00, 0x00}, // F
    {0x00, 0x00, 0x70, 0x88, 0x80, 0x80, 0x80, 0x98, 0x88, 0x88, 0x70, 0x00, 0x00}, // G
    {0x00, 0x00, 0x88, 0x88, 0x88, 0x88, 0xf8, 0x88, 0x88, 0x88, 0x88, 0x00, 0x00}, // H
    {0x00, 0x00, 0x70, 0x20, 0x20, 0x20, 0x20, 0x20, 0x20, 0x20, 0x70, 0x00, 0x00}, // I
    {0x00, 0x00, 0x38, 0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x90, 0x60, 0x00, 0x00}, // J
    {0x00, 0x00, 0x88, 0x88, 0x90, 0xa0, 0xc0, 0xa0, 0x90, 0x88, 0x88, 0x00, 0x00}, // K
    {0x00, 0x00, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0xf8, 0x00, 0x00}, // L
    {0x00, 0x00, 0x88, 0x88, 0xd8, 0xa8, 0xa8, 0x88, 0x88, 0x88, 0x88, 0x00, 0x00}, // M
    {0x00, 0x00, 0x88, 0xc8, 0xc8, 0xa8, 0xa8, 0x98, 0x98, 0x88, 0x88, 0x00, 0x00}, // N
    {0x00, 0x00, 0x70, 0x88, 0x88, 0x88, 0x88, 0x88, 0x88, 0x88, 0x70, 0x00, 0x00}, // O
    {0x00, 0x00, 0xf0, 0x88, 0x88, 0x88, 0xf0, 0x80, 0x80, 0x80, 0x80, 0x00, 0x00}, // P
    {0x00, 0x00, 0x70, 0x88, 0x88, 0x88, 0x88, 0x88, 0x88, 0xa8, 0x70, 0x08, 0x00}, // Q
    {0x00, 0x00, 0xf0, 0x88, 0x88, 0x88, 0xf0, 0xa0, 0x90, 0x88, 0x88, 0x00, 0x00}, // R
    {0x00, 0x00, 0x70, 0x88, 0x80, 0x80, 0x70, 0x08, 0x08, 0x88, 0x70, 0x00, 0x00}, // S
    {0x00, 0x00, 0xf8, 0x20, 0x20, 0x20, 0x20, 0x20, 0x20, 0x20, 0x20, 0x00, 0x00}, // T
    {0x00, 0x00, 0x88, 0x88, 0x88, 0x88, 0x88, 0x88, 0x88, 0x88, 0x70, 0x00, 0x00}, // U
    {0x00, 0x00, 0x88, 0x88, 0x88, 0x88, 0x50, 0x50, 0x50, 0x20, 0x20, 0x00, 0x00}, // V
    {0x00, 0x00, 0x88, 0x88, 0x88, 0x88, 0xa8, 0xa8, 0xa8, 0xa8, 0x50, 0x00, 0x00}, // W
    {0x00, 0x00, 0x88, 0x88, 0x50, 0x50, 0x20, 0x50, 0x50, 0x88, 0x88, 0x00, 0x00}, // X
    {0x00, 0x00, 0x88, 0x88, 0x50, 0x50, 0x20, 0x20, 0x20, 0x20, 0x20, 0x00, 0x00}, // Y
    {0x00, 0x00, 0xf8, 0x08, 0x10, 0x10, 0x20, 0x40, 0x40, 0x80, 0xf8, 0x00, 0x00}, // Z
    {0x00, 0x70, 0x40, 0x40, 0x40, 0x40, 0x40, 0x40, 0x40, 0x40, 0x40, 0x70, 0x00}, // [
    {0x00, 0x00, 0x80, 0x80, 0x40, 0x40, 0x20, 0x10, 0x10, 0x08, 0x08, 0x00, 0x00}, // backslash
    {0x00, 0x70, 0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x70, 0x00}, // ]
    {0x00, 0x00, 0x20, 0x50, 0x88, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}, // ^
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xf8, 0x00}, // _
    {0x00, 0x20, 0x10, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}, // `
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x70, 0x08, 0x78, 0x88, 0x98, 0x68, 0x00, 0x00}, // a
    {0x00, 0x00, 0x80, 0x80, 0x80, 0xf0, 0x88, 0x88, 0x88, 0x88, 0xf0, 0x00, 0x00}, // b
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x70, 0x88, 0x80, 0x80, 0x88, 0x70, 0x00, 0x00}, // c
    {0x00, 0x00, 0x08, 0x08, 0x08, 0x78, 0x88, 0x88, 0x88, 0x88, 0x78, 0x00, 0x00}, // d
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x70, 0x88, 0xf8, 0x80, 0x88, 0x70, 0x00, 0x00}, // e
    {0x00, 0x00, 0x30, 0x48, 0x40, 0x40, 0xf0, 0x40, 0x40, 0x40, 0x40, 0x00, 0x00}, // f
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x70, 0x88, 0x88, 0x88, 0x78, 0x08, 0x88, 0x70}, // g
    {0x00, 0x00, 0x80, 0x80, 0x80, 0xb0, 0xc8, 0x88, 0x88, 0x88, 0x88, 0x00, 0x00}, // h
    {0x00, 0x00, 0x00, 0x20, 0x00, 0x60, 0x20, 0x20, 0x20, 0x20, 0x70, 0x00, 0x00}, // i
    {0x00, 0x00, 0x00, 0x10, 0x00, 0x30, 0x10, 0x10, 0x10, 0x10, 0x90, 0x90, 0x60}, // j
    {0x00, 0x00, 0x80, 0x80, 0x80, 0x90, 0xa0, 0xc0, 0xa0, 0x90, 0x88, 0x00, 0x00}, // k
    {0x00, 0x00, 0x60, 0x20, 0x20, 0x20, 0x20, 0x20, 0x20, 0x20, 0x70, 0x00, 0x00}, // l
    {0x00, 0x00, 0x00, 0x00, 0x00, 0xd0, 0xa8, 0xa8, 0xa8, 0xa8, 0x88, 0x00, 0x00}, // m
    {0x00, 0x00, 0x00, 0x00, 0x00, 0xb0, 0xc8, 0x88, 0x88, 0x88, 0x88, 0x00, 0x00}, // n
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x70, 0x88, 0x88, 0x88, 0x88, 0x70, 0x00, 0x00}, // o
    {0x00, 0x00, 0x00, 0x00, 0x00, 0xf0, 0x88, 0x88, 0x88, 0xf0, 0x80, 0x80, 0x80}, // p
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x78, 0x88, 0x88, 0x88, 0x78, 0x08, 0x08, 0x08}, // q
    {0x00, 0x00, 0x00, 0x00, 0x00, 0xb0, 0xc8, 0x80, 0x80, 0x80, 0x80, 0x00, 0x00}, // r
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x70, 0x88, 0x60, 0x10, 0x88, 0x70, 0x00, 0x00}, // s
    {0x00, 0x00, 0x00, 0x40, 0x40, 0xf0, 0x40, 0x40, 0x40, 0x48, 0x30, 0x00, 0x00}, // t
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x88, 0x88, 0x88, 0x88, 0x98, 0x68, 0x00, 0x00}, // u
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x88, 0x88, 0x88, 0x50, 0x50, 0x20, 0x00, 0x00}, // v
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x88, 0x88, 0xa8, 0xa8, 0xa8, 0x50, 0x00, 0x00}, // w
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x88, 0x50, 0x20, 0x20, 0x50, 0x88, 0x00, 0x00}, // x
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x88, 0x88, 0x88, 0x98, 0x68, 0x08, 0x88, 0x70}, // y
    {0x00, 0x00, 0x00, 0x00, 0x00, 0xf8, 0x10, 0x20, 0x40, 0x80, 0xf8, 0x00, 0x00}, // z
    {0x00, 0x18, 0x20, 0x20, 0x20, 0x20, 0xc0, 0x20, 0x20, 0x20, 0x20, 0x18, 0x00}, // {
    {0x00, 0x00, 0x20, 0x20, 0x20, 0x20, 0x20, 0x20, 0x20, 0x20, 0x20, 0x00, 0x00}, // |
    {0x00, 0xc0, 0x20, 0x20, 0x20, 0x20, 0x18, 0x20, 0x20, 0x20, 0x20, 0xc0, 0x00}, // }
    {0x00, 0x00, 0x48, 0xa8, 0x90, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}, // ~
        };
        // clang-format on

        // Paul Tol's "bright" qualitative scheme (colour-blind safe), in sRGB.
        const glm::vec3 kPalette[] = {
            {0x44 / 255.0f, 0x77 / 255.0f, 0xAA / 255.0f}, {0xEE / 255.0f, 0x66 / 255.0f, 0x77 / 255.0f},
            {0x22 / 255.0f, 0x88 / 255.0f, 0x33 / 255.0f}, {0xCC / 255.0f, 0xBB / 255.0f, 0x44 / 255.0f},
            {0x66 / 255.0f, 0xCC / 255.0f, 0xEE / 255.0f}, {0xAA / 255.0f, 0x33 / 255.0f, 0x77 / 255.0f},
            {0xBB / 255.0f, 0xBB / 255.0f, 0xBB / 255.0f}};
        constexpr int kPaletteSize = int(sizeof(kPalette) / sizeof(kPalette[0]));

        const glm::vec3 kInk(0.0f);
        const glm::vec3 kGrid(0.86f);
        const glm::vec3 kMinorGrid(0.94f);

        // Layout, in pixels.
        constexpr int kPad = 10;         // outer padding
        constexpr int kTickLen = 5;      // major tick, outwards
        constexpr int kMinorTickLen = 3; // minor tick
        constexpr int kTickGap = 4;      // tick to its label
        constexpr int kTitleScale = 2;

        double lineWidthOf(const PlotSeries& s)
        {
            return std::isfinite(s.lineWidth) && s.lineWidth > 0.0f ? double(s.lineWidth) : 2.0;
        }

        bool usable(double v, bool logScale) { return std::isfinite(v) && (!logScale || v > 0.0); }

        double pow10i(int k)
        {
            double r = 1.0;
            for (int i = 0; i < std::abs(k); ++i)
                r *= 10.0;
            return k >= 0 ? r : 1.0 / r;
        }

        // m * 10^k with m an integer, rounded as well as a double allows (3 / 10, not 3 * 0.1).
        double scaled(double m, int k) { return k >= 0 ? m * pow10i(k) : m / pow10i(-k); }

        int floorLog10(double v) { return int(std::floor(std::log10(v) + 1e-9)); }

        std::string printf1(const char* format, int decimals, double v)
        {
            char buffer[64];
            std::snprintf(buffer, sizeof buffer, format, decimals, v);
            return buffer;
        }

        // "2e6", "0.001", "100": a value that is m * 10^k with an integer m; with `exponents`
        // (some label on the axis needs one) every |k| >= 3 gets one too, so the axis reads alike.
        std::string formatPower(double v, bool exponents)
        {
            int k = floorLog10(v);
            if (exponents ? std::abs(k) < 3 : k >= -3 && k <= 4)
                return printf1("%.*f", std::max(0, -k), v);
            char buffer[64];
            std::snprintf(buffer, sizeof buffer, "%de%d", int(std::lround(v / pow10i(k))), k);
            return buffer;
        }

        // Labels of linear ticks spaced `step` = m * 10^stepExp apart.
        std::vector<std::string> linearLabels(const std::vector<double>& ticks, int stepExp)
        {
            double maxAbs = 0.0;
            for (double t : ticks)
                maxAbs = std::max(maxAbs, std::abs(t));
            std::vector<std::string> labels;
            int e = maxAbs > 0.0 ? floorLog10(maxAbs) : 0;
            bool scientific = maxAbs >= 1e6 || (maxAbs > 0.0 && maxAbs < 1e-3);
            for (double t : ticks)
            {
                if (std::abs(t) < scaled(1.0, stepExp) * 1e-6)
                    t = 0.0; // no "-0"
                if (scientific && t == 0.0)
                    labels.push_back("0");
                else if (scientific)
                    labels.push_back(printf1("%.*f", std::max(0, e - stepExp), t / pow10i(e)) + "e" +
                                     std::to_string(e));
                else
                    labels.push_back(printf1("%.*f", std::clamp(-stepExp, 0, 15), t));
            }
            return labels;
        }

        PlotTicks linearTicks(double lo, double hi, int maxMajor)
        {
            PlotTicks ticks;
            double span = hi - lo;
            if (!(span > 0.0) || !std::isfinite(span))
                return ticks;
            maxMajor = std::max(maxMajor, 2);
            int k = int(std::floor(std::log10(span / (maxMajor - 1))));
            // The smallest 1-2-5 step giving at most maxMajor ticks in [lo, hi].
            for (int tries = 0; tries < 8; ++tries, ++k)
                for (int m : {1, 2, 5})
                {
                    double step = scaled(m, k);
                    double first = std::ceil(lo / step - 1e-9), last = std::floor(hi / step + 1e-9);
                    if (last - first + 1.0 > maxMajor)
                        continue;
                    if (std::abs(first) > 1e15 || std::abs(last) > 1e15)
                        return ticks; // the span is below double precision of the values: no ticks
                    for (double i = first; i <= last; i += 1.0)
                        ticks.major.push_back(scaled(i * m, k));
                    ticks.labels = linearLabels(ticks.major, k);
                    return ticks;
                }
            return ticks;
        }

        PlotTicks logTicks(double lo, double hi, int maxMajor)
        {
            double a = std::log10(lo), b = std::log10(hi);
            if (b - a < 1.0)
                return linearTicks(lo, hi, maxMajor); // less than a decade: decades say too little
            int d0 = int(std::ceil(a - 1e-9)), d1 = int(std::floor(b + 1e-9));
            maxMajor = std::max(maxMajor, 2);
            // Label every 1, 2, 5, 10, 20... decades: the smallest step giving at most maxMajor.
            int every = 1;
            for (int m = 1;; m *= 10)
            {
                auto count = [&](int e) { return int(std::floor(double(d1) / e) - std::ceil(double(d0) / e)) + 1; };
                int s = count(m) <= maxMajor       ? m
                        : count(2 * m) <= maxMajor ? 2 * m
                        : count(5 * m) <= maxMajor ? 5 * m
                                                   : 0;
                if (s != 0 || m > d1 - d0)
                {
                    every = s != 0 ? s : m;
                    break;
                }
            }
            PlotTicks ticks;
            auto inside = [&](double v) { return v >= lo * (1.0 - 1e-12) && v <= hi * (1.0 + 1e-12); };
            bool fewDecades = d1 - d0 + 1 < 2;
            for (int d = int(std::floor(a)); d <= d1; ++d)
            {
                double decade = pow10i(d);
                bool labelled = d >= d0 && ((d % every) + every) % every == 0;
                if (d >= d0)
                    (labelled ? ticks.major : ticks.minor).push_back(decade);
                if (every != 1 || b - a > 10.0)
                    continue; // minors between decades only when they stay readable
                for (int m = 2; m <= 9; ++m)
                {
                    double v = scaled(m, d);
                    if (!inside(v))
                        continue;
                    bool major = fewDecades && (m == 2 || m == 5);
                    (major ? ticks.major : ticks.minor).push_back(v);
                }
            }
            std::sort(ticks.major.begin(), ticks.major.end());
            bool exponents = false;
            for (double v : ticks.major)
                exponents |= floorLog10(v) < -3 || floorLog10(v) > 4;
            for (double v : ticks.major)
                ticks.labels.push_back(formatPower(v, exponents));
            return ticks;
        }

        // A float mask over the image: strokes take the max coverage per pixel, then the
        // mask is blended once in one colour, so joints of a polyline do not darken.
        class Coverage
        {
        public:
            Coverage(int width, int height) : mWidth(width), mHeight(height), mValues(std::size_t(width) * height, 0.0f)
            {}

            void clip(int x0, int y0, int x1, int y1)
            {
                mClip = {std::max(0, x0), std::max(0, y0), std::min(mWidth - 1, x1), std::min(mHeight - 1, y1)};
            }

            // A capsule of full width `width` around segment a-b: coverage of a pixel is how far
            // its centre is inside the edge, clamped to [0, 1] (one-pixel linear ramp).
            void segment(glm::dvec2 a, glm::dvec2 b, double width)
            {
                if (!clipSegment(a, b, width + 2.0))
                    return;
                double half = std::max(width, 1.0) * 0.5;
                double fade = std::min(width, 1.0);
                int x0 = int(std::floor(std::min(a.x, b.x) - half - 1.0)),
                    x1 = int(std::ceil(std::max(a.x, b.x) + half + 1.0));
                int y0 = int(std::floor(std::min(a.y, b.y) - half - 1.0)),
                    y1 = int(std::ceil(std::max(a.y, b.y) + half + 1.0));
                glm::dvec2 ab = b - a;
                double len2 = glm::dot(ab, ab);
                forEach(x0, y0, x1, y1, [&](int x, int y) {
                    glm::dvec2 p(x + 0.5, y + 0.5);
                    double t = len2 > 0.0 ? std::clamp(glm::dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
                    double d = glm::length(p - (a + t * ab));
                    return float(std::clamp(half + 0.5 - d, 0.0, 1.0) * fade);
                });
            }

            void disc(glm::dvec2 c, double radius)
            {
                forEach(int(std::floor(c.x - radius - 1)), int(std::floor(c.y - radius - 1)),
                        int(std::ceil(c.x + radius + 1)), int(std::ceil(c.y + radius + 1)), [&](int x, int y) {
                            double d = glm::length(glm::dvec2(x + 0.5, y + 0.5) - c);
                            return float(std::clamp(radius + 0.5 - d, 0.0, 1.0));
                        });
            }

            void ring(glm::dvec2 c, double radius, double width)
            {
                double r = radius + width;
                forEach(int(std::floor(c.x - r - 1)), int(std::floor(c.y - r - 1)), int(std::ceil(c.x + r + 1)),
                        int(std::ceil(c.y + r + 1)), [&](int x, int y) {
                            double d = std::abs(glm::length(glm::dvec2(x + 0.5, y + 0.5) - c) - radius);
                            return float(std::clamp(width * 0.5 + 0.5 - d, 0.0, 1.0));
                        });
            }

            // Blend the mask onto the image in one colour and clear it.
            void flush(Image& image, const glm::vec3& colour, float opacity = 1.0f)
            {
                if (mX0 > mX1)
                    return;
                for (int y = mY0; y <= mY1; ++y)
                    for (int x = mX0; x <= mX1; ++x)
                    {
                        float& c = mValues[std::size_t(y) * mWidth + x];
                        if (c > 0.0f)
                        {
                            glm::vec4& p = image.at(x, y);
                            float a = c * opacity;
                            p = glm::vec4(glm::vec3(p) * (1.0f - a) + colour * a, 1.0f);
                            c = 0.0f;
                        }
                    }
                mX0 = mY0 = std::numeric_limits<int>::max();
                mX1 = mY1 = std::numeric_limits<int>::min();
            }

        private:
            template <typename F> void forEach(int x0, int y0, int x1, int y1, F coverage)
            {
                x0 = std::max(x0, mClip[0]), y0 = std::max(y0, mClip[1]);
                x1 = std::min(x1, mClip[2]), y1 = std::min(y1, mClip[3]);
                for (int y = y0; y <= y1; ++y)
                    for (int x = x0; x <= x1; ++x)
                    {
                        float c = coverage(x, y);
                        if (c <= 0.0f)
                            continue;
                        float& v = mValues[std::size_t(y) * mWidth + x];
                        v = std::max(v, c);
                        mX0 = std::min(mX0, x), mX1 = std::max(mX1, x);
                        mY0 = std::min(mY0, y), mY1 = std::max(mY1, y);
                    }
            }

            // Liang-Barsky against the clip box grown by `grow`; false when nothing is left.
            bool clipSegment(glm::dvec2& a, glm::dvec2& b, double grow) const
            {
                if (!std::isfinite(a.x) || !std::isfinite(a.y) || !std::isfinite(b.x) || !std::isfinite(b.y))
                    return false;
                double lo[2] = {mClip[0] - grow, mClip[1] - grow}, hi[2] = {mClip[2] + 1 + grow, mClip[3] + 1 + grow};
                double t0 = 0.0, t1 = 1.0;
                glm::dvec2 d = b - a;
                for (int axis = 0; axis < 2; ++axis)
                {
                    if (d[axis] == 0.0)
                    {
                        if (a[axis] < lo[axis] || a[axis] > hi[axis])
                            return false;
                        continue;
                    }
                    double ta = (lo[axis] - a[axis]) / d[axis], tb = (hi[axis] - a[axis]) / d[axis];
                    t0 = std::max(t0, std::min(ta, tb));
                    t1 = std::min(t1, std::max(ta, tb));
                }
                if (t0 > t1)
                    return false;
                glm::dvec2 start = a + t0 * d;
                b = a + t1 * d;
                a = start;
                return true;
            }

            int mWidth, mHeight;
            std::vector<float> mValues;
            std::array<int, 4> mClip{0, 0, mWidth - 1, mHeight - 1};
            int mX0 = std::numeric_limits<int>::max(), mY0 = std::numeric_limits<int>::max();
            int mX1 = std::numeric_limits<int>::min(), mY1 = std::numeric_limits<int>::min();
        };

        void blendPixel(Image& image, int x, int y, const glm::vec3& colour, float alpha = 1.0f)
        {
            if (x < 0 || y < 0 || x >= image.width || y >= image.height)
                return;
            glm::vec4& p = image.at(x, y);
            p = glm::vec4(glm::vec3(p) * (1.0f - alpha) + colour * alpha, 1.0f);
        }

        void fillRect(Image& image, int x0, int y0, int x1, int y1, const glm::vec3& colour, float alpha = 1.0f)
        {
            for (int y = y0; y <= y1; ++y)
                for (int x = x0; x <= x1; ++x)
                    blendPixel(image, x, y, colour, alpha);
        }

        int textWidth(const std::string& text, int scale = 1) { return int(text.size()) * kGlyphW * scale; }

        // Text with its top-left corner at (x, y); each font pixel becomes scale x scale pixels.
        void drawText(Image& image, int x, int y, const std::string& text, int scale = 1,
                      const glm::vec3& colour = kInk)
        {
            for (char ch : text)
            {
                int code = static_cast<unsigned char>(ch);
                const std::uint8_t* rows = kFont[(code >= 32 && code <= 126 ? code : '?') - 32];
                for (int r = 0; r < kGlyphH; ++r)
                    for (int c = 0; c < kGlyphW; ++c)
                        if (rows[r] & (0x80 >> c))
                            fillRect(image, x + c * scale, y + r * scale, x + (c + 1) * scale - 1,
                                     y + (r + 1) * scale - 1, colour);
                x += kGlyphW * scale;
            }
        }

        // Outline marker of `shape` centred at c with half-size r.
        void markerShape(Coverage& mask, char shape, glm::dvec2 c, double r, double width)
        {
            switch (shape)
            {
            case 'o':
                mask.ring(c, r, width);
                break;
            case 's':
            {
                glm::dvec2 p[4] = {c + glm::dvec2(-r, -r), c + glm::dvec2(r, -r), c + glm::dvec2(r, r),
                                   c + glm::dvec2(-r, r)};
                for (int i = 0; i < 4; ++i)
                    mask.segment(p[i], p[(i + 1) % 4], width);
                break;
            }
            case '^':
            {
                double h = r * 1.15;
                glm::dvec2 p[3] = {c + glm::dvec2(0.0, -h), c + glm::dvec2(h * 0.866 * 1.15, h * 0.5 * 1.15),
                                   c + glm::dvec2(-h * 0.866 * 1.15, h * 0.5 * 1.15)};
                for (int i = 0; i < 3; ++i)
                    mask.segment(p[i], p[(i + 1) % 3], width);
                break;
            }
            default:
                mask.segment(c + glm::dvec2(-r, -r), c + glm::dvec2(r, r), width);
                mask.segment(c + glm::dvec2(-r, r), c + glm::dvec2(r, -r), width);
                break;
            }
        }

        // Dashes along a-b (axis-aligned or not), 7 px on, 4 px off.
        void dashedLine(Coverage& mask, glm::dvec2 a, glm::dvec2 b, double width)
        {
            double len = glm::length(b - a);
            if (!(len > 0.0) || !std::isfinite(len))
                return;
            glm::dvec2 dir = (b - a) / len;
            for (double s = 0.0; s < len; s += 11.0)
                mask.segment(a + dir * s, a + dir * std::min(s + 7.0, len), width);
        }

        struct Range
        {
            double lo = std::numeric_limits<double>::infinity(), hi = -std::numeric_limits<double>::infinity();
            void add(double v) { lo = std::min(lo, v), hi = std::max(hi, v); }
            bool empty() const { return lo > hi; }
        };

        // The axis range: the given one if usable, else the data's with a 5% margin each side.
        void settleRange(double givenMin, double givenMax, const Range& data, bool logScale, double& outMin,
                         double& outMax)
        {
            if (usable(givenMin, logScale) && usable(givenMax, logScale) && givenMin < givenMax)
            {
                outMin = givenMin, outMax = givenMax;
                return;
            }
            if (data.empty())
            {
                outMin = logScale ? 1.0 : 0.0, outMax = logScale ? 10.0 : 1.0;
                return;
            }
            double lo = logScale ? std::log10(data.lo) : data.lo, hi = logScale ? std::log10(data.hi) : data.hi;
            double margin = (hi - lo) * 0.05;
            if (!(margin > 0.0) || !std::isfinite(margin)) // one value: a decade, or 10% of it, around it
                margin = logScale ? 0.5 : lo != 0.0 ? std::abs(lo) * 0.1 : 1.0;
            lo -= margin, hi += margin;
            outMin = logScale ? std::pow(10.0, lo) : lo;
            outMax = logScale ? std::pow(10.0, hi) : hi;
            if (!std::isfinite(outMin) || !std::isfinite(outMax) || !(outMin < outMax))
                outMin = data.lo, outMax = data.hi > data.lo ? data.hi : data.lo + 1.0;
        }

        // Frame plus the ticks that shaped it.
        struct Layout
        {
            PlotFrame frame;
            PlotTicks xTicks, yTicks;
            int width = 0, height = 0;
        };

        double axisPixel(double v, double lo, double hi, bool logScale, double p0, double p1)
        {
            if (logScale)
            {
                if (!(v > 0.0))
                    return std::numeric_limits<double>::quiet_NaN();
                v = std::log10(v), lo = std::log10(lo), hi = std::log10(hi);
            }
            return p0 + (v - lo) / (hi - lo) * (p1 - p0);
        }

        // Largest major count whose labels keep `gap` pixels apart along the axis.
        PlotTicks fittingTicks(double lo, double hi, bool logScale, int maxMajor, double p0, double p1, bool horizontal)
        {
            PlotTicks ticks;
            for (int n = std::max(maxMajor, 2); n >= 2; --n)
            {
                ticks = plotTicks(lo, hi, logScale, n);
                bool fits = true;
                for (std::size_t i = 1; i < ticks.major.size() && fits; ++i)
                {
                    double d = std::abs(axisPixel(ticks.major[i], lo, hi, logScale, p0, p1) -
                                        axisPixel(ticks.major[i - 1], lo, hi, logScale, p0, p1));
                    double need = horizontal
                                      ? (textWidth(ticks.labels[i]) + textWidth(ticks.labels[i - 1])) * 0.5 + 12.0
                                      : kGlyphH + 6.0;
                    fits = d >= need;
                }
                if (fits)
                    break;
            }
            return ticks;
        }

        Layout layout(const PlotSpec& spec)
        {
            Layout out;
            PlotFrame& f = out.frame;
            out.width = std::max(spec.width, 200);
            out.height = std::max(spec.height, 150);
            f.logX = spec.logX, f.logY = spec.logY;

            Range xs, ys;
            for (const PlotSeries& s : spec.series)
                for (const glm::dvec2& p : s.points)
                    if (usable(p.x, f.logX) && usable(p.y, f.logY))
                        xs.add(p.x), ys.add(p.y), f.hasData = true;
            for (const PlotMarker& m : spec.markers)
                if (usable(m.point.x, f.logX) && usable(m.point.y, f.logY))
                    xs.add(m.point.x), ys.add(m.point.y), f.hasData = true;
            for (const PlotRule& r : spec.rules)
                if (usable(r.value, r.vertical ? f.logX : f.logY))
                    (r.vertical ? xs : ys).add(r.value);
            settleRange(spec.xMin, spec.xMax, xs, f.logX, f.xMin, f.xMax);
            settleRange(spec.yMin, spec.yMax, ys, f.logY, f.yMin, f.yMax);

            // Vertical: title, y label above the axis, plot, tick labels, x label.
            int top = kPad;
            if (!spec.title.empty())
                top += kGlyphH * kTitleScale + 8;
            top += spec.yLabel.empty() ? kGlyphH / 2 : kGlyphH + 8;
            int bottom = out.height - kPad - kGlyphH - kTickGap - kTickLen;
            if (!spec.xLabel.empty())
                bottom -= kGlyphH + 8;
            f.top = top + 0.5, f.bottom = bottom + 0.5;

            out.yTicks = fittingTicks(f.yMin, f.yMax, f.logY, std::max(2, (bottom - top) / 45), f.bottom, f.top, false);
            int labelW = 0;
            for (const std::string& s : out.yTicks.labels)
                labelW = std::max(labelW, textWidth(s));
            int left = kPad + labelW + kTickGap + kTickLen;
            int right = out.width - 1 - 3 * kGlyphW - kPad;
            f.left = left + 0.5, f.right = right + 0.5;
            out.xTicks = fittingTicks(f.xMin, f.xMax, f.logX, std::max(2, (right - left) / 80), f.left, f.right, true);
            return out;
        }
    }

    glm::dvec2 PlotFrame::toPixel(const glm::dvec2& p) const
    {
        return {axisPixel(p.x, xMin, xMax, logX, left, right), axisPixel(p.y, yMin, yMax, logY, bottom, top)};
    }

    PlotTicks plotTicks(double min, double max, bool logScale, int maxMajor)
    {
        if (!(min < max) || !std::isfinite(min) || !std::isfinite(max) || (logScale && !(min > 0.0)))
            return {};
        return logScale ? logTicks(min, max, maxMajor) : linearTicks(min, max, maxMajor);
    }

    PlotFrame plotFrame(const PlotSpec& spec) { return layout(spec).frame; }

    Image drawPlot(const PlotSpec& spec)
    {
        Layout lay = layout(spec);
        const PlotFrame& f = lay.frame;
        Image image(lay.width, lay.height, glm::vec4(1.0f));
        Coverage mask(lay.width, lay.height);

        // Frame lines sit on pixel columns/rows L, R, T, B (centres at f.left ... f.bottom).
        int L = int(f.left), R = int(f.right), T = int(f.top), B = int(f.bottom);
        auto xPixel = [&](double v) { return axisPixel(v, f.xMin, f.xMax, f.logX, f.left, f.right); };
        auto yPixel = [&](double v) { return axisPixel(v, f.yMin, f.yMax, f.logY, f.bottom, f.top); };
        auto column = [&](double v) { return int(std::floor(xPixel(v))); };
        auto row = [&](double v) { return int(std::floor(yPixel(v))); };

        // Grid: minor first so majors win where they meet.
        for (double v : lay.xTicks.minor)
            fillRect(image, column(v), T + 1, column(v), B - 1, kMinorGrid);
        for (double v : lay.yTicks.minor)
            fillRect(image, L + 1, row(v), R - 1, row(v), kMinorGrid);
        for (double v : lay.xTicks.major)
            fillRect(image, column(v), T + 1, column(v), B - 1, kGrid);
        for (double v : lay.yTicks.major)
            fillRect(image, L + 1, row(v), R - 1, row(v), kGrid);

        // Data, clipped to the inside of the frame.
        mask.clip(L + 1, T + 1, R - 1, B - 1);
        std::vector<glm::vec3> seriesColour;
        int nextColour = 0;
        for (const PlotSeries& s : spec.series)
        {
            bool automatic = s.colour.r < 0.0f || s.colour.g < 0.0f || s.colour.b < 0.0f;
            seriesColour.push_back(automatic ? kPalette[nextColour++ % kPaletteSize]
                                             : glm::clamp(s.colour, 0.0f, 1.0f));
        }
        for (const PlotRule& r : spec.rules)
        {
            double p = r.vertical ? xPixel(r.value) : yPixel(r.value);
            if (!std::isfinite(p))
                continue;
            if (r.vertical)
                dashedLine(mask, {p, f.top}, {p, f.bottom}, 1.5);
            else
                dashedLine(mask, {f.left, p}, {f.right, p}, 1.5);
            mask.flush(image, glm::clamp(r.colour, 0.0f, 1.0f));
        }
        std::vector<glm::dvec2> samples; // data positions in pixels, for placing the legend
        for (std::size_t i = 0; i < spec.series.size(); ++i)
        {
            const PlotSeries& s = spec.series[i];
            double width = lineWidthOf(s);
            glm::dvec2 previous(std::numeric_limits<double>::quiet_NaN());
            for (const glm::dvec2& p : s.points)
            {
                glm::dvec2 q = usable(p.x, f.logX) && usable(p.y, f.logY) ? f.toPixel(p) : glm::dvec2(NAN);
                bool ok = std::isfinite(q.x) && std::isfinite(q.y);
                if (ok)
                    samples.push_back(q);
                if (ok && s.lines && std::isfinite(previous.x))
                {
                    mask.segment(previous, q, width);
                    double len = glm::length(q - previous);
                    for (double t = 4.0; t < len && t < 4096.0; t += 4.0)
                        samples.push_back(previous + (q - previous) * (t / len));
                }
                previous = q; // a skipped point leaves NaN: the next segment is not drawn
            }
            mask.flush(image, seriesColour[i]);
        }
        for (std::size_t i = 0; i < spec.series.size(); ++i) // markers over all lines
        {
            const PlotSeries& s = spec.series[i];
            if (!s.markers)
                continue;
            double width = lineWidthOf(s);
            for (const glm::dvec2& p : s.points)
                if (usable(p.x, f.logX) && usable(p.y, f.logY))
                    mask.disc(f.toPixel(p), std::max(3.0, width * 1.5));
            mask.flush(image, seriesColour[i]);
        }
        for (const PlotMarker& m : spec.markers)
        {
            if (!usable(m.point.x, f.logX) || !usable(m.point.y, f.logY))
                continue;
            glm::dvec2 q = f.toPixel(m.point);
            for (int k = 0; k < 4; ++k)
                samples.push_back(q); // a marker weighs more than a line sample
            markerShape(mask, m.shape, q, 6.0, 2.0);
            mask.flush(image, glm::clamp(m.colour, 0.0f, 1.0f));
        }

        // Frame, ticks and tick labels.
        fillRect(image, L, T, R, T, kInk);
        fillRect(image, L, B, R, B, kInk);
        fillRect(image, L, T, L, B, kInk);
        fillRect(image, R, T, R, B, kInk);
        for (double v : lay.xTicks.minor)
            fillRect(image, column(v), B + 1, column(v), B + kMinorTickLen, kInk);
        for (double v : lay.yTicks.minor)
            fillRect(image, L - kMinorTickLen, row(v), L - 1, row(v), kInk);
        for (std::size_t i = 0; i < lay.xTicks.major.size(); ++i)
        {
            int x = column(lay.xTicks.major[i]);
            fillRect(image, x, B + 1, x, B + kTickLen, kInk);
            const std::string& label = lay.xTicks.labels[i];
            int tx = std::clamp(x - textWidth(label) / 2 + 1, 0, lay.width - textWidth(label));
            drawText(image, tx, B + kTickLen + kTickGap, label);
        }
        for (std::size_t i = 0; i < lay.yTicks.major.size(); ++i)
        {
            int y = row(lay.yTicks.major[i]);
            fillRect(image, L - kTickLen, y, L - 1, y, kInk);
            const std::string& label = lay.yTicks.labels[i];
            drawText(image, L - kTickLen - kTickGap - textWidth(label), y - kGlyphH / 2 - 1, label);
        }

        // Axis labels and title.
        if (!spec.xLabel.empty())
            drawText(image, (L + R) / 2 - textWidth(spec.xLabel) / 2, B + kTickLen + kTickGap + kGlyphH + 8,
                     spec.xLabel);
        if (!spec.yLabel.empty())
            drawText(image, kPad, T - kGlyphH - 8, spec.yLabel);
        if (!spec.title.empty())
            drawText(image, (L + R) / 2 - textWidth(spec.title, kTitleScale) / 2, kPad, spec.title, kTitleScale);
        if (!f.hasData)
        {
            const std::string text = "no data";
            drawText(image, (L + R) / 2 - textWidth(text, 2) / 2, (T + B) / 2 - kGlyphH, text, 2, glm::vec3(0.45f));
        }

        // Legend: series, then markers, then rules; in the corner covering the fewest samples.
        struct Entry
        {
            const std::string* label;
            glm::vec3 colour;
            int kind; // 0 series, 1 marker, 2 rule
            std::size_t index;
        };
        std::vector<Entry> entries;
        for (std::size_t i = 0; i < spec.series.size(); ++i)
            if (!spec.series[i].label.empty())
                entries.push_back({&spec.series[i].label, seriesColour[i], 0, i});
        for (std::size_t i = 0; i < spec.markers.size(); ++i)
            if (!spec.markers[i].label.empty())
                entries.push_back({&spec.markers[i].label, glm::clamp(spec.markers[i].colour, 0.0f, 1.0f), 1, i});
        for (std::size_t i = 0; i < spec.rules.size(); ++i)
            if (!spec.rules[i].label.empty())
                entries.push_back({&spec.rules[i].label, glm::clamp(spec.rules[i].colour, 0.0f, 1.0f), 2, i});
        constexpr int kRow = 18, kSample = 30, kInset = 8, kInner = 8;
        int rows =
            std::min(int(entries.size()), std::max(0, (B - T - 2 * kInset - 2 * kInner + kRow - kGlyphH) / kRow));
        if (rows > 0)
        {
            int textW = 0;
            for (int i = 0; i < rows; ++i)
                textW = std::max(textW, textWidth(*entries[std::size_t(i)].label));
            int boxW = std::min(kInner + kSample + 8 + textW + kInner, R - L - 2 * kInset);
            int boxH = kInner + rows * kRow - (kRow - kGlyphH) + kInner;
            // Corners in order of preference: top right, top left, bottom right, bottom left.
            const int corners[4][2] = {{R - kInset - boxW, T + kInset},
                                       {L + kInset + 1, T + kInset},
                                       {R - kInset - boxW, B - kInset - boxH},
                                       {L + kInset + 1, B - kInset - boxH}};
            int best = 0;
            std::size_t bestCount = std::numeric_limits<std::size_t>::max();
            for (int c = 0; c < 4; ++c)
            {
                std::size_t count = 0;
                for (const glm::dvec2& p : samples)
                    count += p.x >= corners[c][0] - 3 && p.x <= corners[c][0] + boxW + 3 && p.y >= corners[c][1] - 3 &&
                             p.y <= corners[c][1] + boxH + 3;
                if (count < bestCount)
                    best = c, bestCount = count;
            }
            int x0 = corners[best][0], y0 = corners[best][1];
            fillRect(image, x0, y0, x0 + boxW, y0 + boxH, glm::vec3(1.0f), 0.9f);
            fillRect(image, x0, y0, x0 + boxW, y0, glm::vec3(0.6f));
            fillRect(image, x0, y0 + boxH, x0 + boxW, y0 + boxH, glm::vec3(0.6f));
            fillRect(image, x0, y0, x0, y0 + boxH, glm::vec3(0.6f));
            fillRect(image, x0 + boxW, y0, x0 + boxW, y0 + boxH, glm::vec3(0.6f));
            mask.clip(x0 + 1, y0 + 1, x0 + boxW - 1, y0 + boxH - 1);
            for (int i = 0; i < rows; ++i)
            {
                const Entry& e = entries[std::size_t(i)];
                int textTop = y0 + kInner + i * kRow;
                double cy = textTop + 6.5; // middle of the lower-case letters, between pixel rows
                glm::dvec2 a(x0 + kInner, cy), b(x0 + kInner + kSample, cy), mid = (a + b) * 0.5;
                if (e.kind == 0)
                {
                    const PlotSeries& s = spec.series[e.index];
                    double width = lineWidthOf(s);
                    if (s.lines || !s.markers)
                        mask.segment(a, b, width);
                    mask.flush(image, e.colour);
                    if (s.markers)
                        mask.disc(mid, std::max(3.0, width * 1.5));
                }
                else if (e.kind == 1)
                    markerShape(mask, spec.markers[e.index].shape, mid, 5.0, 2.0);
                else
                    dashedLine(mask, a, b, 1.5);
                mask.flush(image, e.colour);
                drawText(image, x0 + kInner + kSample + 8, textTop, *e.label);
            }
        }
        return image;
    }

    Result<void> writePlot(const std::string& path, const PlotSpec& spec)
    {
        Result<void> written = writePng(path, drawPlot(spec));
        if (!written.ok() && written.error().file.empty())
            return fail(path, "plot", written.error().message());
        return written;
    }
}
