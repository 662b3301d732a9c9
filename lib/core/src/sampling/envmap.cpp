#include "envmis/sampling/envmap.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "detail/luminance.h"
#include "detail/parallel.h"

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
// Rows per task of the parallel passes.
constexpr uint32_t kRowsPerChunk = 8;

void check_image(RgbImageView image, Mapping mapping) {
    const size_t n = size_t{image.width} * image.height;
    if (image.width == 0 || image.height == 0 || image.width > kMaxCells1D || image.height > kMaxCells1D ||
        n > kMaxTexels)
        throw std::invalid_argument("environment map size " + std::to_string(image.width) + "x" +
                                    std::to_string(image.height) +
                                    " is empty, above 65536 on a side or above 2^31 texels");
    if (image.pixels.size() != n)
        throw std::invalid_argument("environment map: " + std::to_string(image.pixels.size()) +
                                    " pixels do not make a " + std::to_string(image.width) + "x" +
                                    std::to_string(image.height) + " image");
    if (mapping == Mapping::equal_area && image.width != image.height)
        throw std::invalid_argument("an equal-area map must be square, got " + std::to_string(image.width) + "x" +
                                    std::to_string(image.height));
}

void check_options(const EnvMapOptions& o) {
    const float a = o.compensation.alpha;
    if (!(a >= 0 && std::isfinite(a)))
        throw std::invalid_argument("compensation alpha must be finite and >= 0, got " + std::to_string(a));
    if (!o.axes.valid()) throw std::invalid_argument("invalid axes " + o.axes.to_string());
    if (o.mapping != Mapping::equirect && o.mapping != Mapping::equal_area)
        throw std::invalid_argument("unknown mapping " + std::to_string(static_cast<uint32_t>(o.mapping)));
    const LumaCoefficients k = o.luma;
    // A working space's weights are its white's Y: each in [0, 1] for any linear space.
    if (!(k.r >= 0 && k.g >= 0 && k.b >= 0 && k.r <= 1 && k.g <= 1 && k.b <= 1 && k.r + k.g + k.b > 0))
        throw std::invalid_argument("luma coefficients must be in [0, 1] and not all 0");
}

// Per-row results, reduced in row order so that the result does not depend on the
// number of threads.
struct RowStats {
    double sum = 0;  // of luminance
    BadPixels bad;
    float max = 0;
    float min_positive = std::numeric_limits<float>::infinity();
    uint32_t positive = 0;  // texels with L > 0
    uint64_t zeroed = 0;
};

