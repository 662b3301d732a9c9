#include "envmis/sampling/envmap.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

#include "detail/parallel.h"
#include "envmis/sampling/density_rows.h"

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

using namespace detail;

// Whether a stored density value is the build's `expected` from a texel of luminance l
// (threshold t, row weight w), up to what builds of other format versions round
// differently (l to an ulp or so): 1e-4 of the value plus 1e-6 of (l + t) w, in double so
// that a luminance near float's maximum cannot make it infinite. A texel clearly below
// the threshold must hold exactly 0: compensation's zeros are exact in every build.
bool stored_density_agrees(float stored, float expected, double l, double t, float w) noexcept {
    if (expected == 0 && l < t * (1 - 1e-6)) return stored == 0;
    return std::abs(double{stored} - expected) <= 1e-4 * expected + 1e-6 * (l + t) * w;
}

// Whether a and b differ by more than `relative` of the larger.
bool differ(double a, double b, double relative) noexcept {
    return !(std::abs(a - b) <= relative * std::max(std::abs(a), std::abs(b)));
}

// The facts a stored map (a table's payload) states, checked against its radiance before
// it is used, so that a crafted table whose checksums were recomputed is refused: every
// channel finite and >= 0; the mean, largest and smallest positive luminance those of the
// radiance (to 1e-3: builds of older format versions summed in other orders); the
// threshold alpha times the mean; each density value the build's from its texel (to 1e-4
// of the texel's luminance plus the threshold, times its row's weight). One pass over the
// radiance and the density, parallel over rows. Throws std::invalid_argument naming the
// first fact that differs.
void check_stored(RgbImageView radiance, const uint32_t* density, const EnvMapOptions& options,
                  const EnvMapStats& stats) {
    const uint32_t w = radiance.width, h = radiance.height;
    const bool uniform = stats.fallback == DensityFallback::uniform;
    std::vector<RowStats> rows(h);
    std::vector<uint64_t> bad(h), wrong(h);
    detail::parallel_for(h, kRowsPerChunk, [&](uint32_t lo, uint32_t hi) {
        std::vector<uint32_t> luminance(w);
        std::vector<float> expected(w);
        for (uint32_t y = lo; y < hi; ++y) {
            const Rgb* pixels = radiance.pixels.data() + size_t{y} * w;
            if (!scan_row(pixels, w, options.luma, luminance.data(), rows[y])) {
                for (uint32_t x = 0; x < w; ++x) {
                    BadPixels b;
                    Rgb copy = pixels[x];
                    sanitize_pixel(copy, b);
                    bad[y] += b.total();
                }
                continue;
            }
            if (!std::isfinite(rows[y].sum)) rows[y].sum = exact_row_sum(luminance.data(), w);
            const float weight = row_weight(options.mapping, y, h);
            fill_density_row(luminance.data(), w, weight, stats.threshold, uniform, expected.data());
            const uint32_t* stored = density + size_t{y} * w;
            for (uint32_t x = 0; x < w; ++x)
                wrong[y] +=
                    !stored_density_agrees(std::bit_cast<float>(stored[x]), expected[x],
                                           uniform ? 1.0 : std::bit_cast<float>(luminance[x]), stats.threshold, weight);
        }
    });
    const auto total = [](const std::vector<uint64_t>& v) { return std::accumulate(v.begin(), v.end(), uint64_t{0}); };
    if (const uint64_t n = total(bad))
        throw std::invalid_argument(std::to_string(n) + " radiance values are negative, NaN or infinite");
    std::vector<double> row_sums(h);
    float max = 0, min_positive = std::numeric_limits<float>::infinity();
    for (uint32_t y = 0; y < h; ++y)
        row_sums[y] = rows[y].sum, max = std::max(max, rows[y].max),
        min_positive = std::min(min_positive, rows[y].min_positive);
    const double mean = solid_angle_mean_of_rows(row_sums, w, options.mapping);
    check_power(mean);
    const auto fact = [](bool ok, const char* name, double stated, double actual) {
        if (ok) return;
        char text[160];
        std::snprintf(text, sizeof text, "%s %.9g is not the radiance's (%.9g)", name, stated, actual);
        throw std::invalid_argument(text);
    };
    fact(!differ(stats.mean_luminance, mean, 1e-3), "mean luminance", stats.mean_luminance, mean);
    fact(!differ(stats.max_luminance, max, 1e-3), "max luminance", stats.max_luminance, max);
    if (!std::isfinite(min_positive)) min_positive = 0;
    fact(!differ(stats.min_positive_luminance, min_positive, 1e-3), "min luminance", stats.min_positive_luminance,
         min_positive);
    // The threshold is 0 where nothing is compensated (the table reader checks that).
    const bool thresholded = options.compensation.enabled && stats.fallback == DensityFallback::none;
    const float threshold = compensation_threshold(stats.mean_luminance, options.compensation.alpha);
    fact(!thresholded || !differ(stats.threshold, threshold, 1e-5), "threshold", stats.threshold, threshold);
    // The uncompensated fallback is only for a map that compensation zeroes whole.
    fact(stats.fallback != DensityFallback::uncompensated || max <= threshold * (1 + 1e-5),
         "max luminance of a map compensation zeroes whole", max, threshold);
    if (const uint64_t n = total(wrong))
        throw std::invalid_argument(std::to_string(n) + " density values are not those of the radiance");
}

}  // namespace

