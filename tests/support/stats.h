// Test support: goodness-of-fit statistics and random numbers with fixed seeds.
//
// chi_square() pools cells expecting fewer than 5 samples (in cell order) so the
// chi-square approximation holds, and fails outright if a cell with zero expectation
// was sampled. Tests compare its p-value with a Sidak-corrected level, so that a whole
// family of tests has a 1e-4 chance of a false alarm on a correct build.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include "envmis/math/math.h"

namespace envmis::test {

// Uniform floats in [0,1) on the 2^-24 grid, from a fixed seed.
class Rng {
public:
    explicit Rng(uint64_t seed) : engine_(seed) {}
    float uniform() { return static_cast<float>(engine_() >> 40) * 0x1p-24f; }
    Vec2 uniform2() { return {uniform(), uniform()}; }
    std::mt19937_64& engine() { return engine_; }

private:
    std::mt19937_64 engine_;
};

// Upper regularised incomplete gamma Q(a, x) (series below a + 1, Lentz's continued fraction above).
inline double gamma_q(double a, double x) {
    if (x <= 0) return 1.0;
    const double log_prefix = -x + a * std::log(x) - std::lgamma(a);
    if (x < a + 1) {
        double term = 1.0 / a, sum = term;
        for (int n = 1; n < 10000 && std::abs(term) > std::abs(sum) * 1e-15; ++n) sum += term *= x / (a + n);
        return 1.0 - sum * std::exp(log_prefix);
    }
    const double tiny = 1e-300;
    double b = x + 1 - a, c = 1 / tiny, d = 1 / b, h = d;
    for (int i = 1; i < 10000; ++i) {
        const double an = -i * (i - a);
        b += 2;
        d = an * d + b;
        d = std::abs(d) < tiny ? tiny : d;
        c = b + an / c;
        c = std::abs(c) < tiny ? tiny : c;
        d = 1 / d;
        const double delta = d * c;
        h *= delta;
        if (std::abs(delta - 1) < 1e-15) break;
    }
    return std::exp(log_prefix) * h;
}

// Per-test level such that m independent tests have a family-wise false-alarm rate alpha.
inline double sidak_level(double alpha, int m) { return 1.0 - std::pow(1.0 - alpha, 1.0 / m); }

struct ChiSquare {
    double statistic = 0;
    int dof = 0;
    double p_value = 1;
    std::string problem;  // non-empty if a cell with zero expectation was sampled

    std::string describe() const {
        std::ostringstream s;
        s << "chi2=" << statistic << " dof=" << dof << " p=" << p_value << (problem.empty() ? "" : " " + problem);
        return s.str();
    }
};

// Pearson's test of observed counts against expected counts (same total).
inline ChiSquare chi_square(std::span<const double> expected, std::span<const double> observed) {
    ChiSquare r;
    std::vector<std::pair<double, double>> pools;
    double pool_e = 0, pool_o = 0;
    for (size_t i = 0; i < expected.size(); ++i) {
        if (expected[i] == 0 && observed[i] > 0) {
            r.problem =
                "cell " + std::to_string(i) + " has zero expectation but " + std::to_string(observed[i]) + " samples";
            r.p_value = 0;
            return r;
        }
        pool_e += expected[i], pool_o += observed[i];
        if (pool_e >= 5) pools.emplace_back(pool_e, pool_o), pool_e = pool_o = 0;
    }
    if (pool_e > 0 || pool_o > 0) {
        if (pools.empty()) pools.emplace_back(0, 0);
        pools.back().first += pool_e, pools.back().second += pool_o;
    }
    for (auto [e, o] : pools) r.statistic += (o - e) * (o - e) / e;
    r.dof = static_cast<int>(pools.size()) - 1;
    r.p_value = r.dof > 0 ? gamma_q(r.dof / 2.0, r.statistic / 2.0) : 1.0;
    return r;
}

// The equirect texel (of w x h) a canonical direction (z up) falls in, from the
// documented convention (mapping.h), in double.
inline size_t equirect_texel_of(Vec3 d, uint32_t w, uint32_t h) {
    const double theta = std::acos(std::clamp<double>(d.z, -1, 1));
    double phi = std::atan2(double{d.y}, double{d.x});
    if (phi < 0) phi += 2 * kPi;
    const auto x = std::min<uint32_t>(w - 1, static_cast<uint32_t>(phi / (2 * kPi) * w));
    const auto y = std::min<uint32_t>(h - 1, static_cast<uint32_t>(theta / kPi * h));
    return size_t{y} * w + x;
}

// Midpoint rule over the sphere on an nt x np grid in (theta, phi), z up: the integral
// of f(direction) d(omega), for checking that a solid-angle pdf integrates to 1.
template <class F>
double sphere_integral(uint32_t nt, uint32_t np, F&& f) {
    double integral = 0;
    for (uint32_t i = 0; i < nt; ++i) {
        const double theta = kPi * (i + 0.5) / nt;
        for (uint32_t j = 0; j < np; ++j) {
            const double phi = 2 * kPi * (j + 0.5) / np;
            const Vec3 d{static_cast<float>(std::sin(theta) * std::cos(phi)),
                         static_cast<float>(std::sin(theta) * std::sin(phi)), static_cast<float>(std::cos(theta))};
            integral += f(d) * std::sin(theta);
        }
    }
    return integral * (kPi / nt) * (2 * kPi / np);
}

}  // namespace envmis::test
