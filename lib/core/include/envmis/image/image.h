// An HDR image in memory and the repair of pixel values a sampler cannot use.
//
// Real maps hold NaN, infinite and negative values (lossy EXR compression leaves small
// negatives); each such channel value is replaced by 0 and counted, never thrown on,
// so a caller can report what was repaired.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <span>

#include "envmis/large_vector.h"
#include "envmis/math/math.h"

namespace envmis {

static_assert(sizeof(Rgb) == 3 * sizeof(float), "Rgb must be three packed floats");

// Read-only view of linear RGB pixels, row-major, row 0 at the top: an RgbImage, or
// pixels that live elsewhere (a memory-mapped table file).
struct RgbImageView {
    uint32_t width = 0, height = 0;
    std::span<const Rgb> pixels;  // width * height

    const Rgb& at(uint32_t x, uint32_t y) const { return pixels[static_cast<size_t>(y) * width + x]; }
};

// An image's pixel buffer: a std::vector whose large blocks live on huge pages
// (large_vector.h), as the lookups into a map's radiance are random.
using RgbPixels = LargeVector<Rgb>;

// Linear RGB pixels, row-major, row 0 at the top.
struct RgbImage {
    uint32_t width = 0, height = 0;
    RgbPixels pixels;  // width * height

    const Rgb& at(uint32_t x, uint32_t y) const { return pixels[static_cast<size_t>(y) * width + x]; }
    operator RgbImageView() const noexcept { return {width, height, pixels}; }
};

// A copy that owns its pixels.
inline RgbImage to_image(RgbImageView view) {
    return {view.width, view.height, RgbPixels(view.pixels.begin(), view.pixels.end())};
}

// Counts of channel values replaced by 0.
struct BadPixels {
    uint64_t nan = 0, infinite = 0, negative = 0;

    uint64_t total() const noexcept { return nan + infinite + negative; }
    BadPixels& operator+=(const BadPixels& o) noexcept {
        nan += o.nan, infinite += o.infinite, negative += o.negative;
        return *this;
    }
};

// Replaces a NaN, infinite or negative channel value by 0, counting it.
inline void sanitize_channel(float& c, BadPixels& bad) noexcept {
    if (c >= 0 && c <= std::numeric_limits<float>::max()) return;
    bad.nan += std::isnan(c);
    bad.infinite += std::isinf(c);
    bad.negative += c < 0 && !std::isinf(c);
    c = 0;
}

inline void sanitize_pixel(Rgb& p, BadPixels& bad) noexcept {
    sanitize_channel(p.r, bad);
    sanitize_channel(p.g, bad);
    sanitize_channel(p.b, bad);
}

}  // namespace envmis
