// Google Benchmark: the guided-CDF sampler (EnvMap) against the textbook float-CDF
// sampler (reference::TextbookEnvMap), building and sampling the same synthetic sky; and
// the binned sampler (BinnedEnvMap, the default 121 bins, lobe class 0) against today's EnvMap,
// plain and compensated, with a random shading normal per call.
// Run with --benchmark_repetitions=5 --benchmark_report_aggregates_only=true for medians.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <random>
#include <tuple>
#include <type_traits>
#include <vector>

#include "envmis/build/bins.h"
#include "envmis/build/env_map.h"
#include "envmis/cpu.h"
#include "envmis/sampling/binned.h"
#include "envmis/sampling/envmap.h"
#include "envmis/study/comparison/comparison.h"
#include "envmis/study/techniques/estimator.h"
#include "pbrt_style.h"
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

// Today's map, compensated (the default) or plain (what the binned sampler builds on).
template <bool kCompensated = true>
envmis::EnvMapOptions options() {
    envmis::EnvMapOptions o;
    o.compensation.enabled = kCompensated;
    return o;
}
envmis::EnvMapOptions plain_options() { return options<false>(); }

// Either sampler from an image, as a renderer's set-up builds it.
template <class Sampler>
Sampler make_sampler(envmis::RgbImage image, const envmis::EnvMapOptions& options) {
    if constexpr (std::is_same_v<Sampler, EnvMap>)
        return envmis::build_env_map(std::move(image), options);
    else
        return Sampler(image, options);
}

template <class Sampler, bool kCompensated = true>
void build(benchmark::State& state) {
    const envmis::RgbImage& image = sky(static_cast<uint32_t>(state.range(0)));
    for (auto _ : state) {
        state.PauseTiming();
        envmis::RgbImage copy = image;
        state.ResumeTiming();
        Sampler s = make_sampler<Sampler>(std::move(copy), options<kCompensated>());
        benchmark::DoNotOptimize(s);
    }
    state.counters["Mtexels/s"] = benchmark::Counter(
        static_cast<double>(image.pixels.size()) * state.iterations() / 1e6, benchmark::Counter::kIsRate);
}

// What a renderer's hot loop calls: the guided sampler through its view (EnvMap's own
// sample and pdf rebuild the view on every call), the textbook sampler as it is.
EnvMapView hot_path(const EnvMap& map) { return map.view(); }
const TextbookEnvMap& hot_path(const TextbookEnvMap& map) { return map; }

template <class Sampler, bool kCompensated = true>
void sample(benchmark::State& state) {
    const Sampler s = make_sampler<Sampler>(sky(static_cast<uint32_t>(state.range(0))), options<kCompensated>());
    const auto& sampler = hot_path(s);
    const auto& us = uniforms();
    size_t i = 0;
    for (auto _ : state) {
        const envmis::EnvSample e = sampler.sample(us[i++ & (us.size() - 1)]);
        benchmark::DoNotOptimize(e);
    }
}

// The distribution behind the guided sampler alone (no direction, radiance or pdf in
// solid angle): its tuned sample (distribution.h) against the plain search of cdf.h,
// which it equals sample for sample; the compensated sky, whose sun rows are hot.
template <bool kTuned>
void distribution_sample(benchmark::State& state) {
    const EnvMap map = build_env_map(sky(static_cast<uint32_t>(state.range(0))), options());
    const envmis::Distribution2DView d = map.view().distribution;
    const auto& us = uniforms();
    size_t i = 0;
    for (auto _ : state) {
        const envmis::Vec2 u = us[i++ & (us.size() - 1)];
        const auto s = kTuned ? d.sample(u) : d.search(u);
        benchmark::DoNotOptimize(s);
    }
}

// The whole guided sample (direction, solid-angle pdf, radiance) through the tuned
// distribution, as EnvMapView::sample draws it, against the same sample through the
// plain search of cdf.h: what the tuning gives a renderer's single call.
template <bool kTuned>
void whole_sample(benchmark::State& state) {
    const EnvMap map = build_env_map(sky(static_cast<uint32_t>(state.range(0))), options());
    const EnvMapView view = map.view();
    const auto& us = uniforms();
    size_t i = 0;
    for (auto _ : state) {
        const envmis::Vec2 u = us[i++ & (us.size() - 1)];
        if constexpr (kTuned) {
            benchmark::DoNotOptimize(view.sample(u));
        } else {
            const auto s = view.distribution.search(u);
            benchmark::DoNotOptimize(view.at(s.p, s.pdf, static_cast<size_t>(s.y) * view.distribution.w + s.x));
        }
    }
}

