#include "envmis/pictures/picture.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numeric>
#include <vector>

namespace envmis::pictures {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

float display_luminance(Rgb8 c) {
    return 0.2126f * srgb_decode(c.r / 255.0f) + 0.7152f * srgb_decode(c.g / 255.0f) +
           0.0722f * srgb_decode(c.b / 255.0f);
}

RgbImage grey_ramp(std::vector<float> values) {
    RgbImage image{static_cast<uint32_t>(values.size()), 1, {}};
    for (float v : values) image.pixels.push_back({v, v, v});
    return image;
}

Image8 checker(uint32_t w, uint32_t h) {
    Image8 image = make_image(w, h, {});
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) fill_rect(image, x, y, 1, 1, {uint8_t(x * 7), uint8_t(y * 11), 200});
    return image;
}

// The box [x0, x1) x [y0, y1) of pixels that differ from `colour`; empty if none do.
struct Box {
    int x0 = 1 << 30, y0 = 1 << 30, x1 = 0, y1 = 0;
};
Box changed_box(const Image8& image, Rgb8 colour) {
    Box box;
    for (uint32_t y = 0; y < image.height; ++y)
        for (uint32_t x = 0; x < image.width; ++x)
            if (pixel(image, x, y) != colour) {
                box.x0 = std::min(box.x0, int(x)), box.x1 = std::max(box.x1, int(x) + 1);
                box.y0 = std::min(box.y0, int(y)), box.y1 = std::max(box.y1, int(y) + 1);
            }
    return box;
}

bool contains_colour(const Image8& image, Rgb8 colour) {
    for (uint32_t y = 0; y < image.height; ++y)
        for (uint32_t x = 0; x < image.width; ++x)
            if (pixel(image, x, y) == colour) return true;
    return false;
}

TEST(Srgb, PiecewiseTransferFunction) {
    EXPECT_EQ(srgb_encode(0), 0);
    EXPECT_EQ(srgb_encode(1), 1);
    EXPECT_NEAR(srgb_encode(0.0031308f), 0.04045f, 1e-5);
    EXPECT_NEAR(srgb_encode(0.0031309f), 0.04045f, 1e-5);  // continuous at the breakpoint
    EXPECT_NEAR(srgb_encode(0.001f), 0.01292f, 1e-6);      // linear segment
    EXPECT_NEAR(srgb_encode(0.5f), 0.735357f, 1e-5);
    EXPECT_NEAR(srgb_encode(0.18f), 0.461356f, 1e-5);
    EXPECT_EQ(srgb_encode(kNaN), 0);
    EXPECT_EQ(srgb_encode(-1), 0);
    EXPECT_EQ(srgb_encode(kInf), 1);
    for (float v : {0.0f, 0.002f, 0.0031308f, 0.01f, 0.2f, 0.7f, 1.0f})
        EXPECT_NEAR(srgb_decode(srgb_encode(v)), v, 1e-6);
}

TEST(Tonemap, BlackStaysBlackAndBrighterNeverGetsDarker) {
    std::vector<float> values{0};
    for (float v = 1e-4f; v < 1e5f; v *= 1.5f) values.push_back(v);
    const Image8 out = tonemap(grey_ramp(values));
    ASSERT_EQ(out.width, values.size());
    ASSERT_EQ(out.height, 1u);
    EXPECT_EQ(pixel(out, 0, 0), (Rgb8{0, 0, 0}));
    for (uint32_t x = 1; x < out.width; ++x) EXPECT_GE(pixel(out, x, 0).g, pixel(out, x - 1, 0).g) << x;
    EXPECT_EQ(pixel(out, out.width - 1, 0), (Rgb8{255, 255, 255}));
}

TEST(Tonemap, ExposureFollowsTheImageAndTheGivenStops) {
    // A uniform image lands on mid grey whatever its level: curve(0.18) = 0.155 -> 0.43 sRGB.
    const Rgb8 dim = pixel(tonemap(grey_ramp({0.01f, 0.01f})), 0, 0);
    const Rgb8 bright = pixel(tonemap(grey_ramp({300.0f, 300.0f})), 0, 0);
    EXPECT_EQ(dim, bright);
    EXPECT_NEAR(dim.g, 110, 2);
    EXPECT_GT(pixel(tonemap(grey_ramp({1, 1}), 2), 0, 0).g, dim.g);
    EXPECT_LT(pixel(tonemap(grey_ramp({1, 1}), -2), 0, 0).g, dim.g);
}

