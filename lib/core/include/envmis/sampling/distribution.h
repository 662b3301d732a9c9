// Piecewise-constant distributions over [0,1) and [0,1)^2, sampled by CDF inversion
// accelerated with a guide table (Chen & Asau 1974).
//
// Measure: image space. A distribution over n cells with function values f_i has
// density pdf(x) = p_i n on cell i, where p_i is the cell's probability, so the pdf
// integrates to 1 over [0,1)^d. `sample` inverts the CDF: it preserves the
// stratification of its input and is exactly invertible (`invert(sample(u).p) == u` up
// to float rounding).
//
// Precision: sums are accumulated in double, then each CDF is stored in 31-bit fixed
// point (uint32: cell i covers [start_i, start_{i+1}) of 2^31 units). Fixed point has
// the same resolution everywhere (a float CDF has 2^-24 near 1 and loses small cells
// after large ones). Every cell with f_i > 0 gets at least one unit, so pdf > 0 exactly
// where f > 0, and pdf() reports the stored probability itself: sample and pdf agree
// exactly. p_i differs from f_i / sum f by at most one unit, 2^-31 = 4.7e-10.
//
// Cost (n cells): build O(n); 6 bytes per cell (uint32 CDF, uint16 guide entry), and in
// 2D one uint16 coarse guide entry per kCoarseGuideStep cells of a row (0.03 bytes a
// cell); sample O(1) expected (a guide-table lookup, then a binary search only inside the
// few cells that share one guide bucket); pdf O(1); invert O(1). Sizes: 1 to 65536 cells
// per dimension.
//
// The owning classes hold the tables and throw on invalid input. Their `view()` is a
// set of flat arrays with noexcept, allocation-free methods that also compile for
// CUDA: upload the arrays and use the same view on the device.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "envmis/large_vector.h"
#include "envmis/math/math.h"

namespace envmis {

inline constexpr uint32_t kCdfUnits = 1u << 31;    // total of a fixed-point CDF
inline constexpr uint32_t kMaxCells1D = 1u << 16;  // per dimension (uint16 guide entries)

// A row holding more than this many times the mean row's share of a 2D distribution
// draws so many of the samples that its data stays in cache: the samplers skip their
// prefetches in it, which take load slots there and save nothing. Measured on the
// compensated 8k sky, whose samples crowd onto the sun's rows (each about 300 times the
// mean; its other rows hold about the mean): single samples 15.4 ns without, 17.2-18.4 ns
// with (AMD EPYC family 0x1a); on small maps, whose rows hold many times more of the
// density each, a relative share keeps ordinary rows prefetched.
inline constexpr uint32_t kHotRowFactor = 64;

// One coarse guide entry per this many guide buckets of a 2D distribution's row: the
// guide entry of every 64th bucket, 1 MiB for an 8192 x 4096 map, small enough to stay
// in cache where the full guide (64 MiB) does not. A sample reads it to guess where in
// the row its answer lies before the guide entry, a cache miss, says so (see
// CdfView::invert), and in a hot row to skip the guide (CdfView::invert_cached).
// Built only where the tables (6 bytes a cell) reach kCoarseGuideMinBytes, about 2.8
// million cells and up: smaller ones stay in the last-level cache, where it has
// little to hide (a 1k map, one process, with against without it: compensated
// 0.99-1.00x, plain 1.05-1.06x; AMD EPYC family 0x1a).
inline constexpr uint32_t kCoarseGuideShift = 6, kCoarseGuideStep = 1u << kCoarseGuideShift;
inline constexpr size_t kCoarseGuideMinBytes = size_t{16} << 20;
// Coarse guide entries of a row of w cells (the last step may be shorter).
ENVMIS_HD inline uint32_t coarse_guide_size(uint32_t w) noexcept {
    return (w + kCoarseGuideStep - 1) / kCoarseGuideStep;
}

// A point found by inverting a CDF: the cell, the position inside it, in [0,1), and the
// cell's width in units (CdfView::width), which the search has read and the caller's pdf
// needs. Reading it again took plain single samples of the 8k sky 6-13% longer (AMD EPYC
// family 0x19): a cold row's sample must leave room in the reorder buffer for the next
// sample's first misses, and a few instructions more decide whether they fit.
struct CellHit {
    uint32_t index = 0;
    float offset = 0;
    uint32_t width = 0;
};

// u clamped into [0, kOneMinusEpsilon], NaN to 0: the samplers take points of [0,1), and
// this keeps any other input from reading outside their tables (a renderer's float
// conversion of a random integer can round up to 1). Valid points pass unchanged.
ENVMIS_HD inline float unit_point(float u) noexcept { return u > 0.0f ? min(u, kOneMinusEpsilon) : 0.0f; }

// The unit of a CDF that u names, u 2^31 truncated (unit_point(u) first): what
// CdfView::invert searches for.
ENVMIS_HD inline uint32_t unit_of(float u) noexcept {
    return static_cast<uint32_t>(unit_point(u) * static_cast<float>(kCdfUnits));
}

// The hint of CdfView::invert that does nothing.
struct NoHint {
    ENVMIS_HD void operator()(uint32_t, uint32_t) const noexcept {}
};

// Non-owning view of one fixed-point CDF over n cells.
struct CdfView {
    const uint32_t* start = nullptr;  // n: first unit of each cell; zero-width cells are empty
    const uint16_t* guide = nullptr;  // n: guide[k] = cell of the first unit of bucket k
    uint32_t n = 0;
    // Optional, ceil(n / kCoarseGuideStep): coarse[j] = guide[j kCoarseGuideStep]; only
    // read for prefetching (predicted_cell), never for the answer.
    const uint16_t* coarse = nullptr;

