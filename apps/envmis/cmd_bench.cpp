// envmis bench [IN | --size WxH] [--bins K]: build and sampling speed of the guided-CDF
// sampler against the textbook float-CDF sampler and a sampler following pbrt-v4's
// (pbrt_style.h; on the equal-area square of the same map), measured in the same run;
// with --bins, also the binned sampler (binned.h) against today's EnvMap, plain and
// compensated, what a renderer pays for normal-aware sampling, and against the global
// sampler over a bin's own density, what its representation costs.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <iterator>
#include <memory>
#include <optional>
#include <random>
#include <tuple>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli.h"
#include "envmis/build/bins.h"
#include "envmis/build/env_map.h"
#include "envmis/build/remap.h"
#include "envmis/cpu.h"
#include "envmis/study/statistics/statistics.h"
#include "pbrt_style.h"
#include "reference.h"

namespace envmis::cli {
namespace {

struct Timing {
    std::string sampler;
    double build_ms = 0, ns_per_sample = 0, ns_per_pdf = 0, bytes_per_texel = 0;
};

// ns per call of `call` over all inputs, once. Each result is kept whole, as Google
// Benchmark's DoNotOptimize keeps it: it must exist in memory, every field of it (a
// sample's direction, pdf and radiance), and nothing further is computed from it. Summing
// the fields instead put a chain of adds through the stack into the timed loop, which
// slowed envmis's samples more than the references' (measured: docs/performance-log.md,
// 'keep_whole'); keeping only part of it let the compiler drop the rest.
template <class T>
void keep_whole(T& value) {
    asm volatile("" : "+m"(value));
}
template <class Input, class Call>
double ns_per_call(const std::vector<Input>& inputs, Call&& call) {
    const auto start = std::chrono::steady_clock::now();
    for (const Input& in : inputs) {
        auto result = call(in);
        keep_whole(result);
    }
    return milliseconds_since(start) * 1e6 / static_cast<double>(inputs.size());
}

// The inputs of sample_many and lookup_many: one array per coordinate, and outputs for
// a batch of kBatch.
constexpr uint32_t kBatch = 64;
struct BatchInputs {
    std::vector<float> ux, uy, x, y, z, nx, ny, nz, choice;  // n, choice: the binned sampler's
    std::vector<float> head_on;                              // view cosines 1: the bins' own densities
    std::vector<float> out = std::vector<float>(7 * kBatch);

