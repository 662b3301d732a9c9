#include "envmis/study/comparison/alpha.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <stdexcept>

#include "detail/parallel.h"
#include "envmis/build/env_map.h"
#include "envmis/study/reference/quadrature.h"

namespace envmis {
namespace {

// One halving step of downsample().
RgbImage halve(RgbImageView in, Mapping mapping) {
    const uint32_t w = in.width / 2, h = in.height / 2;
    std::vector<double> sin_theta(in.height, 1.0);
    if (mapping == Mapping::equirect)
        for (uint32_t y = 0; y < in.height; ++y) sin_theta[y] = std::sin(kPi * (y + 0.5) / in.height);
    RgbImage out{w, h, RgbPixels(size_t{w} * h)};
    detail::parallel_for(h, 8, [&](uint32_t lo, uint32_t hi) {
        for (uint32_t row = lo; row < hi; ++row) {
            const uint32_t y0 = 2 * row, y1 = row + 1 == h ? in.height : y0 + 2;
            for (uint32_t col = 0; col < w; ++col) {
                const uint32_t x0 = 2 * col, x1 = col + 1 == w ? in.width : x0 + 2;
                double r = 0, g = 0, b = 0, weight = 0;
                for (uint32_t y = y0; y < y1; ++y)
                    for (uint32_t x = x0; x < x1; ++x) {
                        Rgb p = in.at(x, y);
                        BadPixels ignored;
                        sanitize_pixel(p, ignored);
                        r += sin_theta[y] * p.r, g += sin_theta[y] * p.g, b += sin_theta[y] * p.b;
                        weight += sin_theta[y];
                    }
                out.pixels[size_t{row} * w + col] = {static_cast<float>(r / weight), static_cast<float>(g / weight),
                                                     static_cast<float>(b / weight)};
            }
        }
    });
    return out;
}

// Relative difference of criteria below which candidates tie.
constexpr double kTie = 1e-6;

bool can_halve(RgbImageView image, uint32_t max_width) {
    return image.width > max_width && image.width >= 2 && image.height >= 2;
}

// Sum of log(variance / baseline) over the valid pairs of each BSDF, and their count.
struct LogRatios {
    double sum = 0;
    size_t count = 0;
    double geometric_mean() const { return count ? std::exp(sum / static_cast<double>(count)) : 1.0; }
};

std::vector<LogRatios> log_ratios(std::span<const double> variances, std::span<const double> baseline, size_t bsdfs) {
    if (variances.size() != baseline.size() || bsdfs == 0 || variances.size() % bsdfs != 0)
        throw std::invalid_argument("geometric_mean_ratios: variances and baseline must both be BSDFs x points");
    const size_t points = variances.size() / bsdfs;
    std::vector<LogRatios> result(bsdfs);
    for (size_t b = 0; b < bsdfs; ++b)
        for (size_t p = 0; p < points; ++p) {
            const double v = variances[b * points + p], v0 = baseline[b * points + p];
            if (v > 0 && v0 > 0) result[b].sum += std::log(v / v0), ++result[b].count;
        }
    return result;
}

}  // namespace

RgbImage downsample(RgbImageView image, uint32_t max_width, Mapping mapping) {
    if (!can_halve(image, max_width)) return to_image(image);
    RgbImage small = halve(image, mapping);
    while (can_halve(small, max_width)) small = halve(small, mapping);
    return small;
}

std::vector<double> exact_variances(const EnvMap& env, Technique technique, Allocation allocation,
                                    std::span<const Bsdf> bsdfs, std::span<const ShadingPoint> points, int subdivisions,
                                    StopFlag stop) {
    std::vector<double> variances;
    variances.reserve(bsdfs.size() * points.size());
    for (const Bsdf& bsdf : bsdfs)
        for (const ShadingPoint& point : points)
            variances.push_back(exact_variance(env, technique, allocation, bsdf, point, subdivisions, stop));
    return variances;
}

std::vector<double> geometric_mean_ratios(std::span<const double> variances, std::span<const double> baseline,
                                          size_t bsdfs) {
    std::vector<double> means;
    for (const LogRatios& r : log_ratios(variances, baseline, bsdfs)) means.push_back(r.geometric_mean());
    return means;
}

AlphaChoice choose_alpha(RgbImageView radiance, const EnvMapOptions& map, const AlphaOptions& options) {
    const auto start = std::chrono::steady_clock::now();
    if (radiance.width == 0 || radiance.height == 0 || options.bsdfs.empty() || options.points.empty())
        throw std::invalid_argument("choose_alpha: needs a non-empty map, a BSDF and a shading point");
    std::vector<float> alphas = options.candidates;
    for (float a : alphas)
        if (!(a >= 0 && std::isfinite(a)))
            throw std::invalid_argument("choose_alpha: candidate alpha " + std::to_string(a) +
                                        " is not a finite number >= 0");
    alphas.push_back(0);
    std::sort(alphas.begin(), alphas.end());
    alphas.erase(std::unique(alphas.begin(), alphas.end()), alphas.end());

    const RgbImage small = downsample(radiance, options.max_width, map.mapping);
    EnvMapOptions plain_options = map;
    plain_options.compensation.enabled = false;
    const EnvMap plain = build_env_map(small, plain_options);
    const Technique balance = Technique::parse("mis-balance"), balance_comp = Technique::parse("mis-balance-comp");
    // One subdivision: texels are constant, and the ratio only ranks candidates.
    const std::vector<double> baseline =
        exact_variances(plain, balance, options.allocation, options.bsdfs, options.points, 1);

    AlphaChoice choice{{}, 0, {}, small.width, small.height};
    for (float alpha : alphas) {
        EnvMapOptions compensated_options = map;
        compensated_options.compensation = {true, alpha};
        const EnvMap compensated = build_env_map(small, compensated_options);
        const std::vector<LogRatios> logs =
            log_ratios(exact_variances(compensated, balance_comp, options.allocation, options.bsdfs, options.points, 1),
                       baseline, options.bsdfs.size());
        AlphaCandidate candidate{alpha, 1, {}};
        LogRatios all;
        for (const LogRatios& r : logs) {
            candidate.per_bsdf.push_back(r.geometric_mean());
            all.sum += r.sum, all.count += r.count;
        }
        candidate.criterion = all.geometric_mean();
        choice.candidates.push_back(std::move(candidate));
    }
    // Candidates ascend, and a stronger one wins only by more than rounding: a tie (a
    // constant map, whose compensated densities all equal the plain one up to float
    // rounding) goes to the weaker compensation.
    auto lowest = [&](auto&& criterion) {
        const AlphaCandidate* best = &choice.candidates.front();
        for (const AlphaCandidate& c : choice.candidates)
            if (criterion(c) < criterion(*best) * (1 - kTie)) best = &c;
        return best->alpha;
    };
    for (size_t b = 0; b < options.bsdfs.size(); ++b)
        choice.bsdf_alphas.push_back(lowest([b](const AlphaCandidate& c) { return c.per_bsdf[b]; }));
    choice.alpha = lowest([](const AlphaCandidate& c) { return c.criterion; });
    choice.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return choice;
}

}  // namespace envmis