    ENVMIS_HD uint32_t width(uint32_t i) const noexcept { return (i + 1 < n ? start[i + 1] : kCdfUnits) - start[i]; }

    // The cell holding unit u * 2^31, and the position inside it.
    // Single precision throughout: x is exact (a power-of-two scale of u), and so are
    // its integer part t and the fraction x - t; only the offset's division rounds.
    //
    // Memory: a map beyond the cache misses on the guide entry, then on the CDF entry it
    // names, then on the caller's data for the cell found. Where the function is flat
    // the answer is near cell k of the guide bucket, so the CDF around k is prefetched
    // and `near_answer(k, k)` lets the caller prefetch its own: the three loads overlap
    // instead of waiting for each other. Real maps are not flat (the answer lies within
    // a cell of k in 1-6% of the samples of 14 maps at 1k), so where a coarse guide is
    // given, the cell it predicts and its two neighbours are prefetched too. A caller
    // that knows the data is in cache passes kPrefetch = false: the prefetches would
    // only take load slots (and see invert_cached).
    //
    // The cells prefetched are tried first (find_near): where they hold the answer, the
    // guide's entry, a miss of its own, is not read at all. Plain single samples of the
    // 8k sky in envmis bench, binaries alternating: 8-17% less time (AMD EPYC family
    // 0x19; fewer instructions, and no branch on the guide's answer). Where they do not
    // (3-16% of cold rows' samples: the 8k sky in equal-area, a real map upscaled to 8k),
    // the guide's entry is already on its way: prefetched too where the coarse guide sees
    // no flat stretch. Plain single samples of rooitou_park upscaled to 33.5M texels, in
    // one process: 4-9% less time; the flat 8k sky unchanged (AMD EPYC family 0x19).
    template <bool kPrefetch = true, class Hint = NoHint>
    ENVMIS_HD ENVMIS_INLINE CellHit invert(float u, Hint near_answer = {}) const noexcept {
        const float x = unit_point(u) * static_cast<float>(kCdfUnits);
        const auto t = static_cast<uint32_t>(x);
        if constexpr (kPrefetch) {
            uint32_t cell;
            if (find_near(prefetch_unit(t, near_answer), t, cell)) return find({cell, cell}, x, t);
        }
        return find(guide_span(bucket_of_unit(t)), x, t);
    }
    // invert for a CDF in cache that has a coarse guide: the search starts from the coarse
    // entries around the guide bucket where they are at most a cell apart, as in a row
    // whose few bright cells span many buckets each. A 2D distribution's row read often
    // (Distribution2DView::row_is_hot) keeps its coarse guide, 1/64 of its guide, in the
    // nearest cache, where its guide spills into the next: compensated single samples on
    // the 8k sky took 0.87-0.99x the time of a search from the guide (AMD EPYC family
    // 0x19). The same answer as invert.
    ENVMIS_HD ENVMIS_INLINE CellHit invert_cached(float u) const noexcept {
        const float x = unit_point(u) * static_cast<float>(kCdfUnits);
        const auto t = static_cast<uint32_t>(x);
        const uint32_t k = bucket_of_unit(t);
        const Span coarse = coarse_span(k);
        return find(coarse.hi - coarse.lo <= 1 ? coarse : guide_span(k), x, t);
    }

