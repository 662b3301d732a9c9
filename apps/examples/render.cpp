// envmis_example_render: direct lighting from an environment map in a small CPU ray
// tracer, written to show how a renderer uses envmis (docs/integration.md walks through
// it). Three spheres (Lambertian, Phong, GGX) stand on a Lambertian ground plane under
// the map. Each pixel sample traces one camera ray; where it hits a surface, the light
// arriving from the map is estimated with one environment sample and one BSDF sample,
// combined by multiple importance sampling (balance heuristic). A sample direction
// that hits any object is in shadow; nothing bounces further.
//
// Whether the environment density is MIS-compensated is decided by the table: build it
// with `envmis precompute MAP -o T.envmis` (compensated, the default) or with
// `--no-compensate`. A compensated density is zero over the dim parts of the map, so it
// must be combined with BSDF sampling; `--technique env` refuses such a table.
//
// --bins samples normal-aware densities (envmis/sampling/binned.h) instead of one global
// one: the table must hold bins (`envmis precompute MAP -o T.envmis --bins K`). At each
// shading point the environment technique samples the bin that the BSDF's lobe class and
// its axis pick (the normal for a diffuse lobe, the mirror direction of the view for a
// glossy one: envmis::lobe_axis), and the MIS weight of the BSDF sample uses that same bin's
// pdf, so both weights describe the densities that were actually sampled. The lobe class
// of each material is found once (Scene::set_lobe_classes), not per shading point.
//
// Usage:
//   envmis_example_render TABLE -o OUT.exr [--size WxH] [--spp N] [--seed S] [--threads T]
//                         [--technique mis|env|bsdf] [--bins]
//       writes OUT.exr (linear RGB, the table's working colour space) and a tone-mapped
//       OUT.png. The image depends on the seed only, not on the number of threads.
//   envmis_example_render --compare REF A [B] [--expect-ratio R]
//       prints the relative MSE of A (and B) against REF, EXR files of one size (see
//       relative_mse). With B and R, exits 1 unless relMSE(B) >= R * relMSE(A).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "envmis/cpu.h"
#include "envmis/io/image_io.h"
#include "envmis/math/random.h"
#include "envmis/pictures/picture.h"
#include "envmis/sampling/binned.h"
#include "envmis/sampling/envmap.h"
#include "envmis/study/shading/bsdf.h"
#include "envmis/study/shading/frame.h"
#include "envmis/table/table.h"
#include "example_support.h"

namespace {

using envmis::Rgb;
using envmis::Vec2;
using envmis::Vec3;

Rgb operator+(Rgb a, Rgb b) { return {a.r + b.r, a.g + b.g, a.b + b.b}; }
Rgb operator*(Rgb a, Rgb b) { return {a.r * b.r, a.g * b.g, a.b * b.b}; }
Rgb operator*(Rgb a, float s) { return {a.r * s, a.g * s, a.b * s}; }
bool is_black(Rgb c) { return c.r == 0 && c.g == 0 && c.b == 0; }

// ---------------------------------------------------------------------------------------
// The scene: world frame z up, the default of `envmis precompute` (--axes z-up).

struct Ray {
    Vec3 origin, direction;  // direction: a unit vector
};

struct Hit {
    Vec3 point, normal;
    const envmis::Bsdf* bsdf = nullptr;
    uint32_t lobe = 0;  // the BSDF's lobe class in a binned map
};

struct Sphere {
    Vec3 centre;
    float radius;
    envmis::Bsdf bsdf;
    uint32_t lobe = 0;
};

struct Scene {
    std::vector<Sphere> spheres;
    envmis::Bsdf ground;  // the plane z = 0, infinite
    uint32_t ground_lobe = 0;

    void set_lobe_classes(const envmis::BinnedEnvMap& binned) {
        for (Sphere& s : spheres) s.lobe = binned.lobe_class(s.bsdf.phong_exponent());
        ground_lobe = binned.lobe_class(ground.phong_exponent());
    }

