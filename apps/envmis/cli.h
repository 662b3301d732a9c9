// Shared pieces of the `envmis` subcommands: the flags that choose how a map is built,
// loading a map from a table or an image, timing, progress and the summary printout.
#pragma once

#include <atomic>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <ostream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <type_traits>
#include <vector>

#include <CLI/CLI.hpp>

#include "envmis/interrupt.h"
#include "envmis/precompute/build.h"
#include "envmis/sampling/binned.h"
#include "envmis/sampling/envmap.h"
#include "envmis/study/comparison/alpha.h"
#include "envmis/table/table.h"

namespace envmis::cli {

// The map flags (--no-compensate, --alpha, --mapping, --colorspace, --working-space,
// --axes), which fill `request` (build.h): how to build a map from an image (ignored for
// tables, which record their own).
void add_map_flags(CLI::App& app, BuildRequest& request);

// The bounds of a count, size or seed flag, in the flag's own type T (an integer):
// "-n: Value -5 not in range 1 to 1099511627776". The text is read as a decimal T in full:
// CLI11 2.1 alone reads "-5" into a uint64_t as 2^64 - 5 and "18446744073709551616" as
// 2^64 - 1, and would pass both where the upper bound is the type's maximum (seeds).
template <class T>
CLI::Validator in_range(T lo, T hi) {
    static_assert(std::is_integral_v<T>);
    return CLI::Validator(
        [lo, hi](std::string& text) -> std::string {
            T value{};
            const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
            if (error == std::errc() && end == text.data() + text.size() && value >= lo && value <= hi) return {};
            return "Value " + text + " not in range " + std::to_string(lo) + " to " + std::to_string(hi);
        },
        CLI::Range(lo, hi).get_description());
}

// A seed flag: any 64-bit unsigned integer, and nothing else.
inline CLI::Validator any_seed() { return in_range(uint64_t{0}, std::numeric_limits<uint64_t>::max()); }

// The most threads a command may be told to use.
inline constexpr uint32_t kMaxThreads = 1024;

// Caps the threads of every parallel loop of the libraries this process runs (builds,
// bins, encodings) at `threads`: sets ENVMIS_THREADS, which envmis::usable_cores reads.
void limit_threads(uint32_t threads);

// --threads N (1 to kMaxThreads) on a command whose work runs on those loops; given, it
// limits them (limit_threads) as it is parsed. Default: every usable core.
void add_threads_flag(CLI::App& app);

// An image size "WxH", each side min_side to max_side (default 1 to kMaxCells1D = 65536),
// or with `single` also "N" (returned as N x 0). Digits only: no sign, no spaces. Empty
// where the text is not one.
struct Size {
    uint32_t width = 0, height = 0;
};
std::optional<Size> parse_size(const std::string& text, bool single, uint32_t min_side = 1,
                               uint32_t max_side = kMaxCells1D);
// A validator for such a flag, saying what it expects when it refuses a value.
CLI::Validator size_validator(bool single, uint32_t min_side = 1, uint32_t max_side = kMaxCells1D);

// A bin count flag (--bins K): a square number g^2 with g 1 to 64, as BinnedOptions
// takes it (bins_problem in build.h); its side g.
CLI::Validator bins_validator();
// An output path flag given an empty value ("-o ''") is refused, not taken as "none".
CLI::Validator non_empty();
// A path that ends in `extension` (".png"; any case), for outputs written in one format
// only, so that a file never holds another format than its name says.
CLI::Validator output_extension(const std::string& extension, const std::string& format);
// --bin-cost R (BinnedOptions::cost, 1 to 100), for the commands that build bins.
CLI::Option* add_bin_cost_flag(CLI::App& app, float& cost);
// --cell-columns N (BinnedOptions::cell_columns, 0 to kMaxCellColumns), for the commands that build bins.
CLI::Option* add_cell_columns_flag(CLI::App& app, uint32_t& columns);
// A direction "X,Y,Z" (a shading normal, a view): three finite numbers, not all zero,
// normalised; empty where the text is not one. The validator refuses what it refuses.
std::optional<Vec3> parse_direction(const std::string& text);
CLI::Validator direction_validator();
// A BSDF as Bsdf::parse reads it: lambert, phong:N or ggx:A.
CLI::Validator bsdf_validator();
inline uint32_t bins_per_side(uint32_t bins) {
    return static_cast<uint32_t>(std::lround(std::sqrt(static_cast<double>(bins))));
}

// `text`, read from a file, made safe to print on a terminal: control characters (C0,
// DEL and UTF-8-encoded C1, which can start escape sequences) and backslashes become
// C-style escapes ("\x1b", "\u009b", "\\"); everything else is kept byte for byte.
std::string printable(std::string_view text);

// The bytes this process can still allocate: the smaller of MemAvailable
// (/proc/meminfo) and what its address-space limit (RLIMIT_AS) leaves; empty where
// neither is known (not Linux, no limit).
std::optional<uint64_t> available_memory();
// Throws "WHAT: needs N MB of memory, more than the M MB available" when `bytes` is more
// than available_memory(); `what` names the flag or the file that asks for it.
void check_memory(const std::string& what, uint64_t bytes);

// The most texels of a map or image a command makes (an EnvMap's limit, 2^31).
inline constexpr uint64_t kMaxTexels = uint64_t{1} << 31;
// Checks a size that `what` (the flag and its value) asks for, before anything is
// allocated for it: at most kMaxTexels, and `bytes_per_texel` times its texels within
// available_memory(). Throws a one-line error naming `what` and the limit.
void check_image_size(const std::string& what, Size size, uint64_t bytes_per_texel);

// A map's peak memory per texel while load_map reads and builds it from an image: the
// pixels read, the radiance and luminance, the CDF tables (measured on a 4096x2048 map,
// /usr/bin/time -v: about 17, with --bins 256 25, rounded up).
inline constexpr uint64_t kBuildPeak = 32;
// The texels of `input`'s map from its header alone (a table's, or an image's largest
// window: read_image_size); 0 where the header cannot be read or the input is not a
// regular file (loading it then says why).
uint64_t header_texels(const std::filesystem::path& input);
// Checks, from its header alone and before any pixel is read, that an image's map of
// `bytes_per_texel` per texel, or a table's load, fits in available_memory(); throws
// "FILE (WxH): needs N MB of memory, more than the M MB available".
void check_map_memory(const std::filesystem::path& input, uint64_t bytes_per_texel);

// A map ready to sample, and where it came from.
struct LoadedMap {
    EnvMap map;
    TableSource source;
    bool from_table = false;
    std::string format;          // "envmis table", "openexr", "hdr", ...
    uint32_t table_version = 0;  // the table file's format version
    bool mapped = false;         // the map borrows its radiance from a mapping of the table file
    bool compact = false;        // the table file holds RGBE radiance (decoded into memory)
    uint32_t channels = 3;
    double load_ms = 0, build_ms = 0;
    std::optional<AlphaChoice> alpha_choice = {};  // with --alpha auto, for an image
    std::optional<BinLayout> bins = {};            // a binned table's bins (map: the plain map)
};

// Reads a table (recognised by its magic) or loads an image and builds its map
// (build_map in build.h); the notices go to `notes`, each a line "note: FILE: ...". An
// image whose map cannot be built (its power overflows float, say) is an error naming
// the file; an interruption (above) stops the load and the build.
LoadedMap load_map(const std::string& path, const BuildRequest& request, std::ostream& notes = std::cerr);
// A map built from an image, as load_map returns it; a binned map's bins stay in `built`
// (loaded.bins is their layout, loaded.map empty).
LoadedMap loaded_map(BuiltMap& built);

// The summary that precompute and info print, of `loaded`'s map or of `map` (precompute
// --bins moves loaded.map into its BinnedEnvMap); with the bins' layout if it has one.
void print_summary(std::ostream& out, const LoadedMap& loaded);
void print_summary(std::ostream& out, const LoadedMap& loaded, const EnvMap& map);

// What a binned map's bins cost: the time to build (or rebuild) them and their bytes
// over the plain map.
void print_bins_cost(std::ostream& out, const BinnedEnvMap& binned, double build_ms);

double milliseconds_since(std::chrono::steady_clock::time_point start);

// This process's resident memory, now and at its peak, with the share of anonymous
// memory and of mapped files' pages; empty where the system does not say (not Linux).
std::string resident_memory();

// Ctrl-C (SIGINT) and SIGTERM set a flag that every long loop checks (the core's builds
// through their StopFlag, interrupt.h), so that the command stops within about a second:
// the work under way throws Interrupted, whose unwinding removes the temporary files,
// and main exits 128 + the signal's number (130, 143) with "envmis: interrupted by
// SIGINT". A second signal ends the process at once (the default action), for a loop
// that does not check; its temporary files are then left behind.
void install_interrupt_handler();
const std::atomic<bool>& interrupted();
// The signal that set the flag (SIGINT or SIGTERM), 0 before one arrived.
int interrupting_signal();
// Throws envmis::Interrupted once a signal has arrived.
void throw_if_interrupted();
// What main prints and returns once a signal has arrived, `detail` (Interrupted's
// message, unless it is the plain "interrupted") after the signal's name.
int exit_interrupted(const std::string& detail);

// A density's solid-angle pdf at every texel centre of a w x h image, row-major (an
// EnvMapView, EnvMap or BinView: anything with pdf_uv). Per steradian: proportional to q,
// the compensated or plain luminance, without the sin(theta) of the image-space density.
template <class Density>
std::vector<float> pdf_image(const Density& density, uint32_t w, uint32_t h) {
    std::vector<float> pdf(size_t{w} * h);
    for (uint32_t y = 0; y < h; ++y) {
        throw_if_interrupted();
        for (uint32_t x = 0; x < w; ++x) pdf[size_t{y} * w + x] = density.pdf_uv({(x + 0.5f) / w, (y + 0.5f) / h});
    }
    return pdf;
}

// Exit statuses: 0 success, 1 a failure of the work (input, output, memory), 2 a usage
// error (an unknown command, flag or value: nothing was started), 128 + the signal's
// number when interrupted (exit_interrupted).
inline constexpr int kExitFailure = 1, kExitUsage = 2;
// A flag's value or a combination of flags refused after parsing (main exits kExitUsage).
struct UsageError : std::runtime_error {
    using std::runtime_error::runtime_error;
};
// The name among `names` nearest `word` by edit distance (insertions, deletions,
// substitutions and swaps of neighbours), if it is at most 2 edits away or `word` is a
// prefix of it; empty otherwise.
std::string nearest_name(std::string_view word, const std::vector<std::string>& names);

// Progress on stderr: "label  42%", redrawn in place when stderr is a terminal; where it
// is not, one line each time the percentage changes if the environment variable
// ENVMIS_PROGRESS is 1 (for logs, and for tests that act at a known point of the work),
// else nothing. A bar is shown from its construction ("label   0%").
class Progress {
public:
    Progress(std::string label, uint64_t total);
    ~Progress();
    void update(uint64_t done);

private:
    std::string label_;
    uint64_t total_;
    int shown_ = -1;
    bool terminal_, lines_;
};

// An output file given on the command line, before any work: refuses one that exists and
// is not a regular file (check_destination in atomic_file.h: a device, FIFO, folder or
// symbolic link is never replaced) and removes its stale temporaries from killed runs,
// one line on stderr for each ("envmis: removed ..."). The writer itself does both again
// (silently), for the files that commands write into folders (--plots, --images).
void prepare_output(const std::filesystem::path& path);

// An output named by a flag (`flag`: "-o", "--json", ...); an empty path is one not given.
struct NamedOutput {
    std::string flag;
    std::filesystem::path path;
};
// Throws std::runtime_error, before any work, where an output is one of the run's inputs
// (the same file by device and inode: through symbolic and hard links) or two outputs
// are one file: writing would destroy an input, or one output would replace another.
void check_outputs(const std::vector<std::filesystem::path>& inputs, const std::vector<NamedOutput>& outputs);

// Standard output whose every write is checked (a full disk, /dev/full): a report that
// did not arrive is an error. While one exists, std::cout writes through it to C's stdout
// (so that its order with printf is kept), noting the reason of the first failure.
class StandardOutput {
public:
    StandardOutput();
    StandardOutput(const StandardOutput&) = delete;
    StandardOutput& operator=(const StandardOutput&) = delete;
    ~StandardOutput();  // gives std::cout its own buffer back
    // Flushes both streams; throws std::runtime_error("standard output: REASON") if that
    // or any earlier write failed.
    void finish();

private:
    class Buffer;
    std::unique_ptr<Buffer> buffer_;
    std::streambuf* previous_;
};

// Each subcommand adds itself to the app, with the function that runs it once parsed.
struct Subcommand {
    CLI::App* app;
    std::function<void()> run;
};
Subcommand add_precompute(CLI::App& app);
Subcommand add_info(CLI::App& app);
Subcommand add_sample(CLI::App& app);
Subcommand add_visualize(CLI::App& app);
Subcommand add_bench(CLI::App& app);
Subcommand add_convert(CLI::App& app);
Subcommand add_compare(CLI::App& app);
Subcommand add_report(CLI::App& app);

}  // namespace envmis::cli
