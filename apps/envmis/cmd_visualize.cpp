// envmis visualize IN -o out.png [--normal X,Y,Z [--bins K] [--lobe BSDF]]: the map and
// its sampling densities, side by side; with --normal, also the density that the binned
// sampler (binned.h) draws from at a shading point with that normal.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <sstream>
#include <vector>

#include "cli.h"
#include "envmis/build/bins.h"
#include "envmis/build/env_map.h"
#include "envmis/io/image_io.h"
#include "envmis/pictures/picture.h"
#include "envmis/study/shading/bsdf.h"

namespace envmis::cli {
namespace {

// The arguments of `envmis visualize`.
struct VisualizeArgs {
    std::string input, output;
    uint32_t panel_width = 512;
    BuildRequest map;                      // the map flags
    std::string normal, lobe = "lambert";  // normal empty: no binned panel
    uint32_t bins = 121;
};

void add_visualize_flags(CLI::App& sub, VisualizeArgs& args) {
    sub.add_option("input", args.input, "HDR image or table")->required();
    sub.add_option("-o,--output", args.output, "PNG file to write")->required()->check(output_extension(".png", "PNG"));
    sub.add_option("--panel-width", args.panel_width,
                   "Width of each panel in pixels (panels keep the map's aspect and are at most 4096 high: a tall "
                   "map's are narrower; a map over 64 times taller than wide is refused)")
        ->capture_default_str()
        ->check(in_range(uint32_t{64}, uint32_t{4096}));
    sub.add_option("--normal", args.normal,
                   "Also show the density of the bin whose square holds this normal (world frame; normalised); "
                   "a shading point there picks among it and its neighbours")
        ->type_name("X,Y,Z")
        ->check(direction_validator());
    sub.add_option("--bins", args.bins, "Bins of the binned sampler (with --normal)")
        ->type_name("K")
        ->capture_default_str()
        ->check(bins_validator());
    sub.add_option("--lobe", args.lobe,
                   "The shading point's BSDF, which picks the bin's lobe class (with --normal): lambert, phong:N "
                   "or ggx:A")
        ->type_name("BSDF")
        ->capture_default_str()
        ->check(bsdf_validator());
    add_map_flags(sub, args.map);
}

// The binned sampler over the map's plain density and the bin that `normal` picks for
// `lobe`'s class, with what the picture says about it.
struct BinPanel {
    std::unique_ptr<BinnedEnvMap> binned;
    Vec3 normal;
    uint32_t lobe = 0;
    std::string title, description;  // the panel's (short: it is cut to the panel), the command's
};

// A binned table's own bins, else bins built here (--bins) over the plain map.
std::optional<BinPanel> bin_panel(const VisualizeArgs& args, const LoadedMap& loaded, const EnvMap& plain) {
    if (args.normal.empty()) return std::nullopt;
    BinnedOptions options;
    options.bins_per_side = bins_per_side(args.bins);
    const Vec3 n = *parse_direction(args.normal);  // the flag's validator has accepted it
    const Bsdf bsdf = Bsdf::parse(args.lobe);
    BinPanel p;
    std::optional<Progress> progress(std::in_place, "building bins", 1);
    p.binned = loaded.bins ? std::make_unique<BinnedEnvMap>(EnvMap(plain), *loaded.bins)
                           : std::make_unique<BinnedEnvMap>(build_bins(EnvMap(plain), options, &interrupted()));
    progress.reset();
    p.normal = n;
    p.lobe = p.binned->lobe_class(bsdf.phong_exponent());
    const uint32_t lobe = p.lobe;
    const float exponent = p.binned->layout().lobe_exponents[lobe];
    std::ostringstream title, description;
    title.precision(2);
    title << "binned, n=(" << n.x << "," << n.y << "," << n.z << ")";
    description << "binned panel: normal (" << n.x << ", " << n.y << ", " << n.z << "), " << bsdf.name()
                << " -> lobe class " << lobe << " (Phong " << exponent << "), "
                << (lobe == 0 ? p.binned->diffuse_bins() : p.binned->bins()) << " bins"
                << (loaded.bins ? " (the table's)\n" : "\n");
    p.title = title.str();
    p.description = description.str();
    return p;
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
    return build_env_map(to_image(map.radiance()), options, &interrupted());
}

// The picture and what the command says about it.
struct Visualization {
    io::Image8 picture;
    uint32_t panel_width = 0, panel_height = 0;
    pictures::ColourScale scale;
};

// Panels keep the map's aspect and are at most kMaxPanelHeight pixels high: a tall map's
// are narrowed to fit, down to kMinPanelWidth; a map taller than that allows (more than
// 64 times taller than wide) is refused, naming `file`, before anything is drawn.
constexpr uint32_t kMinPanelWidth = 64, kMaxPanelHeight = 4096;

struct PanelSize {
    uint32_t width = 0, height = 0;
};

PanelSize panel_size(const std::string& file, uint32_t w, uint32_t h, uint32_t panel_width) {
    if (uint64_t{h} * kMinPanelWidth > uint64_t{w} * kMaxPanelHeight)
        throw std::runtime_error(
            file + ": a " + std::to_string(w) + "x" + std::to_string(h) + " map is too tall to draw: at most " +
            std::to_string(kMaxPanelHeight / kMinPanelWidth) + " times taller than wide (panels at most " +
            std::to_string(kMaxPanelHeight) + " pixels high)");
    const auto fit = static_cast<uint32_t>(uint64_t{kMaxPanelHeight} * w / h);
    const uint32_t pw = std::min({panel_width, std::max(w, kMinPanelWidth), std::max(fit, kMinPanelWidth)});
    return {pw, std::max(1u, static_cast<uint32_t>(uint64_t{pw} * h / w))};
}

Visualization visualize(const std::string& name, const Densities& d, const std::optional<BinPanel>& bin,
                        PanelSize panel) {
    const uint32_t w = d.loaded.width(), h = d.loaded.height();
    const uint32_t pw = panel.width, ph = panel.height;
    std::vector<std::vector<float>> pdfs = {pictures::resize(pdf_image(d.plain(), w, h), w, h, pw, ph),
                                            pictures::resize(pdf_image(d.compensated(), w, h), w, h, pw, ph)};
    if (bin) {
        const BinnedEnvMapView view = bin->binned->view();  // the bin points into it
        pdfs.push_back(pictures::resize(pdf_image(view.nearest_bin(bin->normal, bin->lobe), w, h), w, h, pw, ph));
    }
    const std::vector<std::span<const float>> spans(pdfs.begin(), pdfs.end());
    const pictures::ColourScale scale = pictures::shared_log_scale(spans);

    char caption[256];
    std::snprintf(caption, sizeof caption,
                  "%s  %ux%u  mean luminance %.3g  alpha %.3g: compensation zeroes %.1f%% of texels", name.c_str(), w,
                  h, d.compensated().stats().mean_luminance, d.compensated().options().compensation.alpha,
                  100.0 * d.compensated().stats().zeroed_texels / (static_cast<double>(w) * h));
    std::vector<pictures::Panel> panels = {
        {pictures::tonemap(pictures::resize(d.loaded.radiance(), pw, ph), 0, d.plain().options().luma),
         "radiance (tone-mapped)", false},
        {pictures::false_colour(pdfs[0], pw, ph, scale), "pdf without compensation", true},
        {pictures::false_colour(pdfs[1], pw, ph, scale), "pdf with compensation", true}};
    if (bin) panels.push_back({pictures::false_colour(pdfs[2], pw, ph, scale), bin->title, true});
    const io::Image8 bar =
        pictures::colour_bar(scale, "solid-angle pdf [1/sr]", static_cast<uint32_t>(pdfs.size()) * pw);
    return {pictures::montage(panels, caption, &bar), pw, ph, scale};
}

void run_visualize(const VisualizeArgs& args) {
    check_outputs({args.input}, {{"-o", args.output}});
    prepare_output(args.output);
    const LoadedMap loaded = load_map(args.input, args.map);
    const PanelSize panel = panel_size(args.input, loaded.map.width(), loaded.map.height(), args.panel_width);
    const Densities densities{loaded.map, opposite_density(loaded.map)};
    const std::optional<BinPanel> bin = bin_panel(args, loaded, densities.plain());
    const Visualization v = visualize(loaded.source.name, densities, bin, panel);
    io::write_png(args.output, v.picture);
    std::printf("envmis visualize: %s -> %s (%ux%u panels, pdf scale %.3g to %.3g per sr)\n", args.input.c_str(),
                args.output.c_str(), v.panel_width, v.panel_height, v.scale.lo, v.scale.hi);
    if (bin) std::fputs(bin->description.c_str(), stdout);
}

}  // namespace

Subcommand add_visualize(CLI::App& app) {
    auto args = std::make_shared<VisualizeArgs>();
    CLI::App* sub = app.add_subcommand(
        "visualize",
        "One labelled PNG: the tone-mapped map, its density without and with compensation and, with --normal, the "
        "binned density at that normal (shared scale)");
    add_visualize_flags(*sub, *args);
    add_threads_flag(*sub);
    return {sub, [args] { run_visualize(*args); }};
}

}  // namespace envmis::cli