    // The first and last cell that may hold the answer for a unit in guide bucket k: from
    // the guide, and from the coarse guide (a wider span, the step's).
    struct Span {
        uint32_t lo, hi;
    };
    ENVMIS_HD Span guide_span(uint32_t k) const noexcept { return {guide[k], k + 1 < n ? guide[k + 1] : n - 1}; }
    ENVMIS_HD Span coarse_span(uint32_t k) const noexcept {
        const uint32_t j = k >> kCoarseGuideShift;
        return {coarse[j], (j + 1) * kCoarseGuideStep < n ? coarse[j + 1] : n - 1};
    }
    // The cell holding unit t if it is one of cells c - 1 to c + 1 (those in the CDF): the
    // last of them whose start is <= t, when the next cell's start is > t. False otherwise.
    ENVMIS_HD bool find_near(uint32_t c, uint32_t t, uint32_t& cell) const noexcept {
        const uint32_t lo = c > 0 ? c - 1 : 0, hi = min(c + 1, n - 1);
        if (start[lo] > t || (hi + 1 < n && start[hi + 1] <= t)) return false;
        cell = lo + (lo < hi && start[lo + 1] <= t) + (lo + 1 < hi && start[lo + 2] <= t);
        return true;
    }
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
        // Both terms are >= 0 (t >= start[lo], t <= x) and the found cell is not empty,
        // so only the rounding up to 1 needs a clamp.
        return {lo, min(offset, kOneMinusEpsilon), cell_width};
    }

    // The prefetches of invert for unit t: the CDF at its guide bucket k and, with a
    // coarse guide, k's guide entry and the CDF around the cell it predicts where that is
    // not next to k; `near_answer` at the same cells. Returns the cell whose
    // neighbourhood it prefetched last, the likeliest answer.
    template <class Hint>
    ENVMIS_HD ENVMIS_INLINE uint32_t prefetch_unit(uint32_t t, Hint near_answer) const noexcept {
        const uint32_t k = bucket_of_unit(t);
        prefetch_cells(k, k, near_answer);
#if defined(__CUDA_ARCH__)
        return k;  // no prefetches on the device: nor the coarse guide's reads for them
#endif
        if (!coarse) return k;
        const uint32_t p = predicted_cell(bucket_position(t));
        if (p + 1 >= k && p <= k + 1) return k;  // a flat stretch: the answer is k, whose lines are on their way
        ENVMIS_PREFETCH(guide + k);              // for the search that follows where p is wrong
        // p is the answer in 29-74% of samples (14 real maps at 1k and the 8k-class sky,
        // either mapping), a neighbour in most of the rest: on the equal-area sky these
        // three cells hold every line the search and its caller read in 97% of samples,
        // p alone in 77% (a texel's 12 bytes may straddle two lines).
        prefetch_cells(p > 0 ? p - 1 : 0, min(p + 1, n - 1), near_answer);
        return p;
    }
    // What the search reads of cells first to last (a few): their CDF entries and the
    // next one, at most two lines, loaded through their ends; `near_answer(first,
    // last)` for the caller's data of the same cells.
    template <class Hint>
    ENVMIS_HD ENVMIS_INLINE void prefetch_cells(uint32_t first, uint32_t last, Hint near_answer) const noexcept {
        ENVMIS_PREFETCH(start + first);
        ENVMIS_PREFETCH(start + last + 1);  // one past the table at most: a prefetch does not fault
        near_answer(first, last);
    }
    // The cell the coarse guide predicts for a unit at bucket position b
    // (bucket_position): the cells from the coarse entry before it to the next one (the
    // end of the row after the last), interpolated linearly to b, fraction and all, then
    // rounded. A coarse entry is the cell of its bucket's first unit, on average half a
    // cell before where the CDF reaches that unit: hence the rounding, not truncation
    // (on 14 real maps at 1k, either mapping: the answer itself 29-67% of the time
    // against 20-51% when the prediction took the bucket's first unit and truncated).
    // It lies in the span that holds the answer.
    ENVMIS_HD ENVMIS_INLINE uint32_t predicted_cell(uint64_t b) const noexcept {
        constexpr uint32_t kStep = 31 + kCoarseGuideShift;  // bits of b below a coarse step
        const uint32_t j = static_cast<uint32_t>(b >> kStep), first = coarse[j];
        const uint64_t into = b & ((uint64_t{1} << kStep) - 1);  // < 2^37; times a span < 2^16
        if ((j + 1) * kCoarseGuideStep < n)
            return first +
                   static_cast<uint32_t>(((coarse[j + 1] - first) * into + (uint64_t{1} << (kStep - 1))) >> kStep);
        const uint64_t buckets = uint64_t{n - j * kCoarseGuideStep} << 31;  // the row's last, shorter step
        return min(first + static_cast<uint32_t>(((n - first) * into + buckets / 2) / buckets), n - 1);
    }

