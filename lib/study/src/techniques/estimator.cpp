#include "envmis/study/techniques/estimator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <type_traits>

#include "envmis/cpu.h"
#include "envmis/study/shading/frame.h"
#include "estimator_simd.h"

namespace envmis {
namespace {

Rgb operator*(Rgb a, Rgb b) noexcept { return {a.r * b.r, a.g * b.g, a.b * b.b}; }
void add(Rgb& sum, Rgb v, float s) noexcept { sum.r += v.r * s, sum.g += v.g * s, sum.b += v.b * s; }

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
    {Strategy::mis, Heuristic::balance, false, false, true},
    {Strategy::mis, Heuristic::power, false, false, true},
    {Strategy::mis, Heuristic::optimal, false, false, true},
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

// Sample counts of the environment (0) and BSDF (1) techniques in one estimate.
struct Counts {
    float n[2];
};
Counts sample_counts(const Technique& t, const Allocation& a) noexcept {
    const Strategy s = t.strategy;
    const bool both = s == Strategy::mis || s == Strategy::one_sample;
    return {{static_cast<float>(s == Strategy::env ? a.total() : (both ? a.env : 0)),
             static_cast<float>(s == Strategy::bsdf ? a.total() : (both ? a.bsdf : 0))}};
}

// The heuristic fixed_weight applies to technique t (the SIMD sums take the same).
detail::Weighting weighting_of(const Technique& t) noexcept {
    if (t.strategy == Strategy::env || t.strategy == Strategy::bsdf) return detail::Weighting::one;
    return t.strategy == Strategy::mis && t.heuristic == Heuristic::power ? detail::Weighting::power
                                                                          : detail::Weighting::balance;
}

// The weight of a sample of technique k (0: environment, 1: BSDF), q = n p of both, for
// the techniques whose weights depend on the densities alone: 1 for a single technique,
// the balance or power heuristic for MIS. One-sample MIS picks technique k with
// probability n_k / total: its estimate, averaged over total draws, is f / sum q as for
// multi-sample balance.
float fixed_weight(const Technique& t, const float* q, int k) noexcept {
    switch (weighting_of(t)) {
        case detail::Weighting::one: return 1;
        case detail::Weighting::power: return power_weight(q, 2, k);
        case detail::Weighting::balance: return balance_weight(q, 2, k);
    }
    return 0;
}

// The lanes' batch sampling and lookups: the map's batch functions, or for bins the batch
// forms over the bins each lane picked (BinLanes below).
void sample_lanes(const EnvMapView& env, PointArrays u, SampleArrays out, uint32_t n) noexcept {
    sample_many(env, u, out, n);
}
void lookup_lanes(const EnvMapView& env, DirectionArrays in, LookupArrays out, uint32_t n) noexcept {
    lookup_many(env, in, out, n);
}

// Estimates side by side, for the fixed-weight techniques over one density (or one
// bin per estimate).
constexpr uint32_t kLanes = 64;

// The bins of the lanes' estimates at one point: each estimate picks its own among the
// bins around the point's axis (BinnedEnvMapView::bin) with its first random number,
// as a single estimate does, then samples and weighs with it alone.
struct BinLanes {
    const BinnedEnvMapView* map;
    BinBlend blend;  // map->blend(axis, lobe) of the point
    mutable BinView bins[kLanes];

