#include "cli.h"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>
#include <string_view>

#include "envmis/io/image_io.h"

namespace envmis::cli {

void add_map_flags(CLI::App& app, MapFlags& flags) {
    app.add_flag("--no-compensate", flags.no_compensate, "Sample proportionally to luminance (no MIS compensation)");
    const CLI::Validator alpha_value(
        [](std::string& text) -> std::string {
            if (text == "auto") return {};
            char* end = nullptr;
            const float alpha = std::strtof(text.c_str(), &end);
            if (end != text.c_str() && *end == '\0' && alpha >= 0 && std::isfinite(alpha)) return {};
            return "'" + text + "': expected a number >= 0 or auto";
        },
        "");
    app.add_option_function<std::string>(
           "--alpha",
           [&flags](const std::string& text) {
               flags.alpha_auto = text == "auto";
               flags.alpha_given = true;
               if (!flags.alpha_auto) flags.alpha = std::strtof(text.c_str(), nullptr);
           },
           "Compensation strength: q = max(L - alpha * mean(L), 0); auto: the candidate with the lowest exact MIS "
           "variance (alpha.h; compare chooses per BSDF)")
        ->type_name("ALPHA|auto")
        ->default_str("1")
        ->check(alpha_value);
    app.add_option("--mapping", flags.mapping,
                   "Image mapping: equirect (latitude-longitude) or equal-area (octahedral, square)")
        ->capture_default_str()
        ->check(CLI::IsMember({"equirect", "equal-area"}));
    app.add_option("--colorspace", flags.colorspace, "Input colour space (default: from the file's metadata)");
    app.add_option("--working-space", flags.working_space, "Linear working colour space, e.g. lin_rec709 or ACEScg")
        ->capture_default_str();
    app.add_option("--axes", flags.axes, "World frame of directions: z-up, y-up or a signed permutation like x,z,-y")
        ->capture_default_str();
}

namespace {
// A side of a size: min_side to max_side (at most kMaxCells1D), digits only.
std::optional<uint32_t> parse_side(std::string_view text, uint32_t min_side, uint32_t max_side) {
    if (text.empty() || text.size() > 5 || text.find_first_not_of("0123456789") != std::string_view::npos) return {};
    const uint32_t side = static_cast<uint32_t>(std::stoul(std::string(text)));
    if (side < min_side || side > max_side) return {};
    return side;
}
}  // namespace

std::optional<Size> parse_size(const std::string& text, bool single, uint32_t min_side, uint32_t max_side) {
    const size_t x = text.find('x');
    if (x == std::string::npos) {
        if (!single) return {};
        if (const auto n = parse_side(text, min_side, max_side)) return Size{*n, 0};
        return {};
    }
    const auto w = parse_side(std::string_view(text).substr(0, x), min_side, max_side),
               h = parse_side(std::string_view(text).substr(x + 1), min_side, max_side);
    if (!w || !h) return {};
    return Size{*w, *h};
}

CLI::Validator size_validator(bool single, uint32_t min_side, uint32_t max_side) {
    const std::string expected = std::string(single ? "N or WxH" : "WxH") + ", each " + std::to_string(min_side) +
                                 " to " + std::to_string(max_side);
    return CLI::Validator(
        [=](std::string& text) -> std::string {
            if (parse_size(text, single, min_side, max_side)) return {};
            return "'" + text + "': expected " + expected;
        },
        "");
}

CLI::Validator bins_validator() {
    return CLI::Validator(
        [](std::string& text) -> std::string {
            uint32_t k = 0;
            const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), k);
            const uint32_t g = bins_per_side(k);
            if (error == std::errc() && end == text.data() + text.size() && g >= 1 && g <= 64 && g * g == k) return {};
            return text +
                   ": expected a square number of bins (g x g octahedral grid) from 1 to 4096, such as 64, "
                   "100 or 144";
        },
        "K");
}

namespace {
// A signal handler can reach only static storage.
std::atomic<bool> g_interrupted{false};
std::atomic<int> g_signal{0};
extern "C" void on_signal(int signal) {
    g_signal = signal;
    g_interrupted = true;
}
}  // namespace

void install_interrupt_handler() {
    struct sigaction action {};
    action.sa_handler = on_signal;
    action.sa_flags = SA_RESETHAND;  // the second signal takes the default action
    sigemptyset(&action.sa_mask);
    sigaction(SIGINT, &action, nullptr);
    sigaction(SIGTERM, &action, nullptr);
}

const std::atomic<bool>& interrupted() { return g_interrupted; }

int interrupting_signal() { return g_signal; }

void throw_if_interrupted() {
    if (g_interrupted) throw Interrupted();
}

int exit_interrupted(const std::string& detail) {
    const int signal = interrupting_signal();
    std::cerr << "envmis: interrupted by " << (signal == SIGTERM ? "SIGTERM" : "SIGINT")
              << (detail.empty() || detail == Interrupted().what() ? "" : ": " + detail) << "\n";
    return 128 + (signal ? signal : SIGINT);
}

double milliseconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

std::string resident_memory() {
    std::ifstream status("/proc/self/status");
    std::map<std::string, double> kib;
    for (std::string line; std::getline(status, line);) {
        std::istringstream fields(line);
        std::string key;
        double value = 0;
        if (fields >> key >> value) kib[key] = value;
    }
    if (!kib.count("VmRSS:") || !kib.count("VmHWM:")) return {};
    const auto mb = [&](const char* key) { return std::to_string(static_cast<long>(kib[key] / 1024 + 0.5)) + " MB"; };
    return "resident " + mb("VmRSS:") + " (anonymous " + mb("RssAnon:") + ", mapped files " + mb("RssFile:") +
           "), peak " + mb("VmHWM:");
}

LoadedMap load_map(const std::string& path, const MapFlags& flags) {
    const auto start = std::chrono::steady_clock::now();
    if (looks_like_table(path)) {
        Table table = read_table(path);
        LoadedMap loaded{std::move(table.map), std::move(table.source), true, "envmis table"};
        loaded.table_version = table.version;
        loaded.mapped = table.mapped;
        loaded.bins = std::move(table.bins);
        loaded.load_ms = milliseconds_since(start);
        return loaded;
    }
    io::LoadedImage image = io::load_image(path, {flags.colorspace, flags.working_space, &interrupted()});
    LoadedMap loaded;
    loaded.load_ms = milliseconds_since(start);
    EnvMapOptions options;
    options.compensation = {!flags.no_compensate, flags.alpha};
    options.luma = image.luma;
    options.axes = Axes::parse(flags.axes);
    options.mapping = parse_mapping(flags.mapping);
    if (options.mapping == Mapping::equal_area && image.image.width != image.image.height)
        throw std::runtime_error(path + ": an equal-area map must be square, this one is " +
                                 std::to_string(image.image.width) + "x" + std::to_string(image.image.height));
    if (options.mapping == Mapping::equirect && image.image.width == image.image.height && image.image.width > 1)
        std::cerr << "note: " << path << " is square; it is read as equirect (pass --mapping equal-area for an "
                  << "equal-area octahedral map)\n";
    if (flags.alpha_auto && !flags.no_compensate) {
        loaded.alpha_choice = choose_alpha(image.image, options);
        options.compensation.alpha = loaded.alpha_choice->alpha;
    }
    const auto build_start = std::chrono::steady_clock::now();
    loaded.map = EnvMap(std::move(image.image), options, &interrupted());
    loaded.build_ms = milliseconds_since(build_start);
    loaded.source = {std::filesystem::path(path).filename().string(), image.content_hash, image.input_colorspace,
                     image.working_colorspace};
    loaded.format = image.format;
    loaded.channels = image.channels;
    return loaded;
}

namespace {

std::string lobe_name(float exponent) {
    if (exponent == 0) return "diffuse";
    std::ostringstream name;
    name << "Phong " << exponent;
    return name.str();
}

// The bins' grids and lobe classes, and per class how many bins chose each alpha.
void print_bins(std::ostream& out, const BinLayout& layout) {
    const uint32_t g = layout.bins_per_side, bins = g * g;
    out << "  bins          " << bins << " (" << g << " x " << g << " octahedral grid of normals), cells "
        << layout.cell_columns << " x " << layout.cell_rows << ", lobe classes";
    for (size_t c = 0; c < layout.lobe_exponents.size(); ++c)
        out << (c ? ", " : " ") << lobe_name(layout.lobe_exponents[c]);
    out << "\n";
    for (size_t c = 0; c < layout.lobe_exponents.size(); ++c) {
        // Plain (alpha < 0) sorts first, then the alphas ascending.
        std::map<float, uint32_t> chosen;
        for (uint32_t b = 0; b < bins && (c * bins + b) < layout.choices.size(); ++b)
            ++chosen[std::max(layout.choices[c * bins + b].alpha, -1.0f)];
        out << "  bin alphas    " << std::left << std::setw(11) << lobe_name(layout.lobe_exponents[c]) + ":"
            << std::right;
        const char* separator = "";
        for (const auto& [alpha, count] : chosen) {
            out << separator << count << " ";
            if (alpha < 0)
                out << "plain";
            else
                out << "alpha " << alpha;
            separator = ", ";
        }
        out << "\n";
    }
}

}  // namespace