// Pass 1 over a row, reading its pixels once: the row sum of luminance, and each
// texel's luminance, as float bits into `bits` (the memory pass 2 reads it from), with
// its extremes and the count of positive values (exact in any order: luminance is never NaN). Returns false, with
// nothing usable computed, if a channel is negative, NaN or infinite: the caller repairs the row and scans it again.
//
// Luminance is linear, so the row sum is the luma-weighted sum of the channel sums,
// accumulated in twelve float lanes (the channels of four pixels) flushed into doubles
// every 64 pixels so that long rows lose no precision. A channel is clean when its bits,
// read as an unsigned integer, lie below those of +Inf: that excludes negative values
// (sign bit), Inf and NaN; exactly then neither b nor 0x7f7fffff - b has the top bit
// set, so ORs of both test every channel. With SSE2 four pixels go at a time, shuffles
// turning their twelve interleaved channels into a vector per channel (which the
// compiler does not do by itself); otherwise, and for the last pixels, `take` does the
// same operations one pixel at a time.
bool scan_row(const Rgb* pixels, uint32_t w, const LumaCoefficients& luma, uint32_t* bits, RowStats& r) noexcept {
    constexpr uint32_t kLanes = 12, kGroupsPerFlush = 16;
    constexpr float kInf = std::numeric_limits<float>::infinity();
    float lane[kLanes] = {};
    double channel_sum[3] = {0, 0, 0};
    auto flush = [&] {
        for (uint32_t j = 0; j < kLanes; ++j) channel_sum[j % 3] += lane[j], lane[j] = 0;
    };
    uint32_t dirty = 0, positive = 0;
    float high = 0, low = kInf;  // low: the smallest positive luminance
    auto take = [&](uint32_t x, uint32_t first_lane) {
        const float channel[3] = {pixels[x].r, pixels[x].g, pixels[x].b};
        for (uint32_t c = 0; c < 3; ++c) {
            lane[first_lane + c] += channel[c];
            const auto b = std::bit_cast<uint32_t>(channel[c]);
            dirty |= b | (0x7f7fffffu - b);
        }
        const float l = detail::texel_luminance(pixels[x], luma);
        bits[x] = std::bit_cast<uint32_t>(l);
        high = std::max(high, l);
        low = std::min(low, l > 0 ? l : kInf);
        positive += l > 0;
    };
    uint32_t x = 0;
#if defined(__SSE2__)
    const __m128 kr = _mm_set1_ps(luma.r), kg = _mm_set1_ps(luma.g), kb = _mm_set1_ps(luma.b);
    const __m128 top = _mm_set1_ps(std::numeric_limits<float>::max()), zero = _mm_setzero_ps(), inf = _mm_set1_ps(kInf);
    const __m128i clean_limit = _mm_set1_epi32(0x7f7fffff);
    __m128 lanes[3] = {zero, zero, zero}, highs = zero, lows = inf;
    __m128i dirt = _mm_setzero_si128(), positives = _mm_setzero_si128();  // minus the count, per lane
    for (uint32_t group = 1; x + 4 <= w; x += 4, ++group) {
        const float* c = &pixels[x].r;
        const __m128 v[3] = {_mm_loadu_ps(c), _mm_loadu_ps(c + 4), _mm_loadu_ps(c + 8)};  // r0g0b0r1 g1b1r2g2 b2r3g3b3
        for (uint32_t k = 0; k < 3; ++k) {
            lanes[k] = _mm_add_ps(lanes[k], v[k]);
            const __m128i b = _mm_castps_si128(v[k]);
            dirt = _mm_or_si128(dirt, _mm_or_si128(b, _mm_sub_epi32(clean_limit, b)));
        }
        if (group % kGroupsPerFlush == 0) {
            for (uint32_t k = 0; k < 3; ++k) _mm_storeu_ps(lane + 4 * k, lanes[k]), lanes[k] = zero;
            flush();
        }
        const __m128 rg = _mm_shuffle_ps(v[1], v[2], _MM_SHUFFLE(2, 1, 3, 2));  // r2 g2 r3 g3
        const __m128 gb = _mm_shuffle_ps(v[0], v[1], _MM_SHUFFLE(1, 0, 2, 1));  // g0 b0 g1 b1
        const __m128 red = _mm_shuffle_ps(v[0], rg, _MM_SHUFFLE(2, 0, 3, 0));
        const __m128 green = _mm_shuffle_ps(gb, rg, _MM_SHUFFLE(3, 1, 2, 0));
        const __m128 blue = _mm_shuffle_ps(gb, v[2], _MM_SHUFFLE(3, 0, 3, 1));
        // min(top, l) and max(l, high) pick as std::min(l, top) and std::max(high, l) do.
        const __m128 l =
            _mm_min_ps(top, _mm_add_ps(_mm_add_ps(_mm_mul_ps(kr, red), _mm_mul_ps(kg, green)), _mm_mul_ps(kb, blue)));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(bits + x), _mm_castps_si128(l));
        highs = _mm_max_ps(l, highs);
        const __m128 positive = _mm_cmpgt_ps(l, zero);
        lows = _mm_min_ps(_mm_or_ps(_mm_and_ps(positive, l), _mm_andnot_ps(positive, inf)), lows);
        positives = _mm_add_epi32(positives, _mm_castps_si128(positive));
    }
    for (uint32_t k = 0; k < 3; ++k) _mm_storeu_ps(lane + 4 * k, lanes[k]);
    float lane_high[4], lane_low[4];
    uint32_t lane_dirt[4], lane_positives[4];
    _mm_storeu_ps(lane_high, highs);
    _mm_storeu_ps(lane_low, lows);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(lane_dirt), dirt);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(lane_positives), positives);
    for (uint32_t j = 0; j < 4; ++j) {
        high = std::max(high, lane_high[j]), low = std::min(low, lane_low[j]), dirty |= lane_dirt[j];
        positive -= lane_positives[j];
    }
#else
    for (uint32_t group = 1; x + 4 <= w; x += 4, ++group) {
        for (uint32_t p = 0; p < 4; ++p) take(x + p, 3 * p);
        if (group % kGroupsPerFlush == 0) flush();
    }
#endif
    for (; x < w; ++x) take(x, 0);
    flush();
    r.sum = luma.r * channel_sum[0] + luma.g * channel_sum[1] + luma.b * channel_sum[2];
    r.max = high;
    r.min_positive = low;
    r.positive = positive;
    return !(dirty >> 31);
}

// A row's luminance sum in double from its texels' (clamped) luminance bits: for a row
// whose float lanes overflowed (channels near float's maximum), where scan_row's sum is Inf.
double exact_row_sum(const uint32_t* luminance, uint32_t w) noexcept {
    double sum = 0;
    for (uint32_t x = 0; x < w; ++x) sum += std::bit_cast<float>(luminance[x]);
    return sum;
}

// Every estimate and pdf is a float scaled by the map's power 4 pi Lbar: a map whose
// power is not a finite float gives Inf and NaN estimates, so it is refused, however
// finite its pixels.
void check_power(double mean_luminance) {
    if (4 * kPi * mean_luminance <= std::numeric_limits<float>::max()) return;
    char text[200];
    std::snprintf(text, sizeof text,
                  "luminance overflows: the map's power 4 pi Lbar (Lbar %.3g) is above float's maximum 3.4e38; scale "
                  "the map down (e.g. multiply it by 1e-%d)",
                  mean_luminance, 1 + static_cast<int>(std::ceil(std::log10(4 * kPi * mean_luminance / 3.4e38))));
    throw std::invalid_argument(text);
}

