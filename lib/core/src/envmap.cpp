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
    if (image.width == 0 || image.height == 0 || n > kMaxTexels)
        throw std::invalid_argument("environment map size " + std::to_string(image.width) + "x" +
                                    std::to_string(image.height) + " is empty or above 2^31 texels");
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

// Per-row results of the luminance pass, reduced in row order so that the result does
// not depend on the number of threads.
struct RowStats {
    double sum = 0;
    BadPixels bad;
    float max = 0;
    float min_positive = std::numeric_limits<float>::infinity();
    uint64_t zeroed = 0;
};

}  // namespace

EnvMap::EnvMap(RgbImage image, const EnvMapOptions& options) : radiance_(std::move(image)), options_(options) {
    check_image(radiance_);
    check_options(options_);
    const uint32_t w = radiance_.width, h = radiance_.height;
    Rgb* pixels = radiance_.pixels.data();

    // Pass 1: repair pixels, luminance, row sums. `func` holds L, then the density.
    std::vector<float> func(size_t{w} * h);
    std::vector<RowStats> rows(h);
    detail::parallel_for(h, kRowsPerThread, [&](uint32_t lo, uint32_t hi) {
        for (uint32_t y = lo; y < hi; ++y) {
            RowStats& r = rows[y];
            for (size_t i = size_t{y} * w, end = i + w; i < end; ++i) {
                sanitize_pixel(pixels[i], r.bad);
                const float l = std::min(luminance(pixels[i], options_.luma), std::numeric_limits<float>::max());
                func[i] = l;
                r.sum += l;
                r.max = std::max(r.max, l);
                if (l > 0) r.min_positive = std::min(r.min_positive, l);
            }
        }
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

    // Pass 2: the density q sin(theta), with the fallbacks for black and constant maps.
    const bool black = !(stats_.max_luminance > 0);
    const float threshold =
        options_.compensation.enabled ? compensation_threshold(stats_.mean_luminance, options_.compensation.alpha) : 0.0f;
    const bool all_zeroed = !black && !(stats_.max_luminance > threshold);
    if (black) stats_.fallback = DensityFallback::uniform;
    if (all_zeroed) stats_.fallback = DensityFallback::uncompensated;
    stats_.threshold = stats_.fallback == DensityFallback::none ? threshold : 0.0f;
    detail::parallel_for(h, kRowsPerThread, [&](uint32_t lo, uint32_t hi) {
        for (uint32_t y = lo; y < hi; ++y) {
            const float s = row_sin_theta(y, h);
            uint64_t zeroed = 0;
            for (size_t i = size_t{y} * w, end = i + w; i < end; ++i) {
                const float q = black ? 1.0f : compensate(func[i], stats_.threshold);
                zeroed += q == 0 && func[i] > 0;
                func[i] = q * s;
            }
            rows[y].zeroed = zeroed;
        }
    });
    for (const RowStats& r : rows) stats_.zeroed_texels += r.zeroed;
    distribution_ = Distribution2D(func, w, h);
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
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) out[size_t{y} * w + x] = distribution_.func(x, y);
    return out;
}

}  // namespace envmis
