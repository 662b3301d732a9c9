#include "envmis/precompute/build.h"

#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <span>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "envmis/io/colour.h"
#include "envmis/io/image_io.h"
#include "envmis/math/hash.h"

namespace envmis {
namespace {

double milliseconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

uint32_t bins_side(uint32_t bins) { return static_cast<uint32_t>(std::lround(std::sqrt(static_cast<double>(bins)))); }

EnvMapOptions map_options(const BuildRequest& r, LumaCoefficients luma) {
    EnvMapOptions options;
    options.compensation = {r.compensate, r.alpha.value_or(1.0f)};
    options.luma = luma;
    options.axes = Axes::parse(r.axes);
    options.mapping = parse_mapping(r.mapping);
    return options;
}

// The map of loaded pixels into `built`; what EnvMap refuses in them (their power
// overflowing float) is the source's fault and names it.
void build_pixels(RgbImage image, const BuildRequest& r, LumaCoefficients luma, const std::string& name, StopFlag stop,
                  BuiltMap& built) {
    EnvMapOptions options = map_options(r, luma);
    if (options.mapping == Mapping::equal_area && image.width != image.height)
        throw std::invalid_argument(name + ": an equal-area map must be square, this one is " +
                                    std::to_string(image.width) + "x" + std::to_string(image.height));
    if (options.mapping == Mapping::equirect && image.width == image.height && image.width > 1)
        built.notices.push_back(name + " is square; it is read as equirect (mapping equal-area reads it as an " +
                                "equal-area octahedral map)");
    try {
        // With bins the texels keep the plain density; the compensation goes into the bins.
        if (r.bins != 0) options.compensation.enabled = false;
        if (r.bins == 0 && r.alpha_auto && r.compensate) {
            built.alpha_choice = choose_alpha(image, options);
            options.compensation.alpha = built.alpha_choice->alpha;
        }
        const auto start = std::chrono::steady_clock::now();
        EnvMap map(std::move(image), options, stop);
        built.build_ms = milliseconds_since(start);
        if (r.bins == 0) {
            built.map = std::move(map);
            return;
        }
        const auto bins_start = std::chrono::steady_clock::now();
        built.binned.emplace(std::move(map), binned_options(r), stop);
        built.bins_ms = milliseconds_since(bins_start);
    } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(name + ": " + e.what());
    }
}

}  // namespace

std::string canonical_options(const BuildRequest& r) {
    const bool automatic = r.bins ? r.alpha_auto || !r.alpha : r.alpha_auto;
    char alpha[32];
    std::snprintf(alpha, sizeof alpha, "%.9g", r.alpha.value_or(1.0f));
    std::ostringstream text;
    text << "compensate=" << r.compensate << " alpha="
         << (!r.compensate ? "-"
             : automatic   ? "auto"
                           : alpha)
         << " mapping=" << r.mapping << " colorspace=" << (r.colorspace.empty() ? "(file)" : r.colorspace)
         << " working-space=" << r.working_space << " axes=" << r.axes << " compact=" << r.compact << " bins=" << r.bins
         << " cell-columns=" << r.cell_columns;
    if (r.bins) {
        char cost[32];
        std::snprintf(cost, sizeof cost, "%.9g", r.bin_cost);
        text << " bin-cost=" << cost;
    }
    return text.str();
}

std::string alpha_problem(std::string_view text) {
    if (text == "auto") return {};
    const std::string value(text);
    char* end = nullptr;
    const float alpha = std::strtof(value.c_str(), &end);
    if (end != value.c_str() && *end == '\0' && alpha >= 0 && std::isfinite(alpha)) return {};
    return "'" + value + "': expected a number >= 0 or auto";
}

std::string bins_problem(std::string_view text) {
    uint32_t k = 0;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), k);
    const uint32_t g = bins_side(k);
    if (error == std::errc() && end == text.data() + text.size() && g >= 1 && g <= 64 && g * g == k) return {};
    return std::string(text) +
           ": expected a square number of bins (g x g octahedral grid) from 1 to 4096, such as 64, 100 or 144";
}

void check(const BuildRequest& r) {
    if (r.bins != 0)
        if (const std::string problem = bins_problem(std::to_string(r.bins)); !problem.empty())
            throw std::invalid_argument("bins: " + problem);
    if (r.alpha) {
        std::ostringstream text;
        text << *r.alpha;
        if (const std::string problem = alpha_problem(text.str()); !problem.empty())
            throw std::invalid_argument("alpha: " + problem);
    }
    if (r.cell_columns > kMaxCellColumns)
        throw std::invalid_argument("cell_columns: Value " + std::to_string(r.cell_columns) + " not in range 0 to " +
                                    std::to_string(kMaxCellColumns));
    if (r.cell_columns != 0 && r.bins == 0) throw std::invalid_argument("cell_columns: needs bins");
    if (!(r.bin_cost >= 1 && r.bin_cost <= 100))
        throw std::invalid_argument("bin_cost: " + std::to_string(r.bin_cost) + " not in range 1 to 100");
}

BinnedOptions binned_options(const BuildRequest& r) {
    BinnedOptions o;
    o.bins_per_side = bins_side(r.bins);
    o.cell_columns = r.cell_columns;
    o.cost = r.bin_cost;
    o.auto_alpha = (r.alpha_auto || !r.alpha) && r.compensate;
    o.alpha = r.compensate ? r.alpha.value_or(1.0f) : 0.0f;
    return o;
}

BuiltMap build_map(const std::filesystem::path& path, const BuildRequest& r, StopFlag stop) {
    check(r);
    const auto start = std::chrono::steady_clock::now();
    io::LoadedImage image = io::load_image(path, {r.colorspace, r.working_space, stop});
    BuiltMap built;
    built.load_ms = milliseconds_since(start);
    built.notices = std::move(image.notices);
    build_pixels(std::move(image.image), r, image.luma, path.string(), stop, built);
    built.source = {path.filename().string(), image.content_hash, image.input_colorspace, image.working_colorspace,
                    canonical_options(r)};
    built.format = image.format;
    built.channels = image.channels;
    return built;
}

BuiltMap build_map(RgbImage pixels, const BuildRequest& r, StopFlag stop) {
    check(r);
    const uint64_t hash = hash64(std::as_bytes(std::span<const Rgb>(pixels.pixels)));
    const std::string input = r.colorspace.empty() ? r.working_space : r.colorspace;
    // BT.709's luma for the default working space, exactly as the shipped OCIO config
    // declares it, without loading the config.
    LumaCoefficients luma;
    if (input != r.working_space || r.working_space != "lin_rec709") {
        const io::ColourConfig config;
        if (!config.has_space(r.working_space))
            throw std::invalid_argument("working_space: unknown colour space '" + r.working_space + "'");
        if (input != r.working_space) config.convert(pixels.pixels, input, r.working_space);
        luma = config.luma(r.working_space);
    }
    BuiltMap built;
    build_pixels(std::move(pixels), r, luma, "array", stop, built);
    built.source = {"array", hash, input, r.working_space, canonical_options(r)};
    built.format = "array";
    return built;
}

}  // namespace envmis
