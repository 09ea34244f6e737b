// Plot: ticks, the data-to-pixel mapping, legend placement, gaps, log axes, "no data",
// errors and determinism; writes example plots to $TREELOD_TEST_OUT/plot for a look.
#include "TreeLod/Plot.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>

using namespace TreeLod;

namespace
{
    std::filesystem::path testOut(const std::string& name)
    {
        const char* dir = std::getenv("TREELOD_TEST_OUT");
        std::filesystem::path root = dir ? dir : std::filesystem::temp_directory_path() / "treelod-test-out";
        root /= "plot";
        std::filesystem::create_directories(root);
        return root / name;
    }

    // Steps between ticks are one constant 1, 2 or 5 x 10^k, every tick a whole multiple of it.
    void expectNiceLinear(double lo, double hi, int maxMajor)
    {
        SCOPED_TRACE(testing::Message() << "[" << lo << ", " << hi << "] max " << maxMajor);
        PlotTicks t = plotTicks(lo, hi, false, maxMajor);
        ASSERT_GE(t.major.size(), 2u);
        ASSERT_LE(t.major.size(), std::size_t(maxMajor));
        ASSERT_EQ(t.labels.size(), t.major.size());
        EXPECT_TRUE(t.minor.empty());
        double step = t.major[1] - t.major[0];
        double mantissa = step / std::pow(10.0, std::floor(std::log10(step) + 1e-9));
        EXPECT_TRUE(std::abs(mantissa - 1) < 1e-6 || std::abs(mantissa - 2) < 1e-6 || std::abs(mantissa - 5) < 1e-6)
            << "step " << step;
        for (std::size_t i = 0; i < t.major.size(); ++i)
        {
            EXPECT_GE(t.major[i], lo - 1e-9 * step);
            EXPECT_LE(t.major[i], hi + 1e-9 * step);
            EXPECT_NEAR(t.major[i] / step, std::round(t.major[i] / step), 1e-6);
            if (i > 0)
            {
                EXPECT_NEAR(t.major[i] - t.major[i - 1], step, 1e-6 * step);
                EXPECT_NE(t.labels[i], t.labels[i - 1]);
            }
        }
        // The next smaller 1-2-5 step would need more than maxMajor ticks.
        EXPECT_GT((hi - lo) / (step * (mantissa == 2 ? 0.5 : mantissa == 5 ? 0.4 : 0.5)), maxMajor - 2.0);
    }

    std::size_t countPixels(const Image& image, int x0, int y0, int x1, int y1, bool (*test)(const glm::vec4&))
    {
        std::size_t n = 0;
        for (int y = std::max(y0, 0); y <= std::min(y1, image.height - 1); ++y)
            for (int x = std::max(x0, 0); x <= std::min(x1, image.width - 1); ++x)
                n += test(image.at(x, y));
        return n;
    }

    bool isRed(const glm::vec4& p) { return p.r > 0.9f && p.g < 0.15f && p.b < 0.15f; }
    bool isDark(const glm::vec4& p) { return p.r < 0.2f && p.g < 0.2f && p.b < 0.2f; }

    PlotSpec diagonal(glm::vec3 colour)
    {
        PlotSpec spec;
        PlotSeries s;
        s.colour = colour;
        s.markers = false;
        s.lineWidth = 3.0f;
        for (int i = 0; i <= 20; ++i)
            s.points.push_back({i, i}); // runs past the set range on purpose
        spec.series.push_back(s);
        spec.xMin = 0.0, spec.xMax = 10.0, spec.yMin = 0.0, spec.yMax = 10.0;
        return spec;
    }

    // A plot like the ones `treelod bench` draws: error against cost for several techniques.
    PlotSpec benchLike()
    {
        PlotSpec spec;
        spec.title = "Image error vs. triangles (oak, 40 m)";
        spec.xLabel = "triangles per tree";
        spec.yLabel = "FLIP mean error";
        spec.logX = true;
        const char* names[] = {"polygon LOD (MeshLodGenerator)", "LODF (ours)", "billboard cloud", "impostor"};
        for (int k = 0; k < 4; ++k)
        {
            PlotSeries s;
            s.label = names[k];
            for (int i = 0; i <= 6; ++i)
            {
                double tris = 40.0 * std::pow(4.0, i) * (k + 1);
                s.points.push_back({tris, 0.02 + 0.25 / (1.0 + 0.002 * tris * (k + 1)) + 0.01 * k});
            }
            spec.series.push_back(s);
        }
        spec.markers.push_back({"polygonal reference", {260000.0, 0.0}, glm::vec3(0.0f), 'x'});
        spec.markers.push_back({"one-quad floor", {2.0, 0.31}, glm::vec3(0.2f), 's'});
        spec.rules.push_back({"FLIP budget 0.05", 0.05, false, glm::vec3(0.45f)});
        spec.rules.push_back({"", 1.0e4, true, glm::vec3(0.7f)});
        return spec;
    }
}