    // The guide bucket of unit t, and of u: where invert starts, for callers that
    // prefetch its first reads (sample_many).
    ENVMIS_HD uint32_t bucket_of_unit(uint32_t t) const noexcept {
        return static_cast<uint32_t>(bucket_position(t) >> 31);
    }
    ENVMIS_HD uint32_t bucket(float u) const noexcept { return bucket_of_unit(unit_of(u)); }
    // Where unit t lies among the guide buckets, in fixed point with 31 bits below the
    // point: bucket_of_unit(t) and t's place inside that bucket.
    ENVMIS_HD uint64_t bucket_position(uint32_t t) const noexcept { return uint64_t{t} * n; }

    // The u that `invert` maps to (index, offset).
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
// many float ulps wide. Forced inline: GCC left it out of line in envmis bench's sample
// loop, a tenth of an equal-area sample's time (measured: docs/performance-log.md).
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

// The uniform CDF over n cells: what build_cdf gives a function without a positive value.
struct UniformCdf {
    std::vector<uint32_t> start;
    std::vector<uint16_t> guide;

    explicit UniformCdf(uint32_t n);
};

// Working memory of build_cdf for up to n cells, reusable from one call to the next.
// `uniform`, when given (over the same n cells), is copied for a function without a
// positive value rather than built again: the rows of a 2D distribution share one.
struct CdfScratch {
    std::vector<double> prefix;
    std::vector<uint16_t> marks;
    const UniformCdf* uniform = nullptr;

    explicit CdfScratch(uint32_t n, const UniformCdf* shared_uniform = nullptr)
        : prefix(n), marks(size_t{n} + 1), uniform(shared_uniform) {}
};

// Fills start and guide (n each) from func and returns the sum of func (double); adds
// the number of negative, NaN or infinite values to `invalid` (the caller rejects them).
// A zero function gets a uniform CDF.
template <class T>
double build_cdf(const T* func, uint32_t n, uint32_t* start, uint16_t* guide, uint32_t& invalid,
                 CdfScratch& scratch) noexcept;

}  // namespace detail

// Non-owning view of a 1D distribution; see the file comment.
struct Distribution1DView {
    CdfView cdf;

    struct Sample {
        float x = 0;         // continuous point in [0,1)
        float pdf = 0;       // density at x (measure: dx on [0,1))
        uint32_t index = 0;  // cell of x
    };

    ENVMIS_HD Sample sample(float u) const noexcept {
        const CellHit hit = cdf.invert(u);
        return {detail::point_in_cell(hit.index, hit.offset, cdf.n), width_pdf(hit.width), hit.index};
    }
    ENVMIS_HD float pdf(float x) const noexcept { return cell_pdf(detail::cell_of(x, cdf.n)); }
    ENVMIS_HD float invert(float x) const noexcept {
        const uint32_t i = detail::cell_of(x, cdf.n);
        return cdf.at(i, detail::offset_in_cell(x, i, cdf.n));
    }
    ENVMIS_HD float cell_pdf(uint32_t i) const noexcept { return width_pdf(cdf.width(i)); }
    // The density of a cell `width` units wide.
    ENVMIS_HD float width_pdf(uint32_t width) const noexcept {
        return static_cast<float>(static_cast<double>(width) * cdf.n / kCdfUnits);
    }
};

// A piecewise-constant distribution over [0,1) with func.size() cells.
class Distribution1D {
public:
    Distribution1D() = default;
    // Throws std::invalid_argument if func is empty, has more than 65536 cells, or holds
    // a negative or non-finite value. An all-zero func gives the uniform distribution.
    explicit Distribution1D(std::span<const float> func);

