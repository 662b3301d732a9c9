// envmis_example_pathtrace: a path tracer over triangle meshes (Embree) lit by an
// environment map sampled with envmis, to measure what envmis gives a renderer at equal
// samples and at equal time (scripts/renderer_compare.py runs the comparison and writes
// docs/results-renderer.md). scene.h has the scenes, integrator.h the light transport.
//
// Usage:
//   envmis_example_pathtrace TABLE -o OUT.exr [--scene NAME] [--obj FILE] [--env global|bins|pbrt]
//                            [--size WxH] [--spp N] [--time SECONDS] [--bounces N] [--light-samples N]
//                            [--bins-depth N [--beyond GLOBAL]] [--rotate DEGREES] [--seed S] [--threads T]
//                            [--reference REF.exr] [--profile] [--progress]
// The image is rendered in passes of one sample per pixel until N passes or, with --time,
// until that many seconds have passed (equal-time comparisons); it depends on the seed and
// the pass count only, not on the threads. Writes OUT.exr (linear), OUT.png (tone-mapped)
// and OUT.json: what was rendered, passes, seconds, rays per second per thread, the image's
// mean luminance with its standard error over passes, and with --profile the share of the
// threads' time spent in the environment's sample and lookup calls; with --reference, the
// relative MSE against that image (relative_mse). --rotate turns the sky about the map's up
// axis at render time (envmis/sampling/rotated.h), every technique alike; --light-samples N
// draws N environment samples a vertex (balance heuristic with counts); --bins-depth N
// samples the bins at the first N vertices of a path only and beyond them the binned
// table's plain density or, with --beyond, a global table of the same image (compensated).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#if defined(__x86_64__) || defined(__i386__)
#include <x86intrin.h>
#endif

#include "envmis/cpu.h"
#include "envmis/io/image_io.h"
#include "envmis/pictures/picture.h"
#include "envmis/table/table.h"
#include "example_support.h"
#include "integrator.h"

namespace pathtrace {

uint64_t ticks() noexcept {
#if defined(__x86_64__) || defined(__i386__)
    return __rdtsc();
#else
    return static_cast<uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count());
#endif
}

