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

// Sum with four accumulators: a single chain of dependent double adds would bound a
// row's build by add latency rather than memory.
template <class T>
double sum_of(const T* v, uint32_t n) noexcept {
    double s[4] = {0, 0, 0, 0};
    uint32_t i = 0;
    for (; i + 4 <= n; i += 4)
        for (int j = 0; j < 4; ++j) s[j] += v[i + j];
    for (; i < n; ++i) s[0] += v[i];
    return (s[0] + s[1]) + (s[2] + s[3]);
}

template <class T>
double build_cdf(const T* func, uint32_t n, uint32_t* start, uint16_t* guide, uint32_t& invalid) noexcept {
    uint32_t nonzero = 0, bad = 0;
    for (uint32_t i = 0; i < n; ++i) {
        bad += !(func[i] >= 0 && func[i] <= std::numeric_limits<T>::max());
        nonzero += func[i] > 0;
    }
    invalid += bad;
    const double sum = bad ? 0.0 : sum_of(func, n);
    if (sum > 0) {
        // Each non-empty cell ends at its rounded prefix sum, but takes at least one unit
        // and leaves at least one for every non-empty cell after it; this also keeps the
        // CDF monotone whatever the rounding.
        const double scale = kCdfUnits / sum;
        double prefix = 0;
        uint64_t s = 0;
        for (uint32_t i = 0; i < n; ++i) {
            start[i] = static_cast<uint32_t>(s);
            if (func[i] > 0) {
                prefix += func[i];
                --nonzero;
                const auto end = static_cast<uint64_t>(prefix * scale + 0.5);
                s = std::clamp<uint64_t>(end, s + 1, kCdfUnits - nonzero);
            }
        }
    } else {
        for (uint32_t i = 0; i < n; ++i) start[i] = static_cast<uint32_t>(uint64_t{i} * kCdfUnits / n);
    }
    // guide[k]: the cell of the first unit of bucket k, ceil(k 2^31 / n), stepped without
    // a division per bucket.
    const uint64_t step = kCdfUnits / n, step_remainder = kCdfUnits % n;
    uint64_t first_floor = 0, remainder = 0;
    uint32_t i = 0;
    for (uint32_t k = 0; k < n; ++k) {
        const uint64_t first = first_floor + (remainder > 0);
        while (i + 1 < n && start[i + 1] <= first) ++i;
        guide[k] = static_cast<uint16_t>(i);
        first_floor += step, remainder += step_remainder;
        if (remainder >= n) ++first_floor, remainder -= n;
    }
    return sum;
}

template double build_cdf<float>(const float*, uint32_t, uint32_t*, uint16_t*, uint32_t&) noexcept;
template double build_cdf<double>(const double*, uint32_t, uint32_t*, uint16_t*, uint32_t&) noexcept;

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
    const double sum = detail::build_cdf(func.data(), n, start_.data(), guide_.data(), invalid);
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
            for (uint32_t y = lo; y < hi; ++y) {
                rows(y, row);
                const size_t offset = size_t{y} * w;
                row_sums[y] = detail::build_cdf(row.data(), w, start_.data() + offset, guide_.data() + offset, row_invalid[y]);
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
    const double sum = detail::build_cdf(row_sums.data(), h, marginal_start_.data(), marginal_guide_.data(), unused);
    uniform_ = !(sum > 0);
    integral_ = sum / static_cast<double>(n);
}

}  // namespace envmis