TEST(Tonemap, InvalidValuesAreBlack) {
    const Image8 out = tonemap(grey_ramp({kNaN, kInf, -5, 1}));
    for (uint32_t x = 0; x < 3; ++x) EXPECT_EQ(pixel(out, x, 0), (Rgb8{0, 0, 0})) << x;
    EXPECT_GT(pixel(out, 3, 0).g, 0);
    const Image8 huge = tonemap(grey_ramp({1, std::numeric_limits<float>::max()}), 10);
    EXPECT_EQ(pixel(huge, 1, 0), (Rgb8{255, 255, 255}));
    EXPECT_EQ(tonemap(grey_ramp({0, 0})).rgb, std::vector<uint8_t>(6, 0));
    EXPECT_TRUE(tonemap(RgbImage{}).rgb.empty());
}

TEST(ColourMap, LuminanceRisesFromDarkToBright) {
    float previous = -1;
    for (int i = 0; i <= 64; ++i) {
        const float y = display_luminance(colour_map(i / 64.0f));
        EXPECT_GT(y, previous) << i;
        previous = y;
    }
    EXPECT_LT(display_luminance(colour_map(0)), 0.03f);
    EXPECT_GT(display_luminance(colour_map(1)), 0.7f);
    EXPECT_GT(display_luminance(colour_map(0)), display_luminance(kNoValueColour));
    EXPECT_EQ(colour_map(-3), colour_map(0));
    EXPECT_EQ(colour_map(7), colour_map(1));
}

TEST(FalseColour, EndsOfTheScaleAndClamping) {
    const ColourScale linear{2, 6, false};
    EXPECT_EQ(false_colour(2, linear), colour_map(0));
    EXPECT_EQ(false_colour(6, linear), colour_map(1));
    EXPECT_EQ(false_colour(4, linear), colour_map(0.5f));
    EXPECT_EQ(false_colour(-100, linear), colour_map(0));
    EXPECT_EQ(false_colour(1e9f, linear), colour_map(1));
    EXPECT_EQ(false_colour(kInf, linear), colour_map(1));
    EXPECT_EQ(false_colour(kNaN, linear), kNoValueColour);

    const ColourScale log{1e-3f, 10, true};
    EXPECT_EQ(false_colour(1e-3f, log), colour_map(0));
    EXPECT_EQ(false_colour(10, log), colour_map(1));
    EXPECT_EQ(false_colour(0.1f, log), colour_map(0.5f));
    EXPECT_NEAR(log.position(1), 0.75f, 1e-6);
    EXPECT_EQ(false_colour(1e-9f, log), colour_map(0));
    EXPECT_EQ(false_colour(1e9f, log), colour_map(1));
    EXPECT_EQ(false_colour(0, log), kNoValueColour);
    EXPECT_EQ(false_colour(-1, log), kNoValueColour);
    EXPECT_EQ(false_colour(kNaN, log), kNoValueColour);
}

TEST(FalseColour, PictureIsRowMajor) {
    const std::vector<float> values{0, 1e-3f, 0.1f, 10, 0.5f, 1};
    const ColourScale scale{1e-3f, 10, true};
    const Image8 out = false_colour(values, 3, 2, scale);
    ASSERT_EQ(out.rgb.size(), 18u);
    for (uint32_t i = 0; i < 6; ++i) EXPECT_EQ(pixel(out, i % 3, i / 3), false_colour(values[i], scale)) << i;
}

TEST(SharedLogScale, CoversEveryImage) {
    std::vector<float> a(1000), b(1000);
    for (int i = 0; i < 1000; ++i) a[i] = 1.0f + i, b[i] = 1e-3f * (1 + i);
    a[3] = kNaN, a[4] = kInf, b[5] = 0, b[6] = -7;
    const ColourScale scale = shared_log_scale({a, b}, 0);
    EXPECT_TRUE(scale.log);
    EXPECT_EQ(scale.hi, 1000.0f);
    EXPECT_LE(scale.lo, 1e-3f);
    EXPECT_GT(scale.lo, 1e-3f / 1.25f);  // the lower edge of its histogram bin

    const ColourScale robust = shared_log_scale({a, b}, 0.25f);
    EXPECT_GT(robust.lo, 0.3f);
    EXPECT_LE(robust.lo, 0.5f);
    EXPECT_EQ(robust.hi, 1000.0f);
}

