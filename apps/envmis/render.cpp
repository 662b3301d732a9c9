#include "render.h"

#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "cli.h"
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
                uint32_t spp, uint64_t seed, uint32_t threads, StopFlag stop) {
    RgbImage image{scene.w, scene.h, RgbPixels(size_t{scene.w} * scene.h)};
    std::atomic<uint32_t> next_row{0};
    auto work = [&] {
        for (uint32_t y; (y = next_row.fetch_add(1)) < scene.h;)
            for (uint32_t x = 0; x < scene.w; ++x) {
                if (stop_requested(stop)) return;
                ShadingPoint p;
                uint32_t sphere = 0;
                if (scene.point(x, y, p, sphere))
                    image.pixels[size_t{y} * scene.w + x] =
                        average_estimate(estimator, p, bsdfs[sphere], spp, seed, uint64_t{y} * scene.w + x);
            }
    };
    {
        std::vector<std::jthread> pool;
        for (uint32_t i = 1; i < threads; ++i) pool.emplace_back(work);
        work();
    }
    throw_if_stopped(stop);  // a picture is written whole or not at all
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

namespace {

Scene parse_scene(const std::string& size, uint32_t spheres) {
    const std::optional<Size> parsed = parse_size(size, false, kMinImageSide, kMaxImageSide);
    if (!parsed)
        throw UsageError("--image '" + size + "': expected WxH, each " + std::to_string(kMinImageSide) + " to " +
                         std::to_string(kMaxImageSide));
    const auto [w, h] = *parsed;
    return {w, h, spheres, 0.45f * std::min(static_cast<float>(w) / spheres, static_cast<float>(h))};
}

// Tone-maps the reference and all renders as one wide image, so that they share one
// exposure; panel 0 is the reference.
io::Image8 tonemap_together(const RgbImage& reference, const std::vector<std::pair<std::string, RgbImage>>& renders,
                            LumaCoefficients luma) {
    const uint32_t w = reference.width, h = reference.height;
    const uint32_t panels = static_cast<uint32_t>(renders.size()) + 1;
    RgbImage wide{w * panels, h, RgbPixels(size_t{w} * panels * h)};
    auto place = [&](const RgbImage& image, uint32_t panel) {
        for (uint32_t y = 0; y < h; ++y)
            for (uint32_t i = 0; i < w; ++i) wide.pixels[size_t{y} * wide.width + panel * w + i] = image.at(i, y);
    };
    place(reference, 0);
    for (uint32_t i = 0; i < renders.size(); ++i) place(renders[i].second, i + 1);
    return pictures::tonemap(wide, 0, luma);
}

// The caption of the montage: map, BSDFs, samples and alpha.
std::string caption_text(const std::string& map_name, const ComparisonOptions& options, uint32_t spp, float alpha) {
    std::string bsdf_names;
    for (const Bsdf& b : options.bsdfs) bsdf_names += (bsdf_names.empty() ? "" : ", ") + b.name();
    char caption[256];
    std::snprintf(caption, sizeof caption, "%s: %s at %u spp (%u env + %u BSDF samples each), alpha %.3g",
                  map_name.c_str(), bsdf_names.c_str(), spp, options.allocation.env, options.allocation.bsdf, alpha);
    return caption;
}

// The montage: the tone-mapped renders on top, their relative squared errors below;
// writes each panel's PNG on the way.
io::Image8 write_panels(const std::filesystem::path& folder, const RgbImage& reference,
                        const std::vector<std::pair<std::string, RgbImage>>& renders, const io::Image8& shown,
                        uint32_t reference_spp, const std::string& caption) {
    const uint32_t w = reference.width, h = reference.height;
    std::vector<pictures::Panel> top = {{crop(shown, 0, w), "reference (" + std::to_string(reference_spp) + " spp)"}};
    io::write_png(folder / "reference.png", top[0].image);
    // A fixed scale: a few pixels hit by a rare bright sample would otherwise stretch it
    // over many decades and leave the typical errors indistinguishable.
    const pictures::ColourScale scale{1e-4f, 10.0f, true};
    std::vector<pictures::Panel> bottom;
    for (uint32_t i = 0; i < renders.size(); ++i) {
        top.push_back({crop(shown, (i + 1) * w, w), renders[i].first});
        io::write_png(folder / (renders[i].first + ".png"), top.back().image);
        double mean_error = 0;
        const std::vector<float> error = relative_squared_error(renders[i].second, reference, mean_error);
        char title[96];
        std::snprintf(title, sizeof title, "%s relMSE %.3g", renders[i].first.c_str(), mean_error);
        bottom.push_back({pictures::false_colour(error, w, h, scale), title, true});
        io::write_png(folder / (renders[i].first + "-relmse.png"), bottom.back().image);
    }
    const io::Image8 bar = pictures::colour_bar(scale, "per-pixel relative squared error", std::min(4u * w, 1600u));
    return stack(pictures::montage(top, caption), pictures::montage(bottom, "", &bar));
}

}  // namespace

std::filesystem::path render_comparison(const StudyInputs& inputs, const RenderOptions& render_options,
                                        const std::filesystem::path& folder, const std::string& map_name,
                                        const RunControl& control) {
    const ComparisonOptions& options = inputs.options;
    const EnvMap& compensated = inputs.compensated.maps.front();
    const Scene scene = parse_scene(render_options.size, static_cast<uint32_t>(options.bsdfs.size()));
    std::filesystem::create_directories(folder);

    const RgbImage reference =
        render(scene, DirectLightingEstimator(inputs.plain, Technique::parse("mis-power"), options.allocation),
               options.bsdfs, render_options.reference_spp, options.seed ^ 0x5eed, options.threads, control.stop);
    io::write_exr(folder / "reference.exr", reference);
    std::vector<std::pair<std::string, RgbImage>> renders;
    for (const Technique& t : options.techniques) {
        const DirectLightingEstimator estimator =
            study_estimator(inputs.plain, compensated, inputs.binned, t, options.allocation);
        renders.emplace_back(t.name(), render(scene, estimator, options.bsdfs, render_options.spp, options.seed,
                                              options.threads, control.stop));
        io::write_exr(folder / (t.name() + ".exr"), renders.back().second);
    }
    const io::Image8 shown = tonemap_together(reference, renders, inputs.plain.options().luma);
    const io::Image8 montage =
        write_panels(folder, reference, renders, shown, render_options.reference_spp,
                     caption_text(map_name, options, render_options.spp, compensated.options().compensation.alpha));
    const std::filesystem::path path = folder / "montage.png";
    io::write_png(path, montage);
    return path;
}

}  // namespace envmis::cli
