// Google Benchmark: the guided-CDF sampler (EnvMap) against the textbook float-CDF
// sampler (reference::TextbookEnvMap), building and sampling the same synthetic sky.
// Run with --benchmark_repetitions=5 --benchmark_report_aggregates_only=true for medians.
#include <benchmark/benchmark.h>

#include <cmath>
#include <map>
#include <random>
#include <vector>

#include "envmis/comparison.h"
#include "envmis/envmap.h"
#include "envmis/estimator.h"
#include "reference.h"

namespace {

using envmis::EnvMap;
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
    state.counters["Mtexels/s"] = benchmark::Counter(static_cast<double>(image.pixels.size()) * state.iterations() / 1e6,
                                                     benchmark::Counter::kIsRate);
}

template <class Sampler>
void sample(benchmark::State& state) {
    const Sampler s(sky(static_cast<uint32_t>(state.range(0))), envmis::EnvMapOptions{});
    const auto& us = uniforms();
    size_t i = 0;
    for (auto _ : state) {
        const envmis::EnvSample e = s.sample(us[i++ & (us.size() - 1)]);
        benchmark::DoNotOptimize(e);
    }
}

template <class Sampler>
void pdf(benchmark::State& state) {
    const Sampler s(sky(static_cast<uint32_t>(state.range(0))), envmis::EnvMapOptions{});
    const auto& us = uniforms();
    size_t i = 0;
    for (auto _ : state) {
        const envmis::Vec2 u = us[i++ & (us.size() - 1)];
        const float z = 1 - 2 * u.x, r = std::sqrt(std::max(0.0f, 1 - z * z)), phi = 2 * envmis::kPiF * u.y;
        benchmark::DoNotOptimize(s.pdf({r * std::cos(phi), r * std::sin(phi), z}));
    }
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
BENCHMARK(pdf<EnvMap>)->Name("pdf/guided")->Apply(sizes_ns);
BENCHMARK(pdf<TextbookEnvMap>)->Name("pdf/textbook")->Apply(sizes_ns);
BENCHMARK_CAPTURE(estimate, mis_balance_lambert, "mis-balance", envmis::Bsdf::lambert())->Name("estimate/mis-balance/lambert")->Args({1024, 1})->Args({1024, 64});
BENCHMARK_CAPTURE(estimate, mis_balance_comp_lambert, "mis-balance-comp", envmis::Bsdf::lambert())->Name("estimate/mis-balance-comp/lambert")->Args({1024, 1})->Args({1024, 64});
BENCHMARK_CAPTURE(estimate, mis_balance_ggx, "mis-balance", envmis::Bsdf::ggx(0.1f))->Name("estimate/mis-balance/ggx:0.1")->Args({1024, 1})->Args({1024, 64});

}  // namespace

BENCHMARK_MAIN();
