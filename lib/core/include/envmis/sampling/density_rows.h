// The rows of an environment map's density (envmap.h), shared by the build that makes a
// map from an image (envmis::build, envmis/build/env_map.h) and the checks the runtime
// makes of a stored map before using it (EnvMap from a table's parts): the scan that
// gives a row's luminance and statistics, and the row of q w_y it gives. Not an API for
// renderers; its names sit in envmis::detail.
//
// Numbers: each texel's luminance is a float (kept as its bits); row sums are doubles,
// reduced in row order so that results do not depend on the number of threads.
#pragma once

#include <algorithm>
#include <bit>
#include <cstdint>
#include <limits>

#include "envmis/core_export.h"
#include "envmis/image/image.h"
#include "envmis/sampling/envmap.h"

namespace envmis::detail {

// Rows per task of the passes over a map, parallel over rows.
inline constexpr uint32_t kRowsPerChunk = 8;

// Throws std::invalid_argument for an image no map can be built from (empty, above
// 65536 on a side or 2^31 texels, pixel count not its size, an equal-area map not
// square) or invalid options.
ENVMIS_CORE_API void check_map_input(RgbImageView image, const EnvMapOptions& options);

// What a scan of one row found.
struct RowStats {
    double sum = 0;  // of luminance
    BadPixels bad;
    float max = 0;
    float min_positive = std::numeric_limits<float>::infinity();
    uint32_t positive = 0;  // texels with L > 0
    uint64_t zeroed = 0;    // texels with L > 0 that compensation zeroes (filled in by the build)
};

// Pass 1 over a row of w pixels, reading them once: the row's luminance sum, and each
// texel's luminance as float bits into `bits`, with its extremes and the count of
// positive values. Returns false, with nothing usable computed, if a channel is
// negative, NaN or infinite: the caller repairs the row (sanitize_pixel) and scans again.
ENVMIS_CORE_API bool scan_row(const Rgb* pixels, uint32_t w, const LumaCoefficients& luma, uint32_t* bits,
                              RowStats& r) noexcept;

// A row's luminance sum in double from its texels' (clamped) luminance bits: for a row
// whose float lanes overflowed (channels near float's maximum), where scan_row's sum is Inf.
ENVMIS_CORE_API double exact_row_sum(const uint32_t* luminance, uint32_t w) noexcept;

// Throws std::invalid_argument ("luminance overflows", with the factor to scale the map
// by) where the map's power 4 pi Lbar is not a finite float: every estimate and pdf would
// be Inf or NaN, however finite the pixels.
ENVMIS_CORE_API void check_power(double mean_luminance);

// Pass 2: row y of the density q w_y (mapping.h: row_weight, given as `weight`) from its
// luminance bits, max(L - threshold, 0) w, or w everywhere where `uniform`; returns the
// number of texels with L > 0 that compensation zeroes.
inline uint32_t fill_density_row(const uint32_t* luminance, uint32_t w, float weight, float threshold, bool uniform,
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

}  // namespace envmis::detail
