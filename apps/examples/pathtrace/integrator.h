// Path tracing under an environment map: what a renderer does with envmis at every bounce.
//
// At each surface vertex the light from the map is estimated twice and the two combined
// by the balance heuristic: next-event estimation draws a direction (or several:
// PathOptions::light_samples) from the environment's density and traces a shadow ray;
// the path continues in a direction drawn from the material, and where that ray escapes
// to the sky its radiance is weighted against the density the environment technique had
// at that vertex. Russian roulette ends paths after a few bounces, by their throughput.
//
// The environment techniques compared (Environment below, one type each, so the loop is
// compiled once per technique with no virtual calls):
//   plain, compensated  one global envmis density (EnvMapView), as a table holds it
//   bins                the normal-aware table: at each vertex the bin that the
//                       material's lobe class and axis pick (lobe_axis) with one uniform;
//                       the same bin gives the BSDF sample's MIS weight; optionally at
//                       the first vertices only, a global table beyond
//   pbrt                a sampler following pbrt-v4's ImageInfiniteLight (equal-area map,
//                       compensated, float CDFs), what a pbrt user renders with today
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "envmis/math/random.h"
#include "envmis/sampling/binned.h"
#include "envmis/sampling/envmap.h"
#include "envmis/sampling/rotated.h"
#include "envmis/study/shading/frame.h"
#include "pbrt_style.h"
#include "scene.h"

namespace pathtrace {

inline Rgb operator+(Rgb a, Rgb b) { return {a.r + b.r, a.g + b.g, a.b + b.b}; }
inline Rgb operator*(Rgb a, Rgb b) { return {a.r * b.r, a.g * b.g, a.b * b.b}; }
inline Rgb operator*(Rgb a, float s) { return {a.r * s, a.g * s, a.b * s}; }

// The density one vertex samples: sample(u) and lookup(direction) (radiance and pdf), as
// EnvMapView and BinView have them, turned by the renderer's rotation of the sky
// (rotated.h; the identity unless --rotate).
struct GlobalEnvironment {
    envmis::Rotated<envmis::EnvMapView> map;
    const envmis::Rotated<envmis::EnvMapView>& at(Vec3 /*normal*/, Vec3 /*to_viewer*/, uint32_t /*lobe*/,
                                                  float /*choice*/, uint32_t /*vertex*/) const {
        return map;
    }
    Rgb eval(Vec3 direction) const noexcept { return map.eval(direction); }
};

// Bins at the first `depth` vertices of a path; beyond, a global density over the same
// texels (`beyond`: a compensated table of the same image, or the binned table's own
// plain density through its cells): a renderer's choice to spend the bins' cost where a path's throughput is
// whole (what it buys: docs/performance.md, 'In a path tracer'). Each vertex samples
// and weighs with one density, so each vertex's estimate is unbiased.
struct BinnedEnvironment {
    envmis::RotatedBinned bins;
    // The global table past `depth`; none: the binned table's own plain density.
    std::optional<envmis::Rotated<envmis::EnvMapView>> beyond;
    uint32_t depth = UINT32_MAX;