    void pick(uint32_t lane, float choice) const noexcept { bins[lane] = map->bin(blend, choice); }
};
void sample_lanes(const BinLanes& env, PointArrays u, SampleArrays out, uint32_t n) noexcept {
    sample_many(env.bins, u, out, n);
}
void lookup_lanes(const BinLanes& env, DirectionArrays in, LookupArrays out, uint32_t n) noexcept {
    lookup_many(env.bins, in, out, n);
}

constexpr uint32_t kMaxLaneSamples = 8;  // per estimate; estimates that spend more go one at a time

bool runs_in_lanes(const Technique& t, const Allocation& a) noexcept {
    return !t.adaptive() && !t.mixture && t.strategy != Strategy::one_sample && a.total() <= kMaxLaneSamples;
}

// Up to `lanes` (<= kMaxLanes) estimates at once, each step over all of them: the random
// numbers (drawn in the order one estimate at a time would draw them: each estimate's
// environment samples, then its BSDF samples, two numbers each), then each environment
// sample, then each BSDF sample (all of them drawn before any is looked up), whose
// radiance and density lookup_many finds for all lanes at once. Compiled once per BSDF
// kind K and flattened (everything it calls inlined), so that the kind's own code runs
// with no branch on the kind and no call: the generic Bsdf::sample, eval and pdf are
// too large for GCC to inline into the loops by itself. With AVX2, the batch functions
// sample and look up eight lanes at a time, and so do the weighted sums and, for a
// surface seen from above (wo.z > 0; every kind), the BSDF's sampling, pdf and value
// (estimator_simd.h): the lanes are then padded to a multiple of eight with valid
// points, whose results are dropped. See docs/performance-log.md for what each step
// gained. kMaxLanes sizes the working arrays, which one estimate alone must not pay for.
template <uint32_t kMaxLanes, BsdfKind K, class Env>
[[gnu::flatten]] void estimate_lanes_of(const Env& env, const Technique& t, const Allocation& a, const Frame& frame,
                                        Vec3 wo, Bsdf bsdf, Pcg32& rng, std::span<Rgb> out) noexcept {
    bsdf.kind = K;
    const Counts counts = sample_counts(t, a);
    const auto n_env = static_cast<uint32_t>(counts.n[0]), n_bsdf = static_cast<uint32_t>(counts.n[1]);
    const uint32_t lanes = static_cast<uint32_t>(out.size());
#ifdef ENVMIS_AVX2_BATCHES
    constexpr uint32_t kWidth = detail::kSimdWidth;
    const bool simd = kMaxLanes % kWidth == 0 && batch_paths().lanes == BatchPath::avx2;
    const bool simd_bsdf = simd && wo.z > 0;
    const uint32_t padded = simd ? (lanes + kWidth - 1) / kWidth * kWidth : lanes;
#else
    const bool simd = false, simd_bsdf = false;
    const uint32_t padded = lanes;
#endif
    float u_x[kMaxLaneSamples][kMaxLanes], u_y[kMaxLaneSamples][kMaxLanes];
    for (uint32_t l = 0; l < lanes; ++l) {
        if constexpr (std::is_same_v<Env, BinLanes>) env.pick(l, rng.uniform());
        for (uint32_t j = 0; j < n_env + n_bsdf; ++j) u_x[j][l] = rng.uniform(), u_y[j][l] = rng.uniform();
    }
    for (uint32_t j = 0; j < n_env + n_bsdf; ++j)
        for (uint32_t l = lanes; l < padded; ++l) u_x[j][l] = u_y[j][l] = 0.5f;
    if constexpr (std::is_same_v<Env, BinLanes>)
        for (uint32_t l = lanes; l < padded; ++l) env.bins[l] = env.bins[0];
    // The environment technique's directions (world frame), densities and radiance; the
    // BSDF's densities and values (f cos) at the same directions.
    float x[kMaxLanes], y[kMaxLanes], z[kMaxLanes], pdf[kMaxLanes], r[kMaxLanes], g[kMaxLanes], bl[kMaxLanes];
    float b_pdf[kMaxLanes], v_r[kMaxLanes], v_g[kMaxLanes], v_b[kMaxLanes];
    float sum_r[kMaxLanes] = {}, sum_g[kMaxLanes] = {}, sum_b[kMaxLanes] = {};
    // Adds each lane's sample of technique k (0: environment, 1: BSDF) to its sum.
    auto add_lanes = [&](int k) {
#ifdef ENVMIS_AVX2_BATCHES
        if (simd)
            return detail::add_samples(weighting_of(t), counts.n, k, {r, g, bl, v_r, v_g, v_b, pdf, b_pdf},
                                       {sum_r, sum_g, sum_b}, padded);
#endif
        for (uint32_t l = 0; l < lanes; ++l) {
            const float q[2] = {counts.n[0] * pdf[l], counts.n[1] * b_pdf[l]};
            if (!(k == 0 ? pdf[l] > 0 : b_pdf[l] > 0)) continue;
            const Rgb f = Rgb{r[l], g[l], bl[l]} * Rgb{v_r[l], v_g[l], v_b[l]};
            const float s = fixed_weight(t, q, k) / q[k];
            sum_r[l] += f.r * s, sum_g[l] += f.g * s, sum_b[l] += f.b * s;
        }
    };
    for (uint32_t j = 0; j < n_env; ++j) {
        if constexpr (kMaxLanes == 1) {
            const EnvSample e = env.sample({u_x[j][0], u_y[j][0]});
            x[0] = e.direction.x, y[0] = e.direction.y, z[0] = e.direction.z, pdf[0] = e.pdf;
            r[0] = e.radiance.r, g[0] = e.radiance.g, bl[0] = e.radiance.b;
        } else {
            sample_lanes(env, {u_x[j], u_y[j]}, {x, y, z, pdf, r, g, bl}, padded);
        }
        if (simd_bsdf) {
#ifdef ENVMIS_AVX2_BATCHES
            detail::eval_bsdf(frame, bsdf, wo, {x, y, z}, {b_pdf, v_r, v_g, v_b}, padded);
#endif
        } else {
            for (uint32_t l = 0; l < padded; ++l) {
                const BsdfValues<float> v = bsdf.values(wo, frame.to_local({x[l], y[l], z[l]}));
                b_pdf[l] = v.pdf, v_r[l] = v.r, v_g[l] = v.g, v_b[l] = v.b;
            }
        }
        add_lanes(0);
    }
    for (uint32_t j = n_env; j < n_env + n_bsdf; ++j) {
        if (simd_bsdf) {
#ifdef ENVMIS_AVX2_BATCHES
            detail::sample_bsdf(frame, bsdf, wo, {u_x[j], u_y[j]}, {x, y, z, b_pdf, v_r, v_g, v_b}, padded);
#endif
        } else {
            for (uint32_t l = 0; l < padded; ++l) {
                const BsdfSample b = bsdf.sample(wo, {u_x[j][l], u_y[j][l]});
                const Vec3 wi = frame.to_world(b.wi);
                x[l] = wi.x, y[l] = wi.y, z[l] = wi.z;
                b_pdf[l] = b.pdf, v_r[l] = b.value.r, v_g[l] = b.value.g, v_b[l] = b.value.b;
            }
        }
        if constexpr (kMaxLanes == 1) {  // one estimate: inline, without the batch's set-up
            const EnvMapView::Lookup e = env.lookup({x[0], y[0], z[0]});
            r[0] = e.radiance.r, g[0] = e.radiance.g, bl[0] = e.radiance.b, pdf[0] = e.pdf;
        } else {
            lookup_lanes(env, {x, y, z}, {r, g, bl, pdf}, padded);
        }
        add_lanes(1);
    }
    for (uint32_t l = 0; l < lanes; ++l) out[l] = {sum_r[l], sum_g[l], sum_b[l]};
}

template <uint32_t kMaxLanes, class Env>
void estimate_lanes(const Env& env, const Technique& t, const Allocation& a, const Frame& frame, Vec3 wo,
                    const Bsdf& bsdf, Pcg32& rng, std::span<Rgb> out) noexcept {
    switch (bsdf.kind) {
        case BsdfKind::lambert:
            return estimate_lanes_of<kMaxLanes, BsdfKind::lambert>(env, t, a, frame, wo, bsdf, rng, out);
        case BsdfKind::phong:
            return estimate_lanes_of<kMaxLanes, BsdfKind::phong>(env, t, a, frame, wo, bsdf, rng, out);
        case BsdfKind::ggx: return estimate_lanes_of<kMaxLanes, BsdfKind::ggx>(env, t, a, frame, wo, bsdf, rng, out);
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
    const std::string suffix = mixture ? "-all" : (compensated ? "-comp" : (bins ? "-bins" : ""));
    switch (strategy) {
        case Strategy::env: return "env" + suffix;
        case Strategy::bsdf: return "bsdf";
        case Strategy::mis: return std::string("mis-") + heuristic_name(heuristic) + suffix;
        case Strategy::one_sample: return "one-sample" + suffix;
    }
    return "unknown";
}

namespace {

// The sample counts every estimator is refused for.
void check_allocation(const Technique& technique, const Allocation& allocation) {
    if (allocation.total() == 0) throw std::invalid_argument("an estimate needs at least one sample");
    if (allocation.env > std::numeric_limits<uint32_t>::max() - allocation.bsdf)
        throw std::invalid_argument("too many samples per estimate: " + std::to_string(allocation.env) + " + " +
                                    std::to_string(allocation.bsdf) + " does not fit in 32 bits");
    const bool both = technique.strategy == Strategy::mis || technique.strategy == Strategy::one_sample;
    if (both && (allocation.env == 0 || allocation.bsdf == 0))
        throw std::invalid_argument(technique.name() +
                                    " needs at least one environment and one BSDF sample per estimate");
}

}  // namespace

DirectLightingEstimator::DirectLightingEstimator(const EnvMap& plain, const EnvMap& compensated, Technique technique,
                                                 Allocation allocation)
    : env_((technique.compensated ? compensated : plain).view()),
      other_(plain.view()),
      luma_(plain.options().luma),
      technique_(technique),
      allocation_(allocation) {
    check_allocation(technique, allocation);
    if (technique.bins) throw std::invalid_argument(technique.name() + " samples a binned map: pass a BinnedEnvMap");
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

DirectLightingEstimator::DirectLightingEstimator(const BinnedEnvMap& binned, Technique technique, Allocation allocation)
    : env_(binned.radiance_map().view()),
      other_(env_),
      luma_(binned.radiance_map().options().luma),
      technique_(technique),
      allocation_(allocation),
      binned_(&binned),
      binned_view_(binned.view()) {
    check_allocation(technique, allocation);
    if (!technique.bins || technique.strategy != Strategy::mis)
        throw std::invalid_argument(technique.name() + " does not sample a binned map (expected mis-*-bins)");
}

BinView DirectLightingEstimator::bin_of(const ShadingPoint& point, const Bsdf& bsdf, float choice) const noexcept {
    const uint32_t lobe = binned_->lobe_class(bsdf.phong_exponent());
    return binned_view_.bin(lobe_axis(lobe, point.normal, point.wo), lobe, choice);
}

Rgb DirectLightingEstimator::estimate(const ShadingPoint& point, const Bsdf& bsdf, Pcg32& rng,
                                      PointState& state) const noexcept {
    if (technique_.bins) return estimate_with(bin_of(point, bsdf, rng.uniform()), point, bsdf, rng, state);
    return estimate_with(env_, point, bsdf, rng, state);
}

template <class Env>
Rgb DirectLightingEstimator::estimate_with(const Env& env, const ShadingPoint& point, const Bsdf& bsdf, Pcg32& rng,
                                           PointState& state) const noexcept {
    const Frame frame = Frame::from_normal(point.normal);
    const Vec3 wo = frame.to_local(point.wo);
    const Technique t = technique_;
    if (runs_in_lanes(t, allocation_)) {
        Rgb sum;
        estimate_lanes<1>(env, t, allocation_, frame, wo, bsdf, rng, {&sum, 1});
        return sum;
    }
    const Strategy s = t.strategy;
    const uint32_t total = allocation_.total();
    const Counts counts = sample_counts(t, allocation_);
    const float* n = counts.n;
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
        const float weight = variance_aware ? variance_aware_weight(q, state.nu, 2, k) : fixed_weight(t, q, k);
        add(sum, f, weight / q[k]);
        if (variance_aware) {
            const double y = luminance(f, luma_) / p[k];
            state.sum[k] += y, state.sum2[k] += y * y, ++state.count[k];
        }
    };

    auto sample_env = [&] {
        // The mixture draws from either density with probability 1/2.
        const bool from_plain = t.mixture && rng.uniform() < 0.5f;
        const Vec2 u = rng.uniform2();
        const EnvSample e = from_plain ? other_.sample(u) : env.sample(u);
        if (!(e.pdf > 0)) return;
        const Vec3 wi = frame.to_local(e.direction);
        const float p_second = t.mixture ? (from_plain ? env.pdf(e.direction) : other_.pdf(e.direction)) : 0.0f;
        const float p_plain = from_plain ? e.pdf : p_second, p_comp = from_plain ? p_second : e.pdf;
        const BsdfValues<float> v = bsdf.values(wo, wi);
        const float p[2] = {t.mixture ? 0.5f * (p_plain + p_comp) : e.pdf, v.pdf};
        const float c[3] = {t.mixture ? p_plain : p[0], t.mixture ? p_comp : p[1], p[1]};
        contribute(0, e.radiance * Rgb{v.r, v.g, v.b}, p, c);
    };
    auto sample_bsdf = [&] {
        const BsdfSample b = bsdf.sample(wo, rng.uniform2());
        if (!(b.pdf > 0)) return;
        const Vec3 wi = frame.to_world(b.wi);
        const EnvMapView::Lookup e = env.lookup(wi);
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
        for (int i = 0; i < m; ++i)
            add(sum, {state.optimal.alpha[i][0], state.optimal.alpha[i][1], state.optimal.alpha[i][2]}, 1);
    if (t.adaptive() && ++state.estimates == state.next_update) {
        update(state, t.heuristic, m);
        state.next_update *= 2;
    }
    return sum;
}

void DirectLightingEstimator::estimate(const ShadingPoint& point, const Bsdf& bsdf, Pcg32& rng, PointState& state,
                                       std::span<Rgb> out) const noexcept {
    if (!runs_in_lanes(technique_, allocation_) || out.size() == 1) {
        for (Rgb& e : out) e = estimate(point, bsdf, rng, state);
        return;
    }
    const Frame frame = Frame::from_normal(point.normal);
    const Vec3 wo = frame.to_local(point.wo);
    auto run = [&](const auto& env) {
        for (size_t first = 0; first < out.size(); first += kLanes)
            estimate_lanes<kLanes>(env, technique_, allocation_, frame, wo, bsdf, rng,
                                   out.subspan(first, std::min<size_t>(kLanes, out.size() - first)));
    };
    if (technique_.bins) {
        const uint32_t lobe = binned_->lobe_class(bsdf.phong_exponent());
        run(BinLanes{&binned_view_, binned_view_.blend(lobe_axis(lobe, point.normal, point.wo), lobe), {}});
    } else {
        run(env_);
    }
}

}  // namespace envmis