EnvMap::EnvMap(RgbImage radiance, LargeVector<uint32_t> density_bits, const EnvMapOptions& options,
               const EnvMapStats& stats)
    : options_(options), stats_(stats) {
    adopt(std::move(radiance));
    rebuild(std::move(density_bits));
}

EnvMap::EnvMap(RgbImageView radiance, std::shared_ptr<const void> owner, LargeVector<uint32_t> density_bits,
               const EnvMapOptions& options, const EnvMapStats& stats)
    : radiance_owner_(std::move(owner)), radiance_(radiance), options_(options), stats_(stats) {
    rebuild(std::move(density_bits));
}

EnvMap::EnvMap(RgbImage radiance, Distribution2D density, const EnvMapOptions& options, const EnvMapStats& stats)
    : distribution_(std::move(density)), options_(options), stats_(stats) {
    adopt(std::move(radiance));
    check_map_input(radiance_, options_);
    if (distribution_.width() != radiance_.width || distribution_.height() != radiance_.height)
        throw std::invalid_argument("environment map: a " + std::to_string(distribution_.width()) + "x" +
                                    std::to_string(distribution_.height()) + " distribution for a " +
                                    std::to_string(radiance_.width) + "x" + std::to_string(radiance_.height) +
                                    " image");
}

void EnvMap::adopt(RgbImage image) {
    auto owned = std::make_shared<RgbPixels>(std::move(image.pixels));
    radiance_ = {image.width, image.height, *owned};
    radiance_owner_ = owned;
}

void EnvMap::rebuild(LargeVector<uint32_t> density_bits) {
    check_map_input(radiance_, options_);
    check_stored(radiance_, density_bits.data(), options_, stats_);
    const uint32_t w = radiance_.width;
    distribution_ = Distribution2D(w, radiance_.height, std::move(density_bits),
                                   [w](uint32_t, std::span<const uint32_t> bits, std::span<float> row) {
                                       for (uint32_t x = 0; x < w; ++x) row[x] = std::bit_cast<float>(bits[x]);
                                   });
}

EnvMap EnvMap::with_density() const {
    EnvMap m = *this;
    const uint32_t w = width();
    LargeVector<uint32_t> bits(size_t{w} * height());
    std::vector<float> row(w);
    for (uint32_t y = 0; y < height(); ++y) {
        density_row(y, row);
        for (uint32_t x = 0; x < w; ++x) bits[size_t{y} * w + x] = std::bit_cast<uint32_t>(row[x]);
    }
    m.rebuild(std::move(bits));
    return m;
}

std::vector<float> EnvMap::density() const {
    const uint32_t w = width(), h = height();
    std::vector<float> out(size_t{w} * h);
    for (uint32_t y = 0; y < h; ++y) density_row(y, std::span(out).subspan(size_t{y} * w, w));
    return out;
}

void EnvMap::density_row(uint32_t y, std::span<float> row) const {
    const uint32_t w = width();
    if (y >= height())
        throw std::invalid_argument("density_row: row " + std::to_string(y) + " of a map " + std::to_string(height()) +
                                    " high");
    envmis::density_row(std::span(radiance_.pixels).subspan(size_t{y} * w, w), y, height(), options_, stats_, row);
}

void density_row(std::span<const Rgb> radiance_row, uint32_t y, uint32_t h, const EnvMapOptions& options,
                 const EnvMapStats& stats, std::span<float> out) {
    const auto w = static_cast<uint32_t>(radiance_row.size());
    if (out.size() != w || y >= h)
        throw std::invalid_argument("density_row: " + std::to_string(out.size()) + " outputs for a row of " +
                                    std::to_string(w) + " (row " + std::to_string(y) + " of " + std::to_string(h) +
                                    ")");
    // scan_row repairs nothing: a map's radiance is clean, and so is a decoded table's.
    std::vector<uint32_t> luminance(w);
    RowStats unused;
    scan_row(radiance_row.data(), w, options.luma, luminance.data(), unused);
    fill_density_row(luminance.data(), w, row_weight(options.mapping, y, h), stats.threshold,
                     stats.fallback == DensityFallback::uniform, out.data());
}

}  // namespace envmis
