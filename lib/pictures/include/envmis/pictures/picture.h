// Labelled pictures for people: tone mapping, false colour, colour bars, text and montages.
//
// Everything here is pure CPU work on images in memory (write_png in image_io.h writes
// the result). Pictures are Image8: 8-bit sRGB-encoded RGB, row 0 at the top. Coordinates
// are pixels, x to the right and y down; drawing is clipped at the image's edges.
//
// A typical figure: resize() the float data down to panel size, tonemap() or
// false_colour() it with one shared_log_scale(), and montage() the panels with a
// colour_bar() of that scale.
#pragma once

#include <array>
#include <cstdint>
#include <initializer_list>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "envmis/image/image.h"
#include "envmis/io/image_io.h"
#include "envmis/math/math.h"

namespace envmis::pictures {

// The picture type is I/O's, so that write_png() in image_io.h takes these directly.
using io::Image8;

// An sRGB-encoded 8-bit colour.
struct Rgb8 {
    uint8_t r = 0, g = 0, b = 0;
    friend bool operator==(Rgb8, Rgb8) = default;
};

// ---------------------------------------------------------------------------------------
// Pixels and encoding

// The sRGB transfer function (IEC 61966-2-1), piecewise: linear below 0.0031308, a 1/2.4
// power above. Input is clamped to [0, 1]; NaN encodes as 0.
float srgb_encode(float linear);
// Its inverse, from an encoded value in [0, 1] to linear.
float srgb_decode(float encoded);

// A width x height picture filled with one colour.
Image8 make_image(uint32_t width, uint32_t height, Rgb8 fill);
// The colour at (x, y); x < width and y < height.
Rgb8 pixel(const Image8& image, uint32_t x, uint32_t y);
// Fills the rectangle [x, x + w) x [y, y + h).
void fill_rect(Image8& image, int x, int y, int w, int h, Rgb8 colour);
// Copies `src` with its top-left corner at (x, y) of `dst`.
void blit(Image8& dst, const Image8& src, int x, int y);

// Area-weighted box resampling to new_width x new_height: each output pixel is the mean of
// the input area it covers, so downsizing an 8192x4096 map to 512x256 averages 16x16
// blocks and keeps the image's mean. NaN and Inf count as 0.
RgbImage resize(RgbImageView image, uint32_t new_width, uint32_t new_height);
// The same for one float per pixel (densities, errors), row-major, width x height values.
std::vector<float> resize(std::span<const float> values, uint32_t width, uint32_t height, uint32_t new_width,
                          uint32_t new_height);
// The same for a picture, averaged in linear light so that edges do not darken.
Image8 resize(const Image8& image, uint32_t new_width, uint32_t new_height);

// ---------------------------------------------------------------------------------------
// Tone mapping

// Maps linear radiance to a displayable picture. The exposure is set from the image, so
// that its log-average luminance (over pixels brighter than 0) lands on mid grey 0.18, and
// then raised by `exposure_stops`; an extended Reinhard curve compresses each channel and
// reaches white at 8 (44 times mid grey), so the sun turns white rather than clipping to
// a hue; the result is sRGB-encoded. Black maps to black and the mapping is monotone in
// each channel. NaN, Inf and negative channel values are treated as 0. Downsize first:
// it is faster, and the exposure is then measured on what is shown.
Image8 tonemap(RgbImageView image, float exposure_stops = 0, LumaCoefficients luma = {});

// ---------------------------------------------------------------------------------------
// False colour

// The range of values a colour map spans: lo maps to the dark end, hi to the bright end,
// values outside are clamped. On a log scale (lo > 0) positions are proportional to
// log(value); values <= 0 have no position and are drawn in kNoValueColour.
struct ColourScale {
    float lo = 0, hi = 1;
    bool log = false;

