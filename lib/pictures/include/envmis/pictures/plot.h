// Charts for reports: line plots (convergence, variance against sample count) and grouped
// bar charts (a measure per BSDF and technique), drawn into an Image8 for write_png().
//
// The look is fixed: white background, a black frame around the plot area with outward
// tick marks, light grey grid lines at the labelled ticks, tick labels from scale_ticks()
// and tick_label() (picture.h), the title above, and a legend box below the axes, so it
// never hides data. All text uses the built-in font at scale 2; it cannot be rotated, so
// the y axis's label is written horizontally above the axis.
//
// Axis ranges are fitted to the data with a 5% margin on each side (a linear bar chart's
// axis starts at 0 instead); a range without extent (one point, equal values) is widened.
// Values that cannot be placed are skipped: NaN, ±Inf, magnitudes beyond float's range
// (which tick labels use), and values <= 0 on a log axis.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "envmis/pictures/picture.h"

namespace envmis::pictures {

// Series and bars take their colours in turn from this palette, series i colour i mod 20:
// Tableau 10's hues first, then Tableau 20's light tints of them where those stay apart
// (three darker hues replace the tints too close to another colour), so that a chart of up
// to 20 techniques gives each its own colour.
inline constexpr std::array<Rgb8, 20> kPlotPalette{{{31, 119, 180},  {255, 127, 14},  {44, 160, 44},   {214, 39, 40},
                                                    {148, 103, 189}, {140, 86, 75},   {227, 119, 194}, {127, 127, 127},
                                                    {188, 189, 34},  {23, 190, 207},  {174, 199, 232}, {255, 187, 120},
                                                    {152, 223, 138}, {255, 152, 150}, {197, 176, 213}, {196, 156, 148},
                                                    {128, 0, 64},    {90, 60, 20},    {219, 219, 141}, {0, 110, 110}}};
// The frame, ticks and all text.
inline constexpr Rgb8 kPlotInk{0, 0, 0};
// A bar chart's dashed reference line.
inline constexpr Rgb8 kPlotReference{70, 70, 70};

// One line through (x[i], y[i]) in the order given, with a marker at each point. A point
// that is skipped (see above) breaks the line there.
struct Series {
    std::string name;  // legend entry; unnamed series are left out of the legend
    std::vector<double> x, y;
    int best = -1;  // a point to mark (a ring around its marker, see LinePlot::best_label); -1: none
};

// Where every x is a whole number (sample counts), the x axis is labelled at whole numbers
// only.
struct LinePlot {
    std::string title, x_label, y_label;
    std::vector<Series> series;  // colours from kPlotPalette; markers cycle through 4 shapes
    bool log_y = false;          // log10 axes, labelled at powers of ten
    bool log_x = false;
    uint32_t width = 720, height = 440;  // of the whole picture, in pixels
    // The legend's entry for the rings of Series::best ("best split"), when one is marked.
    std::string best_label = "best";
};

// Throws std::invalid_argument when there is no series, or none has a point, when a
// series's x and y differ in length, or when the picture is too small to leave a plot
// area of at least 32 x 32 pixels beside the text (and legend), or over 16384 a side.
Image8 draw(const LinePlot& plot);

// Bars side by side in groups along x, one per group and entry of `bars`, in that entry's
// colour; each rises from 0 (from the bottom of a log axis) to its value.
struct BarChart {
    std::string title, y_label;
    std::vector<std::string> groups;          // labels under the groups, left to right
    std::vector<std::string> bars;            // legend entries, in order within each group
    std::vector<std::vector<double>> values;  // values[group][bar]; NaN: no bar
    bool log_y = false;
    double reference_line = NAN;  // a level to compare with (1 for a ratio), dashed; NaN: none
    uint32_t width = 720, height = 440;
};

// Throws std::invalid_argument when there are no groups or no bars, when `values` is not
// groups x bars, or when the picture is too small (as for line plots).
Image8 draw(const BarChart& chart);

}  // namespace envmis::pictures