// Pass 2: row y of the density q w_y (mapping.h: row_weight) from its luminance bits; returns the
// number of texels with L > 0 that compensation zeroes.
uint32_t fill_density_row(const uint32_t* luminance, uint32_t w, float weight, float threshold, bool uniform,
                          float* row) noexcept {
    if (uniform) {
        std::fill_n(row, w, weight);
        return 0;
    }
    uint32_t zeroed = 0;
    for (uint32_t x = 0; x < w; ++x) {
        const auto l = std::bit_cast<float>(luminance[x]);
        zeroed += (static_cast<int32_t>(luminance[x]) > 0) & (l <= threshold);
        // max(L - t, 0) is compensate(L, t): for L > t the difference of two floats is > 0.
        row[x] = std::max(l - threshold, 0.0f) * weight;
    }
    return zeroed;
}

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

EnvMap::EnvMap(RgbImage image, const EnvMapOptions& options, StopFlag stop) : options_(options) {
    check_image(image, options_.mapping);
    check_options(options_);
    const uint32_t w = image.width, h = image.height;
    Rgb* pixels = adopt(std::move(image)).data();

    // Pass 1 gives Lbar, and keeps each texel's luminance in the memory that the start
    // table will occupy: pass 2 then reads 4 bytes a texel instead of the 12 of RGB.
    std::vector<RowStats> rows(h);
    auto luminance = [&] {
        LargeVector<uint32_t> bits(size_t{w} * h);
        detail::parallel_for(h, kRowsPerChunk, stop, [&](uint32_t lo, uint32_t hi) {
            for (uint32_t y = lo; y < hi; ++y) {
                const size_t offset = size_t{y} * w;
                Rgb* row = pixels + offset;
                if (!scan_row(row, w, options_.luma, bits.data() + offset, rows[y])) {
                    for (uint32_t x = 0; x < w; ++x) sanitize_pixel(row[x], rows[y].bad);
                    scan_row(row, w, options_.luma, bits.data() + offset, rows[y]);
                }
                if (!std::isfinite(rows[y].sum)) rows[y].sum = exact_row_sum(bits.data() + offset, w);
            }
        });
        return bits;
    };
    LargeVector<uint32_t> luminance_bits = luminance();
    std::vector<double> row_sums(h);
    for (uint32_t y = 0; y < h; ++y) {
        row_sums[y] = rows[y].sum;
        stats_.bad_pixels += rows[y].bad;
    }
    stats_.mean_luminance = solid_angle_mean_of_rows(row_sums, w, options_.mapping);
    check_power(stats_.mean_luminance);

    // A black map is sampled uniformly; a map that compensation zeroes whole (a constant
    // one) is rebuilt without compensation, from its luminance computed again.
    if (!(stats_.mean_luminance > 0)) stats_.fallback = DensityFallback::uniform;
    if (options_.compensation.enabled && stats_.fallback == DensityFallback::none)
        stats_.threshold = compensation_threshold(stats_.mean_luminance, options_.compensation.alpha);
    // A row whose brightest texel is at or below the threshold compensates to +0 whole:
    // its luminance is not read again (most of a sky with a sun: the build's largest saving).
    const auto density = [&](uint32_t y, std::span<const uint32_t> cells, std::span<float> row) {
        const bool uniform = stats_.fallback == DensityFallback::uniform;
        if (!uniform && rows[y].max <= stats_.threshold) {
            std::fill(row.begin(), row.end(), 0.0f);
            rows[y].zeroed = rows[y].positive;
            return;
        }
        rows[y].zeroed = fill_density_row(cells.data(), w, row_weight(options_.mapping, y, h), stats_.threshold,
                                          uniform, row.data());
    };
    distribution_ = Distribution2D(w, h, std::move(luminance_bits), density);
    throw_if_stopped(stop);
    if (stats_.threshold > 0 && distribution_.uniform_fallback()) {
        stats_.fallback = DensityFallback::uncompensated;
        stats_.threshold = 0;
        distribution_ = Distribution2D(w, h, luminance(), density);
    }
    float min_positive = std::numeric_limits<float>::infinity();
    for (const RowStats& r : rows) {
        stats_.zeroed_texels += r.zeroed;
        stats_.max_luminance = std::max(stats_.max_luminance, r.max);
        min_positive = std::min(min_positive, r.min_positive);
    }
    stats_.min_positive_luminance = std::isfinite(min_positive) ? min_positive : 0.0f;
}

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

RgbPixels& EnvMap::adopt(RgbImage image) {
    auto owned = std::make_shared<RgbPixels>(std::move(image.pixels));
    radiance_ = {image.width, image.height, *owned};
    radiance_owner_ = owned;
    return *owned;
}

void EnvMap::rebuild(LargeVector<uint32_t> density_bits) {
    check_image(radiance_, options_.mapping);
    check_options(options_);
    check_stored(radiance_, density_bits.data(), options_, stats_);
    const uint32_t w = radiance_.width;
    distribution_ = Distribution2D(w, radiance_.height, std::move(density_bits),
                                   [w](uint32_t, std::span<const uint32_t> bits, std::span<float> row) {
                                       for (uint32_t x = 0; x < w; ++x) row[x] = std::bit_cast<float>(bits[x]);
                                   });
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