TEST(SharedLogScale, SpansAtMostMaxDecadesAndHandlesEmptyInput) {
    const std::vector<float> wide{1e-20f, 1e-12f, 1, 100};
    const ColourScale scale = shared_log_scale({wide}, 0, 8);
    EXPECT_FLOAT_EQ(scale.lo, 1e-6f);
    EXPECT_EQ(scale.hi, 100.0f);

    const std::vector<float> nothing{0, -1, kNaN};
    const ColourScale fallback = shared_log_scale({nothing});
    EXPECT_TRUE(fallback.log);
    EXPECT_LT(fallback.lo, fallback.hi);
    const std::vector<float> single{5};
    const ColourScale one = shared_log_scale({single});
    EXPECT_EQ(one.hi, 5.0f);
    EXPECT_LT(one.lo, one.hi);
}

TEST(Ticks, DecadesOnLogScales) {
    EXPECT_EQ(scale_ticks({1e-3f, 100, true}), (std::vector<float>{1e-3f, 1e-2f, 1e-1f, 1, 10, 100}));
    EXPECT_EQ(scale_ticks({2e-3f, 50, true}), (std::vector<float>{1e-2f, 1e-1f, 1, 10}));
    const auto long_range = scale_ticks({1e-6f, 1e5f, true});
    EXPECT_LE(long_range.size(), 6u);
    EXPECT_EQ(long_range.front(), 1e-6f);
    EXPECT_EQ(scale_ticks({0.3f, 2, true}), (std::vector<float>{0.5f, 1, 2}));
    EXPECT_GE(scale_ticks({1.1f, 1.9f, true}).size(), 2u);
    // Short ranges get at least three labels: finer round steps where 1-2-5 gives two.
    EXPECT_EQ(scale_ticks({0.35f, 1.2f, true}), (std::vector<float>{0.4f, 0.6f, 0.8f, 1}));
    EXPECT_EQ(scale_ticks({2e7f, 2e9f, true}), (std::vector<float>{3e7f, 1e8f, 3e8f, 1e9f}));
}

TEST(Ticks, RoundStepsOnLinearScales) {
    EXPECT_EQ(scale_ticks({0, 1, false}), (std::vector<float>{0, 0.2f, 0.4f, 0.6f, 0.8f, 1}));
    EXPECT_EQ(scale_ticks({-3, 17, false}), (std::vector<float>{0, 5, 10, 15}));
    EXPECT_EQ(scale_ticks({4, 4, false}), (std::vector<float>{4}));
    EXPECT_TRUE(scale_ticks({kNaN, 1, false}).empty());
}

TEST(Ticks, ShortLabels) {
    EXPECT_EQ(tick_label(1e-3f), "1e-3");
    EXPECT_EQ(tick_label(0.01f), "0.01");
    EXPECT_EQ(tick_label(0.5f), "0.5");
    EXPECT_EQ(tick_label(1), "1");
    EXPECT_EQ(tick_label(100), "100");
    EXPECT_EQ(tick_label(1000), "1000");
    EXPECT_EQ(tick_label(1e4f), "1e4");
    EXPECT_EQ(tick_label(2.5e4f), "2.5e4");
    EXPECT_EQ(tick_label(1e-6f), "1e-6");
    EXPECT_EQ(tick_label(0.2f), "0.2");
    EXPECT_EQ(tick_label(0), "0");
    EXPECT_EQ(tick_label(-20), "-20");
    EXPECT_EQ(tick_label(9.9999e-4f), "1e-3");
}

TEST(Font, EveryPrintableCharacterHasAGlyph) {
    for (int c = 33; c <= 126; ++c) {
        const GlyphRows& rows = glyph(char(c));
        EXPECT_NE(std::accumulate(rows.begin(), rows.end(), 0), 0) << char(c);
        for (uint8_t row : rows) EXPECT_LT(row, 1 << kGlyphWidth) << char(c);
    }
    const GlyphRows& space = glyph(' ');
    EXPECT_EQ(std::accumulate(space.begin(), space.end(), 0), 0);
    EXPECT_EQ(&glyph('\n'), &glyph('?'));
    EXPECT_EQ(&glyph(char(200)), &glyph('?'));
    EXPECT_NE(glyph('0'), glyph('O'));
    EXPECT_NE(glyph('l'), glyph('1'));
}

