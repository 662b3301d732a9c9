#include "envmis/sampling/density_rows.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "detail/luminance.h"

namespace envmis::detail {
namespace {

constexpr size_t kMaxTexels = size_t{1} << 31;

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

}  // namespace

void check_map_input(RgbImageView image, const EnvMapOptions& options) {
    check_image(image, options.mapping);
    check_options(options);
}

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
        const float l = texel_luminance(pixels[x], luma);
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

double exact_row_sum(const uint32_t* luminance, uint32_t w) noexcept {
    double sum = 0;
    for (uint32_t x = 0; x < w; ++x) sum += std::bit_cast<float>(luminance[x]);
    return sum;
}

void check_power(double mean_luminance) {
    if (4 * kPi * mean_luminance <= std::numeric_limits<float>::max()) return;
    char text[200];
    std::snprintf(text, sizeof text,
                  "luminance overflows: the map's power 4 pi Lbar (Lbar %.3g) is above float's maximum 3.4e38; scale "
                  "the map down (e.g. multiply it by 1e-%d)",
                  mean_luminance, 1 + static_cast<int>(std::ceil(std::log10(4 * kPi * mean_luminance / 3.4e38))));
    throw std::invalid_argument(text);
}

}  // namespace envmis::detail