    struct Density {
        bool binned;
        envmis::Rotated<envmis::BinView> bin;
        const envmis::Rotated<envmis::EnvMapView>* global;
        envmis::EnvSample sample(Vec2 u) const noexcept { return binned ? bin.sample(u) : global->sample(u); }
        envmis::EnvMapView::Lookup lookup(Vec3 direction) const noexcept {
            return binned ? bin.lookup(direction) : global->lookup(direction);
        }
    };
    Density at(Vec3 normal, Vec3 to_viewer, uint32_t lobe, float choice, uint32_t vertex) const {
        if (vertex >= depth)
            return beyond ? Density{false, {}, &*beyond}
                          : Density{true, {bins.map->plain_bin(), bins.rotation}, nullptr};
        return {true, bins.bin(envmis::lobe_axis(lobe, normal, to_viewer), lobe, choice), nullptr};
    }
    Rgb eval(Vec3 direction) const noexcept { return bins.eval(direction); }
};

// pbrt's sampler for directions and pdfs; the radiance of a direction from the same
// square image by envmis's equal-area lookup (the nearest texel, as pbrt's).
struct PbrtEnvironment {
    const envmis::reference::PbrtStyleEnvMap* sampler = nullptr;
    envmis::EnvMapView map;  // the plain equal-area map whose radiance the sampler holds
    envmis::Rotation rotation;
    struct Density {
        const PbrtEnvironment* env;
        envmis::EnvSample sample(Vec2 u) const noexcept {
            envmis::EnvSample s = env->sampler->sample(u);
            s.direction = env->rotation.to_world(s.direction);
            return s;
        }
        envmis::EnvMapView::Lookup lookup(Vec3 direction) const noexcept {
            const Vec3 local = env->rotation.to_local(direction);
            return {env->map.eval(local), env->sampler->pdf(local)};
        }
    };
    Density at(Vec3, Vec3, uint32_t, float, uint32_t) const { return {this}; }
    Rgb eval(Vec3 direction) const noexcept { return map.eval(rotation.to_local(direction)); }
};

struct PathOptions {
    uint32_t max_bounces = 4;     // surface vertices lit along a path
    uint32_t roulette_after = 2;  // vertices before Russian roulette starts
    // Environment samples at each vertex (one material sample): n light samples and the
    // material's combined by the balance heuristic with counts (n p_env + p_bsdf). Many
    // make direct lighting nearly noise-free: what is left is the floor no environment
    // sampler can lower.
    uint32_t light_samples = 1;
};

// What one thread traced: rays (camera, continuation and shadow) and, where profiled,
// the cycles spent choosing, sampling and weighing the environment's densities.
struct Counters {
    uint64_t rays = 0, samples = 0, lookups = 0;
    uint64_t sampler_ticks = 0;
};

// The CPU's cycle counter (steady_clock elsewhere), read around the environment's calls
// only when profiling (--profile): the sampler's share of the threads' time.
uint64_t ticks() noexcept;

// Starts at `origin` + t `direction` (a camera ray) and returns the radiance along it.
template <bool Profile, class Environment>
Rgb trace_path(const Environment& env, const RayScene& scene, const SceneDescription& description,
               const std::vector<uint32_t>& lobes, Vec3 origin, Vec3 direction, const PathOptions& options,
               envmis::Pcg32& rng, Counters& counters) {
    ++counters.rays;
    std::optional<Hit> hit = scene.intersect(origin, direction);
    if (!hit) return env.eval(direction);
    Rgb radiance, throughput{1, 1, 1};
    for (uint32_t vertex = 0;; ++vertex) {
        const Material& material = description.materials[hit->material];
        const envmis::Frame frame = envmis::Frame::from_normal(hit->shading_normal);
        const Vec3 to_viewer = direction * -1.0f, wo = frame.to_local(to_viewer);
        if (wo.z <= 0) break;  // a shading normal turned away from the viewer
        const uint64_t t0 = Profile ? ticks() : 0;
        const auto density = env.at(hit->shading_normal, to_viewer, lobes[hit->material], rng.uniform(), vertex);
        if constexpr (Profile) counters.sampler_ticks += ticks() - t0;
        // Both samples count only on the geometric normal's side, so rays leave from just
        // above the surface there.
        const Vec3 lifted = hit->point + hit->geometric_normal * scene.epsilon();
        const auto n = static_cast<float>(options.light_samples);
        for (uint32_t k = 0; k < options.light_samples; ++k) {
            const uint64_t t1 = Profile ? ticks() : 0;
            const envmis::EnvSample light = density.sample(rng.uniform2());
            if constexpr (Profile) counters.sampler_ticks += ticks() - t1;
            ++counters.samples;
            if (!(light.pdf > 0) || envmis::dot(light.direction, hit->geometric_normal) <= 0) continue;
            const envmis::BsdfValues<float> f = material.values(wo, frame.to_local(light.direction));
            if (!(f.r > 0 || f.g > 0 || f.b > 0)) continue;
            ++counters.rays;
            if (!scene.occluded(lifted, light.direction))  // balance heuristic over n + 1 samples
                radiance = radiance + throughput * light.radiance * Rgb{f.r, f.g, f.b} * (1 / (n * light.pdf + f.pdf));
        }
        const envmis::BsdfSample s = material.sample(wo, rng.uniform2(), rng.uniform());
        // A lobe's sample below the shading horizon has a density but no value: the path
        // would carry nothing further and still trace its rays.
        if (!(s.pdf > 0) || !(s.value.r > 0 || s.value.g > 0 || s.value.b > 0)) break;
        const Vec3 next = frame.to_world(s.wi);
        if (envmis::dot(next, hit->geometric_normal) <= 0) break;  // below the surface: no light through it
        throughput = throughput * s.value * (1 / s.pdf);
        ++counters.rays;
        hit = scene.intersect(lifted, next);
        if (!hit) {
            const uint64_t t1 = Profile ? ticks() : 0;
            const envmis::EnvMapView::Lookup sky = density.lookup(next);
            if constexpr (Profile) counters.sampler_ticks += ticks() - t1;
            ++counters.lookups;
            radiance = radiance + throughput * sky.radiance * (s.pdf / (s.pdf + n * sky.pdf));
            break;
        }
        if (vertex + 1 >= options.max_bounces) break;
        if (vertex + 1 >= options.roulette_after) {
            const float keep = std::min(1.0f, std::max({throughput.r, throughput.g, throughput.b}));
            if (!(rng.uniform() < keep)) break;
            throughput = throughput * (1 / keep);
        }
        direction = next;
    }
    return radiance;
}

}  // namespace pathtrace