void print_bins_cost(std::ostream& out, const BinnedEnvMap& binned, double build_ms) {
    const EnvMap& plain = binned.plain();
    const double plain_bytes =
        static_cast<double>(plain.distribution().bytes()) + static_cast<double>(plain.radiance().pixels.size_bytes());
    const auto flags = out.flags();
    out << std::fixed << std::setprecision(1) << "  bins build    " << build_ms << " ms";
    if (binned.choice_seconds() > 0)
        out << " (choosing alphas " << 1e3 * binned.choice_seconds() << " ms)";
    else
        out << " (rebuilt from the stored layout)";
    out << ", " << binned.bytes() << " bytes over the plain map (+" << 100 * binned.bytes() / plain_bytes << "%)\n";
    // The summary's "complete pdf" is the plain map's; a compensated bin is incomplete.
    bool all = true;
    out << "  bins complete";
    for (uint32_t c = 0; c < binned.classes(); ++c) {
        out << (c ? ", " : " ") << lobe_name(binned.layout().lobe_exponents[c]) << " "
            << (binned.complete(c) ? "yes" : "no");
        all = all && binned.complete(c);
    }
    out << (all ? "\n" : " (where no: combine with BSDF sampling through MIS)\n");
    out.flags(flags);
}

void print_summary(std::ostream& out, const LoadedMap& loaded) { print_summary(out, loaded, loaded.map); }

void print_summary(std::ostream& out, const LoadedMap& loaded, const EnvMap& m) {
    const EnvMapStats& s = m.stats();
    const EnvMapOptions& o = m.options();
    const double texels = static_cast<double>(m.width()) * m.height();
    const auto flags = out.flags();
    out << std::setprecision(4);
    out << "  source        " << loaded.source.name << " (" << loaded.format << ", hash " << std::hex << std::setw(16)
        << std::setfill('0') << loaded.source.content_hash << std::dec << std::setfill(' ') << ")\n";
    out << "  size          " << m.width() << " x " << m.height() << "\n";
    out << "  colour        " << loaded.source.input_colorspace << " -> " << loaded.source.working_colorspace
        << ", luma (" << o.luma.r << ", " << o.luma.g << ", " << o.luma.b << ")\n";
    out << "  mapping       " << to_string(o.mapping) << ", axes " << o.axes.to_string() << "\n";
    out << "  luminance     max " << s.max_luminance << ", min positive " << s.min_positive_luminance;
    if (s.min_positive_luminance > 0)
        out << ", dynamic range " << s.max_luminance / s.min_positive_luminance << " ("
            << std::log10(s.max_luminance / s.min_positive_luminance) << " decades)";
    out << "\n  mean (Lbar)   " << s.mean_luminance << " (solid-angle weighted)\n";
    if (o.compensation.enabled)
        out << "  compensation  alpha " << o.compensation.alpha << ", threshold " << s.threshold << ", zeroed "
            << s.zeroed_texels << " texels with radiance (" << 100.0 * s.zeroed_texels / texels << "%)\n";
    else
        out << "  compensation  " << (loaded.bins ? "per bin (below)" : "off") << "\n";
    if (const auto& c = loaded.alpha_choice)
        out << "  alpha auto    " << c->alpha << " of " << c->candidates.size()
            << " candidates, by the exact variance of mis-balance-comp over mis-balance on a " << c->width << "x"
            << c->height << " copy (" << std::setprecision(3) << 1e3 * c->seconds << std::setprecision(4) << " ms)\n";
    out << "  bad pixels    " << s.bad_pixels.nan << " NaN, " << s.bad_pixels.infinite << " Inf, "
        << s.bad_pixels.negative << " negative channel values (replaced by 0)\n";
    out << "  fallback      " << to_string(s.fallback) << "\n";
    out << "  complete pdf  " << (m.complete() ? "yes" : "no: combine with BSDF sampling through MIS") << "\n";
    out << "  memory        " << std::setprecision(3) << m.distribution().bytes() / texels
        << " bytes/texel (distribution) + " << sizeof(Rgb) << " (radiance)\n";
    out.flags(flags);
    if (loaded.bins) print_bins(out, *loaded.bins);
}

namespace {
bool progress_lines() {
    const char* value = std::getenv("ENVMIS_PROGRESS");
    return value && std::string_view(value) == "1";
}
}  // namespace

Progress::Progress(std::string label, uint64_t total)
    : label_(std::move(label)),
      total_(total),
      terminal_(total > 0 && ::isatty(STDERR_FILENO)),
      lines_(total > 0 && !terminal_ && progress_lines()) {
    update(0);
}

Progress::~Progress() {
    if (terminal_ && shown_ >= 0) std::fprintf(stderr, "\r%*s\r", static_cast<int>(label_.size()) + 6, "");
}

void Progress::update(uint64_t done) {
    if (!terminal_ && !lines_) return;
    const int percent = static_cast<int>(100 * std::min(done, total_) / total_);
    if (percent == shown_) return;
    shown_ = percent;
    std::fprintf(stderr, terminal_ ? "\r%s %3d%%" : "%s %3d%%\n", label_.c_str(), percent);
    std::fflush(stderr);
}

}  // namespace envmis::cli
