// Tone mapping, false colour, resampling and figure layout (picture.h).
#include "envmis/pictures/picture.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>

namespace envmis::pictures {
namespace {

// Keeps negatives: averaging signed data (differences) is meaningful, Inf and NaN are not.
float finite_or_zero(float v) { return std::isfinite(v) ? v : 0.0f; }
float radiance_or_zero(float v) { return v > 0 && v <= std::numeric_limits<float>::max() ? v : 0.0f; }

// sRGB encoding to 8 bits by searching the linear values where the byte steps up: the
// same bytes as rounding srgb_encode(), without a pow per channel of a full-size map.
class ByteEncoder {
public:
    ByteEncoder() {
        for (size_t k = 0; k < steps_.size(); ++k) steps_[k] = srgb_decode((k + 0.5f) / 255);
    }
    uint8_t operator()(float linear) const {
        if (!(linear > 0)) return 0;
        return static_cast<uint8_t>(std::upper_bound(steps_.begin(), steps_.end(), linear) - steps_.begin());
    }

private:
    std::array<float, 255> steps_;
};

uint8_t* at(Image8& image, int x, int y) { return &image.rgb[(static_cast<size_t>(y) * image.width + x) * 3]; }

// The source pixels an output pixel covers along one axis, with the fraction of its
// area each contributes.
struct Footprint {
    uint32_t first = 0;
    std::vector<float> weights;
};

std::vector<Footprint> footprints(uint32_t from, uint32_t to) {
    std::vector<Footprint> result(to);
    const double ratio = static_cast<double>(from) / to;
    for (uint32_t i = 0; i < to; ++i) {
        const double begin = i * ratio, end = (i + 1) * ratio;
        Footprint& f = result[i];
        f.first = static_cast<uint32_t>(begin);
        const auto last = std::min(from, static_cast<uint32_t>(std::ceil(end)));
        for (uint32_t j = f.first; j < last; ++j)
            f.weights.push_back(static_cast<float>((std::min(end, j + 1.0) - std::max(begin, double(j))) / ratio));
    }
    return result;
}

// Separable box resampling of `channels` interleaved floats per pixel.
std::vector<float> resample(const float* src, uint32_t width, uint32_t height, uint32_t channels, uint32_t new_width,
                            uint32_t new_height) {
    std::vector<float> out(static_cast<size_t>(new_width) * new_height * channels);
    if (width == 0 || height == 0 || out.empty()) return out;
    const auto fx = footprints(width, new_width), fy = footprints(height, new_height);
    const size_t in_row = static_cast<size_t>(width) * channels, out_row = static_cast<size_t>(new_width) * channels;
    std::vector<float> rows(out_row * height);
    for (size_t y = 0; y < height; ++y)
        for (size_t x = 0; x < new_width; ++x)
            for (size_t k = 0; k < fx[x].weights.size(); ++k)
                for (size_t c = 0; c < channels; ++c)
                    rows[y * out_row + x * channels + c] +=
                        fx[x].weights[k] * finite_or_zero(src[y * in_row + (fx[x].first + k) * channels + c]);
    for (size_t y = 0; y < new_height; ++y)
        for (size_t k = 0; k < fy[y].weights.size(); ++k) {
            const float* row = &rows[(fy[y].first + k) * out_row];
            for (size_t i = 0; i < out_row; ++i) out[y * out_row + i] += fy[y].weights[k] * row[i];
        }
    return out;
}

// Keeps every k-th tick so that at most max_ticks remain.
std::vector<float> thin(std::vector<float> ticks, int max_ticks) {
    const size_t limit = std::max(1, max_ticks), every = std::max<size_t>(1, (ticks.size() + limit - 1) / limit);
    std::vector<float> kept;
    for (size_t i = 0; i < ticks.size(); i += every) kept.push_back(ticks[i]);
    return kept;
}

std::vector<float> linear_ticks(double lo, double hi, int max_ticks) {
    if (!(hi > lo)) return {static_cast<float>(lo)};
    const double raw = (hi - lo) / std::max(1, max_ticks - 1);
    const double unit = std::pow(10.0, std::floor(std::log10(raw)));
    double step = 10 * unit;
    for (double m : {1.0, 2.0, 5.0})
        if (m * unit >= raw) {
            step = m * unit;
            break;
        }
    std::vector<float> ticks;
    for (double k = std::ceil(lo / step - 1e-6); k * step <= hi + 1e-6 * step; ++k)
        ticks.push_back(static_cast<float>(k * step));
    return thin(std::move(ticks), max_ticks);
}

// The values m x 10^e in [lo, hi] for every mantissa m of `mantissas`, ascending.
std::vector<float> mantissa_ticks(double lo, double hi, std::span<const double> mantissas) {
    const double slack = 1e-6;
    std::vector<float> ticks;
    for (int e = static_cast<int>(std::floor(std::log10(lo))) - 1; e <= static_cast<int>(std::ceil(std::log10(hi)));
         ++e)
        for (double m : mantissas)
            if (const double v = m * std::pow(10.0, e); v >= lo * (1 - slack) && v <= hi * (1 + slack))
                ticks.push_back(static_cast<float>(v));
    return ticks;
}

// Powers of ten where there are three or more; else the coarsest round steps that give
// three to max_ticks ticks (1-2-5, 1-3, 1-2-4-6-8, every digit); else the 1-2-5 ticks
// thinned, or a linear scale within one decade.
std::vector<float> log_ticks(double lo, double hi, int max_ticks) {
    static constexpr double decades[] = {1}, one_two_five[] = {1, 2, 5}, one_three[] = {1, 3}, even[] = {1, 2, 4, 6, 8},
                            digits[] = {1, 2, 3, 4, 5, 6, 7, 8, 9};
    if (std::vector<float> ticks = mantissa_ticks(lo, hi, decades); ticks.size() >= 3)
        return thin(std::move(ticks), max_ticks);
    for (std::span<const double> steps : {std::span<const double>(one_two_five), std::span<const double>(one_three),
                                          std::span<const double>(even), std::span<const double>(digits)})
        if (std::vector<float> ticks = mantissa_ticks(lo, hi, steps);
            ticks.size() >= 3 && ticks.size() <= static_cast<size_t>(max_ticks))
            return ticks;
    std::vector<float> ticks = mantissa_ticks(lo, hi, one_two_five);
    return ticks.size() >= 2 ? thin(std::move(ticks), max_ticks) : linear_ticks(lo, hi, max_ticks);
}

}  // namespace

float srgb_encode(float linear) {
    if (!(linear > 0)) return 0;
    if (linear >= 1) return 1;
    return linear <= 0.0031308f ? 12.92f * linear : 1.055f * std::pow(linear, 1 / 2.4f) - 0.055f;
}

float srgb_decode(float encoded) {
    if (!(encoded > 0)) return 0;
    if (encoded >= 1) return 1;
    return encoded <= 0.04045f ? encoded / 12.92f : std::pow((encoded + 0.055f) / 1.055f, 2.4f);
}

Image8 make_image(uint32_t width, uint32_t height, Rgb8 fill) {
    Image8 image{width, height, std::vector<uint8_t>(static_cast<size_t>(width) * height * 3)};
    fill_rect(image, 0, 0, static_cast<int>(width), static_cast<int>(height), fill);
    return image;
}

Rgb8 pixel(const Image8& image, uint32_t x, uint32_t y) {
    const uint8_t* p = &image.rgb[(static_cast<size_t>(y) * image.width + x) * 3];
    return {p[0], p[1], p[2]};
}

void fill_rect(Image8& image, int x, int y, int w, int h, Rgb8 colour) {
    const int x0 = std::max(x, 0), x1 = std::min(x + w, static_cast<int>(image.width));
    const int y0 = std::max(y, 0), y1 = std::min(y + h, static_cast<int>(image.height));
    for (int row = y0; row < y1; ++row)
        for (int col = x0; col < x1; ++col) {
            uint8_t* p = at(image, col, row);
            p[0] = colour.r, p[1] = colour.g, p[2] = colour.b;
        }
}

void blit(Image8& dst, const Image8& src, int x, int y) {
    const int col0 = std::max(0, -x), col1 = std::min(static_cast<int>(src.width), static_cast<int>(dst.width) - x);
    const int row1 = std::min(static_cast<int>(src.height), static_cast<int>(dst.height) - y);
    if (col0 >= col1) return;
    for (int row = std::max(0, -y); row < row1; ++row)
        std::copy_n(&src.rgb[(static_cast<size_t>(row) * src.width + col0) * 3], (col1 - col0) * 3,
                    at(dst, x + col0, y + row));
}

RgbImage resize(RgbImageView image, uint32_t new_width, uint32_t new_height) {
    const auto values = resample(reinterpret_cast<const float*>(image.pixels.data()), image.width, image.height, 3,
                                 new_width, new_height);
    RgbImage out{new_width, new_height, RgbPixels(values.size() / 3)};
    for (size_t i = 0; i < out.pixels.size(); ++i)
        out.pixels[i] = {values[3 * i], values[3 * i + 1], values[3 * i + 2]};
    return out;
}

std::vector<float> resize(std::span<const float> values, uint32_t width, uint32_t height, uint32_t new_width,
                          uint32_t new_height) {
    return resample(values.data(), width, height, 1, new_width, new_height);
}

Image8 resize(const Image8& image, uint32_t new_width, uint32_t new_height) {
    std::array<float, 256> decoded;
    for (int i = 0; i < 256; ++i) decoded[i] = srgb_decode(i / 255.0f);
    std::vector<float> linear(image.rgb.size());
    std::transform(image.rgb.begin(), image.rgb.end(), linear.begin(), [&](uint8_t v) { return decoded[v]; });
    const auto values = resample(linear.data(), image.width, image.height, 3, new_width, new_height);
    Image8 out{new_width, new_height, std::vector<uint8_t>(values.size())};
    std::transform(values.begin(), values.end(), out.rgb.begin(), ByteEncoder());
    return out;
}

Image8 tonemap(RgbImageView image, float exposure_stops, LumaCoefficients luma) {
    constexpr float kMidGrey = 0.18f, kWhite = 8;
    double log_sum = 0;
    size_t lit = 0;
    for (const Rgb& p : image.pixels) {
        const float y = luminance({radiance_or_zero(p.r), radiance_or_zero(p.g), radiance_or_zero(p.b)}, luma);
        if (y > 0 && std::isfinite(y)) log_sum += std::log(double(y)), ++lit;
    }
    const double log_average = lit ? std::exp(log_sum / lit) : 1;
    const float exposure = static_cast<float>(kMidGrey / log_average * std::exp2(double(exposure_stops)));
    // Extended Reinhard, which reaches exactly 1 at kWhite; clamping there first keeps
    // huge values (the sun at a high exposure) from overflowing to NaN.
    const ByteEncoder to_byte;
    const auto encode = [&](float v) {
        const float x = std::min(exposure * radiance_or_zero(v), kWhite);
        return to_byte(x * (1 + x / (kWhite * kWhite)) / (1 + x));
    };
    Image8 out{image.width, image.height, std::vector<uint8_t>(image.pixels.size() * 3)};
    for (size_t i = 0; i < image.pixels.size(); ++i) {
        out.rgb[3 * i] = encode(image.pixels[i].r);
        out.rgb[3 * i + 1] = encode(image.pixels[i].g);
        out.rgb[3 * i + 2] = encode(image.pixels[i].b);
    }
    return out;
}

float ColourScale::position(float value) const {
    const float t =
        log ? (value > 0 && lo > 0 ? std::log(value / lo) / std::log(hi / lo) : 0.0f) : (value - lo) / (hi - lo);
    return std::isnan(t) ? 0.0f : clamp(t, 0.0f, 1.0f);
}

Rgb8 colour_map(float t) {
    // Chosen so that CIELAB L* rises in nearly equal steps of ~9.3 between neighbours.
    constexpr std::array<Rgb8, 9> kStops{{{70, 8, 88},
                                          {71, 42, 122},
                                          {62, 74, 138},
                                          {48, 106, 142},
                                          {36, 138, 140},
                                          {38, 168, 128},
                                          {88, 196, 100},
                                          {166, 216, 62},
                                          {250, 230, 40}}};
    const float x = (std::isnan(t) ? 0.0f : clamp(t, 0.0f, 1.0f)) * (kStops.size() - 1);
    const size_t i = std::min(static_cast<size_t>(x), kStops.size() - 2);
    const float f = x - i;
    const auto mix = [f](uint8_t a, uint8_t b) { return static_cast<uint8_t>(std::lround(a + f * (b - a))); };
    const Rgb8 a = kStops[i], b = kStops[i + 1];
    return {mix(a.r, b.r), mix(a.g, b.g), mix(a.b, b.b)};
}

Rgb8 false_colour(float value, const ColourScale& scale) {
    if (std::isnan(value) || (scale.log && !(value > 0))) return kNoValueColour;
    return colour_map(scale.position(value));
}

Image8 false_colour(std::span<const float> values, uint32_t width, uint32_t height, const ColourScale& scale) {
    Image8 out{width, height, std::vector<uint8_t>(static_cast<size_t>(width) * height * 3)};
    for (size_t i = 0; i < std::min(values.size(), out.rgb.size() / 3); ++i) {
        const Rgb8 c = false_colour(values[i], scale);
        out.rgb[3 * i] = c.r, out.rgb[3 * i + 1] = c.g, out.rgb[3 * i + 2] = c.b;
    }
    return out;
}

ColourScale shared_log_scale(std::span<const std::span<const float>> images, float low_quantile, float max_decades) {
    // A histogram gives the quantile without copying or sorting hundreds of millions of
    // values. Its bins are a float's exponent and two leading mantissa bits: ordered like
    // the values, at most a third of a stop wide, and found without a logarithm.
    constexpr int kDroppedBits = 21;
    const auto bin_of = [](float v) { return std::bit_cast<uint32_t>(v) >> kDroppedBits; };
    std::vector<uint64_t> histogram(bin_of(std::numeric_limits<float>::infinity()));
    float hi = 0;
    uint64_t count = 0;
    for (std::span<const float> image : images)
        for (float v : image)
            if (v > 0 && std::isfinite(v)) {
                hi = std::max(hi, v), ++count;
                ++histogram[bin_of(v)];
            }
    if (count == 0) return {0.1f, 1, true};
    const auto below = static_cast<uint64_t>(clamp(low_quantile, 0.0f, 1.0f) * static_cast<double>(count));
    size_t bin = 0;
    for (uint64_t seen = histogram[0]; seen <= below && bin + 1 < histogram.size();) seen += histogram[++bin];
    float lo = std::bit_cast<float>(static_cast<uint32_t>(bin) << kDroppedBits);
    lo = std::max(lo, hi * std::pow(10.0f, -max_decades));
    if (!(lo < hi)) lo = hi / 10;
    return {lo, hi, true};
}

std::vector<float> scale_ticks(const ColourScale& scale, int max_ticks) {
    if (!std::isfinite(scale.lo) || !std::isfinite(scale.hi)) return {};
    if (scale.log && scale.lo > 0 && scale.hi > scale.lo) return log_ticks(scale.lo, scale.hi, max_ticks);
    return linear_ticks(scale.lo, scale.hi, max_ticks);
}

std::string tick_label(float value) {
    if (value == 0) return "0";
    if (!std::isfinite(value)) return std::isnan(value) ? "nan" : value > 0 ? "inf" : "-inf";
    // Scientific notation first, for the decimal exponent after rounding (9.999 -> 1.00e1).
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.2e", double(value));
    const int exponent = std::atoi(std::strchr(buf, 'e') + 1);
    if (exponent >= -2 && exponent <= 3)
        std::snprintf(buf, sizeof buf, "%.4g", double(value));
    else
        std::snprintf(buf, sizeof buf, "%.3ge%d", value / std::pow(10.0, exponent), exponent);
    return buf;
}

Image8 colour_bar(const ColourScale& scale, std::string_view label, uint32_t length, Orientation orientation,
                  const Style& style) {
    const bool horizontal = orientation == Orientation::horizontal;
    const int s = style.text_scale, th = text_height(s), cap = (kGlyphHeight - 2) * s;
    const int thickness = 12 * s, tick = 3 * s, head = th + 2 * s;

    std::vector<std::pair<float, std::string>> ticks;
    int widest = text_width("0", s);
    for (float v : scale_ticks(scale)) {
        ticks.emplace_back(v, tick_label(v));
        widest = std::max(widest, text_width(ticks.back().second, s));
    }

    // The along axis runs from the low end (left, or bottom) at 0; labels centred on the
    // end ticks overhang the strip by half their extent. On a log scale the "0" swatch
    // comes first, far enough from the strip that its label keeps clear of the first tick's.
    const int end_room = (horizontal ? widest / 2 : cap / 2) + s;
    const int swatch_to_strip = scale.log ? std::max(thickness, horizontal ? widest + 2 * s : 0) + thickness / 2 : 0;
    const int strip_begin = end_room + swatch_to_strip;
    const int strip_length =
        std::max(static_cast<int>(length) - (horizontal ? 0 : head) - end_room, strip_begin + 8 * s) - strip_begin;
    const int along = strip_begin + strip_length + end_room;
    const int across = 1 + thickness + tick + 3 * s + widest;
    const int strip_across = horizontal ? head + 1 : 1;
    const int width = horizontal ? along : std::max(across, text_width(label, s));
    const int height = horizontal ? strip_across + thickness + tick + s + th : along + head;

    Image8 bar = make_image(width, height, style.background);
    const auto rect = [&](int a, int a_length, int c, int c_length, Rgb8 colour) {
        if (horizontal)
            fill_rect(bar, a, c, a_length, c_length, colour);
        else
            fill_rect(bar, c, height - a - a_length, c_length, a_length, colour);
    };
    const auto mark = [&](int a, std::string_view text) {
        rect(a - s / 2, s, strip_across + thickness, tick, style.text);
        // Further from a vertical bar's ticks, which would otherwise read as minus signs.
        const int label_at = strip_across + thickness + tick + (horizontal ? s : 3 * s);
        if (horizontal)
            draw_text(bar, a - text_width(text, s) / 2, label_at, text, style.text, s);
        else
            draw_text(bar, label_at, height - 1 - a - cap / 2, text, style.text, s);
    };

    draw_text(bar, horizontal ? (width - text_width(label, s)) / 2 : 0, 0, label, style.text, s);
    rect(strip_begin - 1, strip_length + 2, strip_across - 1, thickness + 2, style.frame);
    for (int i = 0; i < strip_length; ++i)
        rect(strip_begin + i, 1, strip_across, thickness, colour_map(static_cast<float>(i) / (strip_length - 1)));
    for (const auto& [value, text] : ticks)
        mark(strip_begin + static_cast<int>(std::lround(scale.position(value) * (strip_length - 1))), text);
    if (scale.log) {
        rect(end_room - 1, thickness + 2, strip_across - 1, thickness + 2, style.frame);
        rect(end_room, thickness, strip_across, thickness, kNoValueColour);
        mark(end_room + thickness / 2, "0");
    }
    return bar;
}

std::string_view cut_to_width(std::string_view text, int width, int scale) {
    const int fitting = (width + (kGlyphAdvance - kGlyphWidth) * scale) / (kGlyphAdvance * scale);
    return text.substr(0, static_cast<size_t>(std::max(fitting, 0)));
}

namespace {

// Greedy line breaks after each '-' and at spaces (dropped), each line at most `width`
// pixels wide at `scale`; a piece too wide alone is cut.
std::vector<std::string> wrap_to_width(std::string_view text, int width, int scale) {
    std::vector<std::string> lines;
    std::string line;
    for (size_t i = 0; i < text.size();) {
        const size_t end = std::min(text.find_first_of("- ", i), text.size() - 1) + 1;
        std::string piece(text.substr(i, end - i));
        i = end;
        const bool space = piece.back() == ' ';
        if (space) piece.pop_back();
        if (!line.empty() && text_width(line + piece, scale) > width) lines.push_back(std::exchange(line, {}));
        line += piece;
        if (space && !line.empty()) line += ' ';
    }
    if (!line.empty()) lines.push_back(line);
    for (std::string& l : lines) {
        while (!l.empty() && l.back() == ' ') l.pop_back();
        l = std::string(cut_to_width(l, width, scale));
    }
    return lines;
}

}  // namespace

Image8 montage(std::span<const Panel> panels, std::string_view caption, const Image8* colour_bar, const Style& style) {
    const int s = style.text_scale, th = text_height(s), margin = style.margin, gap = style.gap;
    int row_width = 0, row_height = 0, keyed_begin = -1, keyed_end = 0;
    bool titled = false;
    for (const Panel& p : panels) {
        row_width += row_width > 0 ? gap : 0;
        if (p.uses_colour_bar && keyed_begin < 0) keyed_begin = row_width;
        row_width += static_cast<int>(p.image.width);
        if (p.uses_colour_bar) keyed_end = row_width;
        row_height = std::max(row_height, static_cast<int>(p.image.height));
        titled |= !p.title.empty();
    }
    if (keyed_begin < 0) keyed_begin = 0, keyed_end = row_width;
    const bool tall_bar = colour_bar && colour_bar->height > colour_bar->width;
    const int bar_width = colour_bar ? static_cast<int>(colour_bar->width) : 0;
    const int bar_height = colour_bar ? static_cast<int>(colour_bar->height) : 0;
    const int top = margin + (caption.empty() ? 0 : th + gap) + (titled ? th + s : 0);
    const int content_width =
        std::max({row_width + (tall_bar ? gap + bar_width : 0), text_width(caption, s), tall_bar ? 0 : bar_width});
    const int content_height =
        tall_bar ? std::max(row_height, bar_height) : row_height + (colour_bar ? gap + bar_height : 0);

    Image8 out = make_image(2 * margin + content_width, top + content_height + margin, style.background);
    draw_text(out, margin, margin, caption, style.text, s);
    int x = margin;
    for (const Panel& p : panels) {
        const int w = static_cast<int>(p.image.width);
        fill_rect(out, x - 1, top - 1, w + 2, static_cast<int>(p.image.height) + 2, style.frame);
        blit(out, p.image, x, top);
        const std::string_view title = cut_to_width(p.title, w, s);
        draw_text(out, x + (w - text_width(title, s)) / 2, top - th - s, title, style.text, s);
        x += w + gap;
    }
    if (tall_bar)
        blit(out, *colour_bar, margin + row_width + gap, top);
    else if (colour_bar)
        blit(out, *colour_bar, margin + clamp((keyed_begin + keyed_end - bar_width) / 2, 0, content_width - bar_width),
             top + row_height + gap);
    return out;
}

GridFigure grid(const Grid& grid, std::string_view caption, const Image8* colour_bar, const Style& style) {
    const size_t columns = grid.columns.size(), rows = grid.rows.size();
    if (grid.cells.size() != rows * columns)
        throw std::invalid_argument("grid: " + std::to_string(grid.cells.size()) + " cells for " +
                                    std::to_string(rows) + " rows x " + std::to_string(columns) + " columns");
    const int s = style.text_scale, th = text_height(s), line = th + s, margin = style.margin, gap = style.gap;
    int cell_w = 0, cell_h = 0, label_w = 0;
    for (const GridCell& c : grid.cells)
        cell_w = std::max(cell_w, static_cast<int>(c.image.width)),
        cell_h = std::max(cell_h, static_cast<int>(c.image.height));
    for (const std::string& r : grid.rows) label_w = std::max(label_w, text_width(r, s));
    if (label_w > 0) label_w += gap;
    std::vector<std::vector<std::string>> titles;
    size_t title_lines = 0;
    for (const std::string& c : grid.columns) {
        titles.push_back(wrap_to_width(c, cell_w, s));
        title_lines = std::max(title_lines, titles.back().size());
    }
    std::vector<int> row_top(rows + 1);
    const int top = margin + (caption.empty() ? 0 : th + gap) + static_cast<int>(title_lines) * line;
    row_top[0] = top;
    for (size_t r = 0; r < rows; ++r) {
        bool captioned = false;
        for (size_t c = 0; c < columns; ++c) captioned |= !grid.cells[r * columns + c].caption.empty();
        row_top[r + 1] = row_top[r] + cell_h + (captioned ? line : 0) + gap;
    }
    const int cells_w = columns ? static_cast<int>(columns) * (cell_w + gap) - gap : 0;
    const int cells_h = rows ? row_top[rows] - gap - top : 0;
    const int bar_w = colour_bar ? static_cast<int>(colour_bar->width) : 0;
    const int content_w = std::max({label_w + cells_w, text_width(caption, s), bar_w});
    const int content_h = cells_h + (colour_bar ? gap + static_cast<int>(colour_bar->height) : 0);

    GridFigure out{make_image(2 * margin + content_w, top + content_h + margin, style.background), {}};
    draw_text(out.image, margin, margin, caption, style.text, s);
    const auto column_x = [&](size_t c) { return margin + label_w + static_cast<int>(c) * (cell_w + gap); };
    for (size_t c = 0; c < columns; ++c)
        for (size_t k = 0; k < titles[c].size(); ++k)
            draw_text(out.image, column_x(c) + (cell_w - text_width(titles[c][k], s)) / 2,
                      top - static_cast<int>(titles[c].size() - k) * line, titles[c][k], style.text, s);
    for (size_t r = 0; r < rows; ++r) {
        draw_text(out.image, margin, row_top[r] + (cell_h - th) / 2, grid.rows[r], style.text, s);
        for (size_t c = 0; c < columns; ++c) {
            const GridCell& cell = grid.cells[r * columns + c];
            const int w = static_cast<int>(cell.image.width), h = static_cast<int>(cell.image.height);
            Rect placed{column_x(c) + (cell_w - w) / 2, row_top[r] + (cell_h - h) / 2, w, h};
            if (w > 0 && h > 0) {
                fill_rect(out.image, placed.x - 1, placed.y - 1, w + 2, h + 2, style.frame);
                blit(out.image, cell.image, placed.x, placed.y);
            } else {
                placed.width = placed.height = 0;
            }
            out.cells.push_back(placed);
            const std::string_view text = cut_to_width(cell.caption, cell_w, s);
            draw_text(out.image, column_x(c) + (cell_w - text_width(text, s)) / 2, row_top[r] + cell_h + s, text,
                      style.text, s);
        }
    }
    if (colour_bar)
        blit(out.image, *colour_bar, margin + clamp(label_w + (cells_w - bar_w) / 2, 0, content_w - bar_w),
             top + cells_h + gap);
    return out;
}

}  // namespace envmis::pictures
