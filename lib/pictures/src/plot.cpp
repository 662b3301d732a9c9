// Line plots and bar charts (plot.h).
#include "envmis/pictures/plot.h"

#include <algorithm>
#include <cfloat>
#include <optional>
#include <span>
#include <stdexcept>
#include <string_view>
#include <utility>

namespace envmis::pictures {
namespace {

constexpr int kScale = 2;  // font pixel size of all text
constexpr int kMargin = 12, kGap = 8;
constexpr int kTick = 5, kMinorTick = 3;
constexpr int kMinPlotSide = 32, kMaxSide = 16384;
constexpr int kMarkerRadius = 4, kRingRadius = 9;
constexpr int kLegendPad = 8, kLegendSpacing = 24, kLegendKeyGap = 6, kLegendLine = 28;
constexpr double kPadding = 0.05;  // of an axis's span, so that markers at the extremes stay whole
constexpr Rgb8 kBackground{255, 255, 255}, kGrid{226, 226, 226}, kLegendFrame{170, 170, 170};

// The plot area, [x0, x1) x [y0, y1), inside a 1-pixel frame.
struct Area {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    int width() const { return x1 - x0; }
    int height() const { return y1 - y0; }
    // The pixel at position t along an axis: 0 and 1 are the frame's lines.
    int column(double t) const { return static_cast<int>(std::lround(x0 - 1 + t * (width() + 1))); }
    int row(double t) const { return static_cast<int>(std::lround(y1 - t * (height() + 1))); }
};

void fill_clipped(Image8& image, const Area& clip, int x, int y, int w, int h, Rgb8 colour) {
    const int x0 = std::max(x, clip.x0), y0 = std::max(y, clip.y0);
    fill_rect(image, x0, y0, std::min(x + w, clip.x1) - x0, std::min(y + h, clip.y1) - y0, colour);
}

void outline(Image8& image, int x, int y, int w, int h, Rgb8 colour) {
    fill_rect(image, x, y, w, 1, colour);
    fill_rect(image, x, y + h - 1, w, 1, colour);
    fill_rect(image, x, y, 1, h, colour);
    fill_rect(image, x + w - 1, y, 1, h, colour);
}

// The longest start of `text` that fits `width` pixels at the plots' text scale.
std::string_view fitted(std::string_view text, int width) { return cut_to_width(text, width, kScale); }

// Centred on `centre` as far as the image's edges allow.
void draw_centred(Image8& image, int centre, int y, std::string_view text, Rgb8 colour) {
    const int w = text_width(text, kScale);
    draw_text(image, clamp(centre - w / 2, 0, std::max(0, static_cast<int>(image.width) - w)), y, text, colour, kScale);
}

// Tick labels are floats, so axes stay within float's range; and a log axis needs v > 0.
bool placeable(double v, bool log) { return log ? v >= FLT_MIN && v <= FLT_MAX : std::abs(v) <= FLT_MAX; }

struct Axis {
    double lo = 0, hi = 1;
    bool log = false;

