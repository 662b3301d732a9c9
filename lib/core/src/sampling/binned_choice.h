// Private parts of the binned build (binned.h): the cell grid and its geometry, the
// per-bin thresholds and alphas, and the cell masses of every (class, bin).
#pragma once

#include <bit>
#include <cstdint>
#include <vector>

#include "envmis/sampling/binned.h"

namespace envmis::detail {

// A w x h map cut into cw x ch cells; cell column c holds texel columns
// [column_edges[c], column_edges[c + 1]), the same as floor(x cw / w) == c.
struct CellGrid {
    uint32_t w, h, cw, ch;
    Mapping mapping;
    std::vector<uint32_t> column_edges, row_edges;

    CellGrid(uint32_t w, uint32_t h, uint32_t columns, uint32_t rows, Mapping mapping);
};

// Canonical directions and angular radii (upper bounds) of the cells and the bins: a
// bin's own square, and its blend support (normal_blend: the normals that may pick it,
// those of its own and its eight neighbours' squares).
struct Geometry {
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

// The choice of every (class, bin), class-major, for the grids and classes of `shape`
// (its choices unused), as BinnedOptions asks. Both builds throw Interrupted once `stop`
// is set (interrupt.h).
std::vector<BinChoice> choose_bins(const EnvMap& plain, const CellGrid& grid, const Geometries& geometries,
                                   const BinLayout& shape, const BinnedOptions& options, StopFlag stop);

// The cell masses (cw ch floats) of every (class, bin) of the layout: the weight times the sum
// over the cell of max(L - threshold, 0) times the texels' relative solid angle, or the
// plain mass for a plain choice. Deterministic: the same for any number of threads.
std::vector<std::vector<float>> bin_masses(const EnvMap& plain, const CellGrid& grid, const Geometries& geometries,
                                           const BinLayout& layout, StopFlag stop = nullptr);

}  // namespace envmis::detail