namespace {

enum class EnvKind { global, bins, pbrt };

struct Options {
    std::filesystem::path table, output;
    std::string scene = "objects";
    std::optional<std::filesystem::path> obj;
    EnvKind env = EnvKind::global;
    uint32_t width = 320, height = 240, spp = 16, threads = envmis::usable_cores();
    double seconds = 0;                           // 0: no time budget
    float rotate_degrees = 0;                     // the sky turned about the map's up axis
    uint32_t bins_depth = UINT32_MAX;             // vertices of a path that sample bins (--env bins)
    std::optional<std::filesystem::path> beyond;  // the global table sampled past bins_depth
    std::optional<std::filesystem::path> reference;
    uint64_t seed = 1;
    PathOptions path;
    bool profile = false, progress = false;
};

// ---------------------------------------------------------------------------------------
// The image, in passes

struct RenderResult {
    envmis::RgbImage image;
    uint32_t passes = 0;
    double seconds = 0, thread_seconds = 0;
    Counters counters;
    double mean_luminance = 0, standard_error = 0;  // over passes
};

// The image's accumulators across passes, and what each thread traced and how long it
// was busy.
struct Accumulator {
    std::vector<double> sum;  // RGB per pixel
    std::vector<double> pass_means;
    std::vector<Counters> counters;
    std::vector<double> busy;
};

inline constexpr uint32_t kTile = 16;

// One pass of one sample per pixel, 16x16 tiles shared among threads; returns the pass's
// mean luminance. `trace(camera_direction, rng, counters)` returns a sample's radiance;
// each (pass, pixel) has its own random stream, so the image does not depend on threads.
template <class Trace>
double render_pass(const Options& o, const examples::PinholeCamera& camera, Trace& trace, uint32_t pass,
                   Accumulator& a) {
    const uint32_t tiles_x = (o.width + kTile - 1) / kTile, tiles = tiles_x * ((o.height + kTile - 1) / kTile);
    std::atomic<uint32_t> next{0};
    std::vector<double> tile_luminance(tiles);
    auto work = [&](uint32_t thread) {
        const auto t0 = std::chrono::steady_clock::now();
        for (uint32_t t; (t = next.fetch_add(1)) < tiles;) {
            const uint32_t x0 = t % tiles_x * kTile, y0 = t / tiles_x * kTile;
            double luminance = 0;
            for (uint32_t y = y0; y < std::min(y0 + kTile, o.height); ++y)
                for (uint32_t x = x0; x < std::min(x0 + kTile, o.width); ++x) {
                    const size_t pixel = size_t{y} * o.width + x;
                    envmis::Pcg32 rng(o.seed, (uint64_t{pass} << 32) | pixel);
                    const Vec2 jitter = rng.uniform2();
                    const Vec3 d = camera.direction((static_cast<float>(x) + jitter.x) / static_cast<float>(o.width),
                                                    (static_cast<float>(y) + jitter.y) / static_cast<float>(o.height));
                    const Rgb c = trace(d, rng, a.counters[thread]);
                    a.sum[3 * pixel] += c.r, a.sum[3 * pixel + 1] += c.g, a.sum[3 * pixel + 2] += c.b;
                    luminance += envmis::luminance(c, {});
                }
            tile_luminance[t] = luminance;
        }
        a.busy[thread] += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    };
    {
        std::vector<std::jthread> pool;
        for (uint32_t t = 1; t < o.threads; ++t) pool.emplace_back(work, t);
        work(0);
    }
    double total = 0;
    for (double l : tile_luminance) total += l;
    return total / (static_cast<double>(o.width) * o.height);
}

// A progress bar on stderr: passes done of --spp, or time spent of --time.
void show_progress(const Options& o, uint32_t passes, double seconds) {
    const double done = o.seconds > 0 ? std::min(1.0, seconds / o.seconds) : static_cast<double>(passes) / o.spp;
    const int width = 30, filled = static_cast<int>(done * width);
    std::fprintf(stderr, "\r%s [%s%s] %3.0f%%  %u spp  %.1f s ", o.output.filename().string().c_str(),
                 std::string(static_cast<size_t>(filled), '#').c_str(),
                 std::string(static_cast<size_t>(width - filled), '.').c_str(), 100 * done, passes, seconds);
}

// The image and figures from a finished accumulator.
RenderResult finish(const Options& o, const Accumulator& a, double seconds) {
    RenderResult r;
    r.seconds = seconds;
    r.passes = static_cast<uint32_t>(a.pass_means.size());
    r.image = {o.width, o.height, envmis::RgbPixels(size_t{o.width} * o.height)};
    const float scale = 1.0f / static_cast<float>(r.passes);
    for (size_t i = 0; i < r.image.pixels.size(); ++i)
        r.image.pixels[i] = Rgb{static_cast<float>(a.sum[3 * i]), static_cast<float>(a.sum[3 * i + 1]),
                                static_cast<float>(a.sum[3 * i + 2])} *
                            scale;
    for (const Counters& c : a.counters) {
        r.counters.rays += c.rays, r.counters.samples += c.samples, r.counters.lookups += c.lookups;
        r.counters.sampler_ticks += c.sampler_ticks;
    }
    for (double b : a.busy) r.thread_seconds += b;
    double m = 0, m2 = 0;
    for (double p : a.pass_means) m += p, m2 += p * p;
    const auto n = static_cast<double>(r.passes);
    r.mean_luminance = m / n;
    r.standard_error = n > 1 ? std::sqrt(std::max(0.0, (m2 - m * m / n) / (n - 1)) / n) : 0;
    return r;
}

// Passes until --spp of them or, with --time, until the first that ends past the budget.
template <class Trace>
RenderResult render_passes(const Options& o, const examples::PinholeCamera& camera, Trace&& trace) {
    Accumulator a{std::vector<double>(3 * size_t{o.width} * o.height),
                  {},
                  std::vector<Counters>(o.threads),
                  std::vector<double>(o.threads)};
    const auto start = std::chrono::steady_clock::now();
    auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
    double shown = -1;
    for (uint32_t pass = 0; pass < o.spp && !(o.seconds > 0 && pass > 0 && elapsed() >= o.seconds); ++pass) {
        a.pass_means.push_back(render_pass(o, camera, trace, pass, a));
        if (o.progress && (elapsed() - shown >= 0.2 || pass + 1 == o.spp))
            show_progress(o, pass + 1, shown = elapsed());
    }
    if (o.progress) std::fputc('\n', stderr);
    return finish(o, a, elapsed());
}

template <class Environment>
RenderResult render(const Environment& env, const SceneDescription& scene, const RayScene& rays,
                    const std::vector<uint32_t>& lobes, const Options& o) {
    const examples::PinholeCamera camera(scene.camera.from, scene.camera.at, scene.camera.vertical_fov_degrees,
                                         static_cast<float>(o.width) / static_cast<float>(o.height));
    auto trace = [&]<bool Profile>(Vec3 d, envmis::Pcg32& rng, Counters& c) {
        return trace_path<Profile>(env, rays, scene, lobes, camera.position, d, o.path, rng, c);
    };
    if (o.profile)
        return render_passes(o, camera, [&](Vec3 d, envmis::Pcg32& rng, Counters& c) {
            return trace.template operator()<true>(d, rng, c);
        });
    return render_passes(o, camera, [&](Vec3 d, envmis::Pcg32& rng, Counters& c) {
        return trace.template operator()<false>(d, rng, c);
    });
}

// ---------------------------------------------------------------------------------------
// Set-up: the environment technique from the table

struct Loaded {
    envmis::Table table;
    std::optional<envmis::BinnedEnvMap> binned;
    std::optional<envmis::Table> beyond;     // --beyond: the global table past --bins-depth
    std::optional<envmis::RgbImage> square;  // the pbrt sampler's copy of the radiance
    std::optional<envmis::reference::PbrtStyleEnvMap> pbrt;
    std::string technique;  // plain, compensated, bins, pbrt

