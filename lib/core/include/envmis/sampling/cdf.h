// The sampling algorithm of envmis, plain: piecewise-constant distributions over [0,1)
// and [0,1)^2 sampled by inverting a fixed-point CDF through a guide table (Chen & Asau
// 1974), as pbrt-v4's PiecewiseConstant1D/2D do by binary search. distribution.h builds
// these tables and tunes the inversion for memory latency, tested equal to this path.
//
// Measure: image space; a cell of probability p_i among n has density p_i n. Each CDF
// is 31-bit fixed point (cell i covers [start_i, start_{i+1}) of 2^31 units): the same
// resolution everywhere, and every cell with f_i > 0 gets at least one unit, so pdf > 0
// exactly where f > 0 and sample and pdf agree exactly (pdf reads the stored widths).
// Cost (n cells): 6 bytes a cell (uint32 CDF, uint16 guide entry); sample O(1) expected
// (the guide names the first cell of the unit's bucket, a binary search covers the few
// cells sharing it); pdf and invert O(1); 1 to 65536 cells a dimension. All noexcept,
// allocation-free, and compiled for CUDA too.
#pragma once

#include <cmath>
#include <cstdint>

#include "envmis/math/math.h"

namespace envmis {

inline constexpr uint32_t kCdfUnits = 1u << 31;    // total of a fixed-point CDF
inline constexpr uint32_t kMaxCells1D = 1u << 16;  // per dimension (uint16 guide entries)

// u clamped into [0, kOneMinusEpsilon], NaN to 0: the samplers take points of [0,1), and
// this keeps any other input from reading outside their tables (a renderer's float
// conversion of a random integer can round up to 1). Valid points pass unchanged.
ENVMIS_HD inline float unit_point(float u) noexcept { return u > 0.0f ? min(u, kOneMinusEpsilon) : 0.0f; }

// The unit of a CDF that u names, u 2^31 truncated (unit_point(u) first): what
// CdfTable::search looks for.
ENVMIS_HD inline uint32_t unit_of(float u) noexcept {
    return static_cast<uint32_t>(unit_point(u) * static_cast<float>(kCdfUnits));
}

// A point found by inverting a CDF: the cell, the position inside it, in [0,1), and the
// cell's width in units, which the search has read and the caller's pdf needs.
struct CellHit {
    uint32_t index = 0;
    float offset = 0;
    uint32_t width = 0;
};

// Non-owning view of one fixed-point CDF over n cells.
struct CdfTable {
    const uint32_t* start = nullptr;  // n: first unit of each cell; zero-width cells are empty
    const uint16_t* guide = nullptr;  // n: guide[k] = cell of the first unit of bucket k
    uint32_t n = 0;

    ENVMIS_HD uint32_t width(uint32_t i) const noexcept { return (i + 1 < n ? start[i + 1] : kCdfUnits) - start[i]; }

    // The cell holding unit u 2^31, and the position inside it: search the cells of u's
    // guide bucket. Single precision: x is exact (a power-of-two scale of u), and so are
    // its integer part t and the fraction x - t; only the offset's division rounds.
    // Always inlined: every sample's row search, which GCC has left as a call in a
    // caller's sampling loop (measured: docs/performance-log.md, 'keep_whole').
    ENVMIS_HD ENVMIS_INLINE CellHit search(float u) const noexcept {
        const float x = unit_point(u) * static_cast<float>(kCdfUnits);
        const auto t = static_cast<uint32_t>(x);
        return find(guide_span(bucket_of_unit(t)), x, t);
    }

    // The first and last cell that may hold a unit of guide bucket k.
    struct Span {
        uint32_t lo, hi;
    };
    ENVMIS_HD Span guide_span(uint32_t k) const noexcept { return {guide[k], k + 1 < n ? guide[k + 1] : n - 1}; }
    // The cell in span s holding unit t (x: t with its fraction), and the position inside it.
    ENVMIS_HD ENVMIS_INLINE CellHit find(Span s, float x, uint32_t t) const noexcept {
        uint32_t lo = s.lo, hi = s.hi;
        while (lo < hi) {  // last cell whose start is <= t
            const uint32_t mid = (lo + hi + 1) / 2;
            if (start[mid] <= t)
                lo = mid;
            else
                hi = mid - 1;
        }
        const uint32_t cell_width = width(lo);
        const float offset =
            (static_cast<float>(t - start[lo]) + (x - static_cast<float>(t))) / static_cast<float>(cell_width);
        // Both terms are >= 0 and the cell found is not empty: only rounding up to 1 needs a clamp.
        return {lo, min(offset, kOneMinusEpsilon), cell_width};
    }
    // The guide bucket of unit t (bucket_position's integer part) and of u.
    ENVMIS_HD uint32_t bucket_of_unit(uint32_t t) const noexcept {
        return static_cast<uint32_t>(bucket_position(t) >> 31);
    }
    ENVMIS_HD uint32_t bucket(float u) const noexcept { return bucket_of_unit(unit_of(u)); }
    // Where unit t lies among the guide buckets, with 31 bits below the point.
    ENVMIS_HD uint64_t bucket_position(uint32_t t) const noexcept { return uint64_t{t} * n; }

