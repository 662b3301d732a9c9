#include "envmis/estimator.h"

#include <stdexcept>

#include "envmis/frame.h"

namespace envmis {
namespace {

Rgb operator*(Rgb a, Rgb b) noexcept { return {a.r * b.r, a.g * b.g, a.b * b.b}; }
void add(Rgb& sum, Rgb v, float s) noexcept {
    sum.r += v.r * s, sum.g += v.g * s, sum.b += v.b * s;
}

}  // namespace

Technique Technique::parse(std::string_view name) {
    constexpr Technique kAll[] = {{Strategy::env},
                                  {Strategy::env, Heuristic::balance, true},
                                  {Strategy::bsdf},
                                  {Strategy::mis, Heuristic::balance},
                                  {Strategy::mis, Heuristic::power},
                                  {Strategy::mis, Heuristic::balance, true},
                                  {Strategy::mis, Heuristic::power, true}};
    for (const Technique& t : kAll)
        if (t.name() == name) return t;
    throw std::invalid_argument("technique '" + std::string(name) +
                                "': expected env, env-comp, bsdf, mis-balance, mis-power, mis-balance-comp or mis-power-comp");
}

// The heuristic only matters to MIS, and compensation only to environment sampling.
std::string Technique::name() const {
    const std::string suffix = compensated ? "-comp" : "";
    switch (strategy) {
        case Strategy::env: return "env" + suffix;
        case Strategy::bsdf: return "bsdf";
        case Strategy::mis: return (heuristic == Heuristic::balance ? "mis-balance" : "mis-power") + suffix;
    }
    return "unknown";
}

DirectLightingEstimator::DirectLightingEstimator(const EnvMap& env, Technique technique, Allocation allocation)
    : env_(env.view()), technique_(technique), allocation_(allocation) {
    if (allocation.total() == 0) throw std::invalid_argument("an estimate needs at least one sample");
    if (technique.strategy == Strategy::mis && (allocation.env == 0 || allocation.bsdf == 0))
        throw std::invalid_argument("MIS needs at least one environment and one BSDF sample per estimate");
    if (technique.strategy == Strategy::env && !env.complete())
        throw std::invalid_argument(
            "environment sampling alone over a compensated density is biased: its pdf is 0 on " +
            std::to_string(env.stats().zeroed_texels) +
            " texels that carry radiance; combine it with BSDF sampling (mis-balance-comp, mis-power-comp)");
}

Rgb DirectLightingEstimator::estimate(const ShadingPoint& point, const Bsdf& bsdf, Pcg32& rng) const noexcept {
    const Frame frame = Frame::from_normal(point.normal);
    const Vec3 wo = frame.to_local(point.wo);
    const Strategy s = technique_.strategy;
    const uint32_t n_env = s == Strategy::env ? allocation_.total() : (s == Strategy::mis ? allocation_.env : 0);
    const uint32_t n_bsdf = s == Strategy::bsdf ? allocation_.total() : (s == Strategy::mis ? allocation_.bsdf : 0);
    const Heuristic h = technique_.heuristic;
    Rgb sum;
    for (uint32_t i = 0; i < n_env; ++i) {
        const EnvSample e = env_.sample(rng.uniform2());
        if (!(e.pdf > 0)) continue;
        const Vec3 wi = frame.to_local(e.direction);
        const Rgb f = bsdf.eval(wo, wi);
        const float weight = s == Strategy::mis ? mis_weight(h, n_env * e.pdf, n_bsdf * bsdf.pdf(wo, wi)) : 1.0f;
        add(sum, e.radiance * f, weight / (n_env * e.pdf));
    }
    for (uint32_t j = 0; j < n_bsdf; ++j) {
        const BsdfSample b = bsdf.sample(wo, rng.uniform2());
        if (!(b.pdf > 0)) continue;
        const EnvMapView::Lookup e = env_.lookup(frame.to_world(b.wi));
        const float weight = s == Strategy::mis ? mis_weight(h, n_bsdf * b.pdf, n_env * e.pdf) : 1.0f;
        add(sum, e.radiance * b.value, weight / (n_bsdf * b.pdf));
    }
    return sum;
}

}  // namespace envmis