    // The nearest surface along the ray, if any.
    std::optional<Hit> intersect(const Ray& ray) const {
        float nearest = INFINITY;
        std::optional<Hit> hit;
        for (const Sphere& s : spheres) {
            const Vec3 oc = ray.origin - s.centre;
            const float b = envmis::dot(oc, ray.direction), c = envmis::dot(oc, oc) - s.radius * s.radius;
            const float disc = b * b - c;
            if (disc < 0) continue;
            const float root = std::sqrt(disc);
            const float t = -b - root > 0 ? -b - root : -b + root;
            if (t <= 0 || t >= nearest) continue;
            nearest = t;
            const Vec3 p = ray.origin + ray.direction * t;
            hit = Hit{p, (p - s.centre) * (1 / s.radius), &s.bsdf, s.lobe};
        }
        if (ray.direction.z < 0 && ray.origin.z > 0) {
            const float t = -ray.origin.z / ray.direction.z;
            if (t < nearest) hit = Hit{ray.origin + ray.direction * t, {0, 0, 1}, &ground, ground_lobe};
        }
        return hit;
    }
    // True if light from `direction` cannot reach `hit`: some object is in the way.
    bool occluded(const Hit& hit, Vec3 direction) const {
        return intersect({hit.point + hit.normal * 1e-4f, direction}).has_value();
    }
};

Scene make_scene() {
    return {{{{-1.6f, 0, 0.7f}, 0.7f, envmis::Bsdf::lambert({0.75f, 0.25f, 0.2f})},
             {{0, 0, 0.7f}, 0.7f, envmis::Bsdf::phong(50, {0.8f, 0.8f, 0.8f})},
             {{1.6f, 0, 0.7f}, 0.7f, envmis::Bsdf::ggx(0.1f)}},
            envmis::Bsdf::lambert({0.5f, 0.5f, 0.5f})};
}

// The environment as the renderer samples it: one global density, or with `binned` the
// bin of each shading point's normal and lobe class (whose radiance is `global`'s, the
// binned map's radiance map, then only evaluated).
struct Environment {
    envmis::EnvMapView global;
    const envmis::BinnedEnvMapView* binned = nullptr;
};

// ---------------------------------------------------------------------------------------
// Direct lighting: the part a renderer copies.

enum class Technique { mis, env, bsdf };

// Radiance leaving `hit` towards the viewer (world direction `to_viewer`): light from
// the map, reflected once. MIS spends one environment and one BSDF sample. `env` is
// the density sampled at this point, an EnvMapView or a binned map's BinView (the same
// interface).
template <class Density>
Rgb direct_lighting(const Density& env, const Scene& scene, const Hit& hit, Vec3 to_viewer, Technique technique,
                    envmis::Pcg32& rng) {
    // BSDFs work in the local shading frame (z = normal); the map in world directions.
    const envmis::Frame frame = envmis::Frame::from_normal(hit.normal);
    const Vec3 wo = frame.to_local(to_viewer);
    const envmis::Bsdf& bsdf = *hit.bsdf;
    Rgb result;

    // 1. Sample the map; weight against the density BSDF sampling has for that direction.
    if (technique != Technique::bsdf) {
        const envmis::EnvSample light = env.sample(rng.uniform2());  // world direction, solid-angle pdf
        const Vec3 wi = frame.to_local(light.direction);
        const envmis::BsdfValues<float> b = bsdf.values(wo, wi);  // eval and pdf at once
        const Rgb f{b.r, b.g, b.b};                               // f * cos(theta_i)
        if (light.pdf > 0 && !is_black(f) && !scene.occluded(hit, light.direction)) {
            const float weight = technique == Technique::mis ? light.pdf / (light.pdf + b.pdf) : 1.0f;
            result = result + light.radiance * f * (weight / light.pdf);
        }
    }
    // 2. Sample the BSDF; weight against the density the map gives that direction. Where
    //    a compensated map's density is 0, the weight is 1: BSDF sampling covers it alone.
    if (technique != Technique::env) {
        const envmis::BsdfSample s = bsdf.sample(wo, rng.uniform2());  // local direction, value = f * cos
        const Vec3 direction = frame.to_world(s.wi);
        if (s.pdf > 0 && !is_black(s.value) && !scene.occluded(hit, direction)) {
            const auto [radiance, env_pdf] = env.lookup(direction);  // eval and pdf at once
            const float weight = technique == Technique::mis ? s.pdf / (s.pdf + env_pdf) : 1.0f;
            result = result + radiance * s.value * (weight / s.pdf);
        }
    }
    return result;
}

// Radiance along a camera ray: the map where it escapes, else the lit surface.
Rgb trace(const Environment& env, const Scene& scene, const Ray& ray, Technique technique, envmis::Pcg32& rng) {
    const std::optional<Hit> hit = scene.intersect(ray);
    if (!hit) return env.global.eval(ray.direction);
    if (env.binned) {
        // One pick of the bins around the lobe axis serves both samples' MIS weights.
        const envmis::LobeAxis axis = envmis::lobe_axis(hit->lobe, hit->normal, ray.direction * -1.0f);
        return direct_lighting(env.binned->bin(axis, hit->lobe, rng.uniform()), scene, *hit, ray.direction * -1.0f,
                               technique, rng);
    }
    return direct_lighting(env.global, scene, *hit, ray.direction * -1.0f, technique, rng);
}

// ---------------------------------------------------------------------------------------
// The image: rows shared among threads, one random stream per pixel, so the result
// depends on the seed only.

struct Options {
    std::filesystem::path table, output;
    uint32_t width = 480, height = 320, spp = 16, threads = envmis::usable_cores();
    uint64_t seed = 1;
    Technique technique = Technique::mis;
    bool bins = false;
};

envmis::RgbImage render(const Environment& env, const Scene& scene, const Options& o) {
    const examples::PinholeCamera camera({0, -7.5f, 2.2f}, {0, 0, 0.55f}, 30,
                                         static_cast<float>(o.width) / static_cast<float>(o.height));
    envmis::RgbImage image{o.width, o.height, envmis::RgbPixels(size_t{o.width} * o.height)};
    std::atomic<uint32_t> next_row{0};
    auto work = [&] {
        for (uint32_t y; (y = next_row.fetch_add(1)) < o.height;)
            for (uint32_t x = 0; x < o.width; ++x) {
                const size_t pixel = size_t{y} * o.width + x;
                envmis::Pcg32 rng(o.seed, pixel);
                Rgb sum;
                for (uint32_t i = 0; i < o.spp; ++i) {
                    const Vec2 jitter = rng.uniform2();
                    const Ray ray{camera.position,
                                  camera.direction((static_cast<float>(x) + jitter.x) / static_cast<float>(o.width),
                                                   (static_cast<float>(y) + jitter.y) / static_cast<float>(o.height))};
                    sum = sum + trace(env, scene, ray, o.technique, rng);
                }
                image.pixels[pixel] = sum * (1.0f / static_cast<float>(o.spp));
            }
    };
    {
        std::vector<std::jthread> pool;
        for (uint32_t i = 1; i < o.threads; ++i) pool.emplace_back(work);
        work();
    }
    return image;
}

// The table's map, and with --bins the BinnedEnvMap its bins describe (which then holds
// the map).
struct Loaded {
    std::optional<envmis::Table> table;
    std::optional<envmis::BinnedEnvMap> binned;
    const envmis::EnvMap& map() const { return binned ? binned->radiance_map() : table->map; }
};

Loaded load(const Options& o) {
    Loaded l;
    l.table = envmis::read_table(o.table);  // checks sizes, checksums, version
    if (!o.bins) return l;
    if (!l.table->bins)
        throw std::runtime_error(o.table.string() +
                                 ": the table has no bins; --bins needs one built with `envmis precompute MAP -o " +
                                 "T.envmis --bins K`");
    l.binned = envmis::binned_map(std::move(*l.table));
    l.table.reset();
    return l;
}

// A compensated density is 0 wherever the map is dimmer than its threshold: sampled
// alone it would miss that light. Only MIS with BSDF sampling is unbiased.
void check_complete(const Loaded& l, const Options& o) {
    if (l.binned) {
        for (uint32_t c = 0; c < l.binned->classes(); ++c)
            if (!l.binned->complete(c) && o.technique == Technique::env)
                throw std::runtime_error(o.table.string() + ": compensated bins (lobe class " + std::to_string(c) +
                                         "): they cannot be sampled alone; use --technique mis");
        return;
    }
    const envmis::EnvMap& map = l.map();
    if (!map.complete()) {
        if (o.technique == Technique::env)
            throw std::runtime_error(o.table.string() + ": compensated table (its density is 0 over " +
                                     std::to_string(map.stats().zeroed_texels) +
                                     " lit texels): it cannot be sampled alone; use --technique mis");
        std::fprintf(stderr, "note: compensated table: %llu lit texels are left to BSDF sampling through MIS\n",
                     static_cast<unsigned long long>(map.stats().zeroed_texels));
    }
}

int run_render(const Options& o) {
    const Loaded loaded = load(o);
    const envmis::EnvMap& map = loaded.map();
    if (map.options().axes != envmis::Axes{})
        std::fprintf(stderr, "note: %s was built for axes %s; this scene is z up, so the map appears turned\n",
                     o.table.string().c_str(), map.options().axes.to_string().c_str());
    check_complete(loaded, o);
    Scene scene = make_scene();
    std::optional<envmis::BinnedEnvMapView> binned_view;
    if (loaded.binned) {
        scene.set_lobe_classes(*loaded.binned);
        binned_view = loaded.binned->view();
    }
    const Environment env{map.view(), binned_view ? &*binned_view : nullptr};
    const auto start = std::chrono::steady_clock::now();
    const envmis::RgbImage image = render(env, scene, o);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

    std::filesystem::path png = o.output;
    png.replace_extension(".png");
    envmis::io::write_exr(o.output, image);
    envmis::io::write_png(png, envmis::pictures::tonemap(image, 0, map.options().luma));
    const char* names[] = {"1 environment + 1 BSDF sample, balance heuristic", "1 environment sample", "1 BSDF sample"};
    const std::string density = loaded.binned       ? std::to_string(loaded.binned->bins()) + " bins"
                                : map.compensated() ? "compensated"
                                                    : "plain";
    std::printf("%s: %ux%u, %u spp (%s), %s density, %.2f s -> %s, %s\n", o.table.string().c_str(), o.width, o.height,
                o.spp, names[static_cast<int>(o.technique)], density.c_str(), seconds, o.output.string().c_str(),
                png.string().c_str());
    return 0;
}

// ---------------------------------------------------------------------------------------
// --compare: relative MSE of renders against a reference.

int run_compare(const std::vector<std::string>& files, double expect_ratio) {
    const envmis::RgbImage reference = examples::read_exr(files[0]);
    std::vector<double> errors;
    for (size_t i = 1; i < files.size(); ++i) {
        errors.push_back(examples::relative_mse(examples::read_exr(files[i]), reference, files[i]));
        std::printf("relMSE %c  %-10.4g %s\n", i == 1 ? 'A' : 'B', errors.back(), files[i].c_str());
    }
    if (errors.size() < 2) return 0;
    const double ratio = errors[1] / errors[0];
    std::printf("B / A     %.3g\n", ratio);
    if (expect_ratio > 0) {
        const bool ok = ratio >= expect_ratio;
        std::printf("%s: relMSE(B) %s %g x relMSE(A)\n", ok ? "ok" : "FAIL", ok ? ">=" : "<", expect_ratio);
        return ok ? 0 : 1;
    }
    return 0;
}

// ---------------------------------------------------------------------------------------

using examples::parse_number;
using examples::UsageError;

const char* const kUsage =
    "usage: envmis_example_render TABLE -o OUT.exr [--size WxH] [--spp N] [--seed S] [--threads T]\n"
    "                             [--technique mis|env|bsdf] [--bins]\n"
    "       envmis_example_render --compare REF A [B] [--expect-ratio R]\n";

}  // namespace