TEST(PlotTicks, linearStepsAreOneTwoFive)
{
    expectNiceLinear(0.0, 1.0, 8);
    expectNiceLinear(-3.7, 12.2, 8);
    expectNiceLinear(0.0013, 0.0091, 6);
    expectNiceLinear(1.0e6, 7.5e6, 8);
    expectNiceLinear(-0.5, 0.5, 5);
    expectNiceLinear(98.0, 102.0, 10);
    expectNiceLinear(-1.0e-7, 3.0e-7, 8);

    // Worked example: span 1, at most 8 ticks: 0.1 gives 11, so 0.2 (6 ticks).
    PlotTicks t = plotTicks(0.0, 1.0, false, 8);
    EXPECT_EQ(t.labels, (std::vector<std::string>{"0.0", "0.2", "0.4", "0.6", "0.8", "1.0"}));
    t = plotTicks(1.0e6, 7.5e6, false, 8);
    EXPECT_EQ(t.labels, (std::vector<std::string>{"1e6", "2e6", "3e6", "4e6", "5e6", "6e6", "7e6"}));
    t = plotTicks(-12.0, 37.0, false, 8);
    EXPECT_EQ(t.labels, (std::vector<std::string>{"-10", "0", "10", "20", "30"}));
    EXPECT_TRUE(plotTicks(1.0, 1.0, false).major.empty()); // no range, no ticks
}

TEST(PlotTicks, logAxesUseDecadesWithMinorTicks)
{
    PlotTicks t = plotTicks(0.5, 2.0e4, true, 8);
    EXPECT_EQ(t.major, (std::vector<double>{1.0, 10.0, 100.0, 1000.0, 10000.0}));
    EXPECT_EQ(t.labels, (std::vector<std::string>{"1", "10", "100", "1000", "10000"}));
    auto has = [&](double v) {
        for (double m : t.minor)
            if (std::abs(m - v) < 1e-9 * v)
                return true;
        return false;
    };
    EXPECT_TRUE(has(0.5) && has(0.9) && has(2.0) && has(50.0) && has(2000.0) && has(20000.0));
    EXPECT_FALSE(has(1.0) || has(10.0) || has(30000.0)); // decades are majors, 3e4 is outside
    for (double m : t.minor)
        EXPECT_TRUE(m >= 0.5 && m <= 2.0e4);

    // 21 decades, at most 8 labels: every 5th decade, unlabelled decades become minors.
    t = plotTicks(1.0e-8, 1.0e12, true, 8);
    EXPECT_EQ(t.labels, (std::vector<std::string>{"1e-5", "1", "1e5", "1e10"}));
    EXPECT_EQ(t.minor.size(), 21u - 4u);
    // Once one label needs an exponent, all from 1e3 on have one.
    EXPECT_EQ(plotTicks(2.0, 3.0e6, true, 8).labels,
              (std::vector<std::string>{"10", "100", "1e3", "1e4", "1e5", "1e6"}));

    // Only one decade inside: 2 and 5 x 10^k join the labels.
    t = plotTicks(0.3, 8.0, true, 8);
    EXPECT_EQ(t.labels, (std::vector<std::string>{"0.5", "1", "2", "5"}));

    // Less than a decade wide: plain 1-2-5 ticks.
    t = plotTicks(2.0, 7.0, true, 8);
    EXPECT_EQ(t.labels, (std::vector<std::string>{"2", "3", "4", "5", "6", "7"}));
    EXPECT_TRUE(plotTicks(-1.0, 10.0, true).major.empty()); // no log of a negative
}