    // The u that search maps to (index, offset).
    ENVMIS_HD float at(uint32_t index, float offset) const noexcept {
        const double units = start[index] + static_cast<double>(offset) * width(index);
        return clamp(static_cast<float>(units / kCdfUnits), 0.0f, kOneMinusEpsilon);
    }
};

namespace detail {

// Cell of x in [0,1); exact, because a float times n <= 2^31 is exact in double. A NaN
// (from a NaN direction) gets cell 0: converting it to an integer is undefined.
ENVMIS_HD inline uint32_t cell_of(float x, uint32_t n) noexcept {
    const float inside = x > 0 ? min(x, 1.0f) : 0.0f;
    const auto i = static_cast<uint32_t>(static_cast<double>(inside) * n);
    return i < n ? i : n - 1;
}

// Position of x inside cell i, in [0,1), from the same exact product as cell_of.
ENVMIS_HD inline float offset_in_cell(float x, uint32_t i, uint32_t n) noexcept {
    return clamp(static_cast<float>(static_cast<double>(x) * n - i), 0.0f, kOneMinusEpsilon);
}

// float(a / n), the double quotient rounded to float, without the double division on
// the sample's critical path: the product with 1/n lies within 3 double ulps of the
// quotient, so both round to the same float unless the quotient is within a few ulps of
// a midpoint between floats (their last 29 mantissa bits near 2^28; about one point in
// 2^24), where the division decides; so does it below 2^-126, where floats are
// subnormal and their midpoints lie elsewhere in the bits.
ENVMIS_HD inline float quotient_to_float(double a, uint32_t n) noexcept {
    const double product = a * (1.0 / n);
    const uint64_t below_float = bit_cast<uint64_t>(product) & ((uint64_t{1} << 29) - 1);
    if (below_float - ((uint64_t{1} << 28) - 16) < 32 || product < 0x1p-126) [[unlikely]]
        return static_cast<float>(a / n);
    return static_cast<float>(product);
}

// The float nearest (index + offset) / n that still lies in cell `index`: rounding to
// float can step over a cell edge, and one step back always suffices because a cell is
// many float ulps wide. Forced inline (measured: docs/performance-log.md, 'point_in_cell').
ENVMIS_HD ENVMIS_INLINE float point_in_cell(uint32_t index, float offset, uint32_t n) noexcept {
    if ((n & (n - 1)) == 0) {
        // Power-of-two n (most maps): index / n and offset / n are exact floats, so
        // their sum rounds once, to the same float as the division below, and can only
        // round up onto the next cell's edge, which is exact too.
        const float inv_n = 1.0f / static_cast<float>(n), i = static_cast<float>(index);
        const float x = i * inv_n + offset * inv_n;
        const float next_edge = (i + 1) * inv_n;
        return x < next_edge ? x : bit_cast<float>(bit_cast<uint32_t>(next_edge) - 1);
    }
    float x = quotient_to_float(index + static_cast<double>(offset), n);
    // x lies within half a float ulp below 1, 2^-25, of the quotient (and 2^-54 more where
    // the double division rounds first): about n 2^-25 cells. An offset twice that far
    // from both edges of its cell keeps x inside, below 1, with no check on the sample's
    // critical path.
    const float margin = static_cast<float>(n) * 0x1p-24f;
    if (offset >= margin && offset <= 1.0f - margin) [[likely]]
        return x;
    const uint32_t c = cell_of(x, n);
    if (c > index) x = ::nextafterf(x, 0.0f);
    if (c < index) x = ::nextafterf(x, 1.0f);
    return clamp(x, 0.0f, kOneMinusEpsilon);
}

}  // namespace detail

// Non-owning view of a 2D distribution: a marginal CDF over the h rows, then one
// conditional CDF per row. Cell (x, y) covers [x/w, (x+1)/w) x [y/h, (y+1)/h).
struct Cdf2DTable {
    const uint32_t* start = nullptr;  // w h, row-major: row y's CDF is start[y w, y w + w)
    const uint16_t* guide = nullptr;  // w h, likewise
    CdfTable marginal;                // over the h rows
    uint32_t w = 0, h = 0;
    float pdf_scale = 0;  // w h 2^-62: density per unit of the marginal times unit of a row

    struct Sample {
        Vec2 p;                 // continuous point in [0,1)^2
        float pdf = 0;          // density at p (measure: dx dy on [0,1)^2)
        uint32_t x = 0, y = 0;  // cell of p
    };

    ENVMIS_HD CdfTable row_table(uint32_t y) const noexcept {
        const size_t offset = static_cast<size_t>(y) * w;
        return {start + offset, guide + offset, w};
    }
    // u.y picks the row, u.x the column within it.
    ENVMIS_HD Sample search(Vec2 u) const noexcept {
        const CellHit r = marginal.search(u.y), c = row_table(r.index).search(u.x);
        const Vec2 p{detail::point_in_cell(c.index, c.offset, w), detail::point_in_cell(r.index, r.offset, h)};
        return {p, pdf_of(r.width, c.width), c.index, r.index};
    }
    ENVMIS_HD float pdf(Vec2 p) const noexcept {
        const uint32_t x = detail::cell_of(p.x, w), y = detail::cell_of(p.y, h);
        return pdf_of(marginal.width(y), row_table(y).width(x));
    }
    ENVMIS_HD Vec2 invert(Vec2 p) const noexcept {
        const uint32_t x = detail::cell_of(p.x, w), y = detail::cell_of(p.y, h);
        return {row_table(y).at(x, detail::offset_in_cell(p.x, x, w)),
                marginal.at(y, detail::offset_in_cell(p.y, y, h))};
    }
    // Density of a cell from its row's and its own widths. In float: the int-to-double
    // conversions cost more than the rest of the product, and the two extra roundings
    // leave it within 3 float ulps of the exact value.
    ENVMIS_HD float pdf_of(uint32_t row_width, uint32_t cell_width) const noexcept {
        return static_cast<float>(row_width) * static_cast<float>(cell_width) * pdf_scale;
    }
};

}  // namespace envmis