    Distribution1DView view() const noexcept { return {{start_.data(), guide_.data(), size()}}; }
    Distribution1DView::Sample sample(float u) const noexcept { return view().sample(u); }
    float pdf(float x) const noexcept { return view().pdf(x); }
    float invert(float x) const noexcept { return view().invert(x); }

    uint32_t size() const noexcept { return static_cast<uint32_t>(start_.size()); }
    double integral() const noexcept { return integral_; }  // mean of the input func over [0,1)
    bool uniform_fallback() const noexcept { return uniform_; }

private:
    LargeVector<uint32_t> start_;
    LargeVector<uint16_t> guide_;
    double integral_ = 0;
    bool uniform_ = false;
};

// Non-owning view of a 2D distribution: a marginal CDF over rows, then one
// conditional CDF per row. Cell (x, y) covers [x/w, (x+1)/w) x [y/h, (y+1)/h).
struct Distribution2DView {
    const uint32_t* start = nullptr;  // w h, row-major: row y's CDF is start[y w, y w + w)
    const uint16_t* guide = nullptr;  // w h, likewise
    CdfView marginal;                 // over the h rows
    uint32_t w = 0, h = 0;
    float pdf_scale = 0;  // w h 2^-62: density per unit of the marginal times unit of a row
    // coarse_row_size() h, row-major, the rows' coarse guides (CdfView::coarse); optional
    // (null below kCoarseGuideMinBytes): samples are the same, only the host's prefetches
    // and hot rows' searches differ. Device code never reads it, so it need not be uploaded.
    const uint16_t* coarse = nullptr;

    struct Sample {
        Vec2 p;                 // continuous point in [0,1)^2
        float pdf = 0;          // density at p (measure: dx dy on [0,1)^2)
        uint32_t x = 0, y = 0;  // cell of p
    };

    ENVMIS_HD CdfView row(uint32_t y) const noexcept {
        const size_t offset = static_cast<size_t>(y) * w;
        return {start + offset, guide + offset, w,
                coarse ? coarse + static_cast<size_t>(y) * coarse_row_size() : nullptr};
    }
    ENVMIS_HD uint32_t coarse_row_size() const noexcept { return coarse_guide_size(w); }
    // u.y picks the row, u.x the column within it. `near_answer(first, last)` is told
    // the row-major indices y w + x of a few cells in a row, usually holding the one
    // sampled (see CdfView::invert), for the caller to prefetch their data.
    template <class Hint = NoHint>
    ENVMIS_HD ENVMIS_INLINE Sample sample(Vec2 u, Hint near_answer = {}) const noexcept {
        return sample_in_row(sample_row(u.y), u.x, near_answer);
    }
    // The first stage of sample: the row that u.y picks. The marginal is read by every
    // sample and stays in cache: its inversion prefetches nothing.
    ENVMIS_HD ENVMIS_INLINE CellHit sample_row(float uy) const noexcept { return marginal.invert<false>(uy); }
    // The second stage of sample: the column in row r (sample_row(u.y)) and the point.
    // Batch callers find many rows first and prefetch the columns' data meanwhile.
    template <class Hint = NoHint>
    ENVMIS_HD ENVMIS_INLINE Sample sample_in_row(CellHit r, float ux, Hint near_answer = {}) const noexcept {
        const size_t row_start = static_cast<size_t>(r.index) * w;
        const CdfView cdf = row(r.index);
        const auto near = [&](uint32_t first, uint32_t last) { near_answer(row_start + first, row_start + last); };
        const CellHit c = !row_is_hot(r.width)   ? cdf.invert(ux, near)
                          : search_from_coarse() ? cdf.invert_cached(ux)
                                                 : cdf.invert<false>(ux);
        const Vec2 p{detail::point_in_cell(c.index, c.offset, w), detail::point_in_cell(r.index, r.offset, h)};
        return {p, pdf_of(r.width, c.width), c.index, r.index};
    }
    // True where hot rows search from the coarse guide (CdfView::invert_cached): on the
    // host where there is one; its cache argument is the CPU's.
    ENVMIS_HD bool search_from_coarse() const noexcept {
#if defined(__CUDA_ARCH__)
        return false;
#else
        return coarse != nullptr;
#endif
    }
    // True if a row of row_width units of the marginal (marginal.width(y), or the
    // CellHit::width of sample_row) holds more than kHotRowFactor times the mean row's
    // units: its data stays in cache. The same as row_width > hot_row_units(), without a
    // division.
    ENVMIS_HD bool row_is_hot(uint32_t row_width) const noexcept {
        return uint64_t{row_width} * h > (uint64_t{kHotRowFactor} << 31);
    }
    ENVMIS_HD uint32_t hot_row_units() const noexcept {
        return static_cast<uint32_t>(min((uint64_t{kHotRowFactor} << 31) / h, uint64_t{kCdfUnits}));
    }
    ENVMIS_HD float pdf(Vec2 p) const noexcept {
        const uint32_t x = detail::cell_of(p.x, w), y = detail::cell_of(p.y, h);
        return pdf_of(marginal.width(y), row(y).width(x));
    }
    ENVMIS_HD Vec2 invert(Vec2 p) const noexcept {
        const uint32_t x = detail::cell_of(p.x, w), y = detail::cell_of(p.y, h);
        return {row(y).at(x, detail::offset_in_cell(p.x, x, w)), marginal.at(y, detail::offset_in_cell(p.y, y, h))};
    }
    // Density of a cell from its row's and its own fixed-point widths. In float: the
    // int-to-double conversions cost more than the whole rest of the product (measured),
    // and the two extra roundings leave it within 3 float ulps of the exact value.
    ENVMIS_HD float pdf_of(uint32_t row_width, uint32_t cell_width) const noexcept {
        return static_cast<float>(row_width) * static_cast<float>(cell_width) * pdf_scale;
    }
};