// A known line must land where PlotFrame::toPixel says, and be clipped at the set range.
TEST(Plot, lineLandsWhereTheMappingSays)
{
    PlotSpec spec = diagonal(glm::vec3(1.0f, 0.0f, 0.0f));
    PlotFrame f = plotFrame(spec);
    Image image = drawPlot(spec);
    ASSERT_EQ(image.width, 960);
    ASSERT_EQ(image.height, 600);
    EXPECT_EQ(f.toPixel({0.0, 0.0}), glm::dvec2(f.left, f.bottom));
    EXPECT_EQ(f.toPixel({10.0, 10.0}), glm::dvec2(f.right, f.top));
    EXPECT_GT(f.right - f.left, 700.0);
    EXPECT_GT(f.bottom - f.top, 400.0);

    for (double v : {1.3, 3.7, 5.5, 8.1})
    {
        glm::dvec2 p = f.toPixel({v, v});
        EXPECT_TRUE(isRed(image.at(int(p.x), int(p.y)))) << "on the line at " << v;
        // 12 pixels straight down is off a 3-pixel line of slope < 1.
        EXPECT_FALSE(isRed(image.at(int(p.x), int(p.y) + 12))) << "below the line at " << v;
    }
    // Anti-aliased: the line edge has blended pixels between white and red.
    glm::dvec2 p = f.toPixel({4.9, 4.9});
    bool blended = false;
    for (int dy = -4; dy <= 4; ++dy)
    {
        const glm::vec4& c = image.at(int(p.x), int(p.y) + dy);
        blended |= c.r > 0.9f && c.g > 0.2f && c.g < 0.8f;
    }
    EXPECT_TRUE(blended);
    // The frame is drawn through left/bottom; nothing red leaks past the right edge.
    EXPECT_TRUE(isDark(image.at(int(f.left), int((f.top + f.bottom) / 2))));
    EXPECT_TRUE(isDark(image.at(int((f.left + f.right) / 2), int(f.bottom))));
    EXPECT_EQ(countPixels(image, int(f.right) + 1, 0, image.width - 1, image.height - 1, isRed), 0u);
    EXPECT_EQ(countPixels(image, 0, 0, image.width - 1, int(f.top) - 1, isRed), 0u);
}

// A diagonal from bottom left to top right leaves the top-left corner free: the legend goes there.
TEST(Plot, legendGoesWhereTheDataIsNot)
{
    PlotSpec plain = diagonal(glm::vec3(1.0f, 0.0f, 0.0f));
    PlotSpec labelled = plain;
    labelled.series[0].label = "diagonal";
    labelled.markers.push_back({"a marker", {50.0, 50.0}, glm::vec3(0.0f, 0.0f, 1.0f), 'o'}); // outside: legend only
    labelled.rules.push_back({"a rule", 50.0, false, glm::vec3(0.3f)});
    PlotFrame f = plotFrame(labelled);
    Image a = drawPlot(plain), b = drawPlot(labelled);
    std::size_t changed = 0, changedOutsideTopLeft = 0, darkInLegend = 0;
    double midX = (f.left + f.right) / 2, midY = (f.top + f.bottom) / 2;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x)
            if (a.at(x, y) != b.at(x, y))
            {
                ++changed;
                changedOutsideTopLeft += !(x > f.left && x < midX && y > f.top && y < midY);
                darkInLegend += isDark(b.at(x, y));
            }
    EXPECT_GT(changed, 500u);
    EXPECT_EQ(changedOutsideTopLeft, 0u);
    EXPECT_GT(darkInLegend, 100u); // the three labels' text

    // Data up the left side and along the top: the legend moves to the bottom right.
    PlotSpec corner = labelled;
    corner.series[0].points = {{0.2, 0.0}, {0.2, 9.8}, {10.0, 9.8}};
    Image c = drawPlot(corner);
    corner.series[0].label.clear();
    corner.markers.clear();
    corner.rules.clear();
    Image d = drawPlot(corner);
    std::size_t changedOutsideBottomRight = 0;
    for (int y = 0; y < c.height; ++y)
        for (int x = 0; x < c.width; ++x)
            if (c.at(x, y) != d.at(x, y))
                changedOutsideBottomRight += !(x > midX && x < f.right && y > midY && y < f.bottom);
    EXPECT_EQ(changedOutsideBottomRight, 0u);
}

