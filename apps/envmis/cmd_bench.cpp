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

}  // namespace

Subcommand add_bench(CLI::App& app) {
    struct Args {
        std::string input, size = "8192x4096";
        int repeats = 5;
        uint32_t samples = 1u << 20;
        bool json = false, no_compensate = false;
    };
    auto args = std::make_shared<Args>();
    CLI::App* sub = app.add_subcommand(
        "bench", "Time building and sampling, guided-CDF sampler versus the textbook sampler (medians of repeats)");
    sub->add_option("input", args->input, "HDR image or table (default: a synthetic sky with a small sun)");
    sub->add_option("--size", args->size, "Size of the synthetic sky, WxH")->capture_default_str();
    sub->add_option("--repeats", args->repeats, "Repeats of each measurement")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    sub->add_option("--samples", args->samples, "Samples and pdf evaluations per repeat")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    sub->add_flag("--no-compensate", args->no_compensate, "Measure the uncompensated density");
    sub->add_flag("--json", args->json, "Print one JSON object instead of text lines");
    return {
        sub, [args] {
            RgbImage image;
            std::string map_name;
            if (args->input.empty()) {
                unsigned w = 0, h = 0;
                char x = 0;
                if (std::sscanf(args->size.c_str(), "%u%c%u", &w, &x, &h) != 3 || x != 'x' || !w || !h ||
                    w > kMaxCells1D || h > kMaxCells1D)
                    throw std::runtime_error("--size '" + args->size + "': expected WxH, each 1 to 65536");
                image = reference::synthetic_sky(w, h);
                map_name = "synthetic-sky";
            } else {
                MapFlags flags;
                flags.no_compensate = true;
                image = to_image(load_map(args->input, flags).map.radiance());
                map_name = args->input;
            }
            EnvMapOptions options;
            options.compensation.enabled = !args->no_compensate;

            std::mt19937_64 rng(7);
            auto uniform = [&rng] { return static_cast<float>(rng() >> 40) * 0x1p-24f; };
            std::vector<Vec2> us(args->samples);
            for (Vec2& u : us) u = {uniform(), uniform()};
            std::vector<Vec3> directions(args->samples);
            for (Vec3& d : directions) {
                const float z = 1 - 2 * uniform(), phi = 2 * kPiF * uniform(), r = std::sqrt(std::max(0.0f, 1 - z * z));
                d = {r * std::cos(phi), r * std::sin(phi), z};
            }

            Progress progress("bench", 3 * args->repeats);
            int step = 0;
            const auto [guided, guided_build] = build_repeatedly<EnvMap>(
                image, args->repeats, [&](RgbImage& copy) { return EnvMap(std::move(copy), options); }, progress, step);
            const auto [textbook, textbook_build] = build_repeatedly<reference::TextbookEnvMap>(
                image, args->repeats, [&](RgbImage&) { return reference::TextbookEnvMap(image, options); }, progress,
                step);
            // Sampling and pdf times: the two samplers back to back in each repeat, so
            // that the ratios compare like with like on a machine whose speed drifts.
            const auto sample_cost = [&](const auto& sampler) {
                return ns_per_call(us, [&](Vec2 u) {
                    const EnvSample s = sampler.sample(u);
                    return s.pdf + s.direction.x + s.radiance.r;
                });
            };
            const auto pdf_cost = [&](const auto& sampler) {
                return ns_per_call(directions, [&](Vec3 d) { return sampler.pdf(d); });
            };
            // The guided sampler through its view, as a renderer's hot loop uses it: the
            // view's flat arrays are read once, not rebuilt from the map at every call.
            // guided-batch is the same sampler through sample_many and lookup_many (the
            // latter finds the radiance too), as a wavefront renderer would call it.
            const EnvMapView view = guided->view();
            BatchInputs batch(us, directions);
            std::vector<double> times[6], ratios[4];
            for (int r = 0; r < args->repeats; ++r) {
                const double t[6] = {sample_cost(view),   sample_cost(*textbook),  pdf_cost(view),
                                     pdf_cost(*textbook), batch.sample_cost(view), batch.lookup_cost(view)};
                for (int k = 0; k < 6; ++k) times[k].push_back(t[k]);
                ratios[0].push_back(t[1] / t[0]);
                ratios[1].push_back(t[3] / t[2]);
                ratios[2].push_back(t[1] / t[4]);
                ratios[3].push_back(t[3] / t[5]);
                progress.update(++step);
            }
            const double texels = static_cast<double>(image.width) * image.height;
            const double guided_bytes = guided->distribution().bytes() / texels;
            const std::vector<Timing> timings = {
                {"guided", guided_build, median(times[0]), median(times[2]), guided_bytes},
                {"guided-batch", guided_build, median(times[4]), median(times[5]), guided_bytes},
                {"textbook", textbook_build, median(times[1]), median(times[3]),
                 textbook->distribution_bytes() / texels}};
            const double build_speedup = textbook_build / guided_build, sample_speedup = median(ratios[0]),
                         pdf_speedup = median(ratios[1]), batch_sample_speedup = median(ratios[2]),
                         batch_pdf_speedup = median(ratios[3]);
            if (args->json) {
                nlohmann::json j = {{"map", map_name},          {"width", image.width},
                                    {"height", image.height},   {"compensated", !args->no_compensate},
                                    {"repeats", args->repeats}, {"samples", args->samples}};
                for (const Timing& t : timings)
                    j["samplers"].push_back({{"sampler", t.sampler},
                                             {"build_ms", t.build_ms},
                                             {"ns_per_sample", t.ns_per_sample},
                                             {"ns_per_pdf", t.ns_per_pdf},
                                             {"bytes_per_texel", t.bytes_per_texel}});
                j["speedup_vs_textbook"] = {{"build", build_speedup},
                                            {"sample", sample_speedup},
                                            {"pdf", pdf_speedup},
                                            {"batch_sample", batch_sample_speedup},
                                            {"batch_pdf", batch_pdf_speedup}};
                std::cout << j.dump(2) << "\n";
                return;
            }
            std::printf("map=%s size=%ux%u compensated=%d repeats=%d samples=%u (medians)\n", map_name.c_str(),
                        image.width, image.height, !args->no_compensate, args->repeats, args->samples);
            for (const Timing& t : timings)
                std::printf("sampler=%s build_ms=%.1f ns_per_sample=%.1f ns_per_pdf=%.1f bytes_per_texel=%.2f\n",
                            t.sampler.c_str(), t.build_ms, t.ns_per_sample, t.ns_per_pdf, t.bytes_per_texel);
            std::printf(
                "speedup_vs_textbook build=%.2fx sample=%.2fx pdf=%.2fx batch_sample=%.2fx "
                "batch_pdf=%.2fx (sample, pdf: median of the ratios within each repeat)\n",
                build_speedup, sample_speedup, pdf_speedup, batch_sample_speedup, batch_pdf_speedup);
        }};
}

}  // namespace envmis::cli
