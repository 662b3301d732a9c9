#include "envmis/study/reference/textbook.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace envmis {
namespace {

// Fills cdf[0, n] (cdf[0] = 0, cdf[n] = 1) from func[0, n); returns the float sum.
float build_cdf(const float* func, uint32_t n, float* cdf) {
    cdf[0] = 0;
    for (uint32_t i = 0; i < n; ++i) cdf[i + 1] = cdf[i] + func[i];
    const float sum = cdf[n];
    for (uint32_t i = 1; i <= n; ++i) cdf[i] = sum > 0 ? cdf[i] / sum : static_cast<float>(i) / n;
    return sum;
}

struct Hit {
    uint32_t index;
    float offset;
};

// Classic inversion: the last CDF entry <= u, found by binary search.
Hit invert_cdf(const float* cdf, uint32_t n, float u) {
    const auto it = std::upper_bound(cdf, cdf + n + 1, u);
    const auto i = static_cast<uint32_t>(clamp<std::ptrdiff_t>(it - cdf - 1, 0, n - 1));
    const float width = cdf[i + 1] - cdf[i];
    const float offset = width > 0 ? (u - cdf[i]) / width : 0.0f;
    return {i, clamp(offset, 0.0f, kOneMinusEpsilon)};
}

}  // namespace

TextbookDistribution2D::TextbookDistribution2D(std::span<const float> func, uint32_t w, uint32_t h)
    : func_(func.begin(), func.end()), w_(w), h_(h) {
    const size_t n = size_t{w} * h;
    if (w == 0 || h == 0 || w > kMaxCells1D || h > kMaxCells1D || func.size() != n)
        throw std::invalid_argument("TextbookDistribution2D: " + std::to_string(func.size()) + " values for a " +
                                    std::to_string(w) + "x" + std::to_string(h) + " grid");
    if (std::any_of(func.begin(), func.end(), [](float f) { return !(f >= 0 && std::isfinite(f)); }))
        throw std::invalid_argument("TextbookDistribution2D: negative, NaN or infinite function values");
    uniform_ = std::all_of(func.begin(), func.end(), [](float f) { return f == 0; });
    if (uniform_) std::fill(func_.begin(), func_.end(), 1.0f);
    cdf_.resize(size_t{h} * (w + 1));
    std::vector<float> row_sums(h);
    for (uint32_t y = 0; y < h; ++y)
        row_sums[y] = build_cdf(func_.data() + size_t{y} * w, w, cdf_.data() + size_t{y} * (w + 1));
    marginal_cdf_.resize(h + 1);
    const float sum = build_cdf(row_sums.data(), h, marginal_cdf_.data());
    integral_ = uniform_ ? 0.0 : static_cast<double>(sum) / static_cast<double>(n);
    inv_integral_ = static_cast<float>(static_cast<double>(n) / sum);
}

TextbookDistribution2D::Sample TextbookDistribution2D::sample(Vec2 u) const noexcept {
    const Hit row = invert_cdf(marginal_cdf_.data(), h_, u.y);
    const Hit col = invert_cdf(cdf_.data() + size_t{row.index} * (w_ + 1), w_, u.x);
    const Vec2 p{detail::point_in_cell(col.index, col.offset, w_), detail::point_in_cell(row.index, row.offset, h_)};
    return {p, func_[size_t{row.index} * w_ + col.index] * inv_integral_, col.index, row.index};
}

float TextbookDistribution2D::pdf(Vec2 p) const noexcept {
    return func_[size_t{detail::cell_of(p.y, h_)} * w_ + detail::cell_of(p.x, w_)] * inv_integral_;
}

Vec2 TextbookDistribution2D::invert(Vec2 p) const noexcept {
    const uint32_t x = detail::cell_of(p.x, w_), y = detail::cell_of(p.y, h_);
    const float* row = cdf_.data() + size_t{y} * (w_ + 1);
    const float ox = detail::offset_in_cell(p.x, x, w_), oy = detail::offset_in_cell(p.y, y, h_);
    return {clamp(row[x] + ox * (row[x + 1] - row[x]), 0.0f, kOneMinusEpsilon),
            clamp(marginal_cdf_[y] + oy * (marginal_cdf_[y + 1] - marginal_cdf_[y]), 0.0f, kOneMinusEpsilon)};
}

}  // namespace envmis
