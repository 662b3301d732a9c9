#include "envmis/study/reference/quadrature.h"

#include <cmath>
#include <stdexcept>
#include <vector>

#include "detail/parallel.h"
#include "envmis/build/mis_variance.h"
#include "envmis/study/shading/frame.h"

namespace envmis {
namespace {

// One quadrature node: a direction in the local shading frame, its solid angle, the
// radiance of its texel and its image point.
struct Node {
    Vec3 wi;
    double solid_angle;
    Rgb radiance;
    Vec2 uv;
};

// Sums fn(acc, node) over the midpoints of s x s sub-cells of every non-black texel
// whose sub-cell lies above the surface. Rows are summed separately and then in order,
// so the result does not depend on the number of threads. Throws Interrupted once `stop`
// is set, a row later at most.
template <class Acc, class Fn>
Acc integrate(const EnvMap& map, const ShadingPoint& point, int s, StopFlag stop, Fn&& fn) {
    const uint32_t w = map.width(), h = map.height(), ws = w * static_cast<uint32_t>(s);
    const Frame frame = Frame::from_normal(point.normal);
    std::vector<float> cos_phi(ws), sin_phi(ws);
    for (uint32_t i = 0; i < ws; ++i) {
        const double phi = 2 * kPi * (i + 0.5) / ws;
        cos_phi[i] = static_cast<float>(std::cos(phi));
        sin_phi[i] = static_cast<float>(std::sin(phi));
    }
    const Rgb* radiance = map.radiance().pixels.data();
    const LumaCoefficients luma = map.options().luma;
    std::vector<Acc> rows(h);
    if (map.options().mapping == Mapping::equal_area) {
        // Every sub-cell of an equal-area map covers the same solid angle.
        const double solid_angle = 4 * kPi / (static_cast<double>(ws) * h * s);
        detail::parallel_for(h, 1, stop, [&](uint32_t lo, uint32_t hi) {
            for (uint32_t y = lo; y < hi; ++y)
                for (uint32_t x = 0; x < w; ++x) {
                    const Rgb l = radiance[size_t{y} * w + x];
                    if (!(luminance(l, luma) > 0)) continue;
                    for (int b = 0; b < s; ++b)
                        for (int a = 0; a < s; ++a) {
                            const Vec2 uv{static_cast<float>((x + (a + 0.5) / s) / w),
                                          static_cast<float>((y + (b + 0.5) / s) / h)};
                            const Vec3 wi = frame.to_local(to_world(map.options().axes, equal_area_direction(uv)));
                            if (wi.z > 0) fn(rows[y], Node{wi, solid_angle, l, uv});
                        }
                }
        });
    } else {
        detail::parallel_for(h, 1, stop, [&](uint32_t lo, uint32_t hi) {
            for (uint32_t y = lo; y < hi; ++y)
                for (int b = 0; b < s; ++b) {
                    const double v = (y + (b + 0.5) / s) / h, theta = kPi * v;
                    const auto st = static_cast<float>(std::sin(theta)), ct = static_cast<float>(std::cos(theta));
                    const double solid_angle = 2 * kPi * kPi * std::sin(theta) / (static_cast<double>(ws) * h * s);
                    for (uint32_t x = 0; x < w; ++x) {
                        const Rgb l = radiance[size_t{y} * w + x];
                        if (!(luminance(l, luma) > 0)) continue;
                        for (int a = 0; a < s; ++a) {
                            const uint32_t i = x * static_cast<uint32_t>(s) + static_cast<uint32_t>(a);
                            const Vec3 world = to_world(map.options().axes, {st * cos_phi[i], st * sin_phi[i], ct});
                            const Vec3 wi = frame.to_local(world);
                            if (wi.z <= 0) continue;
                            fn(rows[y], Node{wi, solid_angle, l, {(i + 0.5f) / ws, static_cast<float>(v)}});
                        }
                    }
                }
        });
    }
    Acc total{};
    for (const Acc& r : rows) total += r;
    return total;
}

struct RgbSum {
    double r = 0, g = 0, b = 0;
    RgbSum& operator+=(const RgbSum& o) {
        r += o.r, g += o.g, b += o.b;
        return *this;
    }
};

Rgb multiply(Rgb a, Rgb b) { return {a.r * b.r, a.g * b.g, a.b * b.b}; }

}  // namespace

QuadratureResult reflected_radiance(const EnvMap& map, const Bsdf& bsdf, const ShadingPoint& point,
                                    const QuadratureOptions& options, StopFlag stop) {
    const Vec3 wo = Frame::from_normal(point.normal).to_local(point.wo);
    const LumaCoefficients luma = map.options().luma;
    auto at = [&](int s) {
        const RgbSum sum = integrate<RgbSum>(map, point, s, stop, [&](RgbSum& acc, const Node& n) {
            const Rgb f = multiply(n.radiance, bsdf.eval(wo, n.wi));
            acc.r += f.r * n.solid_angle, acc.g += f.g * n.solid_angle, acc.b += f.b * n.solid_angle;
        });
        return Rgb{static_cast<float>(sum.r), static_cast<float>(sum.g), static_cast<float>(sum.b)};
    };
    QuadratureResult result{at(1), 0, 0, 1};
    result.luminance = luminance(result.value, luma);
    for (int s = 2; s <= options.max_subdivisions; s *= 2) {
        const Rgb next = at(s);
        const double l = luminance(next, luma);
        result.error = std::abs(l - result.luminance);
        result = {next, l, result.error, s};
        if (result.error <= options.tolerance * std::abs(l)) break;
    }
    return result;
}

namespace {

// exact_variance with the environment technique's density `env_pdf(uv)` and the
// radiance of `env`.
template <class EnvPdf>
double exact_variance_with(const EnvMap& env, EnvPdf&& env_pdf, Technique technique, Allocation allocation,
                           const Bsdf& bsdf, const ShadingPoint& point, int subdivisions, StopFlag stop) {
    if (technique.adaptive() || technique.mixture)
        throw std::invalid_argument("exact_variance: " + technique.name() +
                                    (technique.adaptive()
                                         ? " learns its weights from its own samples; its variance has no closed form"
                                         : " samples two maps; pass one technique of one map"));
    const Strategy strategy = technique.strategy;
    const bool both = strategy == Strategy::mis || strategy == Strategy::one_sample;
    const MisCounts n{strategy == Strategy::env ? allocation.total() : (both ? allocation.env : 0.0),
                      strategy == Strategy::bsdf ? allocation.total() : (both ? allocation.bsdf : 0.0)};
    const Vec3 wo = Frame::from_normal(point.normal).to_local(point.wo);
    const LumaCoefficients luma = env.options().luma;
    const MisMoments m = integrate<MisMoments>(env, point, subdivisions, stop, [&](MisMoments& acc, const Node& node) {
        const BsdfValues<float> b = bsdf.values(wo, node.wi);
        const double f = luminance(multiply(node.radiance, Rgb{b.r, b.g, b.b}), luma);
        if (f == 0) return;
        const MisNode at{f, node.solid_angle, env_pdf(node.uv), b.pdf};
        if (strategy == Strategy::one_sample) {
            // total() draws z = f / Q from the mixture Q / total: the estimate's variance
            // is integral f^2 / Q - (integral f)^2 / total. Kept in env and second.
            const double q = n.env * at.p_env + n.bsdf * at.p_bsdf;
            acc.env += f * at.solid_angle;
            if (q > 0) acc.second += f * f / q * at.solid_angle;
            return;
        }
        // The weights the estimator uses (float, as its samples compute them), of the
        // techniques that can sample the node.
        const auto weight = [&](double n_self, double p_self, double n_other, double p_other) {
            if (!(n_self > 0 && p_self > 0)) return 0.0;
            return strategy == Strategy::mis
                       ? double{mis_weight(technique.heuristic, static_cast<float>(n_self * p_self),
                                           static_cast<float>(n_other * p_other))}
                       : 1.0;
        };
        acc.add(at, n, weight(n.env, at.p_env, n.bsdf, at.p_bsdf), weight(n.bsdf, at.p_bsdf, n.env, at.p_env));
    });
    if (strategy == Strategy::one_sample) return m.second - m.env * m.env / allocation.total();
    return m.variance(n);
}

}  // namespace

double exact_variance(const EnvMap& env, Technique technique, Allocation allocation, const Bsdf& bsdf,
                      const ShadingPoint& point, int subdivisions, StopFlag stop) {
    if (technique.bins)
        throw std::invalid_argument("exact_variance: " + technique.name() + " samples a binned map: pass it");
    return exact_variance_with(
        env, [&](Vec2 uv) { return env.pdf_uv(uv); }, technique, allocation, bsdf, point, subdivisions, stop);
}

double exact_variance(const BinnedEnvMap& binned, Technique technique, Allocation allocation, const Bsdf& bsdf,
                      const ShadingPoint& point, int subdivisions, StopFlag stop) {
    if (!technique.bins)
        throw std::invalid_argument("exact_variance: " + technique.name() + " does not sample a binned map");
    const BinnedEnvMapView view = binned.view();
    const uint32_t lobe = binned.lobe_class(bsdf.phong_exponent());
    // Each pick gives an unbiased estimator, so the variance is the weights' mixture of
    // the picks' (no spread of means between picks to add).
    const BinBlend blend = view.blend(lobe_axis(lobe, point.normal, point.wo), lobe);
    double variance = 0;
    for (int k = 0; k < 4; ++k) {
        if (!(blend.weight[k] > 0)) continue;
        const BinView bin = view.bin_at(blend.bin[k], blend.view_cos);
        variance += blend.weight[k] * exact_variance_with(
                                          binned.radiance_map(), [&](Vec2 uv) { return bin.pdf_uv(uv); }, technique,
                                          allocation, bsdf, point, subdivisions, stop);
    }
    return variance;
}

}  // namespace envmis
