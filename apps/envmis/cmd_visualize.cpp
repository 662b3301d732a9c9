// envmis visualize IN -o out.png: the map and its sampling densities, side by side.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <vector>

#include "cli.h"
#include "envmis/io/image_io.h"
#include "envmis/pictures/picture.h"

namespace envmis::cli {
namespace {

// Solid-angle pdf at every texel centre (per steradian): proportional to q, the
// compensated or plain luminance, without the sin(theta) of the image-space density.
std::vector<float> pdf_image(const EnvMap& map) {
    const uint32_t w = map.width(), h = map.height();
    std::vector<float> pdf(size_t{w} * h);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) pdf[size_t{y} * w + x] = map.pdf_uv({(x + 0.5f) / w, (y + 0.5f) / h});
    return pdf;
}

// The arguments of `envmis visualize`.
struct VisualizeArgs {
    std::string input, output;
    uint32_t panel_width = 512;
    MapFlags map;
};

void add_visualize_flags(CLI::App& sub, VisualizeArgs& args) {
    sub.add_option("input", args.input, "HDR image or table")->required();
    sub.add_option("-o,--output", args.output, "PNG file to write")->required();
    sub.add_option("--panel-width", args.panel_width, "Width of each panel in pixels")
        ->capture_default_str()
        ->check(in_range(uint32_t{64}, uint32_t{4096}));
    add_map_flags(sub, args.map);
}

// The two densities of a map: `loaded` is one of them, `other` the other one, built here.
struct Densities {
    const EnvMap& loaded;
    EnvMap other;
    const EnvMap& plain() const { return loaded.options().compensation.enabled ? other : loaded; }
    const EnvMap& compensated() const { return loaded.options().compensation.enabled ? loaded : other; }
};

EnvMap opposite_density(const EnvMap& map) {
    EnvMapOptions options = map.options();
    options.compensation.enabled = !options.compensation.enabled;
    return EnvMap(to_image(map.radiance()), options);
}

// The picture and what the command says about it.
struct Visualization {
    io::Image8 picture;
    uint32_t panel_width = 0, panel_height = 0;
    pictures::ColourScale scale;
};

Visualization visualize(const std::string& name, const Densities& d, uint32_t panel_width) {
    const uint32_t w = d.loaded.width(), h = d.loaded.height();
    const uint32_t pw = std::min(panel_width, std::max(w, 64u));
    const uint32_t ph = std::max(1u, static_cast<uint32_t>(static_cast<uint64_t>(pw) * h / w));
    const std::vector<float> pdfs[2] = {pictures::resize(pdf_image(d.plain()), w, h, pw, ph),
                                        pictures::resize(pdf_image(d.compensated()), w, h, pw, ph)};
    const pictures::ColourScale scale = pictures::shared_log_scale({pdfs[0], pdfs[1]});

    char caption[256];
    std::snprintf(caption, sizeof caption,
                  "%s  %ux%u  mean luminance %.3g  alpha %.3g: compensation zeroes %.1f%% of texels", name.c_str(), w,
                  h, d.compensated().stats().mean_luminance, d.compensated().options().compensation.alpha,
                  100.0 * d.compensated().stats().zeroed_texels / (static_cast<double>(w) * h));
    const pictures::Panel panels[] = {
        {pictures::tonemap(pictures::resize(d.loaded.radiance(), pw, ph), 0, d.plain().options().luma),
         "radiance (tone-mapped)", false},
        {pictures::false_colour(pdfs[0], pw, ph, scale), "pdf without compensation", true},
        {pictures::false_colour(pdfs[1], pw, ph, scale), "pdf with compensation", true}};
    const io::Image8 bar = pictures::colour_bar(scale, "solid-angle pdf [1/sr]", 2 * pw);
    return {pictures::montage(panels, caption, &bar), pw, ph, scale};
}

void run_visualize(const VisualizeArgs& args) {
    const LoadedMap loaded = load_map(args.input, args.map);
    const Densities densities{loaded.map, opposite_density(loaded.map)};
    const Visualization v = visualize(loaded.source.name, densities, args.panel_width);
    io::write_png(args.output, v.picture);
    std::printf("envmis visualize: %s -> %s (%ux%u panels, pdf scale %.3g to %.3g per sr)\n", args.input.c_str(),
                args.output.c_str(), v.panel_width, v.panel_height, v.scale.lo, v.scale.hi);
}

}  // namespace

Subcommand add_visualize(CLI::App& app) {
    auto args = std::make_shared<VisualizeArgs>();
    CLI::App* sub = app.add_subcommand(
        "visualize", "One labelled PNG: the tone-mapped map, its density without and with compensation (shared scale)");
    add_visualize_flags(*sub, *args);
    return {sub, [args] { run_visualize(*args); }};
}

}  // namespace envmis::cli
