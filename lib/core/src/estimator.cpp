#include "envmis/estimator.h"

#include <cmath>
#include <stdexcept>

#include "envmis/frame.h"

namespace envmis {
namespace {

Rgb operator*(Rgb a, Rgb b) noexcept { return {a.r * b.r, a.g * b.g, a.b * b.b}; }
void add(Rgb& sum, Rgb v, float s) noexcept {
    sum.r += v.r * s, sum.g += v.g * s, sum.b += v.b * s;
}

constexpr Technique kAll[] = {
    {Strategy::env},
    {Strategy::env, Heuristic::balance, true},
    {Strategy::bsdf},
    {Strategy::mis, Heuristic::balance},
    {Strategy::mis, Heuristic::power},
    {Strategy::mis, Heuristic::optimal},
    {Strategy::mis, Heuristic::variance_aware},
    {Strategy::mis, Heuristic::balance, true},
    {Strategy::mis, Heuristic::power, true},
    {Strategy::mis, Heuristic::optimal, true},
    {Strategy::mis, Heuristic::variance_aware, true},
    {Strategy::mis, Heuristic::balance, true, true},
    {Strategy::mis, Heuristic::optimal, true, true},
    {Strategy::one_sample},
    {Strategy::one_sample, Heuristic::balance, true},
};

const char* heuristic_name(Heuristic h) noexcept {
    switch (h) {
        case Heuristic::balance: return "balance";
        case Heuristic::power: return "power";
        case Heuristic::optimal: return "optimal";
        case Heuristic::variance_aware: return "var";
    }
    return "unknown";
}

// Relearns what the adaptive techniques use from everything the point has seen.
void update(PointState& s, Heuristic h, int m) noexcept {
    if (h == Heuristic::optimal) {
        // A ridge of 1% of the diagonal: the plain and compensated densities are nearly
        // collinear control variates, and coefficients learnt from noisy sums swing along
        // that direction. Any alpha keeps the estimate unbiased; the ridge trades a little
        // of the exact optimum for much less noise (measured on studio.exr, phong:50,
        // mis-optimal-all: 1.27 -> 0.94 of balance MIS's variance; Lambert gains kept).
        constexpr double kRidge = 0.01;
        double a[kMaxTechniques * kMaxTechniques];
        for (int i = 0; i < m * m; ++i) a[i] = s.a[i] * (i % (m + 1) == 0 ? 1 + kRidge : 1);
        const OptimalAlpha solved = solve_optimal_alpha(a, s.b, m);
        s.optimal = solved;  // alpha = 0 (balance) when unsolved
        s.ill_conditioned += !solved.solved;
        return;
    }
    // nu = E[y^2] / Var[y] of each technique's own estimate y (Grittmann et al. 2019, as
    // the lecture writes it): 1 when a technique's mean is negligible against its spread,
    // large when it is nearly noise-free. Bounded at kMaxNu: a few pilot samples that
    // happen to miss a small bright source make a technique look noise-free, and an
    // unbounded nu would then silence the other technique where it matters.
    constexpr double kMaxNu = 100;
    for (int k = 0; k < 2; ++k) {
        if (s.count[k] < 2) continue;
        const double n = static_cast<double>(s.count[k]), second = s.sum2[k] / n, mean = s.sum[k] / n;
        const double variance = second - mean * mean;
        s.nu[k] = second > 0 ? static_cast<float>(variance * kMaxNu > second ? second / variance : kMaxNu) : 1.0f;
    }
}

}  // namespace

Technique Technique::parse(std::string_view name) {
    for (const Technique& t : kAll)
        if (t.name() == name) return t;
    std::string names;
    for (const Technique& t : kAll) {
        if (!names.empty()) names += ", ";
        names += t.name();
    }
    throw std::invalid_argument("technique '" + std::string(name) + "': expected one of " + names);
}

std::vector<Technique> Technique::all() { return {std::begin(kAll), std::end(kAll)}; }

// The heuristic only matters to MIS, and compensation only to environment sampling.
std::string Technique::name() const {
    const std::string suffix = mixture ? "-all" : (compensated ? "-comp" : "");
    switch (strategy) {
        case Strategy::env: return "env" + suffix;
        case Strategy::bsdf: return "bsdf";
        case Strategy::mis: return std::string("mis-") + heuristic_name(heuristic) + suffix;
        case Strategy::one_sample: return "one-sample" + suffix;
    }
    return "unknown";
}

DirectLightingEstimator::DirectLightingEstimator(const EnvMap& plain, const EnvMap& compensated, Technique technique,
                                                 Allocation allocation)
    : env_((technique.compensated ? compensated : plain).view()),
      other_(plain.view()),
      luma_(plain.options().luma),
      technique_(technique),
      allocation_(allocation) {
    if (allocation.total() == 0) throw std::invalid_argument("an estimate needs at least one sample");
    const bool both = technique.strategy == Strategy::mis || technique.strategy == Strategy::one_sample;
    if (both && (allocation.env == 0 || allocation.bsdf == 0))
        throw std::invalid_argument(technique.name() + " needs at least one environment and one BSDF sample per estimate");
    const EnvMap& sampled = technique.compensated ? compensated : plain;
    if (technique.strategy == Strategy::env && !sampled.complete())
        throw std::invalid_argument(
            "environment sampling alone over a compensated density is biased: its pdf is 0 on " +
            std::to_string(sampled.stats().zeroed_texels) +
            " texels that carry radiance; combine it with BSDF sampling (mis-balance-comp, mis-power-comp)");
}

DirectLightingEstimator::DirectLightingEstimator(const EnvMap& env, Technique technique, Allocation allocation)
    : DirectLightingEstimator(env, env, technique, allocation) {
    if (technique.mixture)
        throw std::invalid_argument(technique.name() + " samples both the plain and the compensated map: pass both");
}

Rgb DirectLightingEstimator::estimate(const ShadingPoint& point, const Bsdf& bsdf, Pcg32& rng,
                                      PointState& state) const noexcept {
    const Frame frame = Frame::from_normal(point.normal);
    const Vec3 wo = frame.to_local(point.wo);
    const Technique t = technique_;
    const Strategy s = t.strategy;
    const uint32_t total = allocation_.total();
    const bool both = s == Strategy::mis || s == Strategy::one_sample;
    // Sample counts of the environment (0) and BSDF (1) techniques.
    const float n[2] = {static_cast<float>(s == Strategy::env ? total : (both ? allocation_.env : 0)),
                        static_cast<float>(s == Strategy::bsdf ? total : (both ? allocation_.bsdf : 0))};
    const bool optimal = s == Strategy::mis && t.heuristic == Heuristic::optimal;
    const bool variance_aware = s == Strategy::mis && t.heuristic == Heuristic::variance_aware;
    const int m = t.mixture ? 3 : 2;  // optimal MIS's control variates

    Rgb sum;
    // One sample, drawn by technique k, with value f = L f cos; p: both techniques'
    // densities there; c: the control variates' (plain, compensated, BSDF for the
    // mixture; otherwise p itself).
    auto contribute = [&](int k, Rgb f, const float* p, const float* c) {
        const float q[2] = {n[0] * p[0], n[1] * p[1]};
        const float q_sum = q[0] + q[1];
        if (optimal) {
            // f - sum alpha c over the balance denominator; sum alpha is added once below.
            const float* alpha[3] = {state.optimal.alpha[0], state.optimal.alpha[1], state.optimal.alpha[2]};
            float fc[3] = {f.r, f.g, f.b};
            for (int ch = 0; ch < 3; ++ch) {
                float control = 0;
                for (int i = 0; i < m; ++i) control += alpha[i][ch] * c[i];
                fc[ch] = (fc[ch] - control) / q_sum;
            }
            sum.r += fc[0], sum.g += fc[1], sum.b += fc[2];
            const double inv_q2 = 1.0 / (static_cast<double>(q_sum) * q_sum);
            for (int i = 0; i < m; ++i) {
                for (int j = 0; j < m; ++j) state.a[i * m + j] += static_cast<double>(c[i]) * c[j] * inv_q2;
                state.b[i * 3 + 0] += static_cast<double>(f.r) * c[i] * inv_q2;
                state.b[i * 3 + 1] += static_cast<double>(f.g) * c[i] * inv_q2;
                state.b[i * 3 + 2] += static_cast<double>(f.b) * c[i] * inv_q2;
            }
            return;
        }
        float weight = 1;
        if (s == Strategy::mis || s == Strategy::one_sample) {
            // One-sample MIS picks technique k with probability n_k / total: its estimate,
            // averaged over total draws, is f / sum q as for multi-sample balance.
            if (s == Strategy::one_sample || t.heuristic == Heuristic::balance) weight = balance_weight(q, 2, k);
            else if (t.heuristic == Heuristic::power) weight = power_weight(q, 2, k);
            else weight = variance_aware_weight(q, state.nu, 2, k);
        }
        add(sum, f, weight / q[k]);
        if (variance_aware) {
            const double y = luminance(f, luma_) / p[k];
            state.sum[k] += y, state.sum2[k] += y * y, ++state.count[k];
        }
    };

    auto sample_env = [&] {
        // The mixture draws from either density with probability 1/2.
        const bool from_plain = t.mixture && rng.uniform() < 0.5f;
        const EnvSample e = (from_plain ? other_ : env_).sample(rng.uniform2());
        if (!(e.pdf > 0)) return;
        const Vec3 wi = frame.to_local(e.direction);
        const float p_second = t.mixture ? (from_plain ? env_ : other_).pdf(e.direction) : 0.0f;
        const float p_plain = from_plain ? e.pdf : p_second, p_comp = from_plain ? p_second : e.pdf;
        const float p[2] = {t.mixture ? 0.5f * (p_plain + p_comp) : e.pdf, bsdf.pdf(wo, wi)};
        const float c[3] = {t.mixture ? p_plain : p[0], t.mixture ? p_comp : p[1], p[1]};
        contribute(0, e.radiance * bsdf.eval(wo, wi), p, c);
    };
    auto sample_bsdf = [&] {
        const BsdfSample b = bsdf.sample(wo, rng.uniform2());
        if (!(b.pdf > 0)) return;
        const Vec3 wi = frame.to_world(b.wi);
        const EnvMapView::Lookup e = env_.lookup(wi);
        const float p_plain = t.mixture ? other_.pdf(wi) : 0.0f;
        const float p[2] = {t.mixture ? 0.5f * (p_plain + e.pdf) : e.pdf, b.pdf};
        const float c[3] = {t.mixture ? p_plain : p[0], t.mixture ? e.pdf : p[1], p[1]};
        contribute(1, e.radiance * b.value, p, c);
    };

    if (s == Strategy::one_sample) {
        const float env_share = n[0] / static_cast<float>(total);
        for (uint32_t i = 0; i < total; ++i) rng.uniform() < env_share ? sample_env() : sample_bsdf();
    } else {
        for (uint32_t i = 0; i < static_cast<uint32_t>(n[0]); ++i) sample_env();
        for (uint32_t i = 0; i < static_cast<uint32_t>(n[1]); ++i) sample_bsdf();
    }

    if (optimal)
        for (int i = 0; i < m; ++i) add(sum, {state.optimal.alpha[i][0], state.optimal.alpha[i][1], state.optimal.alpha[i][2]}, 1);
    if (t.adaptive() && ++state.estimates == state.next_update) {
        update(state, t.heuristic, m);
        state.next_update *= 2;
    }
    return sum;
}

}  // namespace envmis
