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

}  // namespace

Subcommand add_visualize(CLI::App& app) {
    struct Args {
        std::string input, output;
        uint32_t panel_width = 512;
        MapFlags map;
    };
    auto args = std::make_shared<Args>();
    CLI::App* sub = app.add_subcommand(
        "visualize", "One labelled PNG: the tone-mapped map, its density without and with compensation (shared scale)");
    sub->add_option("input", args->input, "HDR image or table")->required();
    sub->add_option("-o,--output", args->output, "PNG file to write")->required();
    sub->add_option("--panel-width", args->panel_width, "Width of each panel in pixels")
        ->capture_default_str()
        ->check(CLI::Range(64u, 4096u));
    add_map_flags(*sub, args->map);
    return {sub, [args] {
                const LoadedMap loaded = load_map(args->input, args->map);
                // The loaded map is one of the two densities; build only the other.
                const bool loaded_compensated = loaded.map.options().compensation.enabled;
                EnvMapOptions other_options = loaded.map.options();
                other_options.compensation.enabled = !loaded_compensated;
                const EnvMap other(to_image(loaded.map.radiance()), other_options);
                const EnvMap* maps[2] = {loaded_compensated ? &other : &loaded.map,
                                         loaded_compensated ? &loaded.map : &other};
                const EnvMapOptions& plain = maps[0]->options();
                const EnvMapOptions& compensated = maps[1]->options();

                const uint32_t w = loaded.map.width(), h = loaded.map.height();
                const uint32_t pw = std::min(args->panel_width, std::max(w, 64u));
                const uint32_t ph = std::max(1u, static_cast<uint32_t>(static_cast<uint64_t>(pw) * h / w));
                std::vector<float> pdfs[2];
                for (int i = 0; i < 2; ++i) pdfs[i] = pictures::resize(pdf_image(*maps[i]), w, h, pw, ph);
                const pictures::ColourScale scale = pictures::shared_log_scale({pdfs[0], pdfs[1]});

                char caption[256];
                std::snprintf(caption, sizeof caption,
                              "%s  %ux%u  mean luminance %.3g  alpha %.3g: compensation zeroes %.1f%% of texels",
                              loaded.source.name.c_str(), w, h, maps[1]->stats().mean_luminance,
                              compensated.compensation.alpha,
                              100.0 * maps[1]->stats().zeroed_texels / (static_cast<double>(w) * h));
                const pictures::Panel panels[] = {
                    {pictures::tonemap(pictures::resize(loaded.map.radiance(), pw, ph), 0, plain.luma),
                     "radiance (tone-mapped)", false},
                    {pictures::false_colour(pdfs[0], pw, ph, scale), "pdf without compensation", true},
                    {pictures::false_colour(pdfs[1], pw, ph, scale), "pdf with compensation", true}};
                const io::Image8 bar = pictures::colour_bar(scale, "solid-angle pdf [1/sr]", 2 * pw);
                io::write_png(args->output, pictures::montage(panels, caption, &bar));
                std::printf("envmis visualize: %s -> %s (%ux%u panels, pdf scale %.3g to %.3g per sr)\n",
                            args->input.c_str(), args->output.c_str(), pw, ph, scale.lo, scale.hi);
            }};
}

}  // namespace envmis::cli
