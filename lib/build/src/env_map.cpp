#include "envmis/build/env_map.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "detail/parallel.h"
#include "envmis/sampling/density_rows.h"

namespace envmis {

using namespace detail;

EnvMap build_env_map(RgbImage image, const EnvMapOptions& options, StopFlag stop) {
    check_map_input(image, options);
    const uint32_t w = image.width, h = image.height;
    Rgb* pixels = image.pixels.data();

    // Pass 1 gives Lbar, and keeps each texel's luminance in the memory that the start
    // table will occupy: pass 2 then reads 4 bytes a texel instead of the 12 of RGB.
    std::vector<RowStats> rows(h);
    auto luminance = [&] {
        LargeVector<uint32_t> bits(size_t{w} * h);
        parallel_for(h, kRowsPerChunk, stop, [&](uint32_t lo, uint32_t hi) {
            for (uint32_t y = lo; y < hi; ++y) {
                const size_t offset = size_t{y} * w;
                Rgb* row = pixels + offset;
                if (!scan_row(row, w, options.luma, bits.data() + offset, rows[y])) {
                    for (uint32_t x = 0; x < w; ++x) sanitize_pixel(row[x], rows[y].bad);
                    scan_row(row, w, options.luma, bits.data() + offset, rows[y]);
                }
                if (!std::isfinite(rows[y].sum)) rows[y].sum = exact_row_sum(bits.data() + offset, w);
            }
        });
        return bits;
    };
    LargeVector<uint32_t> luminance_bits = luminance();
    EnvMapStats stats;
    std::vector<double> row_sums(h);
    for (uint32_t y = 0; y < h; ++y) {
        row_sums[y] = rows[y].sum;
        stats.bad_pixels += rows[y].bad;
    }
    stats.mean_luminance = solid_angle_mean_of_rows(row_sums, w, options.mapping);
    check_power(stats.mean_luminance);

    // A black map is sampled uniformly; a map that compensation zeroes whole (a constant
    // one) is rebuilt without compensation, from its luminance computed again.
    if (!(stats.mean_luminance > 0)) stats.fallback = DensityFallback::uniform;
    if (options.compensation.enabled && stats.fallback == DensityFallback::none)
        stats.threshold = compensation_threshold(stats.mean_luminance, options.compensation.alpha);
    // A row whose brightest texel is at or below the threshold compensates to +0 whole:
    // its luminance is not read again (most of a sky with a sun: the build's largest saving).
    const auto density = [&](uint32_t y, std::span<const uint32_t> cells, std::span<float> row) {
        const bool uniform = stats.fallback == DensityFallback::uniform;
        if (!uniform && rows[y].max <= stats.threshold) {
            std::fill(row.begin(), row.end(), 0.0f);
            rows[y].zeroed = rows[y].positive;
            return;
        }
        rows[y].zeroed =
            fill_density_row(cells.data(), w, row_weight(options.mapping, y, h), stats.threshold, uniform, row.data());
    };
    Distribution2D distribution(w, h, std::move(luminance_bits), density);
    throw_if_stopped(stop);
    if (stats.threshold > 0 && distribution.uniform_fallback()) {
        stats.fallback = DensityFallback::uncompensated;
        stats.threshold = 0;
        distribution = Distribution2D(w, h, luminance(), density);
    }
    float min_positive = std::numeric_limits<float>::infinity();
    for (const RowStats& r : rows) {
        stats.zeroed_texels += r.zeroed;
        stats.max_luminance = std::max(stats.max_luminance, r.max);
        min_positive = std::min(min_positive, r.min_positive);
    }
    stats.min_positive_luminance = std::isfinite(min_positive) ? min_positive : 0.0f;
    return EnvMap(std::move(image), std::move(distribution), options, stats);
}

}  // namespace envmis
