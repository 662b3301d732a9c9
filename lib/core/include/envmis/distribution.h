// Piecewise-constant distributions over [0,1) and [0,1)^2, sampled by CDF inversion
// accelerated with a guide table (Chen & Asau 1974).
//
// Measure: image space. A distribution over n cells has density
//   pdf(x) = func[cell(x)] / integral,   integral = mean of func over the domain,
// so pdf integrates to 1 over [0,1)^d. `sample` inverts the CDF: it preserves the
// stratification of its input and is exactly invertible (`invert(sample(u).p) == u` up
// to float rounding).
//
// Precision: cumulative sums are accumulated and stored in double (a CDF over 32M
// texels loses small cells in float); function values are stored as float.
//
// Cost (n cells): build O(n), 16 bytes per cell (double cdf, float func, uint32 guide);
// sample O(1) expected (guide-table lookup, then a binary search only inside the few
// cells that share one guide bucket), pdf O(1), invert O(1).
//
// The owning classes hold std::vector storage and throw on invalid input. Their
// `view()` is a pair of flat arrays with noexcept, allocation-free methods that also
// compile for CUDA: upload the arrays and use the same view on the device.
#pragma once

#include <cstddef>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "envmis/math.h"

namespace envmis {

// One cell of a 1D CDF table; bucket k of the guide table lives in cell k.
struct CdfCell {
    double cdf = 0;      // cumulative normalised mass of cells [0, i]; the last cell holds exactly 1
    float func = 0;      // the function value of this cell (>= 0)
    uint32_t guide = 0;  // first cell i whose cdf lies in guide bucket k or later (bucket of x: floor(x n))
};
static_assert(sizeof(CdfCell) == 16);

// A point found by inverting a CDF: the cell and the position inside it, in [0,1).
struct CellHit {
    uint32_t index = 0;
    float offset = 0;
};

namespace detail {

ENVMIS_HD inline uint32_t guide_bucket(double x, uint32_t n) noexcept {
    const auto k = static_cast<uint32_t>(x * n);
    return k < n ? k : n - 1;
}

// Inverts the CDF held by cells[0, n): the first cell whose cdf exceeds u.
ENVMIS_HD inline CellHit invert_cdf(const CdfCell* cells, uint32_t n, float u) noexcept {
    const double t = u;
    const uint32_t k = guide_bucket(t, n);
    uint32_t lo = cells[k].guide;
    uint32_t hi = k + 1 < n ? cells[k + 1].guide : n - 1;
    while (lo < hi) {
        const uint32_t mid = (lo + hi) / 2;
        if (cells[mid].cdf > t) hi = mid; else lo = mid + 1;
    }
    const double before = lo > 0 ? cells[lo - 1].cdf : 0.0;
    const auto offset = static_cast<float>((t - before) / (cells[lo].cdf - before));
    return {lo, clamp(offset, 0.0f, kOneMinusEpsilon)};
}

// The u that `invert_cdf` maps to (index, offset).
ENVMIS_HD inline float cdf_at(const CdfCell* cells, uint32_t index, float offset) noexcept {
    const double before = index > 0 ? cells[index - 1].cdf : 0.0;
    const double u = before + offset * (cells[index].cdf - before);
    return clamp(static_cast<float>(u), 0.0f, kOneMinusEpsilon);
}

// Cell of x in [0,1); exact, because a float times n <= 2^31 is exact in double.
ENVMIS_HD inline uint32_t cell_of(float x, uint32_t n) noexcept {
    const auto i = static_cast<uint32_t>(static_cast<double>(clamp(x, 0.0f, 1.0f)) * n);
    return i < n ? i : n - 1;
}

// Position inside cell x in [0,1), from the same exact product as cell_of.
ENVMIS_HD inline float offset_in_cell(float x, uint32_t i, uint32_t n) noexcept {
    return clamp(static_cast<float>(static_cast<double>(x) * n - i), 0.0f, kOneMinusEpsilon);
}

// The float nearest (index + offset) / n that still lies in cell `index`: rounding to
// float can step over a cell edge, and one step back always suffices because a cell is
// many float ulps wide.
ENVMIS_HD inline float point_in_cell(uint32_t index, float offset, uint32_t n) noexcept {
    float x = static_cast<float>((index + static_cast<double>(offset)) / n);
    const uint32_t c = cell_of(x, n);
    if (c > index) x = ::nextafterf(x, 0.0f);
    if (c < index) x = ::nextafterf(x, 1.0f);
    return clamp(x, 0.0f, kOneMinusEpsilon);
}

// Fills cells[0, n) from func (cdf, func and guide) and returns the sum of func; adds
// the number of negative, NaN or infinite values to `invalid` (the caller rejects them).
// A zero row gets a uniform CDF (it keeps its zero func, so its pdf stays 0).
template <class T>
double build_cells(const T* func, uint32_t n, CdfCell* cells, uint32_t& invalid) noexcept;

}  // namespace detail

// Non-owning view of a 1D distribution; see the file comment.
struct Distribution1DView {
    const CdfCell* cells = nullptr;
    uint32_t n = 0;
    double inv_integral = 0;  // 1 / (mean of func)

    struct Sample {
        float x = 0;        // continuous point in [0,1)
        float pdf = 0;      // density at x (measure: dx on [0,1))
        uint32_t index = 0; // cell of x
    };

