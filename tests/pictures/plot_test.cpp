#include "envmis/pictures/plot.h"

#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <vector>

namespace envmis::pictures {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr Rgb8 kWhite{255, 255, 255};

// The plot area [x0, x1) x [y0, y1), found as the inside of the frame: the rows and
// columns that are mostly ink.
struct Area {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};

Area plot_area(const Image8& image) {
    std::vector<int> rows, columns;
    for (uint32_t y = 0; y < image.height; ++y) {
        uint32_t ink = 0;
        for (uint32_t x = 0; x < image.width; ++x) ink += pixel(image, x, y) == kPlotInk;
        if (2 * ink >= image.width) rows.push_back(int(y));
    }
    for (uint32_t x = 0; x < image.width; ++x) {
        uint32_t ink = 0;
        for (uint32_t y = 0; y < image.height; ++y) ink += pixel(image, x, y) == kPlotInk;
        if (2 * ink >= image.height) columns.push_back(int(x));
    }
    EXPECT_EQ(rows.size(), 2u) << "a frame has a top and a bottom line";
    EXPECT_EQ(columns.size(), 2u) << "a frame has a left and a right line";
    if (rows.size() < 2 || columns.size() < 2) return {0, 0, int(image.width), int(image.height)};
    return {columns.front() + 1, rows.front() + 1, columns.back(), rows.back()};
}

struct Point {
    int x, y;
};

std::vector<Point> pixels_of(const Image8& image, Rgb8 colour) {
    std::vector<Point> found;
    for (uint32_t y = 0; y < image.height; ++y)
        for (uint32_t x = 0; x < image.width; ++x)
            if (pixel(image, x, y) == colour) found.push_back({int(x), int(y)});
    return found;
}

bool inside(Point p, const Area& a) { return p.x >= a.x0 && p.x < a.x1 && p.y >= a.y0 && p.y < a.y1; }

// The mean row of `colour` in each column of the plot area that has it.
std::map<int, double> mean_rows(const Image8& image, Rgb8 colour, const Area& area) {
    std::map<int, std::pair<double, int>> sums;
    for (Point p : pixels_of(image, colour))
        if (inside(p, area)) sums[p.x].first += p.y, ++sums[p.x].second;
    std::map<int, double> means;
    for (const auto& [x, sum] : sums) means[x] = sum.first / sum.second;
    return means;
}

// A series drawn as one unbroken straight line from the lower left corner of the plot
// area to its upper right, within 4 pixels: markers pull the mean rows of columns they
// share with the line towards their centres.
void expect_rising_diagonal(const Image8& image, Rgb8 colour) {
    constexpr double kTolerance = 4;
    const Area area = plot_area(image);
    const auto rows = mean_rows(image, colour, area);
    ASSERT_GT(rows.size(), 10u);
    const auto [first, first_row] = *rows.begin();
    const auto [last, last_row] = *rows.rbegin();
    const int width = area.x1 - area.x0, height = area.y1 - area.y0;
    EXPECT_EQ(int(rows.size()), last - first + 1) << "a column without the line";
    EXPECT_LT(first - area.x0, width / 10);
    EXPECT_LT(area.x1 - last, width / 10);
    EXPECT_LT(area.y1 - first_row, height / 10.0);
    EXPECT_LT(last_row - area.y0, height / 10.0);
    // The least-squares line through the columns' mean rows.
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (const auto& [x, row] : rows) sx += x, sy += row, sxx += double(x) * x, sxy += x * row;
    const double n = double(rows.size()), slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
    const double offset = (sy - slope * sx) / n;
    for (const auto& [x, row] : rows) EXPECT_NEAR(row, offset + slope * x, kTolerance) << "column " << x;
}

// No pixel of `colour` left of, right of or above the plot area (the legend is below it).
void expect_only_inside_or_legend(const Image8& image, Rgb8 colour) {
    const Area area = plot_area(image);
    for (Point p : pixels_of(image, colour)) EXPECT_TRUE(inside(p, area) || p.y > area.y1) << p.x << "," << p.y;
}

Series series(std::vector<double> x, std::vector<double> y, std::string name = "s") {
    return {std::move(name), std::move(x), std::move(y), -1};
}

LinePlot line_plot(std::vector<Series> series, bool log = false) {
    LinePlot plot;
    plot.series = std::move(series);
    plot.log_x = plot.log_y = log;
    return plot;
}

BarChart bar_chart(std::vector<std::string> groups, std::vector<std::string> bars,
                   std::vector<std::vector<double>> values, double reference_line = kNaN) {
    BarChart chart;
    chart.groups = std::move(groups), chart.bars = std::move(bars), chart.values = std::move(values);
    chart.reference_line = reference_line;
    return chart;
}

std::vector<double> range(int n) {
    std::vector<double> v;
    for (int i = 0; i < n; ++i) v.push_back(i);
    return v;
}

// Height in pixels of a bar of `colour` in the plot area (its tallest column) and its
// lowest and highest rows.
struct Bar {
    int height = 0, top = -1, bottom = -1;
};

Bar bar(const Image8& image, Rgb8 colour) {
    const Area area = plot_area(image);
    std::map<int, Bar> columns;
    for (Point p : pixels_of(image, colour))
        if (inside(p, area)) {
            Bar& b = columns[p.x];
            ++b.height;
            b.top = b.top < 0 ? p.y : std::min(b.top, p.y);
            b.bottom = std::max(b.bottom, p.y);
        }
    Bar tallest;
    for (const auto& [x, b] : columns)
        if (b.height > tallest.height) tallest = b;
    return tallest;
}

TEST(Palette, TwentyColoursApartFromEachOtherFromWhiteAndFromInk) {
    ASSERT_GE(kPlotPalette.size(), 20u);  // the comparison's 17 techniques each get their own
    const auto distance = [](Rgb8 a, Rgb8 b) {
        return std::abs(a.r - b.r) + std::abs(a.g - b.g) + std::abs(a.b - b.b);
    };
    for (size_t i = 0; i < kPlotPalette.size(); ++i) {
        EXPECT_GT(distance(kPlotPalette[i], kWhite), 150) << i;
        EXPECT_GT(distance(kPlotPalette[i], kPlotInk), 150) << i;
        for (size_t j = 0; j < i; ++j) EXPECT_GT(distance(kPlotPalette[i], kPlotPalette[j]), 60) << i << " " << j;
    }
}

TEST(LinePlot, HasTheRequestedSizeOnWhite) {
    LinePlot plot = line_plot({series({0, 1}, {0, 1})});
    plot.title = "t", plot.x_label = "x", plot.y_label = "y";
    Image8 image = draw(plot);
    EXPECT_EQ(image.width, 720u);
    EXPECT_EQ(image.height, 440u);
    EXPECT_EQ(image.rgb.size(), 720u * 440 * 3);
    EXPECT_EQ(pixel(image, 0, 0), kWhite);
    EXPECT_EQ(pixel(image, 719, 439), kWhite);
    plot.width = 500, plot.height = 300;
    image = draw(plot);
    EXPECT_EQ(image.width, 500u);
    EXPECT_EQ(image.height, 300u);
}

TEST(LinePlot, YEqualsXRunsAlongTheDiagonalOfThePlotArea) {
    const Image8 image = draw(line_plot({series(range(11), range(11))}));
    expect_rising_diagonal(image, kPlotPalette[0]);
    const Area area = plot_area(image);
    EXPECT_GT(area.x1 - area.x0, 500);  // most of the picture, the legend being below
    EXPECT_GT(area.y1 - area.y0, 250);
}

TEST(LinePlot, LogAxesMakePowersStraight) {
    std::vector<double> x, y;
    for (int i = 0; i <= 12; ++i) x.push_back(std::pow(2.0, i)), y.push_back(std::pow(10.0, -i / 3.0));
    std::vector<double> reversed(y.rbegin(), y.rend());
    expect_rising_diagonal(draw(line_plot({series(x, reversed)}, true)), kPlotPalette[0]);
    std::vector<double> rising;
    for (int i = 0; i <= 12; ++i) rising.push_back(std::pow(10.0, i / 4.0));
    LinePlot log_y = line_plot({series(range(13), rising)});
    log_y.log_y = true;
    expect_rising_diagonal(draw(log_y), kPlotPalette[0]);
}

TEST(LinePlot, EqualValuesAndASinglePointSitMidPlot) {
    for (const Series& s : {series({1, 2, 3}, {5, 5, 5}), series({3}, {7}), series({-2, -2}, {0, 0})}) {
        const Image8 image = draw(line_plot({s}));
        const Area area = plot_area(image);
        double row = 0;
        int n = 0;
        for (Point p : pixels_of(image, kPlotPalette[0]))
            if (inside(p, area)) row += p.y, ++n;
        ASSERT_GT(n, 0);
        EXPECT_NEAR(row / n, (area.y0 + area.y1) / 2.0, 2);
    }
}

TEST(LinePlot, LogAxisSkipsNonPositiveValuesLikeNaN) {
    const auto plot = [](double bad) {
        LinePlot plot = line_plot({series(range(5), {1, 10, bad, 100, 1000})});
        plot.log_y = true;
        return draw(plot);
    };
    const Image8 with_nan = plot(kNaN);
    EXPECT_EQ(plot(0).rgb, with_nan.rgb);
    EXPECT_EQ(plot(-5).rgb, with_nan.rgb);
    // Nothing near the bottom, where 0 would be clamped to.
    const Area area = plot_area(with_nan);
    for (Point p : pixels_of(with_nan, kPlotPalette[0]))
        if (inside(p, area)) {
            EXPECT_LT(p.y, area.y1 - 4);
        }
}

TEST(LinePlot, ValuesBeyondFloatRangeAreSkippedLikeNaN) {
    const auto plot = [](double bad) { return draw(line_plot({series(range(4), {1, 2, bad, 3})})); };
    const Image8 with_nan = plot(kNaN);
    for (double bad : {1e300, -1e300, kInf, -kInf, DBL_MAX}) EXPECT_EQ(plot(bad).rgb, with_nan.rgb) << bad;
}

TEST(LinePlot, ExtremeValuesStayInsideThePlotArea) {
    // FLT_MAX, the largest value placed, leaves no margin: its marker is cut at the frame.
    for (bool log : {false, true}) {
        const Image8 image = draw(line_plot({series(range(7), {1e30, -1e30, kNaN, 1, kInf, -kInf, FLT_MAX}, "y"),
                                             series({1e30, -FLT_MAX, 0, kNaN, 5}, {0, 1, 2, 3, 1e-30}, "x")},
                                            log));
        ASSERT_EQ(image.rgb.size(), 720u * 440 * 3);
        expect_only_inside_or_legend(image, kPlotPalette[0]);
        expect_only_inside_or_legend(image, kPlotPalette[1]);
    }
}

TEST(LinePlot, LegendShowsEachNamedSeriesInItsColourBelowTheAxes) {
    const Image8 image = draw(line_plot({series({0, 1}, {1, 2}, "env"), series({0, 1}, {2, 1}, "bsdf"),
                                         series({0, 1}, {1.5, 1.5}, "mis"), series({0, 1}, {1, 1}, "")}));
    const Area area = plot_area(image);
    for (size_t i = 0; i < 4; ++i) {
        int below = 0;
        for (Point p : pixels_of(image, kPlotPalette[i])) below += p.y > area.y1;
        if (i < 3)
            EXPECT_GT(below, 20) << "series " << i;
        else
            EXPECT_EQ(below, 0) << "an unnamed series has no legend entry";
    }
}

TEST(LinePlot, SeriesTakeThePaletteColoursInTurn) {
    LinePlot plot;
    for (int i = 0; i < 20; ++i) plot.series.push_back(series({}, {}, ""));
    plot.series.push_back(series({0, 1}, {0, 1}, "twenty-first"));
    const Image8 image = draw(plot);
    EXPECT_FALSE(pixels_of(image, kPlotPalette[0]).empty());
    for (size_t i = 1; i < kPlotPalette.size(); ++i) EXPECT_TRUE(pixels_of(image, kPlotPalette[i]).empty()) << i;
}

// A series's best point (an allocation sweep's best split, an alpha sweep's best alpha) is
// ringed in ink, centred on its marker, and the legend says what the ring means.
TEST(LinePlot, TheBestPointIsRingedAndTheLegendSaysWhatTheRingMeans) {
    LinePlot plot = line_plot({series({0, 1, 2}, {1, 3, 2})});
    const Image8 plain = draw(plot);
    plot.series[0].best = 1;
    plot.best_label = "best split";
    const Image8 ringed = draw(plot);
    const Area area = plot_area(ringed);
    double sx = 0, sy = 0;
    int inside_changed = 0, legend_changed = 0;
    for (uint32_t y = 0; y < ringed.height; ++y)
        for (uint32_t x = 0; x < ringed.width; ++x)
            if (pixel(ringed, x, y) != pixel(plain, x, y)) {
                if (inside({int(x), int(y)}, area))
                    sx += x, sy += y, ++inside_changed;
                else if (int(y) > area.y1)
                    ++legend_changed;
                else
                    ADD_FAILURE() << "changed outside the plot area and legend at " << x << "," << y;
            }
    ASSERT_GT(inside_changed, 40);
    EXPECT_GT(legend_changed, 40);
    // The ring's centre is the middle point's: mid-plot across, at the top (y = 3).
    EXPECT_NEAR(sx / inside_changed, (area.x0 + area.x1) / 2.0, 2);
    EXPECT_LT(sy / inside_changed - area.y0, (area.y1 - area.y0) / 8.0);
}

// Sample counts are whole numbers: their axis is labelled at 1, 2, 3, not at 1.5 and 2.5.
TEST(LinePlot, WholeNumberXValuesAreLabelledAtWholeNumbersOnly) {
    const auto x_ticks = [](std::vector<double> x) {
        const Image8 image = draw(line_plot({series(x, {1, 2, 3})}));
        const Area area = plot_area(image);
        int ticks = 0;
        for (int x = area.x0 - 1; x <= area.x1; ++x) ticks += pixel(image, x, area.y1 + 3) == kPlotInk;
        return ticks;
    };
    EXPECT_EQ(x_ticks({1, 2, 3}), 3);
    EXPECT_GT(x_ticks({1, 2, 3.5}), 3);
}

TEST(LinePlot, TitleAndLabelsAreWrittenAroundThePlotArea) {
    const auto ink_above = [](const Image8& image) {
        const int top = plot_area(image).y0 - 12;  // clear of the highest tick label
        int n = 0;
        for (Point p : pixels_of(image, kPlotInk)) n += p.y < top;
        return n;
    };
    const LinePlot bare = line_plot({series({0, 1}, {0, 1})});
    LinePlot titled = bare;
    titled.title = "Variance against samples";
    titled.y_label = "variance";
    EXPECT_EQ(ink_above(draw(bare)), 0);
    EXPECT_GT(ink_above(draw(titled)), 100);
}

TEST(LinePlot, InvalidInputThrows) {
    EXPECT_THROW(draw(LinePlot{}), std::invalid_argument);
    EXPECT_THROW(draw(line_plot({series({}, {})})), std::invalid_argument);
    EXPECT_THROW(draw(line_plot({series({1, 2}, {1})})), std::invalid_argument);
    for (auto [width, height] : {std::pair{100u, 80u}, {0u, 0u}, {100000u, 440u}}) {
        LinePlot plot = line_plot({series({1}, {1})});
        plot.width = width, plot.height = height;
        EXPECT_THROW(draw(plot), std::invalid_argument) << width << "x" << height;
    }
}

TEST(BarChart, BarsRiseFromZeroInProportionToTheirValues) {
    const Image8 image = draw(bar_chart({"lambert"}, {"a", "b"}, {{1, 2}}));
    const Area area = plot_area(image);
    const Bar one = bar(image, kPlotPalette[0]), two = bar(image, kPlotPalette[1]);
    EXPECT_NEAR(two.height, 2 * one.height, 1.0);
    EXPECT_GT(two.height, 0.9 * (area.y1 - area.y0));
    EXPECT_EQ(one.bottom, area.y1 - 1);  // the axis starts at 0
    EXPECT_EQ(two.bottom, area.y1 - 1);
}

TEST(BarChart, NegativeBarsHangFromZero) {
    const Image8 image = draw(bar_chart({"g"}, {"a", "b"}, {{-1, -2}}));
    const Area area = plot_area(image);
    const Bar one = bar(image, kPlotPalette[0]), two = bar(image, kPlotPalette[1]);
    EXPECT_EQ(one.top, area.y0);
    EXPECT_EQ(two.top, area.y0);
    EXPECT_NEAR(two.height, 2 * one.height, 1.0);
}

TEST(BarChart, LogAxisGivesEqualStepsPerDecadeAndSkipsNonPositiveBars) {
    BarChart chart = bar_chart({"g"}, {"1", "10", "100", "0"}, {{1, 10, 100, 0}});
    chart.log_y = true;
    const Image8 image = draw(chart);
    const Bar b1 = bar(image, kPlotPalette[0]), b10 = bar(image, kPlotPalette[1]), b100 = bar(image, kPlotPalette[2]);
    EXPECT_GT(b1.height, 0);
    EXPECT_NEAR(b10.height - b1.height, b100.height - b10.height, 1.0);
    EXPECT_EQ(bar(image, kPlotPalette[3]).height, 0);
}

TEST(BarChart, NaNMeansNoBarButKeepsTheLegendEntry) {
    const Image8 image = draw(bar_chart({"g", "h"}, {"a", "b"}, {{1, kNaN}, {2, kNaN}}));
    EXPECT_GT(bar(image, kPlotPalette[0]).height, 0);
    EXPECT_EQ(bar(image, kPlotPalette[1]).height, 0);
    EXPECT_FALSE(pixels_of(image, kPlotPalette[1]).empty());
}

TEST(BarChart, ReferenceLineIsDashedAtItsValue) {
    const Image8 image = draw(bar_chart({"g"}, {"a", "b"}, {{0.5, 2}}, 1));
    const Area area = plot_area(image);
    const Bar two = bar(image, kPlotPalette[1]);
    const auto dashes = pixels_of(image, kPlotReference);
    ASSERT_FALSE(dashes.empty());
    double row = 0;
    int left = area.x1, right = 0;
    for (Point p : dashes) {
        EXPECT_TRUE(inside(p, area));
        row += p.y, left = std::min(left, p.x), right = std::max(right, p.x);
    }
    EXPECT_NEAR(row / dashes.size(), area.y1 - two.height / 2.0, 1.5);  // half as high as the bar of 2
    EXPECT_LT(left - area.x0, 5);
    EXPECT_GT(right, area.x1 - 15);
    EXPECT_LT(double(dashes.size()), 0.9 * 2 * (area.x1 - area.x0)) << "dashed, not solid";
}

TEST(BarChart, ReferenceLineBeyondTheBarsWidensTheAxis) {
    const Image8 image = draw(bar_chart({"g"}, {"a"}, {{1}}, 10));
    const Area area = plot_area(image);
    const auto dashes = pixels_of(image, kPlotReference);
    ASSERT_FALSE(dashes.empty());
    for (Point p : dashes) EXPECT_LT(p.y, area.y0 + (area.y1 - area.y0) / 10);
    EXPECT_NEAR(bar(image, kPlotPalette[0]).height, (area.y1 - area.y0) / 10.5, 1.5);
}

TEST(BarChart, LegendShowsEachBarColourBelowTheAxes) {
    BarChart chart = bar_chart({"lambert", "phong:50", "ggx:0.1"}, {"env", "bsdf", "mis-balance"},
                               {{1, 2, 3}, {2, 3, 1}, {3, 1, 2}});
    chart.title = "Variance ratio", chart.y_label = "ratio";
    const Image8 image = draw(chart);
    EXPECT_EQ(image.width, 720u);
    EXPECT_EQ(image.height, 440u);
    const Area area = plot_area(image);
    for (size_t i = 0; i < 3; ++i) {
        int below = 0;
        for (Point p : pixels_of(image, kPlotPalette[i])) below += p.y > area.y1;
        EXPECT_GT(below, 50) << i;
    }
}

TEST(BarChart, ExtremeValuesStayInsideThePlotArea) {
    for (bool log : {false, true}) {
        BarChart chart = bar_chart({"a", "b"}, {"x", "y", "z"}, {{1e30, -1e30, kNaN}, {kInf, 1e300, 1e-30}}, -1e30);
        chart.log_y = log;
        const Image8 image = draw(chart);
        for (size_t i = 0; i < 3; ++i) expect_only_inside_or_legend(image, kPlotPalette[i]);
        expect_only_inside_or_legend(image, kPlotReference);
    }
}

TEST(BarChart, InvalidInputThrows) {
    EXPECT_THROW(draw(BarChart{}), std::invalid_argument);
    EXPECT_THROW(draw(bar_chart({"g"}, {}, {{}})), std::invalid_argument);
    EXPECT_THROW(draw(bar_chart({"g"}, {"a"}, {})), std::invalid_argument);
    EXPECT_THROW(draw(bar_chart({"g", "h"}, {"a"}, {{1}, {1, 2}})), std::invalid_argument);
    BarChart tiny = bar_chart({"g"}, {"a"}, {{1}});
    tiny.width = tiny.height = 60;
    EXPECT_THROW(draw(tiny), std::invalid_argument);
}

}  // namespace
}  // namespace envmis::pictures