// The guided sampler through sample_many, kBatch points a call (as the estimator's lanes
// or a wavefront renderer ask): the points are the same as sample's, stored as the
// batch call reads them; the counter is the time per sample.
constexpr size_t kBatch = 64;
const std::vector<envmis::Vec3>& directions();
const std::vector<envmis::Vec3>& normals();
const std::vector<float>& choices();
struct BatchPoints {
    std::vector<float> ux, uy, nx, ny, nz, dx, dy, dz, choice;  // points, normals, directions, bin picks
    std::vector<float> head_on;                                 // view cosines 1
};
const BatchPoints& batch_points() {
    static const BatchPoints p = [] {
        BatchPoints b;
        for (const envmis::Vec2 u : uniforms()) b.ux.push_back(u.x), b.uy.push_back(u.y);
        for (const envmis::Vec3 n : normals()) b.nx.push_back(n.x), b.ny.push_back(n.y), b.nz.push_back(n.z);
        for (const envmis::Vec3 d : directions()) b.dx.push_back(d.x), b.dy.push_back(d.y), b.dz.push_back(d.z);
        b.choice = choices();
        b.head_on.assign(b.nx.size(), 1.0f);
        return b;
    }();
    return p;
}
// Output arrays of n samples each, one after the other in o (7 n floats).
envmis::SampleArrays sample_arrays(float* o, size_t n = kBatch) {
    return {o, o + n, o + 2 * n, o + 3 * n, o + 4 * n, o + 5 * n, o + 6 * n};
}
// The time per sample of n samples an iteration.
void per_sample(benchmark::State& state, size_t n = kBatch) {
    state.counters["per_sample"] = benchmark::Counter(
        static_cast<double>(n), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

template <bool kCompensated>
void sample_batch(benchmark::State& state) {
    const EnvMap map = build_env_map(sky(static_cast<uint32_t>(state.range(0))), options<kCompensated>());
    const EnvMapView view = map.view();
    const BatchPoints& p = batch_points();
    std::vector<float> out(7 * kBatch);
    const envmis::SampleArrays arrays = sample_arrays(out.data());
    size_t first = 0;
    for (auto _ : state) {
        envmis::sample_many(view, {p.ux.data() + first, p.uy.data() + first}, arrays, kBatch);
        benchmark::DoNotOptimize(out.data());
        first = (first + kBatch) & (p.ux.size() - 1);
    }
    per_sample(state);
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

// The binned sampler over the plain map of sky(w), built once per width for all its
// benchmarks (a build at 8k takes seconds).
const envmis::BinnedEnvMap& binned(uint32_t w) {
    static std::map<uint32_t, envmis::BinnedEnvMap> maps;
    auto it = maps.find(w);
    if (it == maps.end()) it = maps.emplace(w, envmis::build_bins(build_env_map(sky(w), plain_options()))).first;
    return it->second;
}

// Shading normals, uniform on the sphere and independent of the points and directions:
// the binned benchmarks pay for finding each call's bin.
const std::vector<envmis::Vec3>& normals() {
    static const std::vector<envmis::Vec3> ns = [] {
        std::vector<envmis::Vec3> v = directions();
        std::rotate(v.begin(), v.begin() + 12345, v.end());
        return v;
    }();
    return ns;
}

// The binned sampler's pick among the bins around each normal: uniform, independent of
// the points (another point's second coordinate).
const std::vector<float>& choices() {
    static const std::vector<float> cs = [] {
        std::vector<float> v;
        const auto& us = uniforms();
        for (size_t i = 0; i < us.size(); ++i) v.push_back(us[(i + 54321) & (us.size() - 1)].y);
        return v;
    }();
    return cs;
}

void build_bins(benchmark::State& state) {
    const EnvMap plain = build_env_map(sky(static_cast<uint32_t>(state.range(0))), plain_options());
    for (auto _ : state) {
        state.PauseTiming();
        EnvMap copy = plain;
        state.ResumeTiming();
        const envmis::BinnedEnvMap b = envmis::build_bins(std::move(copy));
        benchmark::DoNotOptimize(b);
    }
}

void sample_binned(benchmark::State& state) {
    const envmis::BinnedEnvMapView view = binned(static_cast<uint32_t>(state.range(0))).view();
    const auto& us = uniforms();
    const auto& ns = normals();
    const auto& cs = choices();
    size_t i = 0;
    for (auto _ : state) {
        const size_t k = i++ & (us.size() - 1);
        const envmis::EnvSample e = view.sample({ns[k]}, 0, cs[k], us[k]);
        benchmark::DoNotOptimize(e);
    }
}

void sample_binned_batch(benchmark::State& state) {
    const envmis::BinnedEnvMapView view = binned(static_cast<uint32_t>(state.range(0))).view();
    const BatchPoints& p = batch_points();
    std::vector<float> out(7 * kBatch);
    const envmis::SampleArrays arrays = sample_arrays(out.data());
    size_t first = 0;
    for (auto _ : state) {
        envmis::sample_many(view, 0,
                            {p.nx.data() + first, p.ny.data() + first, p.nz.data() + first, p.head_on.data() + first},
                            p.choice.data() + first, {p.ux.data() + first, p.uy.data() + first}, arrays, kBatch);
        benchmark::DoNotOptimize(out.data());
        first = (first + kBatch) & (p.ux.size() - 1);
    }
    per_sample(state);
}

void pdf_binned(benchmark::State& state) {
    const envmis::BinnedEnvMapView view = binned(static_cast<uint32_t>(state.range(0))).view();
    const auto& ds = directions();
    const auto& ns = normals();
    const auto& cs = choices();
    size_t i = 0;
    for (auto _ : state) {
        const size_t k = i++ & (ds.size() - 1);
        benchmark::DoNotOptimize(view.pdf({ns[k]}, 0, cs[k], ds[k]));
    }
}

template <class Sampler, bool kCompensated = true>
void pdf(benchmark::State& state) {
    const Sampler s = make_sampler<Sampler>(sky(static_cast<uint32_t>(state.range(0))), options<kCompensated>());
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
    const EnvMap map = build_env_map(sky(static_cast<uint32_t>(state.range(0))), options);
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

// Equal-area against equirect at nearly the same texel count: the synthetic sky w x h
// under `mapping` (equal-area: square), built once per size for every row that times it.
using envmis::reference::SkyDetail;
const EnvMap& mapped_sky(uint32_t w, uint32_t h, envmis::Mapping mapping, bool compensated,
                         SkyDetail detail = SkyDetail::clear) {
    static std::map<std::tuple<uint32_t, uint32_t, envmis::Mapping, bool, SkyDetail>, EnvMap> maps;
    const auto key = std::make_tuple(w, h, mapping, compensated, detail);
    auto it = maps.find(key);
    if (it == maps.end()) {
        envmis::EnvMapOptions o = options();
        o.compensation.enabled = compensated;
        o.mapping = mapping;
        it = maps.emplace(key, build_env_map(envmis::reference::synthetic_sky(w, h, mapping, detail), o)).first;
    }
    return it->second;
}

// Single calls through the view, as sample<EnvMap>; arguments: width, height, compensated.
template <envmis::Mapping kMapping>
void sample_mapped(benchmark::State& state) {
    const EnvMapView view = mapped_sky(static_cast<uint32_t>(state.range(0)), static_cast<uint32_t>(state.range(1)),
                                       kMapping, state.range(2) != 0)
                                .view();
    const auto& us = uniforms();
    size_t i = 0;
    for (auto _ : state) {
        const envmis::EnvSample e = view.sample(us[i++ & (us.size() - 1)]);
        benchmark::DoNotOptimize(e);
    }
    state.counters["Mtexels"] = static_cast<double>(state.range(0) * state.range(1)) / 1e6;
}

// Two kinds of work in turns, `work(m, first)` for m = 0 and 1 on the block of `block`
// points from `first` (of `points`, a power of two) each iteration, the one going first
// alternating (the first of a pair reads its points cold), so that their ratio spans the
// same seconds of the machine's drift. Manual time: work 0's; returns the ratio of work
// 0's total time to work 1's.
template <class Work>
double in_turns(benchmark::State& state, size_t points, size_t block, Work&& work) {
    double seconds[2] = {0, 0};
    size_t first = 0;
    int leader = 0;
    for (auto _ : state) {
        for (int turn = 0; turn < 2; ++turn) {
            const int m = leader ^ turn;
            const auto start = std::chrono::steady_clock::now();
            work(m, first);
            const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            seconds[m] += elapsed;
            if (m == 0) state.SetIterationTime(elapsed);
        }
        first = (first + block) & (points - 1);
        leader ^= 1;
    }
    per_sample(state, block);
    return seconds[0] / seconds[1];
}

// The two mappings in turns: blocks of 1024 samples at the same points on the equal-area
// sky and on the equirect one (the cases above run minutes apart). Manual time: the
// equal-area map's; the counter equal_area/equirect is the ratio of the two maps' totals.
// Arguments: the equal-area side, the equirect width and height, compensated, and
// sample_many (1) or single calls (0). On the clear sky the equirect side's cold rows are
// flat (SkyDetail), on the cloudy one neither side's are.
template <SkyDetail kDetail>
void equal_area_over_equirect(benchmark::State& state) {
    const bool compensated = state.range(3) != 0, batch = state.range(4) != 0;
    const auto side = static_cast<uint32_t>(state.range(0));
    const EnvMapView maps[2] = {mapped_sky(side, side, envmis::Mapping::equal_area, compensated, kDetail).view(),
                                mapped_sky(static_cast<uint32_t>(state.range(1)), static_cast<uint32_t>(state.range(2)),
                                           envmis::Mapping::equirect, compensated, kDetail)
                                    .view()};
    constexpr size_t kBlock = 1024;  // long enough to make the clock's reading negligible
    const BatchPoints& p = batch_points();
    std::vector<float> out(7 * kBlock);
    const envmis::SampleArrays arrays = sample_arrays(out.data(), kBlock);
    state.counters["equal_area/equirect"] = in_turns(state, p.ux.size(), kBlock, [&](int m, size_t first) {
        if (batch) {
            envmis::sample_many(maps[m], {p.ux.data() + first, p.uy.data() + first}, arrays, kBlock);
            benchmark::DoNotOptimize(out.data());
            return;
        }
        for (size_t i = first; i < first + kBlock; ++i) {
            const envmis::EnvSample e = maps[m].sample({p.ux[i], p.uy[i]});
            benchmark::DoNotOptimize(e);
        }
    });
}

// The pbrt-v4-style sampler (pbrt_style.h) over an equal-area sky of `side`, compensated
// or plain, built once per case for every row that times it (the map reads the image
// it keeps beside it).
struct PbrtSky {
    envmis::RgbImage image;
    envmis::reference::PbrtStyleEnvMap map;
    PbrtSky(uint32_t side, const envmis::EnvMapOptions& o)
        : image(envmis::reference::synthetic_sky(side, side, envmis::Mapping::equal_area)), map(image, o) {}
};
const envmis::reference::PbrtStyleEnvMap& pbrt_sky(uint32_t side, bool compensated) {
    static std::map<std::pair<uint32_t, bool>, std::unique_ptr<PbrtSky>> skies;
    std::unique_ptr<PbrtSky>& sky = skies[{side, compensated}];
    if (!sky) {
        envmis::EnvMapOptions o = options();
        o.compensation.enabled = compensated;
        o.mapping = envmis::Mapping::equal_area;
        sky = std::make_unique<PbrtSky>(side, o);
    }
    return sky->map;
}

// envmis against the pbrt-style sampler in turns (in_turns), single calls in blocks of
// 1024: samples (kPdf false) or pdfs of the same points, envmis on the same equal-area sky
// or on an equirect one of about as many texels. Manual time: envmis's; the counter
// pbrt/envmis is the speedup. Arguments: the square's side, envmis's map's width and
// height (the side twice for equal-area), compensated.
template <envmis::Mapping kMapping, bool kPdf>
void over_pbrt(benchmark::State& state) {
    const bool compensated = state.range(3) != 0;
    const envmis::reference::PbrtStyleEnvMap& pbrt = pbrt_sky(static_cast<uint32_t>(state.range(0)), compensated);
    const EnvMapView view =
        mapped_sky(static_cast<uint32_t>(state.range(1)), static_cast<uint32_t>(state.range(2)), kMapping, compensated)
            .view();
    constexpr size_t kBlock = 1024;
    const auto& us = uniforms();
    const auto& ds = directions();
    const auto ratio = in_turns(state, us.size(), kBlock, [&](int m, size_t first) {
        for (size_t i = first; i < first + kBlock; ++i) {
            if constexpr (kPdf) {
                benchmark::DoNotOptimize(m == 0 ? view.pdf(ds[i]) : pbrt.pdf(ds[i]));
            } else {
                const envmis::EnvSample e = m == 0 ? view.sample(us[i]) : pbrt.sample(us[i]);
                benchmark::DoNotOptimize(e);
            }
        }
    });
    state.counters["pbrt/envmis"] = 1 / ratio;
}

// lookup_many against the memory's floor: independent reads of the data each of its
// lookups must fetch (the texel's radiance at both ends, its CDF start and the next, its
// row's marginal entry), at texels found before timing. On a map beyond the cache those
// reads are the misses, and a loop that only issues them keeps as many in flight as the
// CPU allows. Blocks of 1024 directions, the two in turns (in_turns): the counter
// many/line_reads is the ratio of their totals; each reads a block the other read half
// the points ago, long out of the cache (its lines would otherwise arrive warm). 1 would
// mean the lookups are bound by the memory system alone, not by their arithmetic or by
// misses that wait on each other. Manual time: lookup_many's. Arguments: the map's
// width, compensated.
void lookup_over_line_reads(benchmark::State& state) {
    const auto w = static_cast<uint32_t>(state.range(0));
    const EnvMap map = build_env_map(sky(w), state.range(1) != 0 ? options<true>() : plain_options());
    const EnvMapView view = map.view();
    const envmis::Distribution2DView& d = view.distribution;
    const BatchPoints& p = batch_points();
    std::vector<uint32_t> texels, rows;
    for (const envmis::Vec3 dir : directions()) {
        const envmis::Vec2 uv = view.uv_of(dir);
        rows.push_back(envmis::detail::cell_of(uv.y, d.h));
        texels.push_back(rows.back() * d.w + envmis::detail::cell_of(uv.x, d.w));
    }
    const size_t last = size_t{d.w} * d.h - 1;
    const auto read_lines = [&](size_t first, size_t n) {
        float radiance = 0;
        uint32_t units = 0;
        for (size_t i = first; i < first + n; ++i) {
            const size_t k = texels[i];
            radiance += view.radiance[k].r + view.radiance[k].b;
            units += d.start[k] + d.start[std::min(k + 1, last)] + d.marginal.start[rows[i]];
        }
        benchmark::DoNotOptimize(radiance);
        benchmark::DoNotOptimize(units);
    };
    constexpr size_t kBlock = 1024;
    std::vector<float> out(4 * kBatch);
    const envmis::LookupArrays arrays{out.data(), out.data() + kBatch, out.data() + 2 * kBatch,
                                      out.data() + 3 * kBatch};
    state.counters["many/line_reads"] = in_turns(state, texels.size(), kBlock, [&](int m, size_t first) {
        if (m == 1) return read_lines((first + texels.size() / 2) & (texels.size() - 1), kBlock);
        for (size_t b = first; b < first + kBlock; b += kBatch) {
            envmis::lookup_many(view, {p.dx.data() + b, p.dy.data() + b, p.dz.data() + b}, arrays, kBatch);
            benchmark::DoNotOptimize(out.data());
        }
    });
}

void sizes(benchmark::internal::Benchmark* b) { b->Arg(1024)->Arg(8192)->Unit(benchmark::kMillisecond); }
void sizes_ns(benchmark::internal::Benchmark* b) { b->Arg(1024)->Arg(8192)->Unit(benchmark::kNanosecond); }

BENCHMARK(build<EnvMap>)->Name("build/guided")->Apply(sizes);
BENCHMARK(build<TextbookEnvMap>)->Name("build/textbook")->Apply(sizes);
BENCHMARK(sample<EnvMap>)->Name("sample/guided")->Apply(sizes_ns);
BENCHMARK(sample<TextbookEnvMap>)->Name("sample/textbook")->Apply(sizes_ns);
BENCHMARK(sample_batch<true>)->Name("sample/guided-many")->Apply(sizes_ns);
BENCHMARK(distribution_sample<false>)->Name("distribution/plain")->Apply(sizes_ns);
BENCHMARK(distribution_sample<true>)->Name("distribution/tuned")->Apply(sizes_ns);
BENCHMARK(whole_sample<false>)->Name("sample/guided-plain-search")->Apply(sizes_ns);
BENCHMARK(whole_sample<true>)->Name("sample/guided-tuned")->Apply(sizes_ns);
// Binned against today's map, plain and compensated (guided above); build/bins is the
// bins alone, on top of a plain map's build.
BENCHMARK(build<EnvMap, false>)->Name("build/plain")->Apply(sizes);
BENCHMARK(build_bins)->Name("build/bins")->Apply(sizes);
BENCHMARK(sample<EnvMap, false>)->Name("sample/plain")->Apply(sizes_ns);
BENCHMARK(sample_batch<false>)->Name("sample/plain-many")->Apply(sizes_ns);
BENCHMARK(sample_binned)->Name("sample/binned")->Apply(sizes_ns);
BENCHMARK(sample_binned_batch)->Name("sample/binned-many")->Apply(sizes_ns);
BENCHMARK(pdf<EnvMap, false>)->Name("pdf/plain")->Apply(sizes_ns);
BENCHMARK(pdf_binned)->Name("pdf/binned")->Apply(sizes_ns);
BENCHMARK(pdf<EnvMap>)->Name("pdf/guided")->Apply(sizes_ns);
BENCHMARK(pdf<TextbookEnvMap>)->Name("pdf/textbook")->Apply(sizes_ns);
// Pairs at nearly equal texel counts: 4096^2 = 16 777 216 against 5792 x 2896 =
// 16 773 632 (0.02% fewer), and 5792^2 = 33 547 264 against 8192 x 4096 = 33 554 432
// (0.02% more); each pair has one power-of-two map, whose point placement is cheaper
// (distribution.h: point_in_cell), so 4096 x 4096 equirect, a size no sky is stored at,
// times the mapping alone at an identical size.
BENCHMARK(sample_mapped<envmis::Mapping::equal_area>)
    ->Name("sample/equal-area")
    ->ArgsProduct({{4096}, {4096}, {0, 1}})
    ->ArgsProduct({{5792}, {5792}, {0, 1}});
BENCHMARK(sample_mapped<envmis::Mapping::equirect>)
    ->Name("sample/equirect")
    ->ArgsProduct({{4096}, {4096}, {0, 1}})
    ->ArgsProduct({{5792}, {2896}, {0, 1}})
    ->ArgsProduct({{8192}, {4096}, {0, 1}});
BENCHMARK(equal_area_over_equirect<SkyDetail::clear>)
    ->Name("sample/equal-area-over-equirect")
    ->ArgsProduct({{4096}, {5792}, {2896}, {0, 1}, {0, 1}})
    ->ArgsProduct({{5792}, {8192}, {4096}, {0, 1}, {0, 1}})
    ->UseManualTime();
BENCHMARK(equal_area_over_equirect<SkyDetail::clouds>)
    ->Name("sample/equal-area-over-equirect-clouds")
    ->ArgsProduct({{5792}, {8192}, {4096}, {0, 1}, {0, 1}})
    ->UseManualTime();
// The sizes: rooitou_park_1k's square (724^2, about 1024 x 512) and the 8k sky's
// (5792^2, about 8192 x 4096); envmis on the square itself or on the equirect map.
template <envmis::Mapping kMapping>
void over_pbrt_sizes(benchmark::internal::Benchmark* b) {
    for (const auto& [side, w, h] : {std::tuple{724, 1024, 512}, {5792, 8192, 4096}}) {
        const bool square = kMapping == envmis::Mapping::equal_area;
        b->ArgsProduct({{side}, {square ? side : w}, {square ? side : h}, {0, 1}});
    }
    b->UseManualTime();
}
BENCHMARK(over_pbrt<envmis::Mapping::equal_area, true>)
    ->Name("pdf/equal-area-over-pbrt")
    ->Apply(over_pbrt_sizes<envmis::Mapping::equal_area>);
BENCHMARK(over_pbrt<envmis::Mapping::equirect, true>)
    ->Name("pdf/equirect-over-pbrt")
    ->Apply(over_pbrt_sizes<envmis::Mapping::equirect>);
BENCHMARK(over_pbrt<envmis::Mapping::equal_area, false>)
    ->Name("sample/equal-area-over-pbrt")
    ->Apply(over_pbrt_sizes<envmis::Mapping::equal_area>);
BENCHMARK(over_pbrt<envmis::Mapping::equirect, false>)
    ->Name("sample/equirect-over-pbrt")
    ->Apply(over_pbrt_sizes<envmis::Mapping::equirect>);
BENCHMARK(lookup_over_line_reads)
    ->Name("lookup/many-over-line-reads")
    ->ArgsProduct({{1024, 8192}, {0, 1}})
    ->UseManualTime();
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
BENCHMARK_CAPTURE(estimate, mis_balance_phong, "mis-balance", envmis::Bsdf::phong(20))
    ->Name("estimate/mis-balance/phong:20")
    ->Args({1024, 1})
    ->Args({1024, 64});

}  // namespace

// BENCHMARK_MAIN, with the CPU and the batch kernels' paths in the context that heads
// the output (text and JSON), so that every figure names the machine it was measured on.
int main(int argc, char** argv) {
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::AddCustomContext("cpu", envmis::cpu_name());
    benchmark::AddCustomContext("batch_paths", envmis::batch_paths_summary());
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