    ENVMIS_HD Sample sample(float u) const noexcept {
        const CellHit hit = detail::invert_cdf(cells, n, u);
        return {detail::point_in_cell(hit.index, hit.offset, n), cell_pdf(hit.index), hit.index};
    }
    ENVMIS_HD float pdf(float x) const noexcept { return cell_pdf(detail::cell_of(x, n)); }
    ENVMIS_HD float invert(float x) const noexcept {
        const uint32_t i = detail::cell_of(x, n);
        return detail::cdf_at(cells, i, detail::offset_in_cell(x, i, n));
    }
    ENVMIS_HD float cell_pdf(uint32_t i) const noexcept { return static_cast<float>(cells[i].func * inv_integral); }
};

// A piecewise-constant distribution over [0,1) with func.size() cells.
class Distribution1D {
public:
    Distribution1D() = default;
    // Throws std::invalid_argument if func is empty, has more than 2^31 cells, or holds a
    // negative or non-finite value. An all-zero func gives the uniform distribution.
    explicit Distribution1D(std::span<const float> func);

    Distribution1DView view() const noexcept { return {cells_.data(), size(), inv_integral_}; }
    Distribution1DView::Sample sample(float u) const noexcept { return view().sample(u); }
    float pdf(float x) const noexcept { return view().pdf(x); }
    float invert(float x) const noexcept { return view().invert(x); }

    uint32_t size() const noexcept { return static_cast<uint32_t>(cells_.size()); }
    double integral() const noexcept { return integral_; }  // mean of the input func over [0,1)
    bool uniform_fallback() const noexcept { return uniform_; }
    std::span<const CdfCell> cells() const noexcept { return cells_; }

private:
    std::vector<CdfCell> cells_;
    double integral_ = 0;
    double inv_integral_ = 0;
    bool uniform_ = false;
};

// Non-owning view of a 2D distribution: a marginal CDF over rows, then one
// conditional CDF per row. Cell (x, y) covers [x/w, (x+1)/w) x [y/h, (y+1)/h).
struct Distribution2DView {
    const CdfCell* cells = nullptr;     // w * h, row-major, row y = cells[y*w, y*w + w)
    const CdfCell* marginal = nullptr;  // h
    uint32_t w = 0, h = 0;
    double inv_integral = 0;

    struct Sample {
        Vec2 p;             // continuous point in [0,1)^2
        float pdf = 0;      // density at p (measure: dx dy on [0,1)^2)
        uint32_t x = 0, y = 0;  // cell of p
    };

    // u.y picks the row, u.x the column within it.
    ENVMIS_HD Sample sample(Vec2 u) const noexcept {
        const CellHit row = detail::invert_cdf(marginal, h, u.y);
        const CellHit col = detail::invert_cdf(cells + static_cast<size_t>(row.index) * w, w, u.x);
        const Vec2 p{detail::point_in_cell(col.index, col.offset, w), detail::point_in_cell(row.index, row.offset, h)};
        return {p, cell_pdf(col.index, row.index), col.index, row.index};
    }
    ENVMIS_HD float pdf(Vec2 p) const noexcept { return cell_pdf(detail::cell_of(p.x, w), detail::cell_of(p.y, h)); }
    ENVMIS_HD Vec2 invert(Vec2 p) const noexcept {
        const uint32_t x = detail::cell_of(p.x, w), y = detail::cell_of(p.y, h);
        return {detail::cdf_at(cells + static_cast<size_t>(y) * w, x, detail::offset_in_cell(p.x, x, w)),
                detail::cdf_at(marginal, y, detail::offset_in_cell(p.y, y, h))};
    }
    ENVMIS_HD float cell_pdf(uint32_t x, uint32_t y) const noexcept {
        return static_cast<float>(cells[static_cast<size_t>(y) * w + x].func * inv_integral);
    }
};

// A piecewise-constant distribution over [0,1)^2 from a w x h row-major function.
class Distribution2D {
public:
    Distribution2D() = default;
    // Throws std::invalid_argument on a size mismatch, w or h of 0, more than 2^31
    // cells, or a negative or non-finite value. An all-zero func gives the uniform
    // distribution. Rows are built in parallel on all cores; the result does not
    // depend on the number of threads.
    Distribution2D(std::span<const float> func, uint32_t w, uint32_t h);

    Distribution2DView view() const noexcept { return {cells_.data(), marginal_.data(), w_, h_, inv_integral_}; }
    Distribution2DView::Sample sample(Vec2 u) const noexcept { return view().sample(u); }
    float pdf(Vec2 p) const noexcept { return view().pdf(p); }
    Vec2 invert(Vec2 p) const noexcept { return view().invert(p); }

    uint32_t width() const noexcept { return w_; }
    uint32_t height() const noexcept { return h_; }
    double integral() const noexcept { return integral_; }  // mean of the input func over [0,1)^2
    bool uniform_fallback() const noexcept { return uniform_; }
    float func(uint32_t x, uint32_t y) const noexcept { return cells_[static_cast<size_t>(y) * w_ + x].func; }
    size_t bytes() const noexcept { return (cells_.size() + marginal_.size()) * sizeof(CdfCell); }

private:
    std::vector<CdfCell> cells_, marginal_;
    uint32_t w_ = 0, h_ = 0;
    double integral_ = 0;
    double inv_integral_ = 0;
    bool uniform_ = false;
};

}  // namespace envmis
