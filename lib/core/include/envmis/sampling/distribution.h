// Piecewise-constant distributions over [0,1) and [0,1)^2: the owning classes, which
// build the tables of cdf.h (the algorithm, its measure, precision and cost), and the
// views renderers sample through, which tune cdf.h's inversion for memory latency.
//
// The tuning, a layer over the plain search that never changes an answer: the CDF
// lines a sample will read are prefetched before the guide entry that names them
// arrives (CdfView::invert); a coarse guide, one uint16 entry per kCoarseGuideStep
// cells of a row (0.03 bytes a cell, built from kCoarseGuideMinBytes of tables on),
// predicts where in a row the answer lies; rows that draw many of the samples
// (kHotRowFactor) are searched from the coarse guide without prefetches. Samples,
// pdfs and inversions are bit-identical to cdf.h's plain ones (distribution_test), and
// apps/benchmarks times the two side by side (distribution/plain, distribution/tuned).
//
// sample preserves the stratification of its input and is exactly invertible
// (`invert(sample(u).p) == u` up to float rounding). Builds sum in double; p_i differs
// from f_i / sum f by at most one unit, 2^-31 = 4.7e-10. The owning classes throw on
// invalid input; their `view()` is a set of flat arrays with noexcept, allocation-free
// methods that also compile for CUDA: upload the arrays and use the same view there.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "envmis/core_export.h"
#include "envmis/large_vector.h"
#include "envmis/math/math.h"
#include "envmis/sampling/cdf.h"

namespace envmis {

// A row holding more than this many times the mean row's share of a 2D distribution
// draws so many of the samples that its data stays in cache: the samplers skip their
// prefetches in it, which take load slots there and save nothing. On small maps, whose
// rows hold many times more of the density each, a relative share keeps ordinary rows
// prefetched (measured: docs/performance-log.md, 'kHotRowFactor').
inline constexpr uint32_t kHotRowFactor = 64;

// One coarse guide entry per this many guide buckets of a 2D distribution's row: the
// guide entry of every 64th bucket, 1 MiB for an 8192 x 4096 map, small enough to stay
// in cache where the full guide (64 MiB) does not. A sample reads it to guess where in
// the row its answer lies before the guide entry, a cache miss, says so (see
// CdfView::invert), and in a hot row to skip the guide (CdfView::invert_cached).
// Built only where the tables (6 bytes a cell) reach kCoarseGuideMinBytes, about 2.8
// million cells and up: smaller ones stay in the last-level cache, where it has
// little to hide (measured: docs/performance-log.md, 'kCoarseGuideMinBytes').
inline constexpr uint32_t kCoarseGuideShift = 6, kCoarseGuideStep = 1u << kCoarseGuideShift;
inline constexpr size_t kCoarseGuideMinBytes = size_t{16} << 20;
// Coarse guide entries of a row of w cells (the last step may be shorter).
ENVMIS_HD inline uint32_t coarse_guide_size(uint32_t w) noexcept {
    return (w + kCoarseGuideStep - 1) / kCoarseGuideStep;
}

// The hint of CdfView::invert that does nothing.
struct NoHint {
    ENVMIS_HD void operator()(uint32_t, uint32_t) const noexcept {}
};

// One fixed-point CDF (cdf.h's CdfTable) with the tuning of its inversion for memory
// latency: the same answers as CdfTable::search (distribution_test), found with fewer
// waits on memory where the tables are beyond the cache.
struct CdfView : CdfTable {
    // Optional, ceil(n / kCoarseGuideStep): coarse[j] = guide[j kCoarseGuideStep]; only
    // read for prefetching (predicted_cell), never for the answer.
    const uint16_t* coarse = nullptr;

    // CdfTable::search's answer. Memory: a map beyond the cache misses on the guide entry, then on the CDF entry it
    // names, then on the caller's data for the cell found. Where the function is flat
    // the answer is near cell k of the guide bucket, so the CDF around k is prefetched
    // and `near_answer(k, k)` lets the caller prefetch its own: the three loads overlap
    // instead of waiting for each other. Real maps are not flat (the answer seldom lies
    // within a cell of k), so where a coarse guide is given, the cell it predicts and
    // its two neighbours are prefetched too. A caller that knows the data is in cache
    // passes kPrefetch = false: the prefetches would only take load slots (and see
    // invert_cached).
    //
    // The cells prefetched are tried first (find_near): where they hold the answer, the
    // guide's entry, a miss of its own, is not read at all (fewer instructions, and no
    // branch on the guide's answer). Where they do not, the guide's entry is already on
    // its way: prefetched too where the coarse guide sees no flat stretch (measured:
    // docs/performance-log.md, 'find_near').
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
    // nearest cache, where its guide spills into the next (measured:
    // docs/performance-log.md, 'invert_cached'). The same answer as invert.
    ENVMIS_HD ENVMIS_INLINE CellHit invert_cached(float u) const noexcept {
        const float x = unit_point(u) * static_cast<float>(kCdfUnits);
        const auto t = static_cast<uint32_t>(x);
        const uint32_t k = bucket_of_unit(t);
        const Span coarse = coarse_span(k);
        return find(coarse.hi - coarse.lo <= 1 ? coarse : guide_span(k), x, t);
    }

