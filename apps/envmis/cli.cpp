#include "cli.h"

#include <signal.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>
#include <string_view>

#include "envmis/build/atomic_file.h"
#include "envmis/io/image_io.h"
#include "envmis/study/shading/bsdf.h"

namespace envmis::cli {

void limit_threads(uint32_t threads) { ::setenv("ENVMIS_THREADS", std::to_string(threads).c_str(), 1); }

void add_threads_flag(CLI::App& app) {
    app.add_option_function<uint32_t>("--threads", limit_threads,
                                      "Threads of the build's parallel loops, 1 to " + std::to_string(kMaxThreads) +
                                          " (default: the cores the CPU affinity and cgroup quota allow, as "
                                          "envmis::usable_cores counts them)")
        ->check(in_range(uint32_t{1}, kMaxThreads));
}

void add_map_flags(CLI::App& app, BuildRequest& request) {
    app.add_flag_callback(
        "--no-compensate", [&request] { request.compensate = false; },
        "Sample proportionally to luminance (no MIS compensation)");
    const CLI::Validator alpha_value([](std::string& text) { return alpha_problem(text); }, "");
    app.add_option_function<std::string>(
           "--alpha",
           [&request](const std::string& text) {
               request.alpha_auto = text == "auto";
               if (!request.alpha_auto) request.alpha = std::strtof(text.c_str(), nullptr);
           },
           "Compensation strength: q = max(L - alpha * mean(L), 0); auto: the candidate with the lowest exact MIS "
           "variance (alpha.h; compare chooses per BSDF)")
        ->type_name("ALPHA|auto")
        ->default_str("1")
        ->check(alpha_value)
        ->excludes("--no-compensate");
    app.add_option("--mapping", request.mapping,
                   "Image mapping: equirect (latitude-longitude) or equal-area (octahedral, square)")
        ->capture_default_str()
        ->check(CLI::IsMember({"equirect", "equal-area"}));
    app.add_option("--colorspace", request.colorspace, "Input colour space (default: from the file's metadata)");
    app.add_option("--working-space", request.working_space, "Linear working colour space, e.g. lin_rec709 or ACEScg")
        ->capture_default_str();
    app.add_option("--axes", request.axes,
                   "World frame of directions: z-up, y-up, a renderer's (pbrt-v4, mitsuba3, blender) or a signed "
                   "permutation like x,z,-y")
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

CLI::Validator non_empty() {
    return CLI::Validator([](std::string& text) { return text.empty() ? "expected a path, got ''" : ""; }, "");
}

CLI::Validator output_extension(const std::string& extension, const std::string& format) {
    return CLI::Validator(
        [extension, format](std::string& text) -> std::string {
            if (text.empty()) return "expected a path, got ''";
            std::string ext = std::filesystem::path(text).extension().string();
            std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
            if (ext == extension) return "";
            return text + ": writes " + format + ", so the name must end in " + extension;
        },
        "");
}

CLI::Validator bins_validator() {
    return CLI::Validator([](std::string& text) { return bins_problem(text); }, "K");
}

CLI::Option* add_cell_columns_flag(CLI::App& app, uint32_t& columns) {
    return app
        .add_option(
            "--cell-columns", columns,
            "With --bins: columns of the bins' cell grid (rows: half as many for equirect, as many for equal-area; "
            "0: width / 32, clamped to 1 to 128 and to at most 112 x 56 cells, 79 x 79 for equal-area)")
        ->type_name("N")
        ->check(in_range(uint32_t{0}, kMaxCellColumns));
}

CLI::Option* add_bin_cost_flag(CLI::App& app, float& cost) {
    return app
        .add_option("--bin-cost", cost,
                    "With --bins: time of an estimate with a compensated bin over one with the plain density; a "
                    "bin keeps compensation only where it is predicted that much lower in variance (equal time). "
                    "Both cost about the same; the default is a margin for the choice's errors, 1 chooses at "
                    "equal samples")
        ->type_name("R")
        ->capture_default_str()
        ->check(CLI::Validator(
            [](std::string& text) -> std::string {
                float value = 0;
                const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
                if (error == std::errc() && end == text.data() + text.size() && value >= 1 && value <= 100) return {};
                return "'" + text + "': expected a number from 1 to 100";
            },
            "R"));
}

std::optional<Vec3> parse_direction(const std::string& text) {
    float v[3];
    const char* p = text.data();
    const char* end = text.data() + text.size();
    for (int i = 0; i < 3; ++i) {
        if (i > 0 && (p == end || *p++ != ',')) return std::nullopt;
        const auto [next, error] = std::from_chars(p, end, v[i]);
        if (error != std::errc() || !std::isfinite(v[i])) return std::nullopt;
        p = next;
    }
    const Vec3 n{v[0], v[1], v[2]};
    if (p != end || !(length(n) > 0) || !std::isfinite(length(n))) return std::nullopt;
    return normalize(n);
}

CLI::Validator direction_validator() {
    return CLI::Validator(
        [](std::string& text) -> std::string {
            if (parse_direction(text)) return {};
            return "'" + text + "': expected X,Y,Z, three finite numbers, not all zero";
        },
        "");
}

CLI::Validator bsdf_validator() {
    return CLI::Validator(
        [](std::string& text) -> std::string {
            try {
                Bsdf::parse(text);
                return {};
            } catch (const std::invalid_argument& e) {
                return "'" + text + "': " + e.what();
            }
        },
        "");
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
              << (detail.empty() || detail == Interrupted().what() ? "" : ": " + printable(detail)) << "\n";
    return 128 + (signal ? signal : SIGINT);
}

std::string nearest_name(std::string_view word, const std::vector<std::string>& names) {
    // Optimal string alignment distance, one row at a time plus the two before it.
    const auto distance = [](std::string_view a, std::string_view b) {
        std::vector<size_t> before(b.size() + 1), last(b.size() + 1), row(b.size() + 1);
        for (size_t j = 0; j <= b.size(); ++j) last[j] = j;
        for (size_t i = 1; i <= a.size(); ++i) {
            row[0] = i;
            for (size_t j = 1; j <= b.size(); ++j) {
                row[j] = std::min({last[j] + 1, row[j - 1] + 1, last[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
                if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
                    row[j] = std::min(row[j], before[j - 2] + 1);
            }
            std::swap(before, last), std::swap(last, row);
        }
        return last[b.size()];
    };
    std::string best;
    size_t best_distance = 3;
    for (const std::string& name : names) {
        const size_t d = !word.empty() && name.starts_with(word) ? 0 : distance(word, name);
        if (d < best_distance) best = name, best_distance = d;
    }
    return best;
}

std::string printable(std::string_view text) {
    std::string out;
    out.reserve(text.size());
    char escape[8];
    for (size_t i = 0; i < text.size(); ++i) {
        const auto c = static_cast<unsigned char>(text[i]);
        const auto next = i + 1 < text.size() ? static_cast<unsigned char>(text[i + 1]) : 0;
        if (c == '\\') {
            out += "\\\\";
        } else if (c < 0x20 || c == 0x7f) {
            std::snprintf(escape, sizeof escape, "\\x%02x", c);
            out += escape;
        } else if (c == 0xc2 && next >= 0x80 && next <= 0x9f) {
            std::snprintf(escape, sizeof escape, "\\u%04x", next);
            out += escape;
            ++i;
        } else {
            out += static_cast<char>(c);
        }
    }
    return out;
}

namespace {
// A "Key:   N kB" line of a /proc file, in bytes; empty where there is none.
std::optional<uint64_t> proc_kib(const char* file, const std::string& key) {
    std::ifstream in(file);
    for (std::string line; std::getline(in, line);)
        if (line.compare(0, key.size(), key) == 0) {
            std::istringstream fields(line.substr(key.size()));
            uint64_t kib = 0;
            if (fields >> kib) return kib * 1024;
        }
    return std::nullopt;
}

// What this process's control group still allows, where it has a limit: in a container
// or a CI runner MemAvailable counts the whole machine. cgroup v2 ("0::PATH": memory.max,
// "max" where unlimited) or v1 (":memory:PATH": memory.limit_in_bytes, a huge number
// where unlimited).
std::optional<uint64_t> cgroup_memory_left() {
    std::ifstream self("/proc/self/cgroup");
    for (std::string line; std::getline(self, line);) {
        std::filesystem::path limit_file, usage_file;
        if (line.rfind("0::", 0) == 0) {
            const std::filesystem::path group = "/sys/fs/cgroup" + line.substr(3);
            limit_file = group / "memory.max", usage_file = group / "memory.current";
        } else if (const size_t at = line.find(":memory:"); at != std::string::npos) {
            const std::filesystem::path group = "/sys/fs/cgroup/memory" + line.substr(at + 8);
            limit_file = group / "memory.limit_in_bytes", usage_file = group / "memory.usage_in_bytes";
        } else {
            continue;
        }
        uint64_t limit = 0, usage = 0;
        std::ifstream limit_in(limit_file), usage_in(usage_file);
        if ((limit_in >> limit) && (usage_in >> usage)) return limit > usage ? limit - usage : 0;
    }
    return std::nullopt;
}
}  // namespace

std::optional<uint64_t> available_memory() {
    std::optional<uint64_t> available = proc_kib("/proc/meminfo", "MemAvailable:");
    if (const std::optional<uint64_t> group = cgroup_memory_left())
        available = std::min(available.value_or(*group), *group);
    rlimit limit{};
    if (::getrlimit(RLIMIT_AS, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY) {
        const uint64_t used = proc_kib("/proc/self/status", "VmSize:").value_or(0);
        const uint64_t left = limit.rlim_cur > used ? limit.rlim_cur - used : 0;
        available = std::min(available.value_or(left), left);
    }
    return available;
}

void check_memory(const std::string& what, uint64_t bytes) {
    const std::optional<uint64_t> available = available_memory();
    if (!available || bytes <= *available) return;
    const auto mb = [](uint64_t b) { return std::to_string((b + (1 << 20) - 1) >> 20) + " MB"; };
    throw std::runtime_error(what + ": needs " + mb(bytes) + " of memory, more than the " + mb(*available) +
                             " available");
}

void check_image_size(const std::string& what, Size size, uint64_t bytes_per_texel) {
    const uint64_t texels = uint64_t{size.width} * size.height;
    if (texels > kMaxTexels)
        throw std::runtime_error(what + ": " + std::to_string(size.width) + "x" + std::to_string(size.height) + " is " +
                                 std::to_string(texels) + " texels, above the limit of " + std::to_string(kMaxTexels) +
                                 " (2^31)");
    check_memory(what, texels * bytes_per_texel);
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

uint64_t header_texels(const std::filesystem::path& input) {
    try {
        if (looks_like_table(input)) {
            const TableHeader header = read_table_header(input);
            return uint64_t{header.width} * header.height;
        }
        return io::read_image_size(input).largest_texels;
    } catch (const std::exception&) {
        return 0;
    }
}

void check_map_memory(const std::filesystem::path& input, uint64_t bytes_per_texel) {
    const auto check = [&](uint32_t w, uint32_t h, uint64_t texels, uint64_t per_texel) {
        check_memory(input.string() + " (" + std::to_string(w) + "x" + std::to_string(h) + ")", texels * per_texel);
    };
    if (looks_like_table(input)) {
        // A mapped table copies only its density (4 bytes a texel) beside its sampling
        // tables (6); a compact or version 1-2 table is read whole and decoded (24).
        const TableHeader header = read_table_header(input);
        const bool read_whole = header.compact || header.version < 3;
        check(header.width, header.height, uint64_t{header.width} * header.height, read_whole ? 24 : 12);
        return;
    }
    const io::ImageSize size = io::read_image_size(input);
    check(size.width, size.height, size.largest_texels, bytes_per_texel);
}

LoadedMap load_map(const std::string& path, const BuildRequest& request, std::ostream& notes) {
    check_map_memory(path, kBuildPeak);
    if (looks_like_table(path)) {
        const auto start = std::chrono::steady_clock::now();
        Table table = read_table(path);
        LoadedMap loaded{std::move(table.map), std::move(table.source), true, "envmis table"};
        loaded.table_version = table.version;
        loaded.mapped = table.mapped;
        loaded.compact = table.compact;
        loaded.bins = std::move(table.bins);
        loaded.load_ms = milliseconds_since(start);
        return loaded;
    }
    BuiltMap built = build_map(path, request, &interrupted());
    for (const std::string& notice : built.notices) notes << "note: " << printable(notice) << "\n";
    return loaded_map(built);
}

LoadedMap loaded_map(BuiltMap& built) {
    LoadedMap loaded{std::move(built.map), std::move(built.source), false, std::move(built.format)};
    loaded.channels = built.channels;
    loaded.load_ms = built.load_ms;
    loaded.build_ms = built.build_ms;
    loaded.alpha_choice = std::move(built.alpha_choice);
    if (built.binned) loaded.bins = built.binned->layout();
    return loaded;
}

namespace {

std::string lobe_name(float exponent) {
    if (exponent == 0) return "diffuse";
    std::ostringstream name;
    name << "Phong " << exponent;
    return name.str();
}

// Per glossy class, how many compensated bins keep their density up to each view angle
// (BinChoice::min_view_cos, in whole degrees from the normal; widest first).
void print_view_limits(std::ostream& out, const BinLayout& layout) {
    for (uint32_t c = 1; c < layout.classes(); ++c) {
        std::map<int, uint32_t, std::greater<>> limits;
        for (size_t i = layout.first(c); i < layout.first(c + 1) && i < layout.choices.size(); ++i)
            if (!layout.choices[i].plain())
                ++limits[static_cast<int>(std::lround(std::acos(layout.choices[i].min_view_cos) * 180 / kPi))];
        if (limits.empty()) continue;
        out << "  bin views     " << std::left << std::setw(11) << lobe_name(layout.lobe_exponents[c]) + ":"
            << std::right;
        const char* separator = "";
        for (const auto& [degrees, count] : limits) {
            out << separator << count << (degrees >= 90 ? " every view" : " up to " + std::to_string(degrees) + " deg");
            separator = ", ";
        }
        out << "\n";
    }
    out << "                (view: from the normal; a compensated glossy bin seen more obliquely samples the plain "
           "density)\n";
}

// The bins' grids and lobe classes, and per class how many bins chose each alpha.
void print_bins(std::ostream& out, const BinLayout& layout) {
    const uint32_t g = layout.bins_per_side, gd = layout.diffuse_bins_per_side;
    out << "  bins          " << g * g << " (" << g << " x " << g << " octahedral grid of normals; the diffuse class "
        << gd * gd << ", " << gd << " x " << gd << "), cells " << layout.cell_columns << " x " << layout.cell_rows
        << ", lobe classes";
    for (size_t c = 0; c < layout.lobe_exponents.size(); ++c)
        out << (c ? ", " : " ") << lobe_name(layout.lobe_exponents[c]);
    out << "\n";
    for (size_t c = 0; c < layout.lobe_exponents.size(); ++c) {
        // Plain (alpha < 0) sorts first, then the alphas ascending.
        std::map<float, uint32_t> chosen;
        const auto cls = static_cast<uint32_t>(c);
        for (size_t i = layout.first(cls); i < layout.first(cls + 1) && i < layout.choices.size(); ++i)
            ++chosen[std::max(layout.choices[i].alpha, -1.0f)];
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
    out << "                (alpha a: max(L - a E_b / pi, 0) times the bin's cosine factor; plain: the map's own "
           "density)\n";
    print_view_limits(out, layout);
}

}  // namespace

void print_bins_cost(std::ostream& out, const BinnedEnvMap& binned, double build_ms) {
    const auto plain_bytes = static_cast<double>(binned.plain_bytes());
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
    out << "  source        " << printable(loaded.source.name) << " (" << loaded.format << ", hash " << std::hex
        << std::setw(16) << std::setfill('0') << loaded.source.content_hash << std::dec << std::setfill(' ') << ")\n";
    out << "  size          " << m.width() << " x " << m.height() << "\n";
    out << "  colour        " << printable(loaded.source.input_colorspace) << " -> "
        << printable(loaded.source.working_colorspace) << ", luma (" << o.luma.r << ", " << o.luma.g << ", " << o.luma.b
        << ")\n";
    out << "  mapping       " << to_string(o.mapping) << ", axes " << o.axes.to_string();
    if (const std::string_view preset = o.axes.preset(); !preset.empty()) out << " (" << preset << ")";
    out << "\n";
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
    out << "  complete pdf  " << (m.complete() ? "yes" : "no: combine with BSDF sampling through MIS")
        << (loaded.bins ? " (the plain map's; the bins': 'bins complete' below)" : "") << "\n";
    if (m.distribution().bytes() == 0)  // a binned map's: its cells' tables hold the density
        out << "  memory        " << sizeof(Rgb) << " bytes/texel (float RGB radiance) + the bins' tables, in memory\n";
    else
        out << "  memory        " << std::setprecision(3) << m.distribution().bytes() / texels
            << " bytes/texel (distribution) + " << sizeof(Rgb) << " (float RGB radiance), in memory\n";
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

namespace {

// One file: by device and inode where both exist, else by their absolute paths with
// symbolic links resolved as far as they exist.
bool same_file(const std::filesystem::path& a, const std::filesystem::path& b) {
    std::error_code ec;
    if (const bool same = std::filesystem::equivalent(a, b, ec); !ec) return same;
    std::error_code ea, eb;
    const std::filesystem::path ca = std::filesystem::weakly_canonical(std::filesystem::absolute(a, ea), ea),
                                cb = std::filesystem::weakly_canonical(std::filesystem::absolute(b, eb), eb);
    return !ea && !eb && ca == cb;
}

}  // namespace

void check_outputs(const std::vector<std::filesystem::path>& inputs, const std::vector<NamedOutput>& outputs) {
    for (size_t i = 0; i < outputs.size(); ++i) {
        const NamedOutput& out = outputs[i];
        if (out.path.empty()) continue;
        for (const std::filesystem::path& input : inputs)
            if (same_file(out.path, input))
                throw std::runtime_error(out.flag + " " + out.path.string() + ": is the input " + input.string() +
                                         "; refusing to overwrite an input (name another output)");
        for (size_t j = 0; j < i; ++j)
            if (!outputs[j].path.empty() && same_file(out.path, outputs[j].path))
                throw std::runtime_error(out.flag + " " + out.path.string() + ": is also " + outputs[j].flag +
                                         "'s file; two outputs cannot share a file");
    }
}

void prepare_output(const std::filesystem::path& path) {
    check_destination(path);
    for (const std::filesystem::path& removed : remove_stale_temporaries(path))
        std::cerr << "envmis: removed " << printable(removed.string())
                  << ", the temporary file of an interrupted earlier run\n";
}

// Writes through C's stdout, as libstdc++'s own synchronised buffer does, but keeps the
// errno of the first failed write: by the final flush it is long gone (the C stream
// discards what it failed to write, and a failed std::cout writes nothing more).
class StandardOutput::Buffer final : public std::streambuf {
public:
    int error() const noexcept { return error_; }
    int sync() override { return std::fflush(stdout) == 0 ? 0 : failed(); }

protected:
    int_type overflow(int_type c) override {
        if (traits_type::eq_int_type(c, traits_type::eof()))
            return sync() == 0 ? traits_type::not_eof(c) : traits_type::eof();
        if (std::fputc(traits_type::to_char_type(c), stdout) == EOF) {
            failed();
            return traits_type::eof();
        }
        return c;
    }
    std::streamsize xsputn(const char* s, std::streamsize n) override {
        const size_t written = std::fwrite(s, 1, static_cast<size_t>(n), stdout);
        if (written < static_cast<size_t>(n)) failed();
        return static_cast<std::streamsize>(written);
    }

private:
    int failed() noexcept {
        if (error_ == 0) error_ = errno != 0 ? errno : EIO;
        return -1;
    }
    int error_ = 0;
};

StandardOutput::StandardOutput() : buffer_(std::make_unique<Buffer>()), previous_(std::cout.rdbuf(buffer_.get())) {}

StandardOutput::~StandardOutput() { std::cout.rdbuf(previous_); }

void StandardOutput::finish() {
    std::cout.flush();
    buffer_->sync();
    // printf's failures leave only the stream's error flag.
    if (buffer_->error() == 0 && !std::ferror(stdout)) return;
    throw std::runtime_error(std::string("standard output: ") +
                             (buffer_->error() != 0 ? std::strerror(buffer_->error()) : "write failed"));
}

}  // namespace envmis::cli