    // The position of `value` on the scale, clamped to [0, 1]; 0 for values without one.
    float position(float value) const;
};

// The colour of values that have no place on the scale: NaN, and <= 0 on a log scale
// (a sampling density of zero). Black, darker than any colour of the map.
inline constexpr Rgb8 kNoValueColour{0, 0, 0};

// The colour map at position t in [0, 1] (clamped): dark violet through blue, teal and
// green to yellow, with CIELAB lightness rising evenly from 16 to 90, so equal steps of the
// scale look equal and the map reads in greyscale.
Rgb8 colour_map(float t);
// The colour of one value: kNoValueColour or colour_map(scale.position(value)).
Rgb8 false_colour(float value, const ColourScale& scale);
// A width x height picture of row-major `values` (width * height of them).
Image8 false_colour(std::span<const float> values, uint32_t width, uint32_t height, const ColourScale& scale);

// One log scale for several images, so they can be compared by colour: hi is the largest
// finite value of all of them, lo the `low_quantile` of their positive values together
// (isolated tiny values would otherwise waste the map), but at most `max_decades` below
// hi. Without any positive value the scale is [0.1, 1].
ColourScale shared_log_scale(std::span<const std::span<const float>> images, float low_quantile = 0.01f,
                             float max_decades = 8);
inline ColourScale shared_log_scale(std::initializer_list<std::span<const float>> images, float low_quantile = 0.01f,
                                    float max_decades = 8) {
    return shared_log_scale(std::span(images.begin(), images.size()), low_quantile, max_decades);
}

// Round values inside the scale to label it with, at most `max_ticks` of them, ascending:
// on a log scale, powers of ten (every k-th decade on long ranges) where there are three,
// else the coarsest of 1-2-5, 1-3, 1-2-4-6-8 and 1-to-9 steps that gives three (0.4, 0.6,
// 0.8, 1 over 0.35 to 1.2); multiples of 1, 2 or 5 times a power of ten on a linear one.
std::vector<float> scale_ticks(const ColourScale& scale, int max_ticks = 6);
// A short label for a tick: "0.01", "0.5", "1", "100", "1000", but "1e-3", "2.5e4"
// outside [0.01, 9999].
std::string tick_label(float value);

// ---------------------------------------------------------------------------------------
// Text

// The built-in font: 5x9 pixel glyphs (7 above the baseline, 2 for descenders) for
// printable ASCII 32..126, on a 6-pixel advance. Each glyph row is a 5-bit mask, bit 4
// the leftmost pixel. Other characters are drawn as '?'.
inline constexpr int kGlyphWidth = 5, kGlyphHeight = 9, kGlyphAdvance = 6;
using GlyphRows = std::array<uint8_t, kGlyphHeight>;
const GlyphRows& glyph(char c);

// Width and height in pixels of the box text drawn at `scale` (each font pixel a
// scale x scale square) covers; the width has no trailing spacing.
int text_width(std::string_view text, int scale = 1);
int text_height(int scale = 1);
// The longest start of `text` whose box fits in `width` pixels at `scale` (labels cut to
// their panel or column).
std::string_view cut_to_width(std::string_view text, int width, int scale = 1);
// Draws one line of text with the top-left corner of its box at (x, y); nothing outside
// that box changes.
void draw_text(Image8& image, int x, int y, std::string_view text, Rgb8 colour, int scale = 1);

// ---------------------------------------------------------------------------------------
// Figures

// Shared look of colour bars and montages.
struct Style {
    int text_scale = 2;  // font pixel size of all labels
    int margin = 16;     // around the figure
    int gap = 12;        // between panels, and between panels and titles or colour bar
    Rgb8 background{22, 22, 26};
    Rgb8 text{232, 232, 232};
    Rgb8 frame{92, 92, 100};  // 1-pixel outline around panels and the colour bar's strip
};

enum class Orientation { horizontal, vertical };

// A colour bar for `scale`: a strip of the colour map with tick marks and tick_label()s,
// `label` (e.g. the quantity and its unit) above it and, for a log scale, a black swatch
// marked "0" for kNoValueColour. Horizontal bars grow left to right and suit the bottom of
// a montage; vertical ones grow upwards and suit its right side. The picture is `length`
// pixels wide (horizontal) or high (vertical, label included), or more if its labels need
// it; the other dimension follows from the text size.
Image8 colour_bar(const ColourScale& scale, std::string_view label, uint32_t length,
                  Orientation orientation = Orientation::horizontal, const Style& style = {});

// A picture with its title, for montage().
struct Panel {
    Image8 image;
    std::string title;
    bool uses_colour_bar = false;  // false colour on the montage's colour bar's scale
};

// Panels side by side, top-aligned, in a frame, each with its title centred above it (cut
// to the panel's width), a caption line at the top left and, optionally, a colour bar:
// a wide one (width >= height) below the panels, centred under those that use it (all
// panels if none is marked) as far as the figure's edges allow; a tall one to their right.
// Width: 2 margins + the panels' widths + a gap between neighbours (+ a gap and the bar's
// width for a tall bar), widened if the caption or a wide bar needs more.
Image8 montage(std::span<const Panel> panels, std::string_view caption, const Image8* colour_bar = nullptr,
               const Style& style = {});

// A cell of a grid(): a picture (an empty one leaves the cell blank) and a caption drawn
// under it ("" for none).
struct GridCell {
    Image8 image;
    std::string caption;
};

// Pictures in rows and columns under column titles, beside row titles.
struct Grid {
    std::vector<std::string> columns, rows;
    std::vector<GridCell> cells;  // row-major: rows.size() x columns.size()
};

// A rectangle of a figure, in its pixels: top-left corner and size.
struct Rect {
    int x = 0, y = 0, width = 0, height = 0;
    friend bool operator==(Rect, Rect) = default;
};

// A figure and where each cell's picture lies in it, so that a reader (or a test) can
// find any cell without knowing the layout rules.
struct GridFigure {
    Image8 image;
    std::vector<Rect> cells;  // row-major like Grid::cells; empty cells get width 0
};

// The grid on the montage's background: a caption line at the top left; every cell as
// wide as the widest picture and as high as the highest, pictures centred in their cells
// and framed; a gap between cells. A column's title is centred above it, broken after '-'
// and at spaces onto as many lines as the widest column needs (a piece too long for the
// column alone is cut); a row's title is left of its cells, vertically centred. A row with
// a caption gets one text line under its cells, each caption centred and cut to its cell.
// A wide colour bar goes below, centred under the cells as far as the figure allows.
// Throws std::invalid_argument if cells.size() is not rows x columns.
GridFigure grid(const Grid& grid, std::string_view caption, const Image8* colour_bar = nullptr,
                const Style& style = {});

}  // namespace envmis::pictures
