// envmis bench [IN | --size WxH]: build and sampling speed of the guided-CDF sampler
// against the textbook float-CDF sampler, measured in the same run on the same map.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <random>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli.h"
#include "reference.h"

namespace envmis::cli {
namespace {

struct Timing {
    std::string sampler;
    double build_ms = 0, ns_per_sample = 0, ns_per_pdf = 0, bytes_per_texel = 0;
};

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

// ns per call of `call` over all inputs, once; the results go to a sink the optimiser
// cannot drop.
template <class Input, class Call>
double ns_per_call(const std::vector<Input>& inputs, Call&& call) {
    volatile float sink = 0;
    float sum = 0;
    const auto start = std::chrono::steady_clock::now();
    for (const Input& in : inputs) sum += call(in);
    sink = sink + sum;
    return milliseconds_since(start) * 1e6 / static_cast<double>(inputs.size());
}

// The inputs of sample_many and lookup_many: one array per coordinate, and outputs for
// a batch of kBatch.
constexpr uint32_t kBatch = 64;
struct BatchInputs {
    std::vector<float> ux, uy, x, y, z;
    std::vector<float> out = std::vector<float>(7 * kBatch);

    BatchInputs(const std::vector<Vec2>& us, const std::vector<Vec3>& directions) {
        for (const Vec2 u : us) ux.push_back(u.x), uy.push_back(u.y);
        for (const Vec3 d : directions) x.push_back(d.x), y.push_back(d.y), z.push_back(d.z);
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
            sample_many(view, {ux.data() + first, uy.data() + first},
                        {o, o + kBatch, o + 2 * kBatch, o + 3 * kBatch, o + 4 * kBatch, o + 5 * kBatch, o + 6 * kBatch},
                        n);
        });
    }
    double lookup_cost(const EnvMapView& view) {
        return ns_per_item(x.size(), [&](size_t first, uint32_t n, float* o) {
            lookup_many(view, {x.data() + first, y.data() + first, z.data() + first},
                        {o, o + kBatch, o + 2 * kBatch, o + 3 * kBatch}, n);
        });
    }
};

// A sampler built `repeats` times (the last one kept) and the median build time.
template <class Sampler>
std::pair<std::unique_ptr<Sampler>, double> build_repeatedly(const RgbImage& image, int repeats,
                                                             const std::function<Sampler(RgbImage&)>& build,
                                                             Progress& progress, int& step) {
    std::vector<double> builds;
    std::unique_ptr<Sampler> sampler;
    for (int r = 0; r < repeats; ++r) {
        RgbImage copy = image;
        const auto start = std::chrono::steady_clock::now();
        sampler = std::make_unique<Sampler>(build(copy));
        builds.push_back(milliseconds_since(start));
        progress.update(++step);
    }
    return {std::move(sampler), median(builds)};
}

// The arguments of `envmis bench`.
struct BenchArgs {
    std::string input, size = "8192x4096";
    int repeats = 5;
    uint32_t samples = 1u << 20;
    bool json = false, no_compensate = false;
};

// At most 2^26 samples a repeat: the points and the batch arrays take about 40 bytes a
// sample (2.7 GB at the limit); at most 1000 repeats.
constexpr uint32_t kMaxBenchSamples = 1u << 26;
constexpr int kMaxRepeats = 1000;

void add_bench_flags(CLI::App& sub, BenchArgs& args) {
    sub.add_option("input", args.input, "HDR image or table (default: a synthetic sky with a small sun)");
    sub.add_option("--size", args.size, "Size of the synthetic sky, WxH, each side 1 to 65536")
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
    sub.add_flag("--json", args.json, "Print one JSON object instead of text lines");
}

// The map measured: the input's radiance, or the synthetic sky of --size.
struct BenchMap {
    RgbImage image;
    std::string name;
};

BenchMap bench_map(const BenchArgs& args) {
    if (args.input.empty()) {
        const Size size = *parse_size(args.size, false);  // the flag's validator has accepted it
        return {reference::synthetic_sky(size.width, size.height), "synthetic-sky"};
    }
    MapFlags flags;
    flags.no_compensate = true;
    return {to_image(load_map(args.input, flags).map.radiance()), args.input};
}

// The random points every sampler is timed on: u for sampling, directions for the pdf.
struct BenchPoints {
    std::vector<Vec2> us;
    std::vector<Vec3> directions;
};

BenchPoints bench_points(uint32_t n) {
    std::mt19937_64 rng(7);
    auto uniform = [&rng] { return static_cast<float>(rng() >> 40) * 0x1p-24f; };
    BenchPoints points{std::vector<Vec2>(n), std::vector<Vec3>(n)};
    for (Vec2& u : points.us) u = {uniform(), uniform()};
    for (Vec3& d : points.directions) {
        const float z = 1 - 2 * uniform(), phi = 2 * kPiF * uniform(), r = std::sqrt(std::max(0.0f, 1 - z * z));
        d = {r * std::cos(phi), r * std::sin(phi), z};
    }
    return points;
}

// Medians over the repeats: per sampler, and the speedups over the textbook sampler.
struct BenchResult {
    std::vector<Timing> timings;
    double build = 0, sample = 0, pdf = 0, batch_sample = 0, batch_pdf = 0;  // speedups
};

// Sampling and pdf times of the two samplers, back to back in each repeat, so that the
// ratios compare like with like on a machine whose speed drifts. The guided sampler
// goes through its view, as a renderer's hot loop uses it (the view's flat arrays are
// read once, not rebuilt from the map at every call); guided-batch is the same sampler
// through sample_many and lookup_many (the latter finds the radiance too), as a
// wavefront renderer would call it. times: guided sample, textbook sample, guided pdf,
// textbook pdf, batch sample, batch lookup; ratios: textbook over the others.
struct CallTimes {
    std::vector<double> times[6], ratios[4];
};

