#include "envmis/sampling/distribution.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <exception>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "detail/parallel.h"

namespace envmis {
namespace detail {

// First guide bucket whose first unit, ceil(k 2^31 / n), is at or after unit t.
inline int64_t first_bucket_at_or_after(int64_t t, uint32_t n) noexcept { return (((t - 1) * n) >> 31) + 1; }

struct Census {
    uint32_t nonzero = 0, invalid = 0;  // positive finite values; negative, NaN or infinite ones
};

// True if every value is +0, as in the rows that compensation zeroes whole: ORs over
// their bits settle them faster than a census, in blocks so that other rows stop early.
template <class T>
bool all_positive_zero(const T* func, uint32_t n) noexcept {
    using Bits = std::conditional_t<sizeof(T) == sizeof(uint32_t), uint32_t, uint64_t>;
    constexpr uint32_t kBlock = 256;
    for (uint32_t lo = 0; lo < n; lo += kBlock) {
        Bits any = 0;
        for (uint32_t i = lo, hi = std::min(n, lo + kBlock); i < hi; ++i) any |= std::bit_cast<Bits>(func[i]);
        if (any) return false;
    }
    return true;
}

template <class T>
Census census(const T* func, uint32_t n) noexcept {
    Census c;
    for (uint32_t i = 0; i < n; ++i) {
        c.invalid += (func[i] < 0) | !(func[i] <= std::numeric_limits<T>::max());
        c.nonzero += func[i] > 0;
    }
    return c;
}

// The same on the bits of each float, in integer operations that vectorise: positive
// finite floats are the integers in (0, +Inf's bits), zeros of either sign those whose
// bits shifted left by one are 0, and every other value is invalid.
template <>
Census census(const float* func, uint32_t n) noexcept {
    constexpr int32_t kInfBits = 0x7f800000;
    uint32_t zeros = 0, nonzero = 0;
    for (uint32_t i = 0; i < n; ++i) {
        const auto bits = std::bit_cast<int32_t>(func[i]);
        nonzero += (bits > 0) & (bits < kInfBits);
        zeros += (std::bit_cast<uint32_t>(bits) << 1) == 0;
    }
    return {nonzero, n - nonzero - zeros};
}

namespace {

// guide[k] = max(marks[0..k]). With SSE2, eight entries at a time: the running maximum
// within a vector in three shifted steps, then with the carry from the vectors before.
// SSE2 has no unsigned 16-bit maximum: max(a, b) = (a - b, saturated at 0) + b.
void carry_maximum(const uint16_t* marks, uint32_t n, uint16_t* guide) noexcept {
    uint16_t last = 0;
    uint32_t k = 0;
#if defined(__SSE2__)
    const auto max = [](__m128i a, __m128i b) { return _mm_add_epi16(_mm_subs_epu16(a, b), b); };
    __m128i carry = _mm_setzero_si128();
    for (; k + 8 <= n; k += 8) {
        __m128i m = _mm_loadu_si128(reinterpret_cast<const __m128i*>(marks + k));
        m = max(m, _mm_slli_si128(m, 2));
        m = max(m, _mm_slli_si128(m, 4));
        m = max(m, _mm_slli_si128(m, 8));
        m = max(m, carry);
        _mm_storeu_si128(reinterpret_cast<__m128i*>(guide + k), m);
        carry = _mm_shuffle_epi32(_mm_shufflehi_epi16(m, 0xff), 0xff);
    }
    last = static_cast<uint16_t>(_mm_cvtsi128_si32(carry));
#endif
    for (; k < n; ++k) guide[k] = last = std::max(last, marks[k]);
}

// Writes the starts of the cells, in order, and the guide table that goes with them.
// guide[k] is the last cell starting at or before bucket k's first unit: each cell marks
// the bucket that starts just after it (the last such cell wins; cells past the last
// bucket mark the spare slot n), and carrying the maximum forward fills the buckets no
// cell marked.
class CellPlacer {
public:
    CellPlacer(uint32_t n, uint32_t* start, uint16_t* marks) noexcept : n_(n), start_(start), marks_(marks) {
        std::fill_n(marks, n + 1, uint16_t{0});
    }
    void operator()(uint32_t i, int64_t s) const noexcept {
        start_[i] = static_cast<uint32_t>(s);
        marks_[first_bucket_at_or_after(s, n_)] = static_cast<uint16_t>(i);
    }
    void finish(uint16_t* guide) const noexcept { carry_maximum(marks_, n_, guide); }

private:
    uint32_t n_;
    uint32_t* start_;
    uint16_t* marks_;
};

// Equal cells, the last one taking the remainder.
void uniform_cdf(uint32_t n, uint32_t* start, uint16_t* guide, uint16_t* marks) noexcept {
    const CellPlacer place(n, start, marks);
    const uint32_t step = kCdfUnits / n;
    for (uint32_t i = 0; i < n; ++i) place(i, int64_t{i} * step);
    place.finish(guide);
}

}  // namespace

UniformCdf::UniformCdf(uint32_t n) : start(n), guide(n) {
    std::vector<uint16_t> marks(size_t{n} + 1);
    uniform_cdf(n, start.data(), guide.data(), marks.data());
}

template <class T>
double build_cdf(const T* func, uint32_t n, uint32_t* start, uint16_t* guide, uint32_t& invalid,
                 CdfScratch& scratch) noexcept {
    const Census counts = all_positive_zero(func, n) ? Census{} : census(func, n);
    invalid += counts.invalid;

    // Prefix sums in four independent chains (quarters of the row, the last one taking
    // the remainder), so that the latency of dependent double adds does not bound the build.
    // A function without a positive value sums to 0 and needs none.
    constexpr uint32_t kChains = 4;
    const uint32_t q = n / kChains;
    double* prefix = scratch.prefix.data();
    double chain[kChains] = {0, 0, 0, 0};
    double sum = 0;
    if (counts.nonzero && !counts.invalid) {
        for (uint32_t i = 0; i < q; ++i)
            for (uint32_t c = 0; c < kChains; ++c) prefix[c * q + i] = chain[c] += func[c * q + i];
        for (uint32_t i = kChains * q; i < n; ++i) prefix[i] = chain[kChains - 1] += func[i];
        sum = (chain[0] + chain[1]) + (chain[2] + chain[3]);
    }
    if (!(sum > 0)) {
        if (scratch.uniform) {
            std::copy_n(scratch.uniform->start.data(), n, start);
            std::copy_n(scratch.uniform->guide.data(), n, guide);
        } else {
            uniform_cdf(n, start, guide, scratch.marks.data());
        }
        return sum;
    }

    // A non-empty cell ends at its rounded prefix sum, but takes at least one unit and
    // leaves one for every non-empty cell after it; this also keeps the CDF monotone
    // whatever the rounding. That is end' = clamp(end, s + 1, units - later) for the cell
    // starting at s; counted relative to `filled`, the non-empty cells so far, both bounds
    // become constant and the recurrence a running maximum of end - filled, capped at
    // units - nonzero: the loop carries no branch and only a short dependency chain. An
    // empty cell repeats the previous end, so it may join the maximum unmasked.
    const CellPlacer place(n, start, scratch.marks.data());
    const double scale = kCdfUnits / sum;
    const int64_t room = int64_t{kCdfUnits} - counts.nonzero;
    int64_t filled = 0, reach = 0;
    double offset = 0;
    for (uint32_t c = 0; c < kChains; ++c) {
        const uint32_t end_index = c + 1 < kChains ? (c + 1) * q : n;
        for (uint32_t i = c * q; i < end_index; ++i) {
            place(i, filled + std::min(reach, room));
            filled += func[i] > 0;
            const auto end = static_cast<int64_t>((offset + prefix[i]) * scale + 0.5);
            reach = std::max(reach, end - filled);
        }
        offset += chain[c];
    }
    place.finish(guide);
    return sum;
}

template double build_cdf<float>(const float*, uint32_t, uint32_t*, uint16_t*, uint32_t&, CdfScratch&) noexcept;
template double build_cdf<double>(const double*, uint32_t, uint32_t*, uint16_t*, uint32_t&, CdfScratch&) noexcept;

}  // namespace detail

namespace {

void check_size(const char* what, uint32_t n) {
    if (n == 0 || n > kMaxCells1D)
        throw std::invalid_argument(std::string(what) + ": " + std::to_string(n) +
                                    " cells per dimension, expected 1 to " + std::to_string(kMaxCells1D));
}

// Rows per task of the parallel build: enough to amortise a task's scratch rows.
constexpr uint32_t kRowsPerChunk = 8;

size_t cell_count(uint32_t w, uint32_t h) {
    check_size("Distribution2D width", w);
    check_size("Distribution2D height", h);
    return size_t{w} * h;
}

void check_invalid(size_t invalid, const char* what) {
    if (invalid)
        throw std::invalid_argument(std::string(what) + ": " + std::to_string(invalid) +
                                    " function values are negative, NaN or infinite");
}

Distribution2D::RowFunction copy_rows(std::span<const float> func, uint32_t w, uint32_t h) {
    if (func.size() != size_t{w} * h)
        throw std::invalid_argument("Distribution2D: expected " + std::to_string(size_t{w} * h) + " values for " +
                                    std::to_string(w) + "x" + std::to_string(h) + ", got " +
                                    std::to_string(func.size()));
    return [func, w](uint32_t y, std::span<float> row) { std::copy_n(func.data() + size_t{y} * w, w, row.data()); };
}

}  // namespace

Distribution1D::Distribution1D(std::span<const float> func) {
    check_size("Distribution1D", static_cast<uint32_t>(std::min<size_t>(func.size(), kMaxCells1D + size_t{1})));
    const auto n = static_cast<uint32_t>(func.size());
    start_.resize(n);
    guide_.resize(n);
    uint32_t invalid = 0;
    detail::CdfScratch scratch(n);
    const double sum = detail::build_cdf(func.data(), n, start_.data(), guide_.data(), invalid, scratch);
    check_invalid(invalid, "Distribution1D");
    uniform_ = !(sum > 0);
    integral_ = sum / n;
}

Distribution2D::Distribution2D(std::span<const float> func, uint32_t w, uint32_t h)
    : Distribution2D(w, h, copy_rows(func, w, h)) {}

Distribution2D::Distribution2D(uint32_t w, uint32_t h, const RowFunction& rows)
    : Distribution2D(w, h, LargeVector<uint32_t>(cell_count(w, h)),
                     [&rows](uint32_t y, std::span<const uint32_t>, std::span<float> row) { rows(y, row); }) {}

Distribution2D::Distribution2D(uint32_t w, uint32_t h, LargeVector<uint32_t> cells, const CellRowFunction& rows)
    : start_(std::move(cells)), w_(w), h_(h) {
    const size_t n = cell_count(w, h);
    if (start_.size() != n)
        throw std::invalid_argument("Distribution2D: " + std::to_string(start_.size()) + " cells for " +
                                    std::to_string(w) + "x" + std::to_string(h));
    guide_.resize(n);
    const uint32_t coarse_row = n * 6 >= kCoarseGuideMinBytes ? coarse_guide_size(w) : 0;
    coarse_.resize(size_t{coarse_row} * h);
    marginal_start_.resize(h);
    marginal_guide_.resize(h);
    std::vector<double> row_sums(h);
    std::vector<uint32_t> row_invalid(h, 0);
    // A row function may throw; the first exception is rethrown here, after all threads end.
    std::exception_ptr error;
    std::mutex error_mutex;
    const detail::UniformCdf uniform(w);
    detail::parallel_for(h, kRowsPerChunk, [&](uint32_t lo, uint32_t hi) {
        try {
            std::vector<float> row(w);
            detail::CdfScratch scratch(w, &uniform);
            for (uint32_t y = lo; y < hi; ++y) {
                const size_t offset = size_t{y} * w;
                rows(y, std::span(start_).subspan(offset, w), row);
                row_sums[y] = detail::build_cdf(row.data(), w, start_.data() + offset, guide_.data() + offset,
                                                row_invalid[y], scratch);
                for (uint32_t j = 0; j < coarse_row; ++j)
                    coarse_[size_t{y} * coarse_row + j] = guide_[offset + size_t{j} * kCoarseGuideStep];
            }
        } catch (...) {
            const std::lock_guard lock(error_mutex);
            if (!error) error = std::current_exception();
        }
    });
    if (error) std::rethrow_exception(error);
    size_t invalid = 0;
    for (uint32_t c : row_invalid) invalid += c;
    check_invalid(invalid, "Distribution2D");
    uint32_t unused = 0;
    detail::CdfScratch scratch(h);
    const double sum =
        detail::build_cdf(row_sums.data(), h, marginal_start_.data(), marginal_guide_.data(), unused, scratch);
    uniform_ = !(sum > 0);
    integral_ = sum / static_cast<double>(n);
}

}  // namespace envmis