    // The first and last cell that may hold a unit of guide bucket k, from the coarse
    // guide (a wider span than guide_span's: the step's).
    ENVMIS_HD Span coarse_span(uint32_t k) const noexcept {
        const uint32_t j = k >> kCoarseGuideShift;
        return {coarse[j], (j + 1) * kCoarseGuideStep < n ? coarse[j + 1] : n - 1};
    }
    // The cell holding unit t if it is one of cells c - 1 to c + 1 (those in the CDF): the
    // last of them whose start is <= t, when the next cell's start is > t. False otherwise.
    ENVMIS_HD ENVMIS_INLINE bool find_near(uint32_t c, uint32_t t, uint32_t& cell) const noexcept {
        const uint32_t lo = c > 0 ? c - 1 : 0, hi = min(c + 1, n - 1);
        if (start[lo] > t || (hi + 1 < n && start[hi + 1] <= t)) return false;
        cell = lo + (lo < hi && start[lo + 1] <= t) + (lo + 1 < hi && start[lo + 2] <= t);
        return true;
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
        // p or a neighbour is the answer in most samples, and these three cells then hold
        // the lines the search and its caller read (a texel's 12 bytes may straddle two
        // lines; measured: docs/performance-log.md, 'prefetch_unit').
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
    // cell before where the CDF reaches that unit: hence the rounding, not truncation,
    // which predicts the answer itself more often (measured: docs/performance-log.md,
    // 'predicted_cell'). It lies in the span that holds the answer.
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
};

namespace detail {

// The uniform CDF over n cells: what build_cdf gives a function without a positive value.
struct ENVMIS_CORE_API UniformCdf {
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
ENVMIS_CORE_API double build_cdf(const T* func, uint32_t n, uint32_t* start, uint16_t* guide, uint32_t& invalid,
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
class ENVMIS_CORE_API Distribution1D {
public:
    Distribution1D() = default;
    // Throws std::invalid_argument if func is empty, has more than 65536 cells, or holds
    // a negative or non-finite value. An all-zero func gives the uniform distribution.
    explicit Distribution1D(std::span<const float> func);

    Distribution1DView view() const noexcept { return {{{start_.data(), guide_.data(), size()}}}; }
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

// Non-owning view of a 2D distribution (cdf.h's Cdf2DTable: its pdf and invert) whose
// sample is tuned for memory latency: the same samples as Cdf2DTable::search
// (distribution_test). Cell (x, y) covers [x/w, (x+1)/w) x [y/h, (y+1)/h).
struct Distribution2DView : Cdf2DTable {
    // coarse_row_size() h, row-major, the rows' coarse guides (CdfView::coarse); optional
    // (null below kCoarseGuideMinBytes): samples are the same, only the host's prefetches
    // and hot rows' searches differ. Device code never reads it, so it need not be uploaded.
    const uint16_t* coarse = nullptr;

    ENVMIS_HD CdfView row(uint32_t y) const noexcept {
        return {row_table(y), coarse ? coarse + static_cast<size_t>(y) * coarse_row_size() : nullptr};
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
    ENVMIS_HD ENVMIS_INLINE CellHit sample_row(float uy) const noexcept { return marginal.search(uy); }
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
};

// A piecewise-constant distribution over [0,1)^2 from a w x h row-major function.
class ENVMIS_CORE_API Distribution2D {
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
        return {{start_.data(),
                 guide_.data(),
                 {marginal_start_.data(), marginal_guide_.data(), h_},
                 w_,
                 h_,
                 static_cast<float>(uint64_t{w_} * h_) * 0x1p-62f},
                coarse_.empty() ? nullptr : coarse_.data()};
    }
    Distribution2DView::Sample sample(Vec2 u) const noexcept { return view().sample(u); }
    float pdf(Vec2 p) const noexcept { return view().pdf(p); }
    Vec2 invert(Vec2 p) const noexcept { return view().invert(p); }

    // The sizes, integral and fallback without the tables: for a holder that samples the
    // function through tables of its own (EnvMap::without_density); not to be sampled.
    Distribution2D without_tables() const {
        Distribution2D d;
        d.w_ = w_, d.h_ = h_, d.integral_ = integral_, d.uniform_ = uniform_;
        return d;
    }

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
