#include "envmis/distribution.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "parallel.h"

namespace envmis {
namespace detail {

template <class T>
double build_cells(const T* func, uint32_t n, CdfCell* cells, uint32_t& invalid) noexcept {
    double sum = 0;
    for (uint32_t i = 0; i < n; ++i) {
        invalid += !(func[i] >= 0 && func[i] <= std::numeric_limits<T>::max());
        sum += func[i];
        cells[i].cdf = sum;
        cells[i].func = static_cast<float>(func[i]);
    }
    if (sum > 0) {
        const double inv = 1.0 / sum;
        for (uint32_t i = 0; i < n; ++i) cells[i].cdf *= inv;
    } else {
        for (uint32_t i = 0; i < n; ++i) cells[i].cdf = static_cast<double>(i + 1) / n;
    }
    // Rounding must not leave mass above the last cell: u < 1 always finds a cell.
    cells[n - 1].cdf = 1.0;
    uint32_t i = 0;
    for (uint32_t k = 0; k < n; ++k) {
        while (guide_bucket(cells[i].cdf, n) < k) ++i;
        cells[k].guide = i;
    }
    return sum;
}

template double build_cells<float>(const float*, uint32_t, CdfCell*, uint32_t&) noexcept;
template double build_cells<double>(const double*, uint32_t, CdfCell*, uint32_t&) noexcept;

}  // namespace detail

namespace {

constexpr size_t kMaxCells = size_t{1} << 31;

void check_invalid(size_t invalid, const char* what) {
    if (invalid)
        throw std::invalid_argument(std::string(what) + ": " + std::to_string(invalid) +
                                    " function values are negative, NaN or infinite");
}

}  // namespace

Distribution1D::Distribution1D(std::span<const float> func) {
    if (func.empty() || func.size() > kMaxCells)
        throw std::invalid_argument("Distribution1D: size must be in [1, 2^31], got " + std::to_string(func.size()));
    const auto n = static_cast<uint32_t>(func.size());
    cells_.resize(n);
    uint32_t invalid = 0;
    double sum = detail::build_cells(func.data(), n, cells_.data(), invalid);
    check_invalid(invalid, "Distribution1D");
    uniform_ = !(sum > 0);
    if (uniform_) {
        const std::vector<float> ones(n, 1.0f);
        sum = detail::build_cells(ones.data(), n, cells_.data(), invalid);
    }
    integral_ = uniform_ ? 0.0 : sum / n;
    inv_integral_ = n / sum;
}

Distribution2D::Distribution2D(std::span<const float> func, uint32_t w, uint32_t h) : w_(w), h_(h) {
    const size_t n = size_t{w} * h;
    if (w == 0 || h == 0 || n > kMaxCells)
        throw std::invalid_argument("Distribution2D: size " + std::to_string(w) + "x" + std::to_string(h) +
                                    " is empty or above 2^31 cells");
    if (func.size() != n)
        throw std::invalid_argument("Distribution2D: expected " + std::to_string(n) + " values for " +
                                    std::to_string(w) + "x" + std::to_string(h) + ", got " +
                                    std::to_string(func.size()));
    cells_.resize(n);
    marginal_.resize(h);
    std::vector<double> row_sums(h);
    std::vector<uint32_t> row_invalid(h);
    auto build_rows = [&](const float* source) {
        detail::parallel_for(h, 16, [&](uint32_t lo, uint32_t hi) {
            for (uint32_t y = lo; y < hi; ++y)
                row_sums[y] = detail::build_cells(source + size_t{y} * w, w, cells_.data() + size_t{y} * w,
                                                  row_invalid[y]);
        });
        uint32_t unused = 0;
        return detail::build_cells(row_sums.data(), h, marginal_.data(), unused);
    };
    double sum = build_rows(func.data());
    size_t invalid = 0;
    for (uint32_t c : row_invalid) invalid += c;
    check_invalid(invalid, "Distribution2D");
    uniform_ = !(sum > 0);
    if (uniform_) {
        const std::vector<float> ones(n, 1.0f);
        sum = build_rows(ones.data());
    }
    integral_ = uniform_ ? 0.0 : sum / static_cast<double>(n);
    inv_integral_ = static_cast<double>(n) / sum;
}

}  // namespace envmis
