#include "envmis/envmap.h"

#include <algorithm>
#include <bit>
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

// Per-row results, reduced in row order so that the result does not depend on the
// number of threads.
struct RowStats {
    double sum = 0;  // of luminance
    BadPixels bad;
    float max = 0;
    float min_positive = std::numeric_limits<float>::infinity();
    uint64_t zeroed = 0;
};

// Pass 1: repairs a row's pixels and sums its luminance. Luminance is linear, so the
// row sum is the luma-weighted sum of the channel sums: one flat loop over 3w floats in
// twelve float lanes (four pixels) that the compiler vectorises, flushed into doubles
// every 64 pixels so that long rows lose no precision.
void scan_row(Rgb* pixels, uint32_t w, const LumaCoefficients& luma, RowStats& r) noexcept {
    // A channel is clean when its bits, read as an unsigned integer, lie below those of
    // +Inf: that excludes negative values (sign bit), Inf and NaN in one comparison.
    const auto* bits = reinterpret_cast<const uint32_t*>(&pixels[0].r);
    uint32_t highest = 0;
    for (uint32_t i = 0; i < 3 * w; ++i) highest = std::max(highest, bits[i]);
    if (highest >= 0x7f800000u)
        for (uint32_t x = 0; x < w; ++x) sanitize_pixel(pixels[x], r.bad);

    constexpr uint32_t kLanes = 12, kFlush = 64 * 3;
    const float* channels = &pixels[0].r;
    const uint32_t n = 3 * w;
    float lane[kLanes] = {};
    double channel_sum[3] = {0, 0, 0};
    auto flush = [&] {
        for (uint32_t j = 0; j < kLanes; ++j) channel_sum[j % 3] += lane[j], lane[j] = 0;
    };
    uint32_t i = 0;
    for (; i + kLanes <= n; i += kLanes) {
        for (uint32_t j = 0; j < kLanes; ++j) lane[j] += channels[i + j];
        if ((i + kLanes) % kFlush == 0) flush();
    }
    for (; i < n; ++i) lane[i % 3] += channels[i];
    flush();
    r.sum = luma.r * channel_sum[0] + luma.g * channel_sum[1] + luma.b * channel_sum[2];
}

// Pass 2: row y of the density q sin(theta_y), and its luminance statistics. Luminance
// goes into `row` first and is transformed in place, in three loops simple enough to
// vectorise. The statistics read the float bits as integers: for non-negative floats
// their order is the values' order, and integer min/max reduce in any order.
void density_row(const Rgb* pixels, uint32_t w, float sin_theta, const LumaCoefficients& luma, float threshold,
                 bool uniform, std::span<float> row, RowStats& r) noexcept {
    for (uint32_t x = 0; x < w; ++x) row[x] = texel_luminance(pixels[x], luma);
    const auto* bits = reinterpret_cast<const int32_t*>(row.data());
    constexpr int32_t kNone = 0x7fffffff;
    int32_t max_bits = 0, min_bits_minus_one = kNone;  // 0 - 1 wraps to kNone, so zeros drop out
    uint32_t zeroed = 0;
    for (uint32_t x = 0; x < w; ++x) {
        max_bits = std::max(max_bits, bits[x]);
        min_bits_minus_one = std::min(min_bits_minus_one, (bits[x] - 1) & kNone);
        zeroed += (bits[x] > 0) & (row[x] <= threshold);
    }
    r.max = std::bit_cast<float>(max_bits);
    r.min_positive = min_bits_minus_one == kNone ? std::numeric_limits<float>::infinity()
                                                 : std::bit_cast<float>(min_bits_minus_one + 1);
    r.zeroed = uniform ? 0 : zeroed;
    if (uniform) {
        std::fill(row.begin(), row.end(), sin_theta);
        return;
    }
    // max(L - t, 0) is compensate(L, t): for L > t the difference of two floats is > 0.
    for (uint32_t x = 0; x < w; ++x) row[x] = std::max(row[x] - threshold, 0.0f) * sin_theta;
}

}  // namespace

EnvMap::EnvMap(RgbImage image, const EnvMapOptions& options) : radiance_(std::move(image)), options_(options) {
    check_image(radiance_);
    check_options(options_);
    const uint32_t w = radiance_.width, h = radiance_.height;
    Rgb* pixels = radiance_.pixels.data();

    // Pass 1 gives Lbar; pass 2, the distribution's build, recomputes luminance rather
    // than holding it: reading the pixels again is cheaper than writing and reading
    // another w x h buffer.
    std::vector<RowStats> rows(h);
    detail::parallel_for(h, kRowsPerThread, [&](uint32_t lo, uint32_t hi) {
        for (uint32_t y = lo; y < hi; ++y) scan_row(pixels + size_t{y} * w, w, options_.luma, rows[y]);
    });
    std::vector<double> row_sums(h);
    for (uint32_t y = 0; y < h; ++y) {
        row_sums[y] = rows[y].sum;
        stats_.bad_pixels += rows[y].bad;
    }
    stats_.mean_luminance = solid_angle_mean_of_rows(row_sums, w);

    // A black map is sampled uniformly; a map that compensation zeroes whole (a constant
    // one) is rebuilt without compensation.
    if (!(stats_.mean_luminance > 0)) stats_.fallback = DensityFallback::uniform;
    if (options_.compensation.enabled && stats_.fallback == DensityFallback::none)
        stats_.threshold = compensation_threshold(stats_.mean_luminance, options_.compensation.alpha);
    auto build = [&] {
        distribution_ = Distribution2D(w, h, [&](uint32_t y, std::span<float> row) {
            density_row(pixels + size_t{y} * w, w, row_sin_theta(y, h), options_.luma, stats_.threshold,
                        stats_.fallback == DensityFallback::uniform, row, rows[y]);
        });
    };
    build();
    if (stats_.threshold > 0 && distribution_.uniform_fallback()) {
        stats_.fallback = DensityFallback::uncompensated;
        stats_.threshold = 0;
        build();
    }
    float min_positive = std::numeric_limits<float>::infinity();
    for (const RowStats& r : rows) {
        stats_.zeroed_texels += r.zeroed;
        stats_.max_luminance = std::max(stats_.max_luminance, r.max);
        min_positive = std::min(min_positive, r.min_positive);
    }
    stats_.min_positive_luminance = std::isfinite(min_positive) ? min_positive : 0.0f;
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
    const uint32_t w = width(), h = height();
    std::vector<float> out(size_t{w} * h);
    RowStats unused;
    for (uint32_t y = 0; y < h; ++y)
        density_row(radiance_.pixels.data() + size_t{y} * w, w, row_sin_theta(y, h), options_.luma, stats_.threshold,
                    stats_.fallback == DensityFallback::uniform, std::span(out).subspan(size_t{y} * w, w), unused);
    return out;
}

}  // namespace envmis
