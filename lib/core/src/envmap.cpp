#include "envmis/envmap.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "parallel.h"

namespace envmis {

std::string_view to_string(DensityFallback f) noexcept {
    switch (f) {
        case DensityFallback::none: return "none";
        case DensityFallback::uncompensated: return "uncompensated";
        case DensityFallback::uniform: return "uniform";
    }
    return "unknown";
}

namespace {

constexpr size_t kMaxTexels = size_t{1} << 31;
constexpr uint32_t kRowsPerThread = 8;

void check_image(const RgbImage& image) {
    const size_t n = size_t{image.width} * image.height;
    if (image.width == 0 || image.height == 0 || image.width > kMaxCells1D || image.height > kMaxCells1D || n > kMaxTexels)
        throw std::invalid_argument("environment map size " + std::to_string(image.width) + "x" +
                                    std::to_string(image.height) + " is empty, above 65536 on a side or above 2^31 texels");
    if (image.pixels.size() != n)
        throw std::invalid_argument("environment map: " + std::to_string(image.pixels.size()) +
                                    " pixels do not make a " + std::to_string(image.width) + "x" +
                                    std::to_string(image.height) + " image");
}

void check_options(const EnvMapOptions& o) {
    const float a = o.compensation.alpha;
    if (!(a >= 0 && std::isfinite(a)))
        throw std::invalid_argument("compensation alpha must be finite and >= 0, got " + std::to_string(a));
    if (!o.axes.valid()) throw std::invalid_argument("invalid axes " + o.axes.to_string());
    const LumaCoefficients k = o.luma;
    if (!(k.r >= 0 && k.g >= 0 && k.b >= 0 && k.r + k.g + k.b > 0 && std::isfinite(k.r + k.g + k.b)))
        throw std::invalid_argument("luma coefficients must be finite, >= 0 and not all 0");
}

// Luminance of a repaired pixel, kept finite when the channels are near float's maximum.
float texel_luminance(const Rgb& p, const LumaCoefficients& k) noexcept {
    return std::min(luminance(p, k), std::numeric_limits<float>::max());
}

// Per-row results of the luminance pass, reduced in row order so that the result does
// not depend on the number of threads.
struct RowStats {
    double sum = 0;
    BadPixels bad;
    float max = 0;
    float min_positive = std::numeric_limits<float>::infinity();
    uint64_t zeroed = 0;
};

// Repairs a row's pixels and gathers its luminance statistics. The common case, a row
// without bad values, is checked first with a loop the compiler vectorises, and four
// partial sums keep double adds from serialising.
void scan_row(Rgb* pixels, uint32_t w, const LumaCoefficients& luma, RowStats& r) noexcept {
    const float* channels = &pixels[0].r;
    bool clean = true;
    for (uint32_t i = 0; i < 3 * w; ++i) clean &= channels[i] >= 0 && channels[i] <= std::numeric_limits<float>::max();
    if (!clean)
        for (uint32_t x = 0; x < w; ++x) sanitize_pixel(pixels[x], r.bad);
    double sums[4] = {0, 0, 0, 0};
    for (uint32_t x = 0; x < w; ++x) {
        const float l = texel_luminance(pixels[x], luma);
        sums[x & 3] += l;
        r.max = std::max(r.max, l);
        if (l > 0) r.min_positive = std::min(r.min_positive, l);
    }
    r.sum = (sums[0] + sums[1]) + (sums[2] + sums[3]);
}

}  // namespace

EnvMap::EnvMap(RgbImage image, const EnvMapOptions& options) : radiance_(std::move(image)), options_(options) {
    check_image(radiance_);
    check_options(options_);
    const uint32_t w = radiance_.width, h = radiance_.height;
    Rgb* pixels = radiance_.pixels.data();

    // Pass 1: repair pixels, row sums of luminance. Pass 2 (the distribution's build)
    // recomputes luminance rather than holding it: reading the pixels again is cheaper
    // than writing and reading another w x h buffer.
    std::vector<RowStats> rows(h);
    detail::parallel_for(h, kRowsPerThread, [&](uint32_t lo, uint32_t hi) {
        for (uint32_t y = lo; y < hi; ++y) scan_row(pixels + size_t{y} * w, w, options_.luma, rows[y]);
    });
    std::vector<double> row_sums(h);
    float min_positive = std::numeric_limits<float>::infinity();
    for (uint32_t y = 0; y < h; ++y) {
        row_sums[y] = rows[y].sum;
        stats_.bad_pixels += rows[y].bad;
        stats_.max_luminance = std::max(stats_.max_luminance, rows[y].max);
        min_positive = std::min(min_positive, rows[y].min_positive);
    }
    stats_.min_positive_luminance = std::isfinite(min_positive) ? min_positive : 0.0f;
    stats_.mean_luminance = solid_angle_mean_of_rows(row_sums, w);

    // Fallbacks: a black map is sampled uniformly, a map that compensation would zero
    // whole (a constant one) without compensation.
    const float threshold =
        options_.compensation.enabled ? compensation_threshold(stats_.mean_luminance, options_.compensation.alpha) : 0.0f;
    if (!(stats_.max_luminance > 0)) stats_.fallback = DensityFallback::uniform;
    else if (!(stats_.max_luminance > threshold)) stats_.fallback = DensityFallback::uncompensated;
    stats_.threshold = stats_.fallback == DensityFallback::none ? threshold : 0.0f;

    distribution_ = Distribution2D(w, h, [&](uint32_t y, std::span<float> row) { density_row(y, row, &rows[y].zeroed); });
    for (const RowStats& r : rows) stats_.zeroed_texels += r.zeroed;
}

void EnvMap::density_row(uint32_t y, std::span<float> row, uint64_t* zeroed) const noexcept {
    const uint32_t w = width();
    const float s = row_sin_theta(y, height());
    const Rgb* pixels = radiance_.pixels.data() + size_t{y} * w;
    const bool uniform = stats_.fallback == DensityFallback::uniform;
    uint64_t count = 0;
    for (uint32_t x = 0; x < w; ++x) {
        const float l = texel_luminance(pixels[x], options_.luma);
        const float q = uniform ? 1.0f : compensate(l, stats_.threshold);
        count += q == 0 && l > 0;
        row[x] = q * s;
    }
    if (zeroed) *zeroed = count;
}

EnvMap::EnvMap(RgbImage radiance, std::span<const float> density, const EnvMapOptions& options,
               const EnvMapStats& stats)
    : radiance_(std::move(radiance)), options_(options), stats_(stats) {
    check_image(radiance_);
    check_options(options_);
    size_t bad = 0;
    for (const Rgb& p : radiance_.pixels) {
        BadPixels b;
        Rgb copy = p;
        sanitize_pixel(copy, b);
        bad += b.total();
    }
    if (bad) throw std::invalid_argument(std::to_string(bad) + " radiance values are negative, NaN or infinite");
    distribution_ = Distribution2D(density, radiance_.width, radiance_.height);
}

std::vector<float> EnvMap::density() const {
    const uint32_t w = width();
    std::vector<float> out(size_t{w} * height());
    for (uint32_t y = 0; y < height(); ++y) density_row(y, std::span(out).subspan(size_t{y} * w, w), nullptr);
    return out;
}

}  // namespace envmis