CallTimes time_calls(const EnvMap& guided, const reference::TextbookEnvMap& textbook, const BenchPoints& points,
                     int repeats, Progress& progress, int& step) {
    const auto sample_cost = [&](const auto& sampler) {
        return ns_per_call(points.us, [&](Vec2 u) {
            const EnvSample s = sampler.sample(u);
            return s.pdf + s.direction.x + s.radiance.r;
        });
    };
    const auto pdf_cost = [&](const auto& sampler) {
        return ns_per_call(points.directions, [&](Vec3 d) { return sampler.pdf(d); });
    };
    const EnvMapView view = guided.view();
    BatchInputs batch(points.us, points.directions);
    CallTimes c;
    for (int r = 0; r < repeats; ++r) {
        const double t[6] = {sample_cost(view),  sample_cost(textbook),   pdf_cost(view),
                             pdf_cost(textbook), batch.sample_cost(view), batch.lookup_cost(view)};
        for (int k = 0; k < 6; ++k) c.times[k].push_back(t[k]);
        c.ratios[0].push_back(t[1] / t[0]);
        c.ratios[1].push_back(t[3] / t[2]);
        c.ratios[2].push_back(t[1] / t[4]);
        c.ratios[3].push_back(t[3] / t[5]);
        progress.update(++step);
    }
    return c;
}

BenchResult measure(const RgbImage& image, const EnvMapOptions& options, const BenchPoints& points, int repeats) {
    Progress progress("bench", 3 * repeats);
    int step = 0;
    const auto [guided, guided_build] = build_repeatedly<EnvMap>(
        image, repeats, [&](RgbImage& copy) { return EnvMap(std::move(copy), options); }, progress, step);
    const auto [textbook, textbook_build] = build_repeatedly<reference::TextbookEnvMap>(
        image, repeats, [&](RgbImage&) { return reference::TextbookEnvMap(image, options); }, progress, step);
    const CallTimes c = time_calls(*guided, *textbook, points, repeats, progress, step);
    const double texels = static_cast<double>(image.width) * image.height;
    const double guided_bytes = guided->distribution().bytes() / texels;
    BenchResult result;
    result.timings = {
        {"guided", guided_build, median(c.times[0]), median(c.times[2]), guided_bytes},
        {"guided-batch", guided_build, median(c.times[4]), median(c.times[5]), guided_bytes},
        {"textbook", textbook_build, median(c.times[1]), median(c.times[3]), textbook->distribution_bytes() / texels}};
    result.build = textbook_build / guided_build;
    result.sample = median(c.ratios[0]);
    result.pdf = median(c.ratios[1]);
    result.batch_sample = median(c.ratios[2]);
    result.batch_pdf = median(c.ratios[3]);
    return result;
}

void print_bench_json(const BenchArgs& args, const BenchMap& map, const BenchResult& result) {
    nlohmann::json j = {{"map", map.name},
                        {"width", map.image.width},
                        {"height", map.image.height},
                        {"compensated", !args.no_compensate},
                        {"repeats", args.repeats},
                        {"samples", args.samples}};
    for (const Timing& t : result.timings)
        j["samplers"].push_back({{"sampler", t.sampler},
                                 {"build_ms", t.build_ms},
                                 {"ns_per_sample", t.ns_per_sample},
                                 {"ns_per_pdf", t.ns_per_pdf},
                                 {"bytes_per_texel", t.bytes_per_texel}});
    j["speedup_vs_textbook"] = {{"build", result.build},
                                {"sample", result.sample},
                                {"pdf", result.pdf},
                                {"batch_sample", result.batch_sample},
                                {"batch_pdf", result.batch_pdf}};
    std::cout << j.dump(2) << "\n";
}

void print_bench_text(const BenchArgs& args, const BenchMap& map, const BenchResult& result) {
    std::printf("map=%s size=%ux%u compensated=%d repeats=%d samples=%u (medians)\n", map.name.c_str(), map.image.width,
                map.image.height, !args.no_compensate, args.repeats, args.samples);
    for (const Timing& t : result.timings)
        std::printf("sampler=%s build_ms=%.1f ns_per_sample=%.1f ns_per_pdf=%.1f bytes_per_texel=%.2f\n",
                    t.sampler.c_str(), t.build_ms, t.ns_per_sample, t.ns_per_pdf, t.bytes_per_texel);
    std::printf(
        "speedup_vs_textbook build=%.2fx sample=%.2fx pdf=%.2fx batch_sample=%.2fx "
        "batch_pdf=%.2fx (sample, pdf: median of the ratios within each repeat)\n",
        result.build, result.sample, result.pdf, result.batch_sample, result.batch_pdf);
}

void run_bench(const BenchArgs& args) {
    const BenchMap map = bench_map(args);
    EnvMapOptions options;
    options.compensation.enabled = !args.no_compensate;
    const BenchResult result = measure(map.image, options, bench_points(args.samples), args.repeats);
    if (args.json)
        print_bench_json(args, map, result);
    else
        print_bench_text(args, map, result);
}

}  // namespace

Subcommand add_bench(CLI::App& app) {
    auto args = std::make_shared<BenchArgs>();
    CLI::App* sub = app.add_subcommand(
        "bench", "Time building and sampling, guided-CDF sampler versus the textbook sampler (medians of repeats)");
    add_bench_flags(*sub, *args);
    return {sub, [args] { run_bench(*args); }};
}

}  // namespace envmis::cli