// A piecewise-constant distribution over [0,1)^2 from a w x h row-major function.
class Distribution2D {
public:
    // Fills `row` (w values) with the function on row y; called once per row, from
    // several threads at a time for different rows.
    using RowFunction = std::function<void(uint32_t y, std::span<float> row)>;
    // The same from `cells`, row y of the values given to the constructor that takes
    // them, read before the build overwrites them.
    using CellRowFunction = std::function<void(uint32_t y, std::span<const uint32_t> cells, std::span<float> row)>;

    Distribution2D() = default;
    // Throws std::invalid_argument on a size mismatch, w or h outside [1, 65536], or a
    // negative or non-finite value. An all-zero func gives the uniform distribution.
    // Rows are built in parallel on all cores; the result does not depend on the
    // number of threads.
    Distribution2D(std::span<const float> func, uint32_t w, uint32_t h);
    // The same from a function evaluated row by row, never held whole in memory.
    Distribution2D(uint32_t w, uint32_t h, const RowFunction& rows);
    // The same, building the start table in `cells` (w h values) and each row from its
    // previous contents: a caller with per-cell data to derive the function from (EnvMap:
    // luminance) needs no second w x h buffer.
    Distribution2D(uint32_t w, uint32_t h, LargeVector<uint32_t> cells, const CellRowFunction& rows);

    Distribution2DView view() const noexcept {
        return {start_.data(),
                guide_.data(),
                {marginal_start_.data(), marginal_guide_.data(), h_},
                w_,
                h_,
                static_cast<float>(uint64_t{w_} * h_) * 0x1p-62f,
                coarse_.empty() ? nullptr : coarse_.data()};
    }
    Distribution2DView::Sample sample(Vec2 u) const noexcept { return view().sample(u); }
    float pdf(Vec2 p) const noexcept { return view().pdf(p); }
    Vec2 invert(Vec2 p) const noexcept { return view().invert(p); }

    uint32_t width() const noexcept { return w_; }
    uint32_t height() const noexcept { return h_; }
    double integral() const noexcept { return integral_; }  // mean of the input func over [0,1)^2
    bool uniform_fallback() const noexcept { return uniform_; }
    size_t bytes() const noexcept {
        return (start_.size() + marginal_start_.size()) * sizeof(uint32_t) +
               (guide_.size() + marginal_guide_.size() + coarse_.size()) * sizeof(uint16_t);
    }

private:
    LargeVector<uint32_t> start_, marginal_start_;
    LargeVector<uint16_t> guide_, marginal_guide_, coarse_;
    uint32_t w_ = 0, h_ = 0;
    double integral_ = 0;
    bool uniform_ = false;
};

}  // namespace envmis
