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

// Maps whose black regions lie beside lit ones, inside one cell of a binned map's grid:
// one lit texel; two bright softboxes on black; a sky over a black lower hemisphere.
inline RgbImage single_texel_map(uint32_t w, uint32_t h, uint32_t x, uint32_t y) {
    RgbImage m = constant_map(w, h, {});
    m.pixels[size_t{y} * w + x] = {1, 1, 1};
    return m;
}
inline RgbImage softboxes_map(uint32_t w, uint32_t h) {
    RgbImage m = constant_map(w, h, {});
    for (uint32_t y = h / 5; y < h / 3; ++y) {
        for (uint32_t x = w / 8; x < w / 8 + w / 10; ++x) m.pixels[size_t{y} * w + x] = {50, 50, 50};
        for (uint32_t x = w / 2 + 3; x < w / 2 + 3 + w / 16; ++x) m.pixels[size_t{y} * w + x] = {20, 30, 40};
    }
    return m;
}
inline RgbImage black_ground_map(uint32_t w, uint32_t h, uint64_t seed) {
    RgbImage m = random_map(w, h, seed, 2);
    for (uint32_t y = h / 2; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) m.pixels[size_t{y} * w + x] = {};
    return m;
}
// Sparse: each texel lit with probability `lit` (over six decades), black otherwise.
inline RgbImage sparse_map(uint32_t w, uint32_t h, uint64_t seed, float lit) {
    Rng rng(seed);
    RgbImage m = constant_map(w, h, {});
    for (Rgb& p : m.pixels)
        if (rng.uniform() < lit) {
            const float l = std::pow(10.0f, 6 * (rng.uniform() - 0.5f));
            p = {l * rng.uniform(), l, l * rng.uniform()};
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