    // 0 at lo, 1 at hi, linear in log(v) on a log axis.
    double position(double v) const { return log ? std::log(v / lo) / std::log(hi / lo) : (v - lo) / (hi - lo); }
};

// The range of `values` (all placeable) with kPadding on both sides; a bar chart's linear
// axis keeps 0 as its end, so that bar lengths are proportional to values.
Axis fit_axis(std::span<const double> values, bool log, bool from_zero) {
    if (values.empty()) return log ? Axis{1, 10, true} : Axis{0, 1, false};
    const auto [min, max] = std::minmax_element(values.begin(), values.end());
    double lo = log ? std::log10(*min) : *min, hi = log ? std::log10(*max) : *max;
    from_zero = from_zero && !log;
    if (from_zero) lo = std::min(lo, 0.0), hi = std::max(hi, 0.0);
    if (lo == hi) {
        // A decade, or 20% of the value, around it; [0, 1] for bars that are all 0.
        const double d = log ? 0.5 : lo == 0 ? 1 : 0.1 * std::abs(lo);
        hi += d;
        if (!from_zero) lo -= d;
    }
    const double pad = kPadding * (hi - lo);
    if (!from_zero || lo != 0) lo -= pad;
    if (!from_zero || hi != 0) hi += pad;
    if (log)
        return {std::max(std::pow(10.0, lo), double(FLT_MIN)), std::min(std::pow(10.0, hi), double(FLT_MAX)), true};
    return {std::max(lo, -double(FLT_MAX)), std::min(hi, double(FLT_MAX)), false};
}

struct Tick {
    double position;
    std::string label;
};

// Labelled ticks at scale_ticks()'s round values, about one per `spacing` pixels of an
// axis `length` pixels long (but 5 on short axes, as 1-2-5 steps can leave fewer), and
// fewer while the labels, `extent(label)` pixels long along the axis, would come closer
// than 2 gaps.
template <class Extent>
std::vector<Tick> labelled_ticks(const Axis& axis, int length, int spacing, Extent extent) {
    const ColourScale scale{static_cast<float>(axis.lo), static_cast<float>(axis.hi), axis.log};
    for (int most = std::max(5, length / spacing);; --most) {
        std::vector<Tick> ticks;
        // The float scale can reach a little beyond the double range.
        for (float v : scale_ticks(scale, most))
            if (const double t = axis.position(v); t >= -1e-6 && t <= 1 + 1e-6) ticks.push_back({t, tick_label(v)});
        bool apart = true;
        for (size_t i = 1; i < ticks.size(); ++i)
            apart &= (ticks[i].position - ticks[i - 1].position) * length >=
                     (extent(ticks[i - 1].label) + extent(ticks[i].label)) / 2.0 + 2 * kGap;
        if (apart || most == 2) return ticks;
    }
}

// Unlabelled ticks on a log axis: at 1, 2 and 5 times the powers of ten over at most three
// decades, so that a reader can judge distances between labels; at the decades labels
// skip over more.
std::vector<double> minor_ticks(const Axis& axis, const std::vector<Tick>& labelled) {
    std::vector<double> ticks;
    if (!axis.log) return ticks;
    const bool short_range = std::log10(axis.hi / axis.lo) <= 3;
    for (int e = static_cast<int>(std::floor(std::log10(axis.lo))); e <= std::ceil(std::log10(axis.hi)); ++e)
        for (double m : {1.0, 2.0, 5.0}) {
            if (m > 1 && !short_range) break;
            const double t = axis.position(m * std::pow(10.0, e));
            const bool is_labelled = std::any_of(labelled.begin(), labelled.end(),
                                                 [t](const Tick& k) { return std::abs(k.position - t) < 1e-6; });
            if (t >= 0 && t <= 1 && !is_labelled) ticks.push_back(t);
        }
    return ticks;
}

Rgb8 colour(size_t series) { return kPlotPalette[series % kPlotPalette.size()]; }

// Shapes as well as colours tell series apart, for readers who cannot tell the colours.
enum class Marker { circle, square, diamond, triangle };

// Half the width of row `dy` (relative to the centre) of a marker; negative outside it.
int marker_half_width(Marker marker, int dy) {
    constexpr int r = kMarkerRadius;
    switch (marker) {
        case Marker::circle:
            return dy * dy <= r * r ? static_cast<int>(std::sqrt(r * r + r - dy * dy)) : -1;  // + r: rounder when small
        case Marker::square: return std::abs(dy) < r ? r - 1 : -1;
        case Marker::diamond: return r + 1 - std::abs(dy);
        case Marker::triangle: return dy >= -r && dy <= r ? (dy + r + 1) / 2 : -1;
    }
    return -1;
}

void draw_marker(Image8& image, const Area& clip, int x, int y, Marker marker, Rgb8 colour) {
    for (int dy = -kMarkerRadius - 1; dy <= kMarkerRadius + 1; ++dy)
        if (const int half = marker_half_width(marker, dy); half >= 0)
            fill_clipped(image, clip, x - half, y + dy, 2 * half + 1, 1, colour);
}

// A 2-pixel ring of radius kRingRadius around (x, y): the mark of a series's best point.
void draw_ring(Image8& image, const Area& clip, int x, int y, Rgb8 colour) {
    for (int dy = -kRingRadius - 1; dy <= kRingRadius + 1; ++dy)
        for (int dx = -kRingRadius - 1; dx <= kRingRadius + 1; ++dx)
            if (std::abs(std::sqrt(double(dx * dx + dy * dy)) - kRingRadius) <= 1.0)
                fill_clipped(image, clip, x + dx, y + dy, 1, 1, colour);
}

// Bresenham's line, stepping one pixel at a time along its longer axis so that it has no
// gaps, 2 pixels wide.
void draw_line(Image8& image, const Area& clip, int xa, int ya, int xb, int yb, Rgb8 colour) {
    const int dx = std::abs(xb - xa), dy = -std::abs(yb - ya), sx = xa < xb ? 1 : -1, sy = ya < yb ? 1 : -1;
    for (int err = dx + dy;;) {
        fill_clipped(image, clip, xa, ya, 2, 2, colour);
        if (xa == xb && ya == yb) return;
        const int e2 = 2 * err;
        if (e2 >= dy) err += dy, xa += sx;
        if (e2 <= dx) err += dx, ya += sy;
    }
}

struct LegendEntry {
    std::string_view name;
    Rgb8 colour;
    std::optional<Marker> marker;  // a line with this marker; none: a bar's swatch
    bool ring = false;             // a ring alone (the best points' mark)
};

int key_width(const LegendEntry& entry) {
    return entry.ring ? 2 * kRingRadius + 3 : entry.marker ? kLegendLine : text_height(kScale) - 4;
}
int entry_width(const LegendEntry& entry) { return key_width(entry) + kLegendKeyGap + text_width(entry.name, kScale); }
int legend_row_height() { return text_height(kScale) + kGap / 2; }

// Entries flow left to right in rows, in a box centred under the axes.
struct Legend {
    std::vector<LegendEntry> entries;
    std::vector<std::vector<size_t>> rows;
    int width = 0;  // of the widest row

