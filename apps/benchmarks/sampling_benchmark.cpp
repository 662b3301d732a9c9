// Google Benchmark: the guided-CDF sampler (EnvMap) against the textbook float-CDF
// sampler (reference::TextbookEnvMap), building and sampling the same synthetic sky.
// Run with --benchmark_repetitions=5 --benchmark_report_aggregates_only=true for medians.
#include <benchmark/benchmark.h>

#include <cmath>
#include <map>
#include <random>
#include <vector>

#include "envmis/sampling/envmap.h"
#include "envmis/study/comparison/comparison.h"
#include "envmis/study/techniques/estimator.h"
#include "reference.h"

namespace {

using envmis::EnvMap;
using envmis::EnvMapView;
using envmis::reference::TextbookEnvMap;

const envmis::RgbImage& sky(uint32_t w) {
    static std::map<uint32_t, envmis::RgbImage> skies;
    auto it = skies.find(w);
    if (it == skies.end()) it = skies.emplace(w, envmis::reference::synthetic_sky(w, w / 2)).first;
    return it->second;
}

const std::vector<envmis::Vec2>& uniforms() {
    static const std::vector<envmis::Vec2> us = [] {
        std::mt19937_64 rng(3);
        std::vector<envmis::Vec2> v(1 << 20);
        for (auto& u : v) u = {static_cast<float>(rng() >> 40) * 0x1p-24f, static_cast<float>(rng() >> 40) * 0x1p-24f};
        return v;
    }();
    return us;
}

template <class Sampler>
void build(benchmark::State& state) {
    const envmis::RgbImage& image = sky(static_cast<uint32_t>(state.range(0)));
    for (auto _ : state) {
        state.PauseTiming();
        envmis::RgbImage copy = image;
        state.ResumeTiming();
        Sampler s(std::move(copy), envmis::EnvMapOptions{});
        benchmark::DoNotOptimize(s);
    }
    state.counters["Mtexels/s"] = benchmark::Counter(
        static_cast<double>(image.pixels.size()) * state.iterations() / 1e6, benchmark::Counter::kIsRate);
}

// What a renderer's hot loop calls: the guided sampler through its view (EnvMap's own
// sample and pdf rebuild the view on every call), the textbook sampler as it is.
EnvMapView hot_path(const EnvMap& map) { return map.view(); }
const TextbookEnvMap& hot_path(const TextbookEnvMap& map) { return map; }

template <class Sampler>
void sample(benchmark::State& state) {
    const Sampler s(sky(static_cast<uint32_t>(state.range(0))), envmis::EnvMapOptions{});
    const auto& sampler = hot_path(s);
    const auto& us = uniforms();
    size_t i = 0;
    for (auto _ : state) {
        const envmis::EnvSample e = sampler.sample(us[i++ & (us.size() - 1)]);
        benchmark::DoNotOptimize(e);
    }
}

// The guided sampler through sample_many, kBatch points a call (as the estimator's lanes
// or a wavefront renderer ask): the points are the same as sample's, stored as the
// batch call reads them; the counter is the time per sample.
void sample_batch(benchmark::State& state) {
    constexpr size_t kBatch = 64;
    const EnvMap map(sky(static_cast<uint32_t>(state.range(0))), envmis::EnvMapOptions{});
    const EnvMapView view = map.view();
    const auto coordinate = [](float envmis::Vec2::*c) {
        std::vector<float> v;
        for (const envmis::Vec2 u : uniforms()) v.push_back(u.*c);
        return v;
    };
    static const std::vector<float> ux = coordinate(&envmis::Vec2::x), uy = coordinate(&envmis::Vec2::y);
    std::vector<float> out(7 * kBatch);
    float* o = out.data();
    const envmis::SampleArrays arrays{
        o, o + kBatch, o + 2 * kBatch, o + 3 * kBatch, o + 4 * kBatch, o + 5 * kBatch, o + 6 * kBatch};
    size_t first = 0;
    for (auto _ : state) {
        envmis::sample_many(view, {ux.data() + first, uy.data() + first}, arrays, kBatch);
        benchmark::DoNotOptimize(o);
        first = (first + kBatch) & (ux.size() - 1);
    }
    state.counters["per_sample"] = benchmark::Counter(
        static_cast<double>(kBatch), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

// Uniformly distributed directions, made before timing: the pdf benchmark times the
// lookup, not the sines and cosines that make its argument.
const std::vector<envmis::Vec3>& directions() {
    static const std::vector<envmis::Vec3> ds = [] {
        std::vector<envmis::Vec3> v;
        v.reserve(uniforms().size());
        for (const envmis::Vec2 u : uniforms()) {
            const float z = 1 - 2 * u.x, r = std::sqrt(std::max(0.0f, 1 - z * z)), phi = 2 * envmis::kPiF * u.y;
            v.push_back({r * std::cos(phi), r * std::sin(phi), z});
        }
        return v;
    }();
    return ds;
}

template <class Sampler>
void pdf(benchmark::State& state) {
    const Sampler s(sky(static_cast<uint32_t>(state.range(0))), envmis::EnvMapOptions{});
    const auto& sampler = hot_path(s);
    const auto& ds = directions();
    size_t i = 0;
    for (auto _ : state) benchmark::DoNotOptimize(sampler.pdf(ds[i++ & (ds.size() - 1)]));
}

// MIS estimates (1 environment + 1 BSDF sample each) of direct lighting, at shading
// points spread over the sphere: the throughput of the variance study. Arguments: the
// map's width, and the estimates asked at a time at one point (1, or 64 as `compare`
// asks them); the time is per call.
void estimate(benchmark::State& state, const char* technique, envmis::Bsdf bsdf) {
    envmis::EnvMapOptions options;
    options.compensation.enabled = envmis::Technique::parse(technique).compensated;
    const EnvMap map(sky(static_cast<uint32_t>(state.range(0))), options);
    const envmis::DirectLightingEstimator estimator(map, envmis::Technique::parse(technique));
    const auto points = envmis::sphere_points(64);
    envmis::Pcg32 rng(5);
    envmis::PointState point_state;
    std::vector<envmis::Rgb> out(static_cast<size_t>(state.range(1)));
    size_t i = 0;
    for (auto _ : state) {
        estimator.estimate(points[i++ & 63], bsdf, rng, point_state, out);
        benchmark::DoNotOptimize(out.data());
    }
    state.counters["estimates/s"] =
        benchmark::Counter(static_cast<double>(state.iterations() * out.size()), benchmark::Counter::kIsRate);
}

void sizes(benchmark::internal::Benchmark* b) { b->Arg(1024)->Arg(8192)->Unit(benchmark::kMillisecond); }
void sizes_ns(benchmark::internal::Benchmark* b) { b->Arg(1024)->Arg(8192)->Unit(benchmark::kNanosecond); }

BENCHMARK(build<EnvMap>)->Name("build/guided")->Apply(sizes);
BENCHMARK(build<TextbookEnvMap>)->Name("build/textbook")->Apply(sizes);
BENCHMARK(sample<EnvMap>)->Name("sample/guided")->Apply(sizes_ns);
BENCHMARK(sample<TextbookEnvMap>)->Name("sample/textbook")->Apply(sizes_ns);
BENCHMARK(sample_batch)->Name("sample/guided-many")->Apply(sizes_ns);
BENCHMARK(pdf<EnvMap>)->Name("pdf/guided")->Apply(sizes_ns);
BENCHMARK(pdf<TextbookEnvMap>)->Name("pdf/textbook")->Apply(sizes_ns);
BENCHMARK_CAPTURE(estimate, mis_balance_lambert, "mis-balance", envmis::Bsdf::lambert())
    ->Name("estimate/mis-balance/lambert")
    ->Args({1024, 1})
    ->Args({1024, 64});
BENCHMARK_CAPTURE(estimate, mis_balance_comp_lambert, "mis-balance-comp", envmis::Bsdf::lambert())
    ->Name("estimate/mis-balance-comp/lambert")
    ->Args({1024, 1})
    ->Args({1024, 64});
BENCHMARK_CAPTURE(estimate, mis_balance_ggx, "mis-balance", envmis::Bsdf::ggx(0.1f))
    ->Name("estimate/mis-balance/ggx:0.1")
    ->Args({1024, 1})
    ->Args({1024, 64});

}  // namespace

BENCHMARK_MAIN();
