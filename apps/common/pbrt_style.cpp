#include "pbrt_style.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace envmis::reference {
namespace {

// pbrt-v4's FindInterval: the last index i in [0, size - 2] with pred(i) true, by a
// binary search whose steps select rather than branch.
template <class Predicate>
size_t find_interval(size_t size, Predicate pred) noexcept {
    size_t first = 1, count = size - 2;
    while (count > 0) {
        const size_t half = count >> 1, middle = first + half;
        const bool below = pred(middle);
        first = below ? middle + 1 : first;
        count = below ? count - (half + 1) : half;
    }
    return std::clamp<size_t>(first - 1, 0, size - 2);
}

}  // namespace

PbrtPiecewise1D::PbrtPiecewise1D(std::vector<float> function)
    : function_(std::move(function)), cdf_(function_.size() + 1) {
    const size_t n = function_.size();
    for (float& f : function_) f = std::abs(f);
    cdf_[0] = 0;
    for (size_t i = 1; i <= n; ++i) cdf_[i] = cdf_[i - 1] + function_[i - 1] / static_cast<float>(n);
    integral_ = cdf_[n];
    for (size_t i = 1; i <= n; ++i)
        cdf_[i] = integral_ == 0 ? static_cast<float>(i) / static_cast<float>(n) : cdf_[i] / integral_;
}

float PbrtPiecewise1D::sample(float u, float* pdf, size_t* offset) const noexcept {
    const size_t o = find_interval(cdf_.size(), [&](size_t i) { return cdf_[i] <= u; });
    *offset = o;
    float du = u - cdf_[o];
    if (cdf_[o + 1] - cdf_[o] > 0) du /= cdf_[o + 1] - cdf_[o];
    *pdf = integral_ > 0 ? function_[o] / integral_ : 0;
    return (static_cast<float>(o) + du) / static_cast<float>(function_.size());
}

namespace {

std::vector<PbrtPiecewise1D> rows_of(const std::vector<float>& function, uint32_t w, uint32_t h) {
    std::vector<PbrtPiecewise1D> rows;
    rows.reserve(h);
    for (uint32_t y = 0; y < h; ++y)
        rows.emplace_back(std::vector<float>(function.begin() + size_t{y} * w, function.begin() + size_t{y + 1} * w));
    return rows;
}

std::vector<float> integrals_of(const std::vector<PbrtPiecewise1D>& rows) {
    std::vector<float> integrals;
    for (const PbrtPiecewise1D& row : rows) integrals.push_back(row.integral());
    return integrals;
}

}  // namespace

PbrtPiecewise2D::PbrtPiecewise2D(const std::vector<float>& function, uint32_t w, uint32_t h)
    : rows_(rows_of(function, w, h)), marginal_(integrals_of(rows_)) {}

Vec2 PbrtPiecewise2D::sample(Vec2 u, float* pdf) const noexcept {
    float row_pdf = 0, column_pdf = 0;
    size_t y = 0, x = 0;
    const float v = marginal_.sample(u.y, &row_pdf, &y);
    const float s = rows_[y].sample(u.x, &column_pdf, &x);
    *pdf = row_pdf * column_pdf;
    return {s, v};
}

float PbrtPiecewise2D::pdf(Vec2 p) const noexcept {
    const auto w = static_cast<int>(rows_[0].function().size()), h = static_cast<int>(rows_.size());
    const int x = std::clamp(static_cast<int>(p.x * static_cast<float>(w)), 0, w - 1);
    const int y = std::clamp(static_cast<int>(p.y * static_cast<float>(h)), 0, h - 1);
    return rows_[static_cast<size_t>(y)].function()[static_cast<size_t>(x)] / marginal_.integral();
}

size_t PbrtPiecewise2D::bytes() const noexcept {
    size_t total = marginal_.bytes();
    for (const PbrtPiecewise1D& row : rows_) total += row.bytes();
    return total;
}

Vec3 pbrt_square_to_sphere(Vec2 p) noexcept {
    const float u = 2 * p.x - 1, v = 2 * p.y - 1, au = std::abs(u), av = std::abs(v);
    const float signed_distance = 1 - (au + av), r = 1 - std::abs(signed_distance);
    const float phi = (r == 0 ? 1 : (av - au) / r + 1) * (kPiF / 4);
    const float z = std::copysign(1 - r * r, signed_distance);
    const float cos_phi = std::copysign(std::cos(phi), u), sin_phi = std::copysign(std::sin(phi), v);
    const float s = r * std::sqrt(std::max(0.0f, 2 - r * r));
    return {cos_phi * s, sin_phi * s, z};
}