    const envmis::EnvMap& map() const { return binned ? binned->radiance_map() : table.map; }
};

// The normal-aware table and, with --beyond, the global table that must hold the same
// texels (same source image, size, mapping and axes).
void load_bins(const Options& o, Loaded& l) {
    if (!l.table.bins)
        throw std::runtime_error(o.table.string() +
                                 ": the table has no bins; --env bins needs one built with `envmis precompute "
                                 "MAP -o T.envmis --bins 121`");
    if (o.beyond) {
        l.beyond = envmis::read_table(*o.beyond);
        const envmis::EnvMap &a = l.table.map, &b = l.beyond->map;
        if (l.beyond->source.content_hash != l.table.source.content_hash || a.width() != b.width() ||
            a.height() != b.height() || a.options().mapping != b.options().mapping ||
            a.options().axes != b.options().axes)
            throw std::runtime_error(o.beyond->string() + ": --beyond needs a table of the same image as " +
                                     o.table.string() + " (source, size, mapping and axes)");
    }
    l.binned = envmis::binned_map(std::move(l.table));
    l.technique = "bins";
}

void load_pbrt(const Options& o, Loaded& l) {
    const envmis::EnvMap& map = l.table.map;
    if (map.options().mapping != envmis::Mapping::equal_area)
        throw std::runtime_error(o.table.string() +
                                 ": --env pbrt samples pbrt-v4's equal-area square; build the table with "
                                 "`envmis precompute MAP -o T.envmis --mapping equal-area`");
    const envmis::RgbImageView radiance = map.radiance();
    l.square = envmis::RgbImage{radiance.width, radiance.height,
                                envmis::RgbPixels(radiance.pixels.begin(), radiance.pixels.end())};
    l.pbrt.emplace(*l.square, map.options());
    l.technique = "pbrt";
}

std::unique_ptr<Loaded> load(const Options& o) {
    auto l = std::make_unique<Loaded>(Loaded{envmis::read_table(o.table), {}, {}, {}, {}, {}});
    l->technique = l->table.map.compensated() ? "compensated" : "plain";
    if (o.env == EnvKind::bins) load_bins(o, *l);
    if (o.env == EnvKind::pbrt) load_pbrt(o, *l);
    return l;
}

// ---------------------------------------------------------------------------------------
// Output

std::string json_string(const std::string& s) {
    std::string out = "\"";
    for (char c : s) {
        if (c == '"' || c == '\\')
            out += '\\', out += c;
        else if (static_cast<unsigned char>(c) < 0x20) {
            char buffer[8];
            std::snprintf(buffer, sizeof buffer, "\\u%04x", c);
            out += buffer;
        } else
            out += c;
    }
    return out + "\"";
}

// The CPU as lscpu names it: vendor, family, model and model name from /proc/cpuinfo.
std::string cpu_name() {
    std::ifstream in("/proc/cpuinfo");
    std::string line, vendor, family, model, name;
    auto value = [&](const std::string& l) { return l.substr(std::min(l.size(), l.find(':') + 2)); };
    while (std::getline(in, line) && !line.empty()) {
        if (line.rfind("vendor_id", 0) == 0) vendor = value(line);
        if (line.rfind("cpu family", 0) == 0) family = value(line);
        if (line.rfind("model\t", 0) == 0) model = value(line);
        if (line.rfind("model name", 0) == 0) name = value(line);
    }
    return name.empty() ? "unknown" : name + " (" + vendor + " family " + family + " model " + model + ")";
}

// Writes `text` to `path` through a temporary file in the same folder, renamed.
void write_file(const std::filesystem::path& path, const std::string& text) {
    std::filesystem::path tmp = path;
    tmp += ".tmp";
    {
        std::ofstream out(tmp, std::ios::binary);
        out << text;
        if (!out.flush()) throw std::runtime_error(tmp.string() + ": cannot write");
    }
    std::filesystem::rename(tmp, path);
}

// A number as JSON has it: null where it is not finite (a NaN pixel in the image).
std::string json_number(double x) {
    if (!std::isfinite(x)) return "null";
    std::ostringstream out;
    out << x;
    return out.str();
}

std::string summary_json(const Options& o, const Loaded& l, const SceneDescription& scene, const RenderResult& r,
                         const std::optional<envmis::RgbImage>& reference) {
    std::ostringstream j;
    const double rays_per_second = r.thread_seconds > 0 ? static_cast<double>(r.counters.rays) / r.thread_seconds : 0;
    j << "{\n  \"scene\": " << json_string(scene.name) << ",\n  \"triangles\": " << scene.triangles()
      << ",\n  \"table\": " << json_string(o.table.string()) << ",\n  \"technique\": " << json_string(l.technique)
      << ",\n  \"width\": " << o.width << ",\n  \"height\": " << o.height << ",\n  \"passes\": " << r.passes
      << ",\n  \"seed\": " << o.seed << ",\n  \"bounces\": " << o.path.max_bounces
      << ",\n  \"bins_depth\": " << (o.bins_depth == UINT32_MAX ? std::string("null") : std::to_string(o.bins_depth))
      << ",\n  \"light_samples\": " << o.path.light_samples << ",\n  \"rotate_degrees\": " << o.rotate_degrees
      << ",\n  \"threads\": " << o.threads << ",\n  \"seconds\": " << r.seconds
      << ",\n  \"thread_seconds\": " << r.thread_seconds << ",\n  \"rays\": " << r.counters.rays
      << ",\n  \"rays_per_second_per_thread\": " << rays_per_second
      << ",\n  \"environment_samples\": " << r.counters.samples
      << ",\n  \"environment_lookups\": " << r.counters.lookups;
    if (o.profile) {
        // Ticks per second from the run itself: the threads' busy time against their ticks is
        // not known, so measure the tick rate over a short interval.
        const uint64_t t0 = ticks();
        const auto c0 = std::chrono::steady_clock::now();
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
        const double rate = static_cast<double>(ticks() - t0) /
                            std::chrono::duration<double>(std::chrono::steady_clock::now() - c0).count();
        j << ",\n  \"sampler_share\": "
          << json_number(static_cast<double>(r.counters.sampler_ticks) / rate / r.thread_seconds);
    }
    if (reference)
        j << ",\n  \"reference\": " << json_string(o.reference->string())
          << ",\n  \"relative_mse\": " << json_number(examples::relative_mse(r.image, *reference, o.output.string()));
    j << ",\n  \"mean_luminance\": " << json_number(r.mean_luminance)
      << ",\n  \"standard_error\": " << json_number(r.standard_error) << ",\n  \"cpu\": " << json_string(cpu_name())
      << "\n}\n";
    return j.str();
}

int run(const Options& o) {
    const std::filesystem::path folder = o.output.parent_path().empty() ? "." : o.output.parent_path();
    if (!std::filesystem::is_directory(folder))
        throw std::runtime_error(o.output.string() + ": no such folder " + folder.string());
    std::optional<envmis::RgbImage> reference;
    if (o.reference) {
        if (!std::filesystem::is_regular_file(*o.reference))
            throw std::runtime_error(o.reference->string() + ": no such reference image");
        reference = examples::read_exr(*o.reference);
        if (reference->width != o.width || reference->height != o.height)
            throw std::runtime_error(o.reference->string() + ": the reference is " + std::to_string(reference->width) +
                                     "x" + std::to_string(reference->height) + ", the render " +
                                     std::to_string(o.width) + "x" + std::to_string(o.height));
    }
    const std::unique_ptr<Loaded> loaded = load(o);
    const envmis::EnvMap& map = loaded->map();
    if (map.options().axes != envmis::Axes{})
        std::fprintf(stderr, "note: %s was built for axes %s; the scenes are z up, so the map appears turned\n",
                     o.table.string().c_str(), map.options().axes.to_string().c_str());
    const SceneDescription scene = make_scene(o.scene, o.obj);
    const RayScene rays(scene);
    std::vector<uint32_t> lobes(scene.materials.size(), 0);
    if (loaded->binned)
        for (size_t m = 0; m < lobes.size(); ++m)
            lobes[m] = loaded->binned->lobe_class(scene.materials[m].phong_exponent());

    const envmis::Rotation rotation =
        envmis::Rotation::about_up(map.options().axes, o.rotate_degrees * envmis::kPiF / 180);
    RenderResult r;
    if (loaded->binned) {
        const envmis::BinnedEnvMapView view = loaded->binned->view();
        std::optional<envmis::Rotated<envmis::EnvMapView>> beyond;
        if (loaded->beyond) beyond = envmis::Rotated<envmis::EnvMapView>{loaded->beyond->map.view(), rotation};
        r = render(BinnedEnvironment{{&view, rotation}, beyond, o.bins_depth}, scene, rays, lobes, o);
    } else if (loaded->pbrt) {
        r = render(PbrtEnvironment{&*loaded->pbrt, map.view(), rotation}, scene, rays, lobes, o);
    } else {
        r = render(GlobalEnvironment{{map.view(), rotation}}, scene, rays, lobes, o);
    }

    std::filesystem::path png = o.output, json = o.output;
    png.replace_extension(".png");
    json.replace_extension(".json");
    envmis::io::write_exr(o.output, r.image);
    envmis::io::write_png(png, envmis::pictures::tonemap(r.image, 0, map.options().luma));
    write_file(json, summary_json(o, *loaded, scene, r, reference));
    std::printf("%s, %s (%zu triangles), %s: %ux%u, %u spp, %.2f s, %.3g rays/s per thread -> %s\n",
                o.table.string().c_str(), scene.name.c_str(), scene.triangles(), loaded->technique.c_str(), o.width,
                o.height, r.passes, r.seconds,
                r.thread_seconds > 0 ? static_cast<double>(r.counters.rays) / r.thread_seconds : 0.0,
                o.output.string().c_str());
    return 0;
}

// ---------------------------------------------------------------------------------------
// Command line

using examples::parse_number;
using examples::UsageError;

const char* const kUsage =
    "usage: envmis_example_pathtrace TABLE -o OUT.exr [--scene objects|materials|interior|mesh] [--obj FILE.obj]\n"
    "                                [--env global|bins|pbrt] [--size WxH] [--spp N] [--time SECONDS]\n"
    "                                [--bounces N] [--light-samples N] [--bins-depth N [--beyond GLOBAL]]\n"
    "                                [--rotate DEGREES] [--seed S] [--threads T] [--reference REF.exr]\n"
    "                                [--profile] [--progress]\n";

double parse_seconds(const std::string& text) {
    char* end = nullptr;
    const double s = std::strtod(text.c_str(), &end);
    if (text.empty() || *end != 0 || !(s > 0 && s <= 1e6))
        throw UsageError("--time '" + text + "': expected seconds, more than 0 and at most 1e6");
    return s;
}

EnvKind parse_env(const std::string& text) {
    if (text == "global") return EnvKind::global;
    if (text == "bins") return EnvKind::bins;
    if (text == "pbrt") return EnvKind::pbrt;
    throw UsageError("--env '" + text + "': expected global, bins or pbrt");
}

Options parse(int argc, char** argv) {
    Options o;
    std::vector<std::string> positional;
    bool spp_given = false;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        auto value = [&]() -> std::string {
            if (i + 1 >= argc) throw UsageError(arg + ": missing value");
            return argv[++i];
        };
        if (arg == "-o" || arg == "--output") {
            o.output = value();
        } else if (arg == "--scene") {
            o.scene = value();
            const auto names = {"objects", "materials", "interior", "mesh"};
            if (std::find(names.begin(), names.end(), o.scene) == names.end())
                throw UsageError("--scene '" + o.scene + "': expected one of " + std::string(kSceneNames));
        } else if (arg == "--obj") {
            o.obj = value();
        } else if (arg == "--env") {
            o.env = parse_env(value());
        } else if (arg == "--size") {
            const std::string text = value();
            const size_t x = text.find('x');
            if (x == std::string::npos) throw UsageError("--size '" + text + "': expected WxH");
            o.width = static_cast<uint32_t>(parse_number("--size", text.substr(0, x), 1, 16384));
            o.height = static_cast<uint32_t>(parse_number("--size", text.substr(x + 1), 1, 16384));
        } else if (arg == "--spp") {
            o.spp = static_cast<uint32_t>(parse_number(arg, value(), 1, 1u << 24));
            spp_given = true;
        } else if (arg == "--time") {
            o.seconds = parse_seconds(value());
        } else if (arg == "--bounces") {
            o.path.max_bounces = static_cast<uint32_t>(parse_number(arg, value(), 1, 64));
        } else if (arg == "--light-samples") {
            o.path.light_samples = static_cast<uint32_t>(parse_number(arg, value(), 1, 1024));
        } else if (arg == "--seed") {
            o.seed = parse_number(arg, value(), 0, UINT64_MAX);
        } else if (arg == "--threads") {
            o.threads = static_cast<uint32_t>(parse_number(arg, value(), 1, 1024));
        } else if (arg == "--bins-depth") {
            o.bins_depth = static_cast<uint32_t>(parse_number(arg, value(), 1, 64));
        } else if (arg == "--beyond") {
            o.beyond = value();
        } else if (arg == "--rotate") {
            const std::string text = value();
            char* end = nullptr;
            o.rotate_degrees = std::strtof(text.c_str(), &end);
            if (text.empty() || *end != 0 || !(std::abs(o.rotate_degrees) <= 360))
                throw UsageError("--rotate '" + text + "': expected degrees from -360 to 360");
        } else if (arg == "--reference") {
            o.reference = value();
        } else if (arg == "--profile") {
            o.profile = true;
        } else if (arg == "--progress") {
            o.progress = true;
        } else if (arg == "-h" || arg == "--help") {
            std::fputs(kUsage, stdout);
            std::exit(0);
        } else if (arg.size() > 1 && arg[0] == '-') {
            throw UsageError(arg + ": unknown option");
        } else {
            positional.push_back(arg);
        }
    }
    if (positional.size() != 1 || o.output.extension() != ".exr") throw UsageError("expected TABLE and -o OUT.exr");
    if (o.obj && o.scene != "mesh") throw UsageError("--obj replaces the mesh scene's knot: add --scene mesh");
    if ((o.beyond || o.bins_depth != UINT32_MAX) && o.env != EnvKind::bins)
        throw UsageError("--bins-depth and --beyond choose where bins are sampled: add --env bins");
    if (o.beyond && o.bins_depth == UINT32_MAX)
        throw UsageError("--beyond is the table past --bins-depth: add --bins-depth N");
    if (o.seconds > 0 && !spp_given) o.spp = 1u << 24;  // the time decides
    o.table = positional[0];
    return o;
}

}  // namespace
}  // namespace pathtrace

int main(int argc, char** argv) {
    try {
        return pathtrace::run(pathtrace::parse(argc, argv));
    } catch (const examples::UsageError& e) {
        std::fprintf(stderr, "envmis_example_pathtrace: %s\n%s", e.what(), pathtrace::kUsage);
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "envmis_example_pathtrace: %s\n", e.what());
        return 1;
    }
}
