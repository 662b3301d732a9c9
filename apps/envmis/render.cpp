#include "render.h"

#include <cmath>
#include <cstdio>
#include <thread>
#include <vector>

#include "envmis/io/image_io.h"
#include "envmis/pictures/picture.h"

namespace envmis::cli {
namespace {

// An orthographic camera on the -y side looking along +y at spheres centred on the x
// axis, z up (the map's default up), one per BSDF, side by side.
struct Scene {
    uint32_t w, h, spheres;
    float radius;

    // The shading point seen through pixel (x, y), or false for the background.
    bool point(uint32_t x, uint32_t y, ShadingPoint& p, uint32_t& sphere) const {
        const float cell = static_cast<float>(w) / spheres;
        sphere = std::min(spheres - 1, static_cast<uint32_t>((x + 0.5f) / cell));
        const float dx = ((x + 0.5f) - (sphere + 0.5f) * cell) / radius, dz = (0.5f * h - (y + 0.5f)) / radius;
        const float r2 = dx * dx + dz * dz;
        if (r2 >= 1) return false;
        p = {{dx, -std::sqrt(1 - r2), dz}, {0, -1, 0}};
        return true;
    }
};

// Renders one technique: each pixel the mean of `spp` estimates, rows shared among threads.
RgbImage render(const Scene& scene, const DirectLightingEstimator& estimator, const std::vector<Bsdf>& bsdfs,
                uint32_t spp, uint64_t seed, uint32_t threads, const std::atomic<bool>* stop) {
    RgbImage image{scene.w, scene.h, std::vector<Rgb>(size_t{scene.w} * scene.h)};
    std::atomic<uint32_t> next_row{0};
    auto work = [&] {
        for (uint32_t y; (y = next_row.fetch_add(1)) < scene.h && !(stop && stop->load());)
            for (uint32_t x = 0; x < scene.w; ++x) {
                ShadingPoint p;
                uint32_t sphere = 0;
                if (scene.point(x, y, p, sphere))
                    image.pixels[size_t{y} * scene.w + x] =
                        average_estimate(estimator, p, bsdfs[sphere], spp, seed, uint64_t{y} * scene.w + x);
            }
    };
    std::vector<std::jthread> pool;
    for (uint32_t i = 1; i < threads; ++i) pool.emplace_back(work);
    work();
    return image;
}

// Per-pixel squared error relative to the reference, in luminance; 0 off the spheres.
std::vector<float> relative_squared_error(const RgbImage& image, const RgbImage& reference, double& mean) {
    std::vector<float> error(image.pixels.size());
    double sum = 0;
    size_t counted = 0;
    for (size_t i = 0; i < error.size(); ++i) {
        const float r = luminance(reference.pixels[i], {});
        if (!(r > 0)) continue;
        const float d = luminance(image.pixels[i], {}) - r;
        error[i] = d * d / (r * r);
        sum += error[i], ++counted;
    }
    mean = counted ? sum / static_cast<double>(counted) : 0;
    return error;
}

io::Image8 crop(const io::Image8& image, uint32_t x0, uint32_t width) {
    io::Image8 out = pictures::make_image(width, image.height, {});
    pictures::blit(out, image, -static_cast<int>(x0), 0);
    return out;
}

io::Image8 stack(const io::Image8& top, const io::Image8& bottom) {
    io::Image8 out = pictures::make_image(std::max(top.width, bottom.width), top.height + bottom.height,
                                          pictures::Style{}.background);
    pictures::blit(out, top, 0, 0);
    pictures::blit(out, bottom, 0, static_cast<int>(top.height));
    return out;
}

}  // namespace

std::filesystem::path render_comparison(const EnvMap& plain, const EnvMap& compensated,
                                        const ComparisonOptions& options, const RenderOptions& render_options,
                                        const std::filesystem::path& folder, const std::string& map_name,
                                        const std::atomic<bool>* stop) {
    unsigned w = 0, h = 0;
    char x = 0;
    if (std::sscanf(render_options.size.c_str(), "%u%c%u", &w, &x, &h) != 3 || x != 'x' || w < 16 || h < 16 ||
        w > 8192 || h > 8192)
        throw std::runtime_error("--image '" + render_options.size + "': expected WxH, each 16 to 8192");
    std::filesystem::create_directories(folder);
    const auto spheres = static_cast<uint32_t>(options.bsdfs.size());
    const Scene scene{w, h, spheres, 0.45f * std::min(static_cast<float>(w) / spheres, static_cast<float>(h))};

    const RgbImage reference =
        render(scene, DirectLightingEstimator(plain, Technique::parse("mis-power"), options.allocation), options.bsdfs,
               render_options.reference_spp, options.seed ^ 0x5eed, options.threads, stop);
    io::write_exr(folder / "reference.exr", reference);
    std::vector<std::pair<std::string, RgbImage>> renders;
    for (const Technique& t : options.techniques) {
        const DirectLightingEstimator estimator(plain, compensated, t, options.allocation);
        renders.emplace_back(
            t.name(), render(scene, estimator, options.bsdfs, render_options.spp, options.seed, options.threads, stop));
        io::write_exr(folder / (t.name() + ".exr"), renders.back().second);
    }

    // Tone-map all renders as one wide image, so that they share one exposure.
    const uint32_t panels = static_cast<uint32_t>(renders.size()) + 1;
    RgbImage wide{w * panels, h, std::vector<Rgb>(size_t{w} * panels * h)};
    auto place = [&](const RgbImage& image, uint32_t panel) {
        for (uint32_t y = 0; y < h; ++y)
            for (uint32_t i = 0; i < w; ++i) wide.pixels[size_t{y} * wide.width + panel * w + i] = image.at(i, y);
    };
    place(reference, 0);
    for (uint32_t i = 0; i < renders.size(); ++i) place(renders[i].second, i + 1);
    const io::Image8 shown = pictures::tonemap(wide, 0, plain.options().luma);

    std::vector<pictures::Panel> top = {
        {crop(shown, 0, w), "reference (" + std::to_string(render_options.reference_spp) + " spp)"}};
    io::write_png(folder / "reference.png", top[0].image);
    std::vector<std::vector<float>> errors;
    std::vector<double> mean_errors;
    for (uint32_t i = 0; i < renders.size(); ++i) {
        top.push_back({crop(shown, (i + 1) * w, w), renders[i].first});
        io::write_png(folder / (renders[i].first + ".png"), top.back().image);
        mean_errors.push_back(0);
        errors.push_back(relative_squared_error(renders[i].second, reference, mean_errors.back()));
    }
    // A fixed scale: a few pixels hit by a rare bright sample would otherwise stretch it
    // over many decades and leave the typical errors indistinguishable.
    const pictures::ColourScale scale{1e-4f, 10.0f, true};
    std::vector<pictures::Panel> bottom;
    for (uint32_t i = 0; i < renders.size(); ++i) {
        char title[96];
        std::snprintf(title, sizeof title, "%s relMSE %.3g", renders[i].first.c_str(), mean_errors[i]);
        bottom.push_back({pictures::false_colour(errors[i], w, h, scale), title, true});
        io::write_png(folder / (renders[i].first + "-relmse.png"), bottom.back().image);
    }
    const io::Image8 bar = pictures::colour_bar(scale, "per-pixel relative squared error", std::min(4u * w, 1600u));
    std::string bsdf_names;
    for (const Bsdf& b : options.bsdfs) bsdf_names += (bsdf_names.empty() ? "" : ", ") + b.name();
    char caption[256];
    std::snprintf(caption, sizeof caption, "%s: %s at %u spp (%u env + %u BSDF samples each), alpha %.3g",
                  map_name.c_str(), bsdf_names.c_str(), render_options.spp, options.allocation.env,
                  options.allocation.bsdf, compensated.options().compensation.alpha);
    const io::Image8 montage = stack(pictures::montage(top, caption), pictures::montage(bottom, "", &bar));
    const std::filesystem::path path = folder / "montage.png";
    io::write_png(path, montage);
    return path;
}

}  // namespace envmis::cli