    BatchInputs(const std::vector<Vec2>& us, const std::vector<Vec3>& directions, const std::vector<Vec3>& normals = {},
                const std::vector<float>& choices = {})
        : choice(choices) {
        for (const Vec2 u : us) ux.push_back(u.x), uy.push_back(u.y);
        for (const Vec3 d : directions) x.push_back(d.x), y.push_back(d.y), z.push_back(d.z);
        for (const Vec3 n : normals) nx.push_back(n.x), ny.push_back(n.y), nz.push_back(n.z);
        head_on.assign(nx.size(), 1.0f);
    }
    LobeAxisArrays axes(size_t first) const {
        return {nx.data() + first, ny.data() + first, nz.data() + first, head_on.data() + first};
    }
    SampleArrays sample_out(float* o) const {
        return {o, o + kBatch, o + 2 * kBatch, o + 3 * kBatch, o + 4 * kBatch, o + 5 * kBatch, o + 6 * kBatch};
    }
    // ns per sample (per lookup) over all inputs, kBatch at a time (the rest, fewer).
    template <class Call>
    double ns_per_item(size_t n, Call&& call) {
        volatile float sink = 0;
        float* o = out.data();
        const auto start = std::chrono::steady_clock::now();
        for (size_t first = 0; first < n; first += kBatch) {
            call(first, static_cast<uint32_t>(std::min<size_t>(kBatch, n - first)), o);
            sink = sink + o[0];
        }
        return milliseconds_since(start) * 1e6 / static_cast<double>(n);
    }
    double sample_cost(const EnvMapView& view) {
        return ns_per_item(ux.size(), [&](size_t first, uint32_t n, float* o) {
            sample_many(view, {ux.data() + first, uy.data() + first}, sample_out(o), n);
        });
    }
    double sample_cost(const BinnedEnvMapView& view, uint32_t lobe) {
        return ns_per_item(ux.size(), [&](size_t first, uint32_t n, float* o) {
            sample_many(view, lobe, axes(first), choice.data() + first, {ux.data() + first, uy.data() + first},
                        sample_out(o), n);
        });
    }
    double lookup_cost(const BinnedEnvMapView& view, uint32_t lobe) {
        return ns_per_item(x.size(), [&](size_t first, uint32_t n, float* o) {
            lookup_many(view, lobe, axes(first), choice.data() + first,
                        {x.data() + first, y.data() + first, z.data() + first},
                        {o, o + kBatch, o + 2 * kBatch, o + 3 * kBatch}, n);
        });
    }
    double lookup_cost(const EnvMapView& view) {
        return ns_per_item(x.size(), [&](size_t first, uint32_t n, float* o) {
            lookup_many(view, {x.data() + first, y.data() + first, z.data() + first},
                        {o, o + kBatch, o + 2 * kBatch, o + 3 * kBatch}, n);
        });
    }
};

// A sampler built `repeats` times from copies of `source` (the copy untimed; the last
// sampler kept) and the median build time.
template <class Sampler, class Source>
std::pair<std::unique_ptr<Sampler>, double> build_repeatedly(const Source& source, int repeats,
                                                             const std::function<Sampler(Source&)>& build,
                                                             Progress& progress, int& step) {
    std::vector<double> builds;
    std::unique_ptr<Sampler> sampler;
    for (int r = 0; r < repeats; ++r) {
        throw_if_interrupted();
        Source copy = source;
        sampler.reset();  // freeing the previous sampler is no part of a build
        const auto start = std::chrono::steady_clock::now();
        sampler = std::make_unique<Sampler>(build(copy));
        builds.push_back(milliseconds_since(start));
        progress.update(++step);
    }
    return {std::move(sampler), median(builds)};
}

// The arguments of `envmis bench`.
struct BenchArgs {
    std::string input, size = "8192x4096", mapping = "equirect";
    int repeats = 5;
    uint32_t samples = 1u << 20;
    uint32_t bins = 0;                // 0: no binned measurement
    uint32_t samples_per_normal = 1;  // consecutive calls that share a normal (a shading point's samples)
    bool json = false, no_compensate = false;
};

// At most 2^26 samples a repeat: the points and the batch arrays take about 40 bytes a
// sample (2.7 GB at the limit); at most 1000 repeats.
constexpr uint32_t kMaxBenchSamples = 1u << 26;
constexpr int kMaxRepeats = 1000;
// What a texel of the synthetic sky costs at the peak of a run, about: the sky, the map's
// radiance, luminance and tables, the textbook sampler's and the bins'.
constexpr uint64_t kBytesPerTexel = 64;

void add_bench_flags(CLI::App& sub, BenchArgs& args) {
    sub.add_option("input", args.input, "HDR image or table (default: a synthetic sky with a small sun)");
    sub.add_option(
           "--size", args.size,
           "Size of the synthetic sky, WxH, each side 1 to 65536, at most 2^31 texels and about 64 bytes a texel "
           "of free memory")
        ->type_name("WxH")
        ->capture_default_str()
        ->check(size_validator(false));
    sub.add_option("--repeats", args.repeats, "Repeats of each measurement")
        ->capture_default_str()
        ->check(in_range(1, kMaxRepeats));
    sub.add_option("--samples", args.samples, "Samples and pdf evaluations per repeat")
        ->capture_default_str()
        ->check(in_range(uint32_t{1}, kMaxBenchSamples));
    sub.add_flag("--no-compensate", args.no_compensate, "Measure the uncompensated density");
    sub.add_option("--mapping", args.mapping,
                   "Mapping of the synthetic sky (equal-area: a square --size) or of an image; a table has its own")
        ->capture_default_str()
        ->check(CLI::IsMember({"equirect", "equal-area"}));
    sub.add_option(
           "--bins", args.bins,
           "Also measure the binned sampler with K bins (square number) against today's EnvMap, plain and "
           "compensated: build, memory, sample and pdf with a random normal per call (lobe class 0), the pdf in a "
           "bin picked beforehand (once per shading point, as a renderer weighs its BSDF samples), and a bin's "
           "sample against the global sampler over the same density (the bins nearest the axes and the diagonal)")
        ->type_name("K")
        ->check(bins_validator());
    sub.add_option("--samples-per-normal", args.samples_per_normal,
                   "With --bins: consecutive calls that share one random normal, as a shading point's samples do "
                   "(1: a new normal every call, the worst case for the bins' caches)")
        ->capture_default_str()
        ->check(in_range(uint32_t{1}, uint32_t{65536}));
    sub.add_flag("--json", args.json, "Print one JSON object instead of text lines");
}

// The map measured, the input's radiance or the synthetic sky of --size, and how to
// sample it: its mapping and axes (a table's own, or the flags'); the compensation is
// the caller's.
struct BenchMap {
    RgbImage image;
    std::string name;
    EnvMapOptions options;
    // The pbrt-style sampler's map: the image itself if equal-area, else the same sky
    // (or the image remapped) on an equal-area square of about as many texels.
    RgbImage square;
};

uint32_t square_side(const RgbImage& image) {
    return std::max(1u, static_cast<uint32_t>(std::lround(std::sqrt(static_cast<double>(image.width) * image.height))));
}

BenchMap bench_map(const BenchArgs& args) {
    EnvMapOptions options;
    options.mapping = parse_mapping(args.mapping);
    if (args.input.empty()) {
        const Size size = *parse_size(args.size, false);  // the flag's validator has accepted it
        if (options.mapping == Mapping::equal_area && size.width != size.height)
            throw UsageError("--size " + args.size + ": an equal-area sky is square, e.g. 5792x5792");
        check_image_size("--size " + args.size, size, kBytesPerTexel);
        BenchMap map{reference::synthetic_sky(size.width, size.height, options.mapping), "synthetic-sky", options, {}};
        const uint32_t side = square_side(map.image);
        map.square = options.mapping == Mapping::equal_area ? map.image
                                                            : reference::synthetic_sky(side, side, Mapping::equal_area);
        return map;
    }
    BuildRequest request;
    request.compensate = false;
    request.mapping = args.mapping;
    const LoadedMap loaded = load_map(args.input, request);
    options.mapping = loaded.map.options().mapping, options.axes = loaded.map.options().axes;
    BenchMap map{to_image(loaded.map.radiance()), args.input, options, {}};
    const uint32_t side = square_side(map.image);
    map.square = options.mapping == Mapping::equal_area
                     ? map.image
                     : remap(map.image, options.mapping, Mapping::equal_area, side, side, 0, &interrupted()).image;
    return map;
}

// The random points every sampler is timed on: u for sampling, directions for the pdf,
// and (with `normals`) a shading normal per call for the binned sampler, whose cost
// includes finding the normal's bin.
struct BenchPoints {
    std::vector<Vec2> us;
    std::vector<Vec3> directions, normals;
    std::vector<float> choices;  // the binned sampler's pick among the bins around each normal
};

BenchPoints bench_points(uint32_t n, bool normals, uint32_t samples_per_normal) {
    std::mt19937_64 rng(7);
    auto uniform = [&rng] { return static_cast<float>(rng() >> 40) * 0x1p-24f; };
    auto sphere = [&](std::vector<Vec3>& v) {
        for (Vec3& d : v) {
            const float z = 1 - 2 * uniform(), phi = 2 * kPiF * uniform(), r = std::sqrt(std::max(0.0f, 1 - z * z));
            d = {r * std::cos(phi), r * std::sin(phi), z};
        }
    };
    BenchPoints points{std::vector<Vec2>(n), std::vector<Vec3>(n), std::vector<Vec3>(normals ? n : 0),
                       std::vector<float>(normals ? n : 0)};
    for (Vec2& u : points.us) u = {uniform(), uniform()};
    for (float& c : points.choices) c = uniform();
    sphere(points.directions);
    sphere(points.normals);
    // Group g takes normal g; downwards, so that every source is read before it is overwritten.
    for (size_t i = points.normals.size(); i-- > 0;) points.normals[i] = points.normals[i / samples_per_normal];
    return points;
}

// The guided sampler's speedups over a reference sampler: its time over the guided one's
// (single and batch calls) or, for the build, the median builds' ratio.
struct Speedups {
    double build = 0, sample = 0, pdf = 0, batch_sample = 0, batch_pdf = 0;
};

// Medians over the repeats: per sampler, and the speedups over the textbook sampler and
// over the pbrt-style one.
struct BenchResult {
    std::vector<Timing> timings;
    Speedups textbook, pbrt;
    // The batch calls' speedups: sample_many over single samples, lookup_many over single
    // pdf calls (which leave the radiance out) and over single lookups (the same work).
    double batch_over_single_sample = 0, batch_over_single_pdf = 0, batch_over_single_lookup = 0;
};

// Sampling and pdf times of the samplers, back to back in each repeat, so that the
// ratios compare like with like on a machine whose speed drifts. The guided sampler
// goes through its view, as a renderer's hot loop uses it (the view's flat arrays are
// read once, not rebuilt from the map at every call); guided-batch is the same sampler
// through sample_many and lookup_many (the latter finds the radiance too), as a
// wavefront renderer would call it.
enum Call { kSample, kTextbookSample, kPdf, kTextbookPdf, kBatchSample, kBatchLookup, kLookup, kPbrtSample, kPbrtPdf };
constexpr int kCalls = 9;
struct CallTimes {
    std::vector<double> times[kCalls];
    std::vector<double> ratios[kCalls][kCalls];  // [a][b]: time a over time b, per repeat
    double median_ratio(Call a, Call b) const { return median(ratios[a][b]); }
};

CallTimes time_calls(const EnvMap& guided, const reference::TextbookEnvMap& textbook,
                     const reference::PbrtStyleEnvMap& pbrt, const BenchPoints& points, int repeats, Progress& progress,
                     int& step) {
    const auto sample_cost = [&](const auto& sampler) {
        return ns_per_call(points.us, [&](Vec2 u) { return sampler.sample(u); });
    };
    const auto pdf_cost = [&](const auto& sampler) {
        return ns_per_call(points.directions, [&](Vec3 d) { return sampler.pdf(d); });
    };
    const EnvMapView view = guided.view();
    const auto lookup_cost = [&] { return ns_per_call(points.directions, [&](Vec3 d) { return view.lookup(d); }); };
    BatchInputs batch(points.us, points.directions);
    CallTimes c;
    for (int r = 0; r < repeats; ++r) {
        throw_if_interrupted();
        const double t[kCalls] = {sample_cost(view),  sample_cost(textbook),   pdf_cost(view),
                                  pdf_cost(textbook), batch.sample_cost(view), batch.lookup_cost(view),
                                  lookup_cost(),      sample_cost(pbrt),       pdf_cost(pbrt)};
        for (int a = 0; a < kCalls; ++a) {
            c.times[a].push_back(t[a]);
            for (int b = 0; b < kCalls; ++b) c.ratios[a][b].push_back(t[a] / t[b]);
        }
        progress.update(++step);
    }
    return c;
}

BenchResult measure(const BenchMap& map, const EnvMapOptions& options, const BenchPoints& points, int repeats) {
    Progress progress("bench", 4 * repeats);
    int step = 0;
    const RgbImage& image = map.image;
    const auto [guided, guided_build] = build_repeatedly<EnvMap, RgbImage>(
        image, repeats, [&](RgbImage& copy) { return build_env_map(std::move(copy), options, &interrupted()); },
        progress, step);
    const auto [textbook, textbook_build] = build_repeatedly<reference::TextbookEnvMap, RgbImage>(
        image, repeats, [&](RgbImage&) { return reference::TextbookEnvMap(image, options); }, progress, step);
    EnvMapOptions square_options = options;
    square_options.mapping = Mapping::equal_area;
    const auto [pbrt, pbrt_build] = build_repeatedly<reference::PbrtStyleEnvMap, RgbImage>(
        map.square, repeats, [&](RgbImage&) { return reference::PbrtStyleEnvMap(map.square, square_options); },
        progress, step);
    const CallTimes c = time_calls(*guided, *textbook, *pbrt, points, repeats, progress, step);
    const double texels = static_cast<double>(image.width) * image.height;
    const double guided_bytes = guided->distribution().bytes() / texels;
    const double square_texels = static_cast<double>(map.square.width) * map.square.height;
    BenchResult result;
    result.timings = {
        {"guided", guided_build, median(c.times[kSample]), median(c.times[kPdf]), guided_bytes},
        {"guided-batch", guided_build, median(c.times[kBatchSample]), median(c.times[kBatchLookup]), guided_bytes},
        {"textbook", textbook_build, median(c.times[kTextbookSample]), median(c.times[kTextbookPdf]),
         textbook->distribution_bytes() / texels},
        {"pbrt-v4-style", pbrt_build, median(c.times[kPbrtSample]), median(c.times[kPbrtPdf]),
         pbrt->distribution_bytes() / square_texels}};
    result.textbook = {textbook_build / guided_build, c.median_ratio(kTextbookSample, kSample),
                       c.median_ratio(kTextbookPdf, kPdf), c.median_ratio(kTextbookSample, kBatchSample),
                       c.median_ratio(kTextbookPdf, kBatchLookup)};
    result.pbrt = {pbrt_build / guided_build * texels / square_texels, c.median_ratio(kPbrtSample, kSample),
                   c.median_ratio(kPbrtPdf, kPdf), c.median_ratio(kPbrtSample, kBatchSample),
                   c.median_ratio(kPbrtPdf, kBatchLookup)};
    result.batch_over_single_sample = c.median_ratio(kSample, kBatchSample);
    result.batch_over_single_pdf = c.median_ratio(kPdf, kBatchLookup);
    result.batch_over_single_lookup = c.median_ratio(kLookup, kBatchLookup);
    return result;
}

// The binned sampler against today's EnvMap, plain and compensated (the binned one
// samples texels by the plain map's density; the compensated one is what a global table
// holds). Kinds of call: single sample, single pdf, sample_many, lookup_many; every
// sampler gets the same (u, normal) and (direction, normal) inputs, today's ignoring the
// normal, so that only the sampler differs.
enum Today { kPlain, kCompensated };
constexpr const char* kCallNames[4] = {"sample", "pdf", "batch_sample", "batch_lookup"};
struct BinnedResult {
    uint32_t bins = 0, cells_w = 0, cells_h = 0, samples_per_normal = 1;
    double build_ms[3] = {}, bytes[3] = {};  // plain, compensated, bins (bins alone)
    double ns[3][4] = {};                    // per sampler and kind of call
    double ratio[2][4] = {};                 // binned over plain, over compensated
    double lookup_ns[3] = {};                // per sampler: a single lookup (pdf and radiance)
    double batch_speedup[3][3] = {};         // per sampler: single sample, pdf, lookup / batch
    // A single pdf call in a bin picked beforehand (a renderer picks once per shading
    // point and weighs its BSDF samples in that bin), and its time over the plain pdf's.
    double pdf_in_bin_ns = 0, pdf_in_bin_ratio = 0;
    // A bin's sample over the global sampler's on the same density (same_density_ratios):
    // least, median and most over the bins measured, and how many (plain bins, and a bin
    // two of the normals share, counted once).
    double same_density[3] = {};
    uint32_t same_density_bins = 0;
};

// ns per call of the three samplers, back to back in each repeat; lobe class 0.
void time_binned_calls(const EnvMapView (&today)[2], const BinnedEnvMapView& binned, const BenchPoints& points,
                       int repeats, Progress& progress, int& step, BinnedResult& result) {
    struct Input {
        Vec2 u;
        Vec3 direction, normal;
        float choice;
    };
    std::vector<Input> inputs;
    for (size_t i = 0; i < points.us.size(); ++i)
        inputs.push_back({points.us[i], points.directions[i], points.normals[i], points.choices[i]});
    BatchInputs batch(points.us, points.directions, points.normals, points.choices);
    std::vector<std::pair<uint32_t, Vec3>> picked;  // (class_bin, direction)
    for (const Input& in : inputs) picked.emplace_back(pick_bin(binned.blend({in.normal}, 0), in.choice), in.direction);
    std::vector<double> ns[3][4], ratio[2][4], lookup_ns[3], speedup[3][3], pdf_in_bin, pdf_in_bin_ratio;
    for (int r = 0; r < repeats; ++r) {
        throw_if_interrupted();
        double t[3][4], lookup[3];
        for (int k = 0; k < 2; ++k) {
            t[k][0] = ns_per_call(inputs, [&](const Input& in) { return today[k].sample(in.u); });
            t[k][1] = ns_per_call(inputs, [&](const Input& in) { return today[k].pdf(in.direction); });
            t[k][2] = batch.sample_cost(today[k]);
            t[k][3] = batch.lookup_cost(today[k]);
            lookup[k] = ns_per_call(inputs, [&](const Input& in) { return today[k].lookup(in.direction); });
        }
        t[2][0] = ns_per_call(inputs, [&](const Input& in) { return binned.sample({in.normal}, 0, in.choice, in.u); });
        t[2][1] =
            ns_per_call(inputs, [&](const Input& in) { return binned.pdf({in.normal}, 0, in.choice, in.direction); });
        t[2][2] = batch.sample_cost(binned, 0);
        t[2][3] = batch.lookup_cost(binned, 0);
        lookup[2] = ns_per_call(
            inputs, [&](const Input& in) { return binned.lookup({in.normal}, 0, in.choice, in.direction); });
        pdf_in_bin.push_back(ns_per_call(
            picked, [&](const std::pair<uint32_t, Vec3>& p) { return binned.bin_at(p.first, 1).pdf(p.second); }));
        pdf_in_bin_ratio.push_back(pdf_in_bin.back() / t[kPlain][1]);
        for (int c = 0; c < 4; ++c) {
            for (int k = 0; k < 3; ++k) ns[k][c].push_back(t[k][c]);
            for (int k = 0; k < 2; ++k) ratio[k][c].push_back(t[2][c] / t[k][c]);
        }
        for (int k = 0; k < 3; ++k) {
            lookup_ns[k].push_back(lookup[k]);
            speedup[k][0].push_back(t[k][0] / t[k][2]), speedup[k][1].push_back(t[k][1] / t[k][3]);
            speedup[k][2].push_back(lookup[k] / t[k][3]);
        }
        progress.update(++step);
    }
    for (int c = 0; c < 4; ++c) {
        for (int k = 0; k < 3; ++k) result.ns[k][c] = median(ns[k][c]);
        for (int k = 0; k < 2; ++k) result.ratio[k][c] = median(ratio[k][c]);
    }
    result.pdf_in_bin_ns = median(pdf_in_bin), result.pdf_in_bin_ratio = median(pdf_in_bin_ratio);
    for (int k = 0; k < 3; ++k) {
        result.lookup_ns[k] = median(lookup_ns[k]);
        for (int c = 0; c < 3; ++c) result.batch_speedup[k][c] = median(speedup[k][c]);
    }
}

// A bin's sample against the global sampler over the same density, which sets aside where
// the density puts its samples (a bin's spread over a hemisphere touches more memory than
// a compensated map crowded onto a sun) and leaves the representation: the bins nearest
// these normals (lobe class 0, head-on), each rebuilt as a plain global map whose texels
// hold the bin's pdf at their centres. A texel's mass is its value times its row's weight
// (sin theta at the row's centre, or 1), and the bin's pdf there is its image density over
// that weight, so each texel gets the bin's probability up to the fixed point's rounding.
constexpr Vec3 kSameDensityNormals[] = {
    {0, 0, 1}, {1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, -1}, {0.57735f, 0.57735f, 0.57735f}};

EnvMap density_as_map(const BinView& bin, const EnvMap& plain) {
    const std::vector<float> pdf = pdf_image(bin, plain.width(), plain.height());
    RgbImage image{plain.width(), plain.height(), RgbPixels(pdf.size())};
    for (size_t i = 0; i < pdf.size(); ++i) image.pixels[i] = {pdf[i], pdf[i], pdf[i]};
    // A map whose compensation fell back (a constant one) keeps it enabled in its options.
    EnvMapOptions options = plain.options();
    options.compensation.enabled = false;
    return build_env_map(std::move(image), options, &interrupted());
}

// Per bin, the median over repeats of its sample's time over the global map's (the two in
// turns at bench's points); the least, median and most over the bins into `result`.
void same_density_ratios(const BinnedEnvMap& binned, const BenchPoints& points, int repeats, Progress& progress,
                         int& step, BinnedResult& result) {
    const BinnedEnvMapView view = binned.view();
    std::vector<double> per_bin;
    std::vector<const uint32_t*> seen;  // a coarse grid puts several of the normals in one bin
    for (Vec3 normal : kSameDensityNormals) {
        const BinView bin = view.nearest_bin(normal, 0);
        if (!bin.plain && std::find(seen.begin(), seen.end(), bin.cells.start) == seen.end()) {
            seen.push_back(bin.cells.start);
            const EnvMap global = density_as_map(bin, binned.radiance_map());
            const EnvMapView global_view = global.view();
            std::vector<double> ratios;
            for (int r = 0; r < repeats; ++r) {
                throw_if_interrupted();
                const double own = ns_per_call(points.us, [&](Vec2 u) { return bin.sample(u); });
                ratios.push_back(own / ns_per_call(points.us, [&](Vec2 u) { return global_view.sample(u); }));
            }
            per_bin.push_back(median(ratios));
        }
        progress.update(++step);
    }
    result.same_density_bins = static_cast<uint32_t>(per_bin.size());
    if (per_bin.empty()) return;
    const auto [least, most] = std::minmax_element(per_bin.begin(), per_bin.end());
    result.same_density[0] = *least, result.same_density[1] = median(per_bin), result.same_density[2] = *most;
}

BinnedResult measure_binned(const RgbImage& image, const EnvMapOptions& mapped, uint32_t bins,
                            const BenchPoints& points, int repeats) {
    Progress progress("bench --bins", 4 * repeats + static_cast<int>(std::size(kSameDensityNormals)));
    int step = 0;
    BinnedResult result;
    std::unique_ptr<EnvMap> today[2];
    for (int k : {kPlain, kCompensated}) {
        EnvMapOptions options = mapped;
        options.compensation.enabled = k == kCompensated;
        std::tie(today[k], result.build_ms[k]) = build_repeatedly<EnvMap, RgbImage>(
            image, repeats, [&](RgbImage& copy) { return build_env_map(std::move(copy), options, &interrupted()); },
            progress, step);
        result.bytes[k] = static_cast<double>(today[k]->distribution().bytes()) +
                          static_cast<double>(sizeof(Rgb)) * image.width * image.height;
    }
    BinnedOptions options;
    options.bins_per_side = bins_per_side(bins);
    const auto [binned, bins_ms] = build_repeatedly<BinnedEnvMap, EnvMap>(
        *today[kPlain], repeats, [&](EnvMap& copy) { return build_bins(std::move(copy), options, &interrupted()); },
        progress, step);
    result.bins = bins;
    result.cells_w = binned->layout().cell_columns, result.cells_h = binned->layout().cell_rows;
    result.build_ms[2] = bins_ms;
    result.bytes[2] = static_cast<double>(binned->bytes());
    const BinnedEnvMapView binned_view = binned->view();
    const EnvMapView views[2] = {today[kPlain]->view(), today[kCompensated]->view()};
    time_binned_calls(views, binned_view, points, repeats, progress, step, result);
    same_density_ratios(*binned, points, repeats, progress, step, result);
    return result;
}

// What a binned precompute costs over today's (a plain map, then its bins, against the
// compensated map), and the bins' memory over today's map (density and radiance).
double binned_build_ratio(const BinnedResult& b) {
    return (b.build_ms[kPlain] + b.build_ms[2]) / b.build_ms[kCompensated];
}
double binned_memory_ratio(const BinnedResult& b) { return b.bytes[2] / b.bytes[kCompensated]; }
constexpr const char* kBinnedSamplers[3] = {"plain", "compensated", "binned"};

nlohmann::json binned_json(const BinnedResult& b) {
    nlohmann::json j = {{"bins", b.bins},
                        {"cells", {b.cells_w, b.cells_h}},
                        {"lobe_class", 0},
                        {"samples_per_normal", b.samples_per_normal}};
    for (int k = 0; k < 3; ++k) {
        nlohmann::json s = {{"sampler", kBinnedSamplers[k]}, {"build_ms", b.build_ms[k]}, {"bytes", b.bytes[k]}};
        for (int c = 0; c < 4; ++c) s[std::string("ns_per_") + kCallNames[c]] = b.ns[k][c];
        s["ns_per_lookup"] = b.lookup_ns[k];
        s["batch_over_single"] = {{"sample", b.batch_speedup[k][0]},
                                  {"lookup_over_pdf", b.batch_speedup[k][1]},
                                  {"lookup_over_lookup", b.batch_speedup[k][2]}};
        j["samplers"].push_back(s);
    }
    for (int k = 0; k < 2; ++k)
        for (int c = 0; c < 4; ++c) j[std::string("binned_over_") + kBinnedSamplers[k]][kCallNames[c]] = b.ratio[k][c];
    j["binned_over_compensated"]["build"] = binned_build_ratio(b);
    j["binned_over_compensated"]["memory"] = binned_memory_ratio(b);
    j["pdf_in_picked_bin"] = {{"ns", b.pdf_in_bin_ns}, {"over_plain_pdf", b.pdf_in_bin_ratio}};
    j["sample_over_global_same_density"] = {{"least", b.same_density[0]},
                                            {"median", b.same_density[1]},
                                            {"most", b.same_density[2]},
                                            {"bins", b.same_density_bins}};
    return j;
}

void print_binned_text(const BinnedResult& b) {
    std::printf(
        "binned bins=%u cells=%ux%u lobe_class=0 samples_per_normal=%u (bins' build_ms and bytes exclude their "
        "plain map)\n",
        b.bins, b.cells_w, b.cells_h, b.samples_per_normal);
    for (int k = 0; k < 3; ++k)
        std::printf(
            "sampler=%s build_ms=%.1f ns_per_sample=%.1f ns_per_pdf=%.1f ns_per_lookup=%.1f ns_per_batch_sample=%.1f "
            "ns_per_batch_lookup=%.1f bytes=%.0f batch_over_single sample=%.2fx lookup_over_pdf=%.2fx "
            "lookup_over_lookup=%.2fx\n",
            kBinnedSamplers[k], b.build_ms[k], b.ns[k][0], b.ns[k][1], b.lookup_ns[k], b.ns[k][2], b.ns[k][3],
            b.bytes[k], b.batch_speedup[k][0], b.batch_speedup[k][1], b.batch_speedup[k][2]);
    for (int k = 0; k < 2; ++k) {
        std::printf("binned_over_%s sample=%.2fx pdf=%.2fx batch_sample=%.2fx batch_lookup=%.2fx", kBinnedSamplers[k],
                    b.ratio[k][0], b.ratio[k][1], b.ratio[k][2], b.ratio[k][3]);
        if (k == kCompensated)
            std::printf(" build=%.2fx memory=%.2f%%", binned_build_ratio(b), 100 * binned_memory_ratio(b));
        std::printf("\n");
    }
    std::printf("binned_pdf_in_picked_bin ns=%.1f over_plain_pdf=%.2fx\n", b.pdf_in_bin_ns, b.pdf_in_bin_ratio);
    std::printf("binned_sample_over_global_same_density median=%.2fx least=%.2fx most=%.2fx bins=%u\n",
                b.same_density[1], b.same_density[0], b.same_density[2], b.same_density_bins);
    std::printf(
        "(binned over today's: time or bytes, median of the ratios within each repeat; build: plain map "
        "plus bins over the compensated map; pdf in picked bin: the bin picked beforehand, once per shading point; "
        "same density: the bins nearest +-x, +-y, +-z and the diagonal, each against its density as a global map)\n");
}

void print_bench_json(const BenchArgs& args, const BenchMap& map, const BenchResult& result,
                      const std::optional<BinnedResult>& binned) {
    nlohmann::json j = {{"map", map.name},
                        {"mapping", std::string(to_string(map.options.mapping))},
                        {"width", map.image.width},
                        {"height", map.image.height},
                        {"compensated", !args.no_compensate},
                        {"repeats", args.repeats},
                        {"samples", args.samples},
                        {"cpu", cpu_name()},
                        {"batch_paths",
                         {{"lookup_many", std::string(to_string(batch_paths().lookup))},
                          {"sample_many", std::string(to_string(batch_paths().sample))},
                          {"lanes", std::string(to_string(batch_paths().lanes))},
                          {"forced", batch_paths().forced},
                          {"unavailable", batch_paths().unavailable}}}};
    for (const Timing& t : result.timings)
        j["samplers"].push_back({{"sampler", t.sampler},
                                 {"build_ms", t.build_ms},
                                 {"ns_per_sample", t.ns_per_sample},
                                 {"ns_per_pdf", t.ns_per_pdf},
                                 {"bytes_per_texel", t.bytes_per_texel}});
    for (const auto& [key, v] : {std::pair{"speedup_vs_textbook", result.textbook}, {"speedup_vs_pbrt", result.pbrt}})
        j[key] = {{"build", v.build},
                  {"sample", v.sample},
                  {"pdf", v.pdf},
                  {"batch_sample", v.batch_sample},
                  {"batch_pdf", v.batch_pdf}};
    j["pbrt_square"] = {map.square.width, map.square.height};
    j["batch_over_single"] = {{"sample", result.batch_over_single_sample},
                              {"lookup_over_pdf", result.batch_over_single_pdf},
                              {"lookup_over_lookup", result.batch_over_single_lookup}};
    if (binned) j["binned"] = binned_json(*binned);
    std::cout << j.dump(2) << "\n";
}

void print_bench_text(const BenchArgs& args, const BenchMap& map, const BenchResult& result,
                      const std::optional<BinnedResult>& binned) {
    std::printf("cpu=%s\nbatch_paths %s\n", cpu_name().c_str(), batch_paths_summary().c_str());
    std::printf("map=%s size=%ux%u mapping=%s compensated=%d repeats=%d samples=%u (medians)\n", map.name.c_str(),
                map.image.width, map.image.height, std::string(to_string(map.options.mapping)).c_str(),
                !args.no_compensate, args.repeats, args.samples);
    for (const Timing& t : result.timings)
        std::printf("sampler=%s build_ms=%.1f ns_per_sample=%.1f ns_per_pdf=%.1f bytes_per_texel=%.2f\n",
                    t.sampler.c_str(), t.build_ms, t.ns_per_sample, t.ns_per_pdf, t.bytes_per_texel);
    for (const auto& [name, v] : {std::pair{"textbook", result.textbook}, {"pbrt", result.pbrt}})
        std::printf("speedup_vs_%s build=%.2fx sample=%.2fx pdf=%.2fx batch_sample=%.2fx batch_pdf=%.2fx\n", name,
                    v.build, v.sample, v.pdf, v.batch_sample, v.batch_pdf);
    std::printf(
        "(sample, pdf: median of the ratios within each repeat; pbrt-v4-style on an equal-area %ux%u square, its "
        "build per texel)\n",
        map.square.width, map.square.height);
    std::printf(
        "batch_over_single sample=%.2fx lookup_over_pdf=%.2fx lookup_over_lookup=%.2fx (guided-batch against guided: "
        "single sample over sample_many, single pdf, and single lookup (pdf and radiance), over lookup_many; median "
        "of the ratios within each repeat)\n",
        result.batch_over_single_sample, result.batch_over_single_pdf, result.batch_over_single_lookup);
    if (binned) print_binned_text(*binned);
}

void run_bench(const BenchArgs& args) {
    const BenchMap map = bench_map(args);
    EnvMapOptions options = map.options;
    options.compensation.enabled = !args.no_compensate;
    const BenchPoints points = bench_points(args.samples, args.bins > 0, args.samples_per_normal);
    const BenchResult result = measure(map, options, points, args.repeats);
    std::optional<BinnedResult> binned;
    if (args.bins > 0) {
        binned = measure_binned(map.image, map.options, args.bins, points, args.repeats);
        binned->samples_per_normal = args.samples_per_normal;
    }
    if (args.json)
        print_bench_json(args, map, result, binned);
    else
        print_bench_text(args, map, result, binned);
}

}  // namespace

Subcommand add_bench(CLI::App& app) {
    auto args = std::make_shared<BenchArgs>();
    CLI::App* sub = app.add_subcommand(
        "bench",
        "Time building and sampling, guided-CDF sampler versus the textbook sampler and a pbrt-v4-style one (medians "
        "of repeats)");
    add_bench_flags(*sub, *args);
    add_threads_flag(*sub);
    return {sub, [args] { run_bench(*args); }};
}

}  // namespace envmis::cli