// Non-positive values have no place on a log axis: they are skipped, the range ignores them.
TEST(Plot, logAxisSkipsNonPositiveValues)
{
    PlotSpec spec;
    spec.logX = spec.logY = true;
    PlotSeries s;
    s.points = {{-1.0, 5.0}, {0.0, 3.0}, {1.0, 1.0}, {10.0, -2.0}, {10.0, 10.0}, {100.0, 100.0}};
    spec.series.push_back(s);
    spec.rules.push_back({"zero", 0.0, false, glm::vec3(0.5f)});
    PlotFrame f = plotFrame(spec);
    EXPECT_TRUE(f.hasData);
    // Data 1..100 on both axes: 5% of two decades each side is 0.1 decade.
    EXPECT_NEAR(f.xMin, std::pow(10.0, -0.1), 1e-9);
    EXPECT_NEAR(f.xMax, std::pow(10.0, 2.1), 1e-9);
    EXPECT_NEAR(f.yMin, std::pow(10.0, -0.1), 1e-9);
    EXPECT_TRUE(std::isnan(f.toPixel({-1.0, 5.0}).x));
    // log10 mapping: 10 sits halfway between 1 and 100.
    EXPECT_NEAR(f.toPixel({10.0, 10.0}).x, (f.toPixel({1.0, 1.0}).x + f.toPixel({100.0, 100.0}).x) / 2, 1e-9);
    Image image = drawPlot(spec);
    EXPECT_EQ(image.width, 960);

    PlotSpec onlyBad;
    onlyBad.logY = true;
    onlyBad.series.emplace_back();
    onlyBad.series[0].points = {{1.0, 0.0}, {2.0, -3.0}};
    EXPECT_FALSE(plotFrame(onlyBad).hasData);
}

// NaN and infinite points are skipped and break the line; nothing crashes.
TEST(Plot, nonFinitePointsLeaveGaps)
{
    PlotSpec spec;
    PlotSeries s;
    s.colour = glm::vec3(1.0f, 0.0f, 0.0f);
    s.markers = false;
    s.points = {{0.0, 0.0}, {1.0, NAN}, {2.0, 2.0}, {INFINITY, 3.0}, {4.0, 4.0}, {5.0, 5.0}};
    spec.series.push_back(s);
    spec.markers.push_back({"nan marker", {NAN, 1.0}, glm::vec3(0.0f), 'o'});
    spec.rules.push_back({"nan rule", NAN, true, glm::vec3(0.0f)});
    PlotFrame f = plotFrame(spec);
    EXPECT_NEAR(f.xMin, -0.25, 1e-12);
    EXPECT_NEAR(f.xMax, 5.25, 1e-12);
    Image image = drawPlot(spec);
    // (0,0)-(2,2) and (2,2)-(4,4) are not joined; (4,4)-(5,5) is.
    glm::dvec2 gap1 = f.toPixel({1.1, 1.1}), gap2 = f.toPixel({3.1, 3.1}), line = f.toPixel({4.5, 4.5});
    EXPECT_FALSE(isRed(image.at(int(gap1.x), int(gap1.y))));
    EXPECT_FALSE(isRed(image.at(int(gap2.x), int(gap2.y))));
    EXPECT_TRUE(isRed(image.at(int(line.x), int(line.y))));
}

// No drawable data: axes, title and the words "no data" in the middle of the plot area.
TEST(Plot, emptySpecSaysNoData)
{
    PlotSpec spec;
    spec.title = "Nothing yet";
    PlotFrame f = plotFrame(spec);
    EXPECT_FALSE(f.hasData);
    EXPECT_EQ(f.xMin, 0.0);
    EXPECT_EQ(f.xMax, 1.0);
    Image image = drawPlot(spec);
    ASSERT_EQ(image.width, 960);
    for (const glm::vec4& p : image.pixels)
        ASSERT_EQ(p.a, 1.0f); // opaque
    auto grey = [](const glm::vec4& p) { return std::abs(p.r - 0.45f) < 0.01f && p.r == p.g && p.g == p.b; };
    int cx = int((f.left + f.right) / 2), cy = int((f.top + f.bottom) / 2);
    std::size_t text = countPixels(image, cx - 60, cy - 20, cx + 60, cy + 20, +grey);
    EXPECT_GT(text, 100u);
    EXPECT_GT(countPixels(image, 0, 0, image.width - 1, int(f.top) - 1, isDark), 100u); // the title
    EXPECT_TRUE(isDark(image.at(int(f.left), cy)));                                     // the frame

    // With data the words are gone.
    spec.series.emplace_back();
    spec.series[0].points = {{0.0, 0.0}, {1.0, 1.0}};
    Image withData = drawPlot(spec);
    EXPECT_EQ(countPixels(withData, cx - 60, cy - 20, cx + 60, cy + 20, +grey), 0u);
}

TEST(Plot, writeToBadPathNamesIt)
{
    const std::string path = "/nonexistent-treelod-dir/sub/plot.png";
    Result<void> r = writePlot(path, PlotSpec{});
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().message().find(path), std::string::npos) << r.error().message();
}

