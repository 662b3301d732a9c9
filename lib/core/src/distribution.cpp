#include "envmis/distribution.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include "parallel.h"

namespace envmis {
namespace detail {

// First guide bucket whose first unit, ceil(k 2^31 / n), is at or after unit t.
inline int64_t first_bucket_at_or_after(int64_t t, uint32_t n) noexcept { return (((t - 1) * n) >> 31) + 1; }

struct Census {
    uint32_t nonzero = 0, invalid = 0;  // positive finite values; negative, NaN or infinite ones
};

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
// finite floats are the integers in (0, +Inf's bits); -0 counts as a valid zero.
template <>
Census census(const float* func, uint32_t n) noexcept {
    constexpr int32_t kInfBits = 0x7f800000;
    const auto* bits = reinterpret_cast<const int32_t*>(func);
    Census c;
    for (uint32_t i = 0; i < n; ++i) {
        const int32_t magnitude = bits[i] & 0x7fffffff;
        c.invalid += (magnitude >= kInfBits) | ((bits[i] < 0) & (magnitude != 0));
        c.nonzero += (bits[i] > 0) & (bits[i] < kInfBits);
    }
    return c;
}

template <class T>
double build_cdf(const T* func, uint32_t n, uint32_t* start, uint16_t* guide, uint32_t& invalid,
                 double* scratch) noexcept {
    const Census counts = census(func, n);
    uint32_t nonzero = counts.nonzero;
    const uint32_t bad = counts.invalid;
    invalid += bad;

    // Prefix sums in four independent chains (quarters of the row, the last one taking
    // the remainder), so that the latency of dependent double adds does not bound the build.
    constexpr uint32_t kChains = 4;
    const uint32_t q = n / kChains;
    double* prefix = scratch;
    double chain[kChains] = {0, 0, 0, 0};
    for (uint32_t i = 0; i < q; ++i)
        for (uint32_t c = 0; c < kChains; ++c) prefix[c * q + i] = chain[c] += func[c * q + i];
    for (uint32_t i = kChains * q; i < n; ++i) prefix[i] = chain[kChains - 1] += func[i];
    const double sum = bad ? 0.0 : (chain[0] + chain[1]) + (chain[2] + chain[3]);

    if (sum > 0) {
        // A non-empty cell ends at its rounded prefix sum, but takes at least one unit and
        // leaves one for every non-empty cell after it; this also keeps the CDF monotone
        // whatever the rounding. Written without branches: zeros and non-zeros mix freely.
        const double scale = kCdfUnits / sum;
        uint64_t s = 0;
        double offset = 0;
        for (uint32_t c = 0; c < kChains; ++c) {
            const uint32_t end_index = c + 1 < kChains ? (c + 1) * q : n;
            for (uint32_t i = c * q; i < end_index; ++i) {
                start[i] = static_cast<uint32_t>(s);
                const bool filled = func[i] > 0;
                nonzero -= filled;
                const auto end = static_cast<uint64_t>((offset + prefix[i]) * scale + 0.5);
                const uint64_t clamped = std::clamp<uint64_t>(end, s + 1, kCdfUnits - nonzero);
                s = filled ? clamped : s;
            }
            offset += chain[c];
        }
    } else {
        // Uniform: equal cells, the last one taking the remainder.
        const uint32_t step = kCdfUnits / n;
        for (uint32_t i = 0; i < n; ++i) start[i] = i * step;
    }
    // guide[k] is the last cell starting at or before bucket k's first unit: mark each
    // bucket with the last cell whose start falls just before it, then carry the maximum
    // forward. Cells past the last bucket mark the spare slot n.
    auto* mark = reinterpret_cast<uint32_t*>(scratch);
    std::fill(mark, mark + n + 1, 0u);
    for (uint32_t i = 0; i < n; ++i) mark[first_bucket_at_or_after(start[i], n)] = i;
    uint32_t last = 0;
    for (uint32_t k = 0; k < n; ++k) guide[k] = static_cast<uint16_t>(last = std::max(last, mark[k]));
    return sum;
}

template double build_cdf<float>(const float*, uint32_t, uint32_t*, uint16_t*, uint32_t&, double*) noexcept;
template double build_cdf<double>(const double*, uint32_t, uint32_t*, uint16_t*, uint32_t&, double*) noexcept;

}  // namespace detail

namespace {

void check_size(const char* what, uint32_t n) {
    if (n == 0 || n > kMaxCells1D)
        throw std::invalid_argument(std::string(what) + ": " + std::to_string(n) + " cells per dimension, expected 1 to " +
                                    std::to_string(kMaxCells1D));
}

void check_invalid(size_t invalid, const char* what) {
    if (invalid)
        throw std::invalid_argument(std::string(what) + ": " + std::to_string(invalid) +
                                    " function values are negative, NaN or infinite");
}

Distribution2D::RowFunction copy_rows(std::span<const float> func, uint32_t w, uint32_t h) {
    if (func.size() != size_t{w} * h)
        throw std::invalid_argument("Distribution2D: expected " + std::to_string(size_t{w} * h) + " values for " +
                                    std::to_string(w) + "x" + std::to_string(h) + ", got " + std::to_string(func.size()));
    return [func, w](uint32_t y, std::span<float> row) { std::copy_n(func.data() + size_t{y} * w, w, row.data()); };
}

}  // namespace

Distribution1D::Distribution1D(std::span<const float> func) {
    check_size("Distribution1D", static_cast<uint32_t>(std::min<size_t>(func.size(), kMaxCells1D + size_t{1})));
    const auto n = static_cast<uint32_t>(func.size());
    start_.resize(n);
    guide_.resize(n);
    uint32_t invalid = 0;
    std::vector<double> prefix(n);
    const double sum = detail::build_cdf(func.data(), n, start_.data(), guide_.data(), invalid, prefix.data());
    check_invalid(invalid, "Distribution1D");
    uniform_ = !(sum > 0);
    integral_ = sum / n;
}

Distribution2D::Distribution2D(std::span<const float> func, uint32_t w, uint32_t h)
    : Distribution2D(w, h, copy_rows(func, w, h)) {}

Distribution2D::Distribution2D(uint32_t w, uint32_t h, const RowFunction& rows) : w_(w), h_(h) {
    check_size("Distribution2D width", w);
    check_size("Distribution2D height", h);
    const size_t n = size_t{w} * h;
    start_.resize(n);
    guide_.resize(n);
    marginal_start_.resize(h);
    marginal_guide_.resize(h);
    std::vector<double> row_sums(h);
    std::vector<uint32_t> row_invalid(h, 0);
    // A row function may throw; the first exception is rethrown here, after all threads end.
    std::exception_ptr error;
    std::mutex error_mutex;
    detail::parallel_for(h, 16, [&](uint32_t lo, uint32_t hi) {
        try {
            std::vector<float> row(w);
            std::vector<double> prefix(w);
            for (uint32_t y = lo; y < hi; ++y) {
                rows(y, row);
                const size_t offset = size_t{y} * w;
                row_sums[y] = detail::build_cdf(row.data(), w, start_.data() + offset, guide_.data() + offset,
                                                row_invalid[y], prefix.data());
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
    std::vector<double> prefix(h);
    const double sum =
        detail::build_cdf(row_sums.data(), h, marginal_start_.data(), marginal_guide_.data(), unused, prefix.data());
    uniform_ = !(sum > 0);
    integral_ = sum / static_cast<double>(n);
}

}  // namespace envmis
