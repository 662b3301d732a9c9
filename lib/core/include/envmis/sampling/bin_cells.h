// The cells and bins of a normal-aware map (binned.h), shared by the build that chooses
// each bin's threshold (envmis::build, envmis/build/bins.h) and the load that rebuilds a
// table's bins from its layout (BinnedEnvMap(plain, layout)): the cell grid and its
// geometry, the luminance histograms the thresholds are rounded to, and the cell masses
// of every (class, bin). Not an API for renderers; its names sit in envmis::detail.
#pragma once

#include <algorithm>
#include <bit>
#include <cstdint>
#include <span>
#include <vector>

#include "envmis/core_export.h"
#include "envmis/interrupt.h"
#include "envmis/sampling/binned.h"

namespace envmis::detail {

// A w x h map cut into cw x ch cells; cell column c holds texel columns
// [column_edges[c], column_edges[c + 1]), the same as floor(x cw / w) == c.
struct ENVMIS_CORE_API CellGrid {
    uint32_t w, h, cw, ch;
    Mapping mapping;
    std::vector<uint32_t> column_edges, row_edges;

    CellGrid(uint32_t w, uint32_t h, uint32_t columns, uint32_t rows, Mapping mapping);
};

// Canonical directions and angular radii (upper bounds) of the cells and the bins: a
// bin's own square, and its blend support (normal_blend: the normals that may pick it,
// those of its own and its eight neighbours' squares).
struct ENVMIS_CORE_API Geometry {
    // cell_light: where a cell's light comes from, the normalised sum of its texels'
    // directions weighted by luminance times solid angle (its centre where it is black).
    std::vector<Vec3> cell_direction, cell_light, bin_normal;
    std::vector<float> cell_radius, bin_radius, support_radius;

    Geometry(const EnvMap& plain, const CellGrid& grid, uint32_t bins_per_side);
    // Another grid of bins over the cells of `cells` (their geometry and light, which a
    // pass over the texels gives, computed once).
    Geometry(const Geometry& cells, uint32_t bins_per_side);
    // c_b: an upper bound of cos+(omega . n) for omega in the cell and n in the bin's support.
    float bound(uint32_t bin, size_t cell) const noexcept;
    // The cosine factor a bin's cell masses carry: for the diffuse class > 0 exactly
    // where bound() is; for a glossy class (`glossy`) > 0 everywhere.
    float weight(uint32_t bin, size_t cell, bool glossy) const noexcept;

private:
    void set_bins(uint32_t bins_per_side);
};

// The two grids of normals a layout uses: the diffuse class's and the glossy classes'.
struct Geometries {
    Geometry diffuse, glossy;
    Geometries(const EnvMap& plain, const CellGrid& grid, const BinLayout& layout)
        : diffuse(plain, grid, layout.diffuse_bins_per_side), glossy(diffuse, layout.bins_per_side) {}
    const Geometry& of(uint32_t lobe_class) const noexcept { return lobe_class == 0 ? diffuse : glossy; }
};

// Thresholds are rounded to the edges of a luminance histogram whose buckets are the
// float bit patterns shifted right by kHistogramShift (8 buckets an octave): the sum
// over a cell of max(L - t, 0) is then exact from the buckets' sums.
inline constexpr uint32_t kHistogramShift = 20;
inline float histogram_edge(float t) noexcept {
    const uint32_t half = 1u << (kHistogramShift - 1);
    return std::bit_cast<float>(((std::bit_cast<uint32_t>(t) + half) >> kHistogramShift) << kHistogramShift);
}
inline bool on_histogram_edge(float t) noexcept {
    return (std::bit_cast<uint32_t>(t) & ((1u << kHistogramShift) - 1)) == 0;
}

// Per cell, over its texels: sums of L w (w: the texel's relative solid angle, as the
// plain density has it) and of w by histogram bucket, as suffix sums (bucket k holds
// every texel of bucket k and above), the plain mass and the largest luminance.
struct CellHistogram {
    int64_t first = 0;     // bucket id of index 0
    uint32_t buckets = 0;  // per cell; the last gathers every texel above
    std::vector<double> suffix_l, suffix_w, total_l;
    std::vector<float> max_l;

    // Sum over the cell of max(L - t, 0) w, for t = 0 or a histogram edge in the window.
    double above(size_t cell, float t) const noexcept {
        if (t == 0) return total_l[cell];
        const auto k = static_cast<int64_t>(std::bit_cast<uint32_t>(t) >> kHistogramShift) - first;
        const size_t at = cell * buckets + static_cast<size_t>(std::clamp<int64_t>(k, 0, buckets - 1));
        const double s = suffix_l[at] - static_cast<double>(t) * suffix_w[at];
        // A texel above t must keep the cell's mass positive, whatever the rounding.
        return max_l[cell] > t ? std::max(s, static_cast<double>(max_l[cell] - t) * 1e-30) : std::max(s, 0.0);
    }
};

// The histograms of the cells, with a window of buckets from the lowest to the highest of
// `thresholds` (positive histogram edges; at most 512 buckets). Throws Interrupted once
// `stop` is set (interrupt.h).
ENVMIS_CORE_API CellHistogram histogram(const EnvMap& plain, const CellGrid& grid, std::span<const float> thresholds,
                                        StopFlag stop);

// Throw std::invalid_argument for options a build refuses, and for a grid of more cells
// than a bin's CDF can name (uint16 guide entries: at most 65536).
ENVMIS_CORE_API void check_options(const BinnedOptions& options);
// Texels of the largest cell of a grid (CellGrid's edges round up).
ENVMIS_CORE_API uint64_t largest_cell(uint32_t w, uint32_t h, uint32_t columns, uint32_t rows) noexcept;
// Throws std::invalid_argument where the grid has more than kMaxCells1D cells or a cell
// more than kMaxCells1D texels.
ENVMIS_CORE_API void check_cells(uint32_t w, uint32_t h, uint32_t columns, uint32_t rows);

// The cell masses (cw ch floats) of every (class, bin) of the layout: the weight times the sum
// over the cell of max(L - threshold, 0) times the texels' relative solid angle, or the
// plain mass for a plain choice. Deterministic: the same for any number of threads.
ENVMIS_CORE_API std::vector<std::vector<float>> bin_masses(const EnvMap& plain, const CellGrid& grid,
                                                           const Geometries& geometries, const BinLayout& layout,
                                                           StopFlag stop = nullptr);

}  // namespace envmis::detail