// Same spec, same pixels; the examples land in $TREELOD_TEST_OUT/plot to be looked at.
TEST(Plot, deterministicAndWritesExamples)
{
    PlotSpec spec = benchLike();
    Image a = drawPlot(spec), b = drawPlot(spec);
    ASSERT_EQ(a.pixels.size(), b.pixels.size());
    EXPECT_TRUE(a.pixels == b.pixels);

    const std::string path = testOut("example-log.png").string();
    Result<void> written = writePlot(path, spec);
    ASSERT_TRUE(written.ok()) << written.error().message();
    Result<Image> back = readImage(path);
    ASSERT_TRUE(back.ok()) << back.error().message();
    EXPECT_EQ(back->width, 960);
    EXPECT_EQ(back->height, 600);

    PlotSpec linear;
    linear.title = "Frame time vs. trees";
    linear.xLabel = "trees in view";
    linear.yLabel = "frame time (ms)";
    for (int k = 0; k < 3; ++k)
    {
        PlotSeries s;
        s.label = k == 0 ? "polygonal" : k == 1 ? "LODF" : "billboard cloud";
        s.lineWidth = 1.5f + k;
        s.markers = k != 2;
        for (int i = 0; i <= 10; ++i)
            s.points.push_back({i * 500.0, i == 7 && k == 1 ? NAN : 1.0 + i * (3.0 - k) * 0.8});
        linear.series.push_back(s);
    }
    linear.rules.push_back({"60 Hz", 1000.0 / 60.0, false, glm::vec3(0.8f, 0.1f, 0.1f)});
    linear.markers.push_back({"measured on H100", {2500.0, 2.0}, glm::vec3(0.0f), '^'});
    linear.markers.push_back({"target", {4000.0, 6.0}, glm::vec3(0.0f), 'o'});
    ASSERT_TRUE(writePlot(testOut("example-linear.png").string(), linear).ok());
    PlotSpec empty;
    empty.title = "Empty";
    empty.xLabel = "x";
    empty.yLabel = "y";
    ASSERT_TRUE(writePlot(testOut("example-empty.png").string(), empty).ok());
}

// Degenerate input still gives a sane frame and a finished picture.
TEST(Plot, oddInputsStillDrawAPlot)
{
    PlotSpec one; // a single point: the range opens 10% around it
    one.series.emplace_back();
    one.series[0].points = {{5.0, 5.0}, {5.0, 5.0}};
    PlotFrame f = plotFrame(one);
    EXPECT_NEAR(f.xMin, 4.5, 1e-12);
    EXPECT_NEAR(f.xMax, 5.5, 1e-12);
    EXPECT_FALSE(plotTicks(f.xMin, f.xMax, false).major.empty());

    PlotSpec odd;
    odd.width = 10; // clamped to 200 x 150
    odd.height = 10;
    odd.title = "caf\xc3\xa9 \x01";                                   // non-ASCII draws as '?'
    odd.series.push_back({"huge", {{-1e300, 1e-300}, {1e300, 2e-300}}}); // range overflows double
    for (int i = 0; i < 12; ++i)                                         // palette wraps, legend overflows
        odd.series.push_back({"series " + std::to_string(i), {{0.0, double(i)}, {1.0, double(i + 1)}}});
    odd.markers.push_back({"odd shape", {0.5, 0.5}, glm::vec3(0.0f), '?'});
    odd.series[1].lineWidth = -3.0f;
    // A span at the limit of double precision: no ticks rather than a hang.
    EXPECT_TRUE(plotTicks(1e12, 1e12 + 1e-3, false).major.empty());
    PlotSpec narrow;
    narrow.series.emplace_back();
    narrow.series[0].points = {{1e12, 1.0}, {std::nextafter(1e12, 2e12), 2.0}};
    EXPECT_EQ(drawPlot(narrow).width, 960);
    Image image = drawPlot(odd);
    EXPECT_EQ(image.width, 200);
    EXPECT_EQ(image.height, 150);
    f = plotFrame(odd);
    EXPECT_LT(f.left, f.right);
    EXPECT_LT(f.top, f.bottom);
    EXPECT_TRUE(std::isfinite(f.xMin) && std::isfinite(f.xMax) && f.xMin < f.xMax);
    ASSERT_TRUE(writePlot(testOut("example-odd.png").string(), odd).ok());
}