TEST(Text, DrawsInsideItsBoxOnly) {
    const Rgb8 background{10, 20, 30}, ink{250, 250, 250};
    for (int scale : {1, 3}) {
        Image8 image = make_image(200, 60, background);
        const std::string_view text = "Hg|E";  // ink in the first and last columns, a descender
        draw_text(image, 7, 5, text, ink, scale);
        const Box box = changed_box(image, background);
        EXPECT_EQ(box.x0, 7);
        EXPECT_EQ(box.y0, 5);
        EXPECT_EQ(box.x1, 7 + text_width(text, scale));
        EXPECT_EQ(box.y1, 5 + text_height(scale));
        EXPECT_TRUE(contains_colour(image, ink));
    }
    EXPECT_EQ(text_width("", 2), 0);
    EXPECT_EQ(text_width("a", 1), kGlyphWidth);
    EXPECT_EQ(text_width("abc", 2), 2 * (3 * kGlyphAdvance - 1));
    EXPECT_EQ(text_height(2), 2 * kGlyphHeight);
}

TEST(Text, ClipsAtTheImageEdges) {
    Image8 image = make_image(20, 10, {});
    draw_text(image, -8, -4, "clipped text", {255, 0, 0}, 2);
    draw_text(image, 15, 6, "more", {255, 0, 0}, 2);
    EXPECT_EQ(image.rgb.size(), 600u);
    EXPECT_TRUE(contains_colour(image, {255, 0, 0}));
}

TEST(Drawing, BlitCopiesAndClips) {
    const Image8 src = checker(5, 4);
    Image8 dst = make_image(8, 6, {1, 2, 3});
    blit(dst, src, 2, 1);
    EXPECT_EQ(pixel(dst, 2, 1), pixel(src, 0, 0));
    EXPECT_EQ(pixel(dst, 6, 4), pixel(src, 4, 3));
    EXPECT_EQ(pixel(dst, 1, 1), (Rgb8{1, 2, 3}));
    blit(dst, src, -3, 4);
    EXPECT_EQ(pixel(dst, 0, 5), pixel(src, 3, 1));
    blit(dst, src, 100, -100);
    EXPECT_EQ(dst.rgb.size(), 8u * 6 * 3);
}

TEST(Resize, ConstantStaysConstant) {
    RgbImage image{100, 60, RgbPixels(6000, Rgb{0.25f, 2, 7})};
    for (auto [w, h] : {std::pair{37u, 11u}, std::pair{16u, 8u}, std::pair{230u, 97u}}) {
        const RgbImage out = resize(image, w, h);
        ASSERT_EQ(out.pixels.size(), size_t(w) * h);
        for (const Rgb& p : out.pixels) {
            EXPECT_NEAR(p.r, 0.25f, 1e-5);
            EXPECT_NEAR(p.g, 2, 1e-5);
            EXPECT_NEAR(p.b, 7, 1e-5);
        }
    }
    const Image8 flat = make_image(33, 17, {128, 7, 255});
    const Image8 small = resize(flat, 10, 5);
    EXPECT_EQ(changed_box(small, {128, 7, 255}).x1, 0);
}

TEST(Resize, BoxFilterAveragesAndKeepsTheMean) {
    std::vector<float> values(64 * 32);
    for (size_t i = 0; i < values.size(); ++i) values[i] = float(i % 7) + float(i / 64);
    const double mean = std::accumulate(values.begin(), values.end(), 0.0) / values.size();
    for (auto [w, h] : {std::pair{16u, 8u}, std::pair{13u, 5u}, std::pair{100u, 50u}}) {
        const auto out = resize(values, 64, 32, w, h);
        EXPECT_NEAR(std::accumulate(out.begin(), out.end(), 0.0) / out.size(), mean, 1e-3 * mean);
    }
    const std::vector<float> two{1, 3, kNaN, 5};
    EXPECT_EQ(resize(two, 2, 2, 1, 1), (std::vector<float>{2.25f}));  // NaN counts as 0
    EXPECT_EQ(resize(two, 2, 2, 1, 2), (std::vector<float>{2, 2.5f}));
}

TEST(Resize, PicturesAverageInLinearLight) {
    Image8 stripes = make_image(2, 1, {0, 0, 0});
    fill_rect(stripes, 1, 0, 1, 1, {255, 255, 255});
    // Half black and half white is 0.5 linear, 188 encoded, not 128.
    EXPECT_EQ(pixel(resize(stripes, 1, 1), 0, 0), (Rgb8{188, 188, 188}));
}

