#include "maps_build.h"

#include <cmath>
#include <stdexcept>
#include <utility>

#include "envmis/io/colour.h"
#include "envmis/io/image_io.h"
#include "envmis/math/hash.h"
#include "envmis/study/comparison/alpha.h"

namespace envmis::python {
namespace {

// The messages are the command line validators' (cli.cpp), with the keyword for the flag.
void check_bins(uint32_t bins) {
    const auto g = static_cast<uint32_t>(std::lround(std::sqrt(static_cast<double>(bins))));
    if (bins != 0 && (g < 1 || g > 64 || g * g != bins))
        throw std::invalid_argument("bins: " + std::to_string(bins) +
                                    ": expected a square number of bins (g x g octahedral grid) from 1 to 4096, such "
                                    "as 64, 100 or 144");
}

EnvMapOptions map_options(const BuildOptions& o, LumaCoefficients luma) {
    EnvMapOptions options;
    options.compensation = {o.compensate, o.alpha.value_or(1.0f)};
    options.luma = luma;
    options.axes = Axes::parse(o.axes);
    options.mapping = parse_mapping(o.mapping);
    return options;
}

// The bins as precompute --bins builds them (cmd_precompute.cpp binned_options): alpha
// auto per bin and lobe class unless a number was given or compensation is off.
BinnedOptions binned_options(const BuildOptions& o) {
    BinnedOptions b;
    b.bins_per_side = static_cast<uint32_t>(std::lround(std::sqrt(static_cast<double>(o.bins))));
    b.cell_columns = o.cell_columns;
    b.auto_alpha = (o.alpha_auto || !o.alpha) && o.compensate;
    b.alpha = o.compensate ? o.alpha.value_or(1.0f) : 0.0f;
    return b;
}

// The map of loaded pixels, as cli.cpp load_map builds it; what EnvMap refuses in them
// (their power overflowing float) is the source's fault and names it.
Built build(RgbImage image, const BuildOptions& o, LumaCoefficients luma, const std::string& name) {
    EnvMapOptions options = map_options(o, luma);
    Built built;
    if (options.mapping == Mapping::equal_area && image.width != image.height)
        throw std::invalid_argument(name + ": an equal-area map must be square, this one is " +
                                    std::to_string(image.width) + "x" + std::to_string(image.height));
    if (options.mapping == Mapping::equirect && image.width == image.height && image.width > 1)
        built.notices.push_back(name + " is square; it is read as equirect (pass mapping=\"equal-area\" for an " +
                                "equal-area octahedral map)");
    try {
        if (o.bins != 0) {
            // The texels keep the plain density; the compensation goes into the bins.
            options.compensation.enabled = false;
            built.binned.emplace(EnvMap(std::move(image), options), binned_options(o));
            return built;
        }
        if (o.alpha_auto && o.compensate) options.compensation.alpha = choose_alpha(image, options).alpha;
        built.map = EnvMap(std::move(image), options);
    } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(name + ": " + e.what());
    }
    return built;
}

}  // namespace

void check(const BuildOptions& o) {
    check_bins(o.bins);
    if (o.alpha && !(*o.alpha >= 0 && std::isfinite(*o.alpha)))
        throw std::invalid_argument("alpha: '" + std::to_string(*o.alpha) + "': expected a number >= 0 or auto");
    if (o.cell_columns > 4096)
        throw std::invalid_argument("cell_columns: Value " + std::to_string(o.cell_columns) +
                                    " not in range 0 to 4096");
    if (o.cell_columns != 0 && o.bins == 0) throw std::invalid_argument("cell_columns: needs bins");
}

Built load_table(const std::filesystem::path& path, bool mapped) {
    Table table = read_table(path, mapped ? TableLoading::map : TableLoading::copy);
    Built built;
    built.source = table.source;
    built.mapped = table.mapped;
    if (table.bins)
        built.binned.emplace(binned_map(std::move(table)));
    else
        built.map = std::move(table.map);
    return built;
}

Built load(const std::filesystem::path& path, const BuildOptions& o) {
    check(o);
    if (looks_like_table(path)) {
        if (o.bins != 0) throw std::invalid_argument(path.string() + ": is already a table; give an image");
        return load_table(path, true);
    }
    io::LoadedImage image = io::load_image(path, {o.colorspace, o.working_space});
    Built built = build(std::move(image.image), o, image.luma, path.string());
    built.source = {path.filename().string(), image.content_hash, image.input_colorspace, image.working_colorspace};
    for (std::string& notice : image.notices) built.notices.push_back(std::move(notice));
    return built;
}

Built from_pixels(RgbImage image, const BuildOptions& o) {
    check(o);
    const uint64_t hash = hash64(std::as_bytes(std::span<const Rgb>(image.pixels)));
    const std::string input = o.colorspace.empty() ? o.working_space : o.colorspace;
    // BT.709's luma for the default working space, exactly as the shipped OCIO config
    // declares it, without loading the config.
    LumaCoefficients luma;
    if (input != o.working_space || o.working_space != "lin_rec709") {
        const io::ColourConfig config;
        if (!config.has_space(o.working_space))
            throw std::invalid_argument("working_space: unknown colour space '" + o.working_space + "'");
        if (input != o.working_space) config.convert(image.pixels, input, o.working_space);
        luma = config.luma(o.working_space);
    }
    Built built = build(std::move(image), o, luma, "array");
    built.source = {"array", hash, input, o.working_space};
    return built;
}

}  // namespace envmis::python