int main(int argc, char** argv) {
    try {
        Options o;
        std::vector<std::string> positional;
        bool compare = false;
        double expect_ratio = 0;
        for (int i = 1; i < argc; ++i) {
            const std::string arg = argv[i];
            auto value = [&]() -> std::string {
                if (i + 1 >= argc) throw UsageError(arg + ": missing value");
                return argv[++i];
            };
            if (arg == "-h" || arg == "--help") {
                std::fputs(kUsage, stdout);
                return 0;
            } else if (arg == "-o" || arg == "--output") {
                o.output = value();
            } else if (arg == "--size") {
                const std::string text = value();
                const size_t x = text.find('x');
                if (x == std::string::npos) throw UsageError("--size '" + text + "': expected WxH");
                o.width = static_cast<uint32_t>(parse_number("--size", text.substr(0, x), 1, 16384));
                o.height = static_cast<uint32_t>(parse_number("--size", text.substr(x + 1), 1, 16384));
            } else if (arg == "--spp") {
                o.spp = static_cast<uint32_t>(parse_number(arg, value(), 1, 1u << 20));
            } else if (arg == "--seed") {
                o.seed = parse_number(arg, value(), 0, UINT64_MAX);
            } else if (arg == "--threads") {
                o.threads = static_cast<uint32_t>(parse_number(arg, value(), 1, 1024));
            } else if (arg == "--technique") {
                const std::string t = value();
                if (t == "mis")
                    o.technique = Technique::mis;
                else if (t == "env")
                    o.technique = Technique::env;
                else if (t == "bsdf")
                    o.technique = Technique::bsdf;
                else
                    throw UsageError("--technique '" + t + "': expected mis, env or bsdf");
            } else if (arg == "--bins") {
                o.bins = true;
            } else if (arg == "--compare") {
                compare = true;
            } else if (arg == "--expect-ratio") {
                const std::string text = value();
                char* end = nullptr;
                expect_ratio = std::strtod(text.c_str(), &end);
                if (text.empty() || *end != 0 || !(expect_ratio > 0))
                    throw UsageError("--expect-ratio '" + text + "': expected a positive number");
            } else if (arg.size() > 1 && arg[0] == '-') {
                throw UsageError(arg + ": unknown option");
            } else {
                positional.push_back(arg);
            }
        }
        if (compare) {
            if (positional.size() < 2 || positional.size() > 3)
                throw UsageError("--compare takes a reference and one or two images");
            return run_compare(positional, expect_ratio);
        }
        if (positional.size() != 1 || o.output.extension() != ".exr") throw UsageError("expected TABLE and -o OUT.exr");
        o.table = positional[0];
        return run_render(o);
    } catch (const examples::UsageError& e) {
        std::fprintf(stderr, "envmis_example_render: %s\n%s", e.what(), kUsage);
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "envmis_example_render: %s\n", e.what());
        return 1;
    }
}
