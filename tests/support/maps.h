// Test support: synthetic functions and environment maps made by code.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "envmis/image/image.h"
#include "stats.h"

namespace envmis::test {

inline RgbImage constant_map(uint32_t w, uint32_t h, Rgb c) { return {w, h, RgbPixels(size_t{w} * h, c)}; }

// A sky that brightens towards the zenith, with a small, very bright sun.
inline RgbImage sun_sky_map(uint32_t w, uint32_t h, float sun_radiance = 5e4f) {
    RgbImage m = constant_map(w, h, {});
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            const float sky = 0.2f + 0.8f * (1.0f - static_cast<float>(y) / h);
            m.pixels[size_t{y} * w + x] = {0.6f * sky, 0.8f * sky, 1.2f * sky};
        }
    const uint32_t sx = w / 3, sy = h / 4;
    for (uint32_t y = sy; y < sy + std::max(1u, h / 64); ++y)
        for (uint32_t x = sx; x < sx + std::max(1u, w / 128); ++x)
            m.pixels[size_t{y} * w + x] = {sun_radiance, sun_radiance, sun_radiance};
    return m;
}

// Random RGB over several decades, so that every texel has a different luminance.
inline RgbImage random_map(uint32_t w, uint32_t h, uint64_t seed, float decades = 4) {
    Rng rng(seed);
    RgbImage m = constant_map(w, h, {});
    for (Rgb& p : m.pixels) {
        const float l = std::pow(10.0f, decades * (rng.uniform() - 0.5f));
        p = {l * rng.uniform(), l * rng.uniform(), l * rng.uniform()};
    }
    return m;
}

// Random non-negative function values over several decades, with some exact zeros.
inline std::vector<float> random_function(size_t n, uint64_t seed, float decades = 3) {
    Rng rng(seed);
    std::vector<float> f(n);
    for (float& v : f) v = rng.uniform() < 0.1f ? 0.0f : std::pow(10.0f, decades * (rng.uniform() - 0.5f));
    return f;
}

}  // namespace envmis::test