Vec2 pbrt_sphere_to_square(Vec3 d) noexcept {
    const float x = std::abs(d.x), y = std::abs(d.y), z = std::abs(d.z);
    const float r = std::sqrt(std::max(0.0f, 1 - z));
    const float a = std::max(x, y), b = a == 0 ? 0 : std::min(x, y) / a;
    // 2/pi atan(b) on [0, 1], a least-squares fit on Chebyshev nodes (degree 7).
    float phi = 3.32057561e-2f;
    for (const float c : {-1.40949099e-1f, 2.00541169e-1f, -1.95594601e-2f, -2.09770820e-1f, -8.35136684e-5f,
                          6.36616196e-1f, 7.16282522e-8f})
        phi = phi * b + c;
    if (x < y) phi = 1 - phi;
    float v = phi * r, u = r - v;
    if (d.z < 0) {
        std::swap(u, v);
        u = 1 - u, v = 1 - v;
    }
    return {0.5f * (std::copysign(u, d.x) + 1), 0.5f * (std::copysign(v, d.y) + 1)};
}

namespace {

// pbrt-v4's sampling values: each texel's channel average, compensated as asked.
std::vector<float> sampling_values(const RgbImage& image, const EnvMapOptions& options) {
    if (options.mapping != Mapping::equal_area || image.width != image.height || image.width == 0)
        throw std::invalid_argument("the pbrt-style sampler takes a square equal-area map, got " +
                                    std::to_string(image.width) + "x" + std::to_string(image.height));
    std::vector<float> values(image.pixels.size());
    double sum = 0;
    for (size_t i = 0; i < values.size(); ++i) {
        const Rgb& p = image.pixels[i];
        values[i] = (p.r + p.g + p.b) / 3;
        sum += values[i];
    }
    if (!options.compensation.enabled) return values;
    const auto threshold = static_cast<float>(options.compensation.alpha * sum / static_cast<double>(values.size()));
    for (float& v : values) v = std::max(v - threshold, 0.0f);
    if (std::all_of(values.begin(), values.end(), [](float v) { return v == 0; }))
        std::fill(values.begin(), values.end(), 1.0f);
    return values;
}

}  // namespace

PbrtStyleEnvMap::PbrtStyleEnvMap(const RgbImage& image, const EnvMapOptions& options)
    : image_(&image), to_world_{}, distribution_(sampling_values(image, options), image.width, image.height) {
    for (int i = 0; i < 3; ++i) {
        const int code = options.axes.code[i];
        to_world_[i][std::abs(code) - 1] = code < 0 ? -1.0f : 1.0f;
    }
}

EnvSample PbrtStyleEnvMap::sample(Vec2 u) const noexcept {
    float map_pdf = 0;
    const Vec2 uv = distribution_.sample(u, &map_pdf);
    const Vec3 c = pbrt_square_to_sphere(uv);
    const float(&m)[3][3] = to_world_;
    const Vec3 world{m[0][0] * c.x + m[0][1] * c.y + m[0][2] * c.z, m[1][0] * c.x + m[1][1] * c.y + m[1][2] * c.z,
                     m[2][0] * c.x + m[2][1] * c.y + m[2][2] * c.z};
    const uint32_t n = image_->width;
    const uint32_t x = std::min(static_cast<uint32_t>(uv.x * static_cast<float>(n)), n - 1);
    const uint32_t y = std::min(static_cast<uint32_t>(uv.y * static_cast<float>(n)), n - 1);
    return {world, map_pdf / kFourPi, image_->pixels[size_t{y} * n + x], uv};
}

float PbrtStyleEnvMap::pdf(Vec3 w) const noexcept {
    const float(&m)[3][3] = to_world_;
    const Vec3 c{m[0][0] * w.x + m[1][0] * w.y + m[2][0] * w.z, m[0][1] * w.x + m[1][1] * w.y + m[2][1] * w.z,
                 m[0][2] * w.x + m[1][2] * w.y + m[2][2] * w.z};
    return distribution_.pdf(pbrt_sphere_to_square(c)) / kFourPi;
}

}  // namespace envmis::reference
