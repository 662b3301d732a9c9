#include "render.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli.h"
#include "envmis/build/atomic_file.h"
#include "envmis/io/image_io.h"
#include "envmis/pictures/picture.h"

namespace envmis::cli {
namespace {

// An orthographic camera on the -y side looking along +y at spheres centred on the x
// axis, z up (the map's default up), one per BSDF, side by side.
struct Scene {
    uint32_t w, h, spheres;
    float radius;

    // The sphere whose cell holds pixel column x.
    uint32_t sphere_of(uint32_t x) const {
        return std::min(spheres - 1, static_cast<uint32_t>((x + 0.5f) * spheres / static_cast<float>(w)));
    }
    // The first pixel column of sphere i's cell (i = spheres: the width).
    uint32_t cell_begin(uint32_t i) const {
        uint32_t x = 0;
        while (x < w && sphere_of(x) < i) ++x;
        return x;
    }

    // The shading point seen through pixel (x, y), or false for the background.
    bool point(uint32_t x, uint32_t y, ShadingPoint& p, uint32_t& sphere) const {
        const float cell = static_cast<float>(w) / spheres;
        sphere = sphere_of(x);
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

// Per-pixel squared error relative to the reference, in luminance (0 off the spheres),
// and its mean over each sphere's pixels (relMSE).
struct RelativeError {
    std::vector<float> pixels;
    std::vector<double> sphere_means;
};
RelativeError relative_squared_error(const RgbImage& image, const RgbImage& reference, const Scene& scene) {
    RelativeError e{std::vector<float>(image.pixels.size()), std::vector<double>(scene.spheres)};
    std::vector<size_t> counted(scene.spheres);
    for (uint32_t y = 0; y < scene.h; ++y)
        for (uint32_t x = 0; x < scene.w; ++x) {
            const size_t i = size_t{y} * scene.w + x;
            const float r = luminance(reference.pixels[i], {});
            if (!(r > 0)) continue;
            const float d = luminance(image.pixels[i], {}) - r;
            e.pixels[i] = d * d / (r * r);
            e.sphere_means[scene.sphere_of(x)] += e.pixels[i], ++counted[scene.sphere_of(x)];
        }
    for (uint32_t k = 0; k < scene.spheres; ++k)
        e.sphere_means[k] = counted[k] ? e.sphere_means[k] / static_cast<double>(counted[k]) : 0.0;
    return e;
}

io::Image8 crop(const io::Image8& image, uint32_t x0, uint32_t width) {
    io::Image8 out = pictures::make_image(width, image.height, {});
    pictures::blit(out, image, -static_cast<int>(x0), 0);
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

// The montage's widest, so that a comparison of every default technique (12 columns with
// the reference) stays about a screen wide.
constexpr int kMontageWidth = 2000;

// The montage's grid: a column per technique (the reference first), for each BSDF a row
// of renders and under it a row of their errors, so that every error map sits under the
// render it measures. Sphere cells are the renders' own pixels, scaled down only where
// the grid would be wider than kMontageWidth.
struct MontageGrid {
    Scene scene;
    double scale = 1;

    // `labels`: the rows' titles.
    MontageGrid(const Scene& scene, const std::vector<std::string>& labels, size_t columns,
                const pictures::Style& style)
        : scene(scene) {
        int label = 0, cell = 0;
        for (const std::string& l : labels) label = std::max(label, pictures::text_width(l, style.text_scale));
        for (uint32_t i = 0; i < scene.spheres; ++i)
            cell = std::max(cell, static_cast<int>(scene.cell_begin(i + 1) - scene.cell_begin(i)));
        const int room = kMontageWidth - 2 * style.margin - label - static_cast<int>(columns) * style.gap;
        scale = std::clamp(static_cast<double>(room) / (static_cast<double>(columns) * cell), 1.0 / cell, 1.0);
    }

    // Sphere i's cell of a picture whose panel for this column starts at x0.
    io::Image8 cell(const io::Image8& picture, uint32_t x0, uint32_t i) const {
        const uint32_t begin = scene.cell_begin(i), width = scene.cell_begin(i + 1) - begin;
        const io::Image8 cut = crop(picture, x0 + begin, width);
        if (scale == 1) return cut;
        const auto side = [&](uint32_t n) { return std::max(1u, static_cast<uint32_t>(n * scale)); };
        return pictures::resize(cut, side(width), side(scene.h));
    }
};

// Where the montage put each cell, with each sphere's relMSE: montage.json, for scripts
// and the test that reads the layout.
nlohmann::json layout_json(const pictures::GridFigure& figure, const pictures::Grid& grid,
                           const std::vector<std::string>& bsdfs, const std::vector<std::vector<double>>& relmse,
                           const std::string& caption) {
    nlohmann::json j{{"caption", caption},
                     {"size", {figure.image.width, figure.image.height}},
                     {"bsdfs", bsdfs},
                     {"columns", grid.columns},
                     {"cells", nlohmann::json::array()}};
    const size_t columns = grid.columns.size();
    const auto rect = [&](size_t row, size_t column) {
        const pictures::Rect r = figure.cells[row * columns + column];
        return nlohmann::json{r.x, r.y, r.width, r.height};
    };
    for (size_t b = 0; b < bsdfs.size(); ++b)
        for (size_t c = 0; c < columns; ++c) {
            nlohmann::json cell{{"column", grid.columns[c]}, {"bsdf", bsdfs[b]}, {"render", rect(2 * b, c)}};
            if (c > 0) cell["error"] = rect(2 * b + 1, c), cell["relmse"] = relmse[c - 1][b];
            j["cells"].push_back(std::move(cell));
        }
    return j;
}

// Writes each panel's PNG, then the montage (montage.png) and its layout (montage.json).
void write_panels(const std::filesystem::path& folder, const Scene& scene, const RgbImage& reference,
                  const std::vector<std::pair<std::string, RgbImage>>& renders, const io::Image8& shown,
                  const ComparisonOptions& options, uint32_t reference_spp, const std::string& caption) {
    const uint32_t w = reference.width, h = reference.height;
    io::write_png(folder / "reference.png", crop(shown, 0, w));
    // A fixed scale: a few pixels hit by a rare bright sample would otherwise stretch it
    // over many decades and leave the typical errors indistinguishable.
    const pictures::ColourScale scale{1e-4f, 10.0f, true};
    std::vector<io::Image8> errors;
    std::vector<std::vector<double>> relmse;
    for (uint32_t i = 0; i < renders.size(); ++i) {
        io::write_png(folder / (renders[i].first + ".png"), crop(shown, (i + 1) * w, w));
        const RelativeError error = relative_squared_error(renders[i].second, reference, scene);
        errors.push_back(pictures::false_colour(error.pixels, w, h, scale));
        relmse.push_back(error.sphere_means);
        io::write_png(folder / (renders[i].first + "-relmse.png"), errors.back());
    }

    const pictures::Style style;
    pictures::Grid grid{{"reference (" + std::to_string(reference_spp) + " spp)"}, {}, {}};
    for (const auto& r : renders) grid.columns.push_back(r.first);
    std::vector<std::string> bsdfs;
    for (const Bsdf& b : options.bsdfs) bsdfs.push_back(b.name());
    std::vector<std::string> labels = bsdfs;
    labels.push_back("error");
    const MontageGrid layout(scene, labels, grid.columns.size(), style);
    for (uint32_t b = 0; b < bsdfs.size(); ++b) {
        grid.rows.push_back(bsdfs[b]);
        for (uint32_t c = 0; c < grid.columns.size(); ++c) grid.cells.push_back({layout.cell(shown, c * w, b), ""});
        grid.rows.push_back("error");
        grid.cells.push_back({});
        for (uint32_t i = 0; i < renders.size(); ++i) {
            char text[32];
            std::snprintf(text, sizeof text, "%.3g", relmse[i][b]);
            grid.cells.push_back({layout.cell(errors[i], 0, b), text});
        }
    }
    const io::Image8 bar =
        pictures::colour_bar(scale, "error rows: per-pixel relative squared error; under each sphere its mean (relMSE)",
                             std::min(4u * w, 1600u), pictures::Orientation::horizontal, style);
    const pictures::GridFigure figure = pictures::grid(grid, caption, &bar, style);
    io::write_png(folder / "montage.png", figure.image);
    write_file_atomically(folder / "montage.json", [&](std::ostream& out) {
        out << layout_json(figure, grid, bsdfs, relmse, caption).dump(2) << "\n";
    });
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
    write_panels(folder, scene, reference, renders, shown, options, render_options.reference_spp,
                 caption_text(map_name, options, render_options.spp, compensated.options().compensation.alpha));
    return folder / "montage.png";
}

}  // namespace envmis::cli
