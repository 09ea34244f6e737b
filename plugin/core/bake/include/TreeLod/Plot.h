// Plot: PNG line plots drawn on the CPU into an Image (for `treelod bench`), with no
// plotting package: nice 1-2-5 ticks (decades on log axes), grid, labels in an embedded
// 6x13 bitmap font (printable ASCII; other bytes draw as '?'), anti-aliased lines,
// markers, dashed rules and a legend in the corner that hides the fewest data.
// Output depends only on the spec (no threads, no clocks): the same spec gives the same pixels.
#pragma once

#include "TreeLod/Image.h"
#include "TreeLod/Result.h"

#include <glm/glm.hpp>

#include <cmath>
#include <string>
#include <vector>

namespace TreeLod
{
    /// One data line. Non-finite points, and on a log axis non-positive ones, are skipped
    /// and break the line (a gap); points outside the axis ranges are clipped.
    struct PlotSeries
    {
        std::string label;              ///< legend text ("" = not in the legend)
        std::vector<glm::dvec2> points; ///< data, drawn in this order; may be empty
        glm::vec3 colour{-1.0f};        ///< sRGB 0..1; any negative = next colour of the palette
        bool lines = true, markers = true;
        /// Pixels (not positive or finite: 2); markers are discs of radius max(3, 1.5 x width).
        float lineWidth = 2.0f;
    };

    /// One labelled point (e.g. "polygonal reference", "one-quad floor"), drawn as an outline.
    struct PlotMarker
    {
        std::string label; ///< legend text ("" = not in the legend)
        glm::dvec2 point{0.0};
        glm::vec3 colour{0.0f}; ///< sRGB 0..1
        char shape = 'x';       ///< 'x', 'o' (circle), 's' (square), '^' (triangle); others draw 'x'
    };

    /// A dashed horizontal line at y = value, or vertical (vertical = true) at x = value.
    struct PlotRule
    {
        std::string label; ///< legend text ("" = not in the legend)
        double value = 0.0;
        bool vertical = false;
        glm::vec3 colour{0.4f}; ///< sRGB 0..1
    };

    struct PlotSpec
    {
        std::string title, xLabel, yLabel; ///< any may be empty; the y label is drawn above the axis
        bool logX = false, logY = false;   ///< log10 axes
        std::vector<PlotSeries> series;
        std::vector<PlotMarker> markers;
        std::vector<PlotRule> rules;
        int width = 960, height = 600; ///< pixels; clamped to at least 200 x 150
        /// Axis ranges: from the data (series, markers, rules) with a 5% margin on each side
        /// (in log10 space on a log axis), unless both ends of an axis are finite (and, on a
        /// log axis, positive) with min < max.
        double xMin = NAN, xMax = NAN, yMin = NAN, yMax = NAN;
    };

    /// Tick positions of one axis, in data units, ascending, all inside [min, max].
    struct PlotTicks
    {
        std::vector<double> major;       ///< labelled, with a grid line
        std::vector<std::string> labels; ///< one per major tick
        std::vector<double> minor;       ///< log axes only: 2..9 x 10^k, or unlabelled decades
    };

    /// Ticks for the range [min, max] (min < max; on a log axis both > 0; else no ticks).
    /// Linear: the smallest step of 1, 2 or 5 x 10^k giving at most maxMajor ticks (below 2
    /// counts as 2); a narrow range may get just one, a span below the precision of its values none.
    /// Log: majors on decades (every 1, 2, 5, 10... decades), plus 2 and 5 x 10^k when fewer than
    /// two decades fall inside; a range narrower than a decade gets linear ticks.
    /// Labels use the decimals the step needs; exponents ("2e6") when the largest linear tick is
    /// from 1e6 or below 1e-3, and on a log axis with a tick outside 0.001..10000 for every
    /// label from 1e3 or 1e-3 on.
    PlotTicks plotTicks(double min, double max, bool logScale, int maxMajor = 8);

    /// Where drawPlot puts things: the axis ranges it settled on and the plot area in
    /// continuous pixel coordinates (x right, y down; pixel (i, j) covers [i, i+1] x [j, j+1]).
    struct PlotFrame
    {
        double xMin = 0.0, xMax = 1.0, yMin = 0.0, yMax = 1.0; ///< data units
        bool logX = false, logY = false;
        double left = 0.0, top = 0.0, right = 1.0, bottom = 1.0; ///< pixels
        bool hasData = false;                                    ///< any drawable series point or marker

        /// Pixel position of a data point (not clamped); NaN for a non-positive value on a log axis.
        glm::dvec2 toPixel(const glm::dvec2& p) const;
    };

    /// The frame drawPlot(spec) uses.
    PlotFrame plotFrame(const PlotSpec& spec);

    /// Draw the plot: white opaque background, axes, grid, labels, title, data, legend.
    /// Without drawable data it is still a plot (axes, title) reading "no data".
    Image drawPlot(const PlotSpec& spec);

    /// drawPlot, then writePng (atomic); the Error names the path.
    Result<void> writePlot(const std::string& path, const PlotSpec& spec);
}