TEST(ColourBar, HorizontalAndVerticalLengths) {
    const ColourScale log{1e-3f, 100, true}, linear{0, 1, false};
    const Style style;
    const Image8 wide = colour_bar(log, "density (1/sr)", 600, Orientation::horizontal, style);
    EXPECT_EQ(wide.width, 600u);
    EXPECT_GT(wide.width, wide.height);
    EXPECT_TRUE(contains_colour(wide, colour_map(0)));
    EXPECT_TRUE(contains_colour(wide, colour_map(1)));
    EXPECT_TRUE(contains_colour(wide, kNoValueColour));  // the "0" swatch
    EXPECT_TRUE(contains_colour(wide, style.text));

    const Image8 tall = colour_bar(linear, "error", 300, Orientation::vertical, style);
    EXPECT_EQ(tall.height, 300u);
    EXPECT_GT(tall.height, tall.width);
    EXPECT_TRUE(contains_colour(tall, colour_map(1)));
    EXPECT_FALSE(contains_colour(tall, kNoValueColour));

    const Image8 stubby = colour_bar(log, "x", 10);
    EXPECT_GT(stubby.width, 10u);  // grows to hold its labels rather than failing
}

TEST(Montage, SizeIsPanelsPlusGapsAndMargins) {
    Style style;
    style.margin = 10, style.gap = 6, style.text_scale = 1;
    const std::vector<Panel> panels{{checker(40, 20), ""}, {checker(30, 20), ""}, {checker(50, 25), ""}};
    const Image8 bare = montage(panels, "", nullptr, style);
    EXPECT_EQ(bare.width, 2u * 10 + 120 + 2 * 6);
    EXPECT_EQ(bare.height, 2u * 10 + 25);
    EXPECT_EQ(pixel(bare, 10, 10), pixel(panels[0].image, 0, 0));
    EXPECT_EQ(pixel(bare, 10 + 40 + 6 + 29, 10 + 19), pixel(panels[1].image, 29, 19));
    EXPECT_EQ(pixel(bare, 9, 9), style.frame);
    EXPECT_EQ(pixel(bare, 0, 0), style.background);

    std::vector<Panel> titled = panels;
    titled[1].title = "a title far too long for thirty pixels";
    const Image8 labelled = montage(titled, "caption", nullptr, style);
    const int th = text_height(1);
    EXPECT_EQ(labelled.width, bare.width);
    EXPECT_EQ(int(labelled.height), int(bare.height) + th + style.gap + th + 1);
    const int top = 10 + th + style.gap + th + 1;
    EXPECT_EQ(pixel(labelled, 10 + 40 + 6, top), pixel(panels[1].image, 0, 0));
    // The cut title stays within its panel's columns.
    const Box title = changed_box(
        [&] {
            Image8 row = make_image(labelled.width, th, style.background);
            blit(row, labelled, 0, -(top - th - 1));
            return row;
        }(),
        style.background);
    EXPECT_GE(title.x0, 10 + 40 + 6);
    EXPECT_LE(title.x1, 10 + 40 + 6 + 30);

    const Image8 captioned = montage(panels, std::string(60, 'W'), nullptr, style);
    EXPECT_EQ(int(captioned.width), 2 * 10 + text_width(std::string(60, 'W'), 1));
}

