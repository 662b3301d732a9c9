#include "envmis/precompute/build.h"

#include <array>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <span>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "envmis/build/bins.h"
#include "envmis/build/env_map.h"
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
                  const StageCallback& on_stage, BuiltMap& built) {
    const auto stage = [&](std::string_view name) {
        if (on_stage) on_stage(name);
    };
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
            stage("choosing alpha");
            built.alpha_choice = choose_alpha(image, options);
            options.compensation.alpha = built.alpha_choice->alpha;
        }
        stage("building");
        const auto start = std::chrono::steady_clock::now();
        EnvMap map = build_env_map(std::move(image), options, stop);
        built.build_ms = milliseconds_since(start);
        if (r.bins == 0) {
            built.map = std::move(map);
            return;
        }
        stage("building bins");
        const auto bins_start = std::chrono::steady_clock::now();
        built.binned.emplace(build_bins(std::move(map), binned_options(r), stop));
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

namespace {

// canonical_options' keys in its order; the last is written only with bins.
constexpr std::string_view kOptionKeys[] = {"compensate", "alpha",   "mapping", "colorspace",   "working-space",
                                            "axes",       "compact", "bins",    "cell-columns", "bin-cost"};
constexpr size_t kOptionCount = std::size(kOptionKeys);

// The length of key i's "key=" at `at` (after a space unless it is the first key), or 0
// where it is not there.
size_t key_at(std::string_view text, size_t at, size_t i) {
    const std::string_view rest = text.substr(std::min(at, text.size()));
    const size_t space = i ? 1 : 0;
    const std::string_view key = kOptionKeys[i];
    if ((space && !rest.starts_with(' ')) || rest.substr(space, key.size()) != key ||
        rest.substr(space + key.size(), 1) != "=")
        return 0;
    return space + key.size() + 1;
}

// Each key's value as `text` spells it ("key=value" separated by spaces; values may hold
// spaces, as colour space names do), or nothing where a key is missing or out of order.
std::optional<std::array<std::string_view, kOptionCount>> option_values(std::string_view text) {
    std::array<std::string_view, kOptionCount> values;
    size_t at = 0;
    for (size_t i = 0; i < kOptionCount; ++i) {
        if (i + 1 == kOptionCount && at == text.size()) break;
        const size_t key = key_at(text, at, i);
        if (key == 0) return std::nullopt;
        at += key;
        size_t end = at;
        while (end < text.size() && !(i + 1 < kOptionCount && key_at(text, end, i + 1))) ++end;
        values[i] = text.substr(at, end - at);
        at = end;
    }
    return values;
}

template <class T>
bool read_number(std::string_view text, T& value) {
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
    return error == std::errc() && end == text.data() + text.size();
}

}  // namespace

std::optional<BuildRequest> parse_canonical_options(std::string_view text) {
    const auto values = option_values(text);
    if (!values) return std::nullopt;
    const auto& [compensate, alpha, mapping, colorspace, working_space, axes, compact, bins, cell_columns, bin_cost] =
        *values;
    BuildRequest r;
    r.compensate = compensate == "1";
    r.compact = compact == "1";
    if (alpha == "auto") {
        r.alpha_auto = true;
    } else if (alpha != "-") {
        float value = 0;
        if (!read_number(alpha, value)) return std::nullopt;
        r.alpha = value;
    }
    r.mapping = mapping;
    r.colorspace = colorspace == "(file)" ? "" : std::string(colorspace);
    r.working_space = working_space;
    r.axes = axes;
    if (!read_number(bins, r.bins) || !read_number(cell_columns, r.cell_columns)) return std::nullopt;
    if (!bin_cost.empty() && !read_number(bin_cost, r.bin_cost)) return std::nullopt;
    if (canonical_options(r) != text) return std::nullopt;
    return r;
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

BuiltMap build_map(const std::filesystem::path& path, const BuildRequest& r, StopFlag stop,
                   const StageCallback& on_stage) {
    check(r);
    if (on_stage) on_stage("reading");
    const auto start = std::chrono::steady_clock::now();
    io::LoadedImage image = io::load_image(path, {r.colorspace, r.working_space, stop});
    BuiltMap built;
    built.load_ms = milliseconds_since(start);
    built.notices = std::move(image.notices);
    build_pixels(std::move(image.image), r, image.luma, path.string(), stop, on_stage, built);
    built.source = {path.filename().string(), image.content_hash, image.input_colorspace, image.working_colorspace,
                    canonical_options(r)};
    built.format = image.format;
    built.channels = image.channels;
    return built;
}

BuiltMap build_map(RgbImage pixels, const BuildRequest& r, StopFlag stop, const StageCallback& on_stage) {
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
    build_pixels(std::move(pixels), r, luma, "array", stop, on_stage, built);
    built.source = {"array", hash, input, r.working_space, canonical_options(r)};
    built.format = "array";
    return built;
}

}  // namespace envmis