    Legend(std::vector<LegendEntry> all, int max_width) : entries(std::move(all)) {
        const int inner = max_width - 2 * kLegendPad;
        int row_width = 0;
        for (size_t i = 0; i < entries.size(); ++i) {
            LegendEntry& e = entries[i];
            e.name = fitted(e.name, inner - key_width(e) - kLegendKeyGap);
            const int w = entry_width(e);
            if (rows.empty() || row_width + kLegendSpacing + w > inner)
                rows.emplace_back(), row_width = -kLegendSpacing;
            rows.back().push_back(i);
            row_width += kLegendSpacing + w;
            width = std::max(width, row_width);
        }
    }
    int height() const {
        return rows.empty() ? 0 : 2 * kLegendPad + static_cast<int>(rows.size()) * legend_row_height() - kGap / 2;
    }

    void draw(Image8& image, int top) const {
        const int cap = (kGlyphHeight - 2) * kScale;
        const int left = (static_cast<int>(image.width) - width) / 2 - kLegendPad;
        outline(image, left, top, width + 2 * kLegendPad, height(), kLegendFrame);
        const Area everywhere{0, 0, static_cast<int>(image.width), static_cast<int>(image.height)};
        int y = top + kLegendPad;
        for (const auto& row : rows) {
            int x = left + kLegendPad;
            for (size_t i : row) {
                const LegendEntry& e = entries[i];
                const int middle = y + cap / 2;
                if (e.ring) {
                    draw_ring(image, everywhere, x + key_width(e) / 2, middle, e.colour);
                } else if (e.marker) {
                    fill_rect(image, x, middle - 1, kLegendLine, 2, e.colour);
                    draw_marker(image, everywhere, x + kLegendLine / 2, middle, *e.marker, e.colour);
                } else {
                    fill_rect(image, x, middle - key_width(e) / 2, key_width(e), key_width(e), e.colour);
                }
                draw_text(image, x + key_width(e) + kLegendKeyGap, y, e.name, kPlotInk, kScale);
                x += entry_width(e) + kLegendSpacing;
            }
            y += legend_row_height();
        }
    }
};

// A chart up to its data and the labels of its x axis: a white picture with the title and
// the y axis's label above the plot area, its tick labels left of it, and below it one
// line for the x axis's tick labels, the x axis's label and the legend.
struct Chart {
    Image8 image;
    Area area;
    int x_tick_labels_top = 0;
};

Chart start_chart(uint32_t width, uint32_t height, std::string_view title, std::string_view y_label,
                  std::string_view x_label, const Axis& y, std::vector<LegendEntry> entries, int right_room) {
    if (width > kMaxSide || height > kMaxSide)
        throw std::invalid_argument("plot: " + std::to_string(width) + "x" + std::to_string(height) +
                                    " pixels is larger than " + std::to_string(kMaxSide) + " a side");
    const int w = static_cast<int>(width), h = static_cast<int>(height);
    const int th = text_height(kScale), cap = (kGlyphHeight - 2) * kScale;
    const Legend legend(std::move(entries), w - 2 * kMargin);

    Area area;
    area.y0 = kMargin + (title.empty() ? 0 : th + kGap) + (y_label.empty() ? 0 : th + kGap) + 1;
    const int x_tick_labels_room = kTick + kGap / 2 + th;
    const int x_label_room = x_label.empty() ? 0 : kGap + th;
    const int legend_room = legend.rows.empty() ? 0 : 2 * kGap + legend.height();
    area.y1 = h - kMargin - legend_room - x_label_room - x_tick_labels_room - 1;

    const auto ticks = labelled_ticks(y, area.height(), 32, [th](const std::string&) { return th; });
    int widest = 0;
    for (const Tick& t : ticks) widest = std::max(widest, text_width(t.label, kScale));
    area.x0 = kMargin + widest + kGap / 2 + kTick + 1;
    area.x1 = w - right_room - 1;
    if (area.width() < kMinPlotSide || area.height() < kMinPlotSide)
        throw std::invalid_argument("plot: " + std::to_string(width) + "x" + std::to_string(height) +
                                    " pixels leave no room for a plot area beside the text");

    Chart chart{make_image(width, height, kBackground), area, area.y1 + 1 + kTick + kGap / 2};
    Image8& image = chart.image;
    for (const Tick& t : ticks) {
        const int row = area.row(t.position);
        fill_clipped(image, area, area.x0, row, area.width(), 1, kGrid);
        fill_rect(image, area.x0 - 1 - kTick, row, kTick, 1, kPlotInk);
        draw_text(image, area.x0 - 1 - kTick - kGap / 2 - text_width(t.label, kScale), row - cap / 2, t.label, kPlotInk,
                  kScale);
    }
    for (double t : minor_ticks(y, ticks))
        fill_rect(image, area.x0 - 1 - kMinorTick, area.row(t), kMinorTick, 1, kPlotInk);
    outline(image, area.x0 - 1, area.y0 - 1, area.width() + 2, area.height() + 2, kPlotInk);

    const int text_room = w - 2 * kMargin, centre = (area.x0 + area.x1) / 2;
    if (!title.empty()) draw_centred(image, centre, kMargin, fitted(title, text_room), kPlotInk);
    draw_text(image, kMargin, area.y0 - 1 - kGap - th, fitted(y_label, text_room), kPlotInk, kScale);
    draw_centred(image, centre, chart.x_tick_labels_top + th + kGap, fitted(x_label, text_room), kPlotInk);
    if (!legend.rows.empty()) legend.draw(image, h - kMargin - legend.height());
    return chart;
}

}  // namespace

Image8 draw(const LinePlot& plot) {
    bool any_point = false;
    for (const Series& s : plot.series) {
        if (s.x.size() != s.y.size())
            throw std::invalid_argument("line plot: series '" + s.name + "' has " + std::to_string(s.x.size()) +
                                        " x and " + std::to_string(s.y.size()) + " y values");
        any_point |= !s.x.empty();
    }
    if (!any_point) throw std::invalid_argument("line plot: no data");

    // Points that cannot be placed neither stretch the other axis nor are drawn.
    const auto placed = [&](const Series& s, size_t i) {
        return placeable(s.x[i], plot.log_x) && placeable(s.y[i], plot.log_y);
    };
    std::vector<double> xs, ys;
    for (const Series& s : plot.series)
        for (size_t i = 0; i < s.x.size(); ++i)
            if (placed(s, i)) xs.push_back(s.x[i]), ys.push_back(s.y[i]);
    const Axis x = fit_axis(xs, plot.log_x, false), y = fit_axis(ys, plot.log_y, false);

    const auto marker = [](size_t i) { return static_cast<Marker>(i % 4); };
    std::vector<LegendEntry> entries;
    bool marked = false;
    for (size_t i = 0; i < plot.series.size(); ++i) {
        if (!plot.series[i].name.empty()) entries.push_back({plot.series[i].name, colour(i), marker(i)});
        marked |= plot.series[i].best >= 0 && static_cast<size_t>(plot.series[i].best) < plot.series[i].x.size();
    }
    if (marked && !plot.best_label.empty()) entries.push_back({plot.best_label, kPlotInk, std::nullopt, true});
    // Room for half a tick label centred at the right end of the axis.
    const int right_room = kMargin + text_width("0.000", kScale) / 2;
    Chart chart =
        start_chart(plot.width, plot.height, plot.title, plot.y_label, plot.x_label, y, std::move(entries), right_room);
    Image8& image = chart.image;
    const Area& area = chart.area;

    auto ticks =
        labelled_ticks(x, area.width(), 80, [](const std::string& label) { return text_width(label, kScale); });
    if (!plot.log_x && std::all_of(xs.begin(), xs.end(), [](double v) { return v == std::round(v); }))
        std::erase_if(ticks, [&](const Tick& t) {
            const double v = x.lo + t.position * (x.hi - x.lo);
            return std::abs(v - std::round(v)) > 1e-6 * std::max(1.0, std::abs(v));
        });
    for (const Tick& t : ticks) {
        const int column = area.column(t.position);
        fill_clipped(image, area, column, area.y0, 1, area.height(), kGrid);
        fill_rect(image, column, area.y1 + 1, 1, kTick, kPlotInk);
        draw_centred(image, column, chart.x_tick_labels_top, t.label, kPlotInk);
    }
    for (double t : minor_ticks(x, ticks)) fill_rect(image, area.column(t), area.y1 + 1, 1, kMinorTick, kPlotInk);

    for (size_t k = 0; k < plot.series.size(); ++k) {
        const Series& s = plot.series[k];
        std::vector<std::optional<std::pair<int, int>>> points(s.x.size());
        for (size_t i = 0; i < s.x.size(); ++i)
            if (placed(s, i)) points[i] = {area.column(x.position(s.x[i])), area.row(y.position(s.y[i]))};
        for (size_t i = 1; i < points.size(); ++i)
            if (points[i - 1] && points[i])
                draw_line(image, area, points[i - 1]->first, points[i - 1]->second, points[i]->first, points[i]->second,
                          colour(k));
        for (const auto& p : points)
            if (p) draw_marker(image, area, p->first, p->second, marker(k), colour(k));
        if (s.best >= 0 && static_cast<size_t>(s.best) < points.size() && points[s.best])
            draw_ring(image, area, points[s.best]->first, points[s.best]->second, kPlotInk);
    }
    return image;
}

Image8 draw(const BarChart& chart) {
    if (chart.groups.empty() || chart.bars.empty()) throw std::invalid_argument("bar chart: no groups or no bars");
    if (chart.values.size() != chart.groups.size())
        throw std::invalid_argument("bar chart: " + std::to_string(chart.values.size()) + " rows of values for " +
                                    std::to_string(chart.groups.size()) + " groups");
    for (size_t g = 0; g < chart.values.size(); ++g)
        if (chart.values[g].size() != chart.bars.size())
            throw std::invalid_argument("bar chart: group '" + chart.groups[g] + "' has " +
                                        std::to_string(chart.values[g].size()) + " values for " +
                                        std::to_string(chart.bars.size()) + " bars");

    std::vector<double> ys;
    for (const auto& row : chart.values)
        for (double v : row)
            if (placeable(v, chart.log_y)) ys.push_back(v);
    const bool reference = placeable(chart.reference_line, chart.log_y);
    if (reference) ys.push_back(chart.reference_line);
    const Axis y = fit_axis(ys, chart.log_y, true);

    std::vector<LegendEntry> entries;
    for (size_t b = 0; b < chart.bars.size(); ++b)
        if (!chart.bars[b].empty()) entries.push_back({chart.bars[b], colour(b), std::nullopt});
    Chart c = start_chart(chart.width, chart.height, chart.title, chart.y_label, "", y, std::move(entries), kMargin);
    Image8& image = c.image;
    const Area& area = c.area;

    // Bars fill 80% of their group's slot, so that groups stand apart.
    const double slot = static_cast<double>(area.width()) / chart.groups.size();
    const int n = static_cast<int>(chart.bars.size());
    const int bar_width = std::max(1, static_cast<int>(0.8 * slot / n));
    const int base = chart.log_y ? area.y1 : area.row(y.position(0));
    for (size_t g = 0; g < chart.groups.size(); ++g) {
        const int centre = static_cast<int>(std::lround(area.x0 + (g + 0.5) * slot));
        const int left = centre - n * bar_width / 2;
        for (int b = 0; b < n; ++b)
            if (const double v = chart.values[g][b]; placeable(v, chart.log_y)) {
                const int top = area.row(y.position(v));
                fill_clipped(image, area, left + b * bar_width, std::min(top, base), bar_width, std::abs(base - top),
                             colour(b));
            }
        fill_rect(image, centre, area.y1 + 1, 1, kTick, kPlotInk);
        draw_centred(image, centre, c.x_tick_labels_top, fitted(chart.groups[g], static_cast<int>(slot) - kGap),
                     kPlotInk);
    }
    if (reference) {
        const int row = area.row(y.position(chart.reference_line));
        for (int x = area.x0; x < area.x1; x += 12) fill_clipped(image, area, x, row - 1, 8, 2, kPlotReference);
    }
    return image;
}

}  // namespace envmis::pictures