TEST(Montage, ColourBarBelowOrBeside) {
    Style style;
    style.margin = 10, style.gap = 6;
    const std::vector<Panel> panels{{checker(100, 50), "a"}, {checker(100, 50), "b"}};
    const Image8 plain = montage(panels, "", nullptr, style);

    const Image8 wide = colour_bar({1e-2f, 1e2f, true}, "density", 180, Orientation::horizontal, style);
    const Image8 below = montage(panels, "", &wide, style);
    EXPECT_EQ(below.width, plain.width);
    EXPECT_EQ(below.height, plain.height + style.gap + wide.height);
    const int bar_x = 10 + (206 - int(wide.width)) / 2, bar_y = int(plain.height) - 10 + style.gap;
    EXPECT_EQ(pixel(below, bar_x + wide.width / 2, bar_y + wide.height / 2),
              pixel(wide, wide.width / 2, wide.height / 2));

    std::vector<Panel> keyed = panels;
    keyed.insert(keyed.begin(), Panel{checker(300, 50), "tone-mapped"});
    keyed[1].uses_colour_bar = keyed[2].uses_colour_bar = true;
    const Image8 under_keyed = montage(keyed, "", &wide, style);
    const int keyed_x = 10 + 300 + 6 + (206 - int(wide.width)) / 2;
    EXPECT_EQ(pixel(under_keyed, keyed_x + wide.width / 2, bar_y + wide.height / 2),
              pixel(wide, wide.width / 2, wide.height / 2));
    EXPECT_EQ(pixel(under_keyed, keyed_x - 1, bar_y + wide.height / 2), style.background);

    const Image8 tall = colour_bar({0, 1, false}, "err", 120, Orientation::vertical, style);
    const Image8 beside = montage(panels, "", &tall, style);
    EXPECT_EQ(beside.width, plain.width + style.gap + tall.width);
    EXPECT_EQ(beside.height, plain.height - 50 + tall.height);
}

TEST(Montage, NoPanels) {
    const Image8 empty = montage({}, "", nullptr, Style{});
    EXPECT_EQ(empty.width, 32u);
    EXPECT_EQ(empty.height, 32u);
}

TEST(Grid, EachCellsPictureLiesWhereItsRectSaysInItsRowAndColumn) {
    Style style;
    style.margin = 10, style.gap = 6, style.text_scale = 1;
    Grid g{{"one", "two", "three"}, {"a", "bb"}, {}};
    for (int i = 0; i < 6; ++i) g.cells.push_back({checker(20 + 4 * (i % 3), 16), i >= 3 ? "cap" : ""});
    g.cells[4].image = {};  // a blank cell
    const GridFigure f = grid(g, "caption", nullptr, style);
    ASSERT_EQ(f.cells.size(), 6u);
    for (size_t i = 0; i < 6; ++i) {
        const Rect r = f.cells[i];
        if (i == 4) {
            EXPECT_EQ(r.width, 0);
            continue;
        }
        EXPECT_EQ(r.width, int(g.cells[i].image.width));
        for (int y : {0, r.height - 1})
            for (int x : {0, r.width - 1})
                EXPECT_EQ(pixel(f.image, r.x + x, r.y + y), pixel(g.cells[i].image, x, y)) << "cell " << i;
    }
    // Cells of a row share their top edge, cells of a column their centre; columns are
    // as wide as the widest picture (28) plus the gap.
    EXPECT_EQ(f.cells[0].y, f.cells[2].y);
    EXPECT_EQ(f.cells[3].y, f.cells[5].y);
    EXPECT_GT(f.cells[3].y, f.cells[0].y + 16);
    EXPECT_EQ(f.cells[0].x + f.cells[0].width / 2, f.cells[3].x + f.cells[3].width / 2);
    EXPECT_EQ(f.cells[1].x + f.cells[1].width / 2 - (f.cells[0].x + f.cells[0].width / 2), 28 + 6);
    // The captioned second row is one text line higher than the first.
    const int th = text_height(1);
    EXPECT_EQ(int(f.image.height), f.cells[3].y + 16 + th + 1 + 10);
}

TEST(Grid, LongColumnTitlesBreakAfterHyphensToFitTheirColumn) {
    Style style;
    style.margin = 10, style.gap = 6, style.text_scale = 1;
    // 40 pixels hold 6 characters: "mis-" / "optim" ... each line within its column.
    const Grid g{{"mis-optimal-bins", "env"}, {"r"}, {{checker(40, 10), ""}, {checker(40, 10), ""}}};
    const GridFigure f = grid(g, "", nullptr, style);
    const int th = text_height(1), line = th + 1;
    EXPECT_EQ(f.cells[0].y, 10 + 3 * line);  // "mis-", "optimal-" cut to "optima", "bins"
    Image8 titles = make_image(f.image.width, 3 * line - 1, style.background);  // without the frames
    blit(titles, f.image, 0, -10);
    const Box box = changed_box(titles, style.background);
    EXPECT_GE(box.x0, f.cells[0].x);
    EXPECT_LE(box.x1, f.cells[1].x + 40);
    EXPECT_THROW(grid(Grid{{"a"}, {"r", "s"}, {{checker(4, 4), ""}}}, ""), std::invalid_argument);
}

}  // namespace
}  // namespace envmis::pictures
