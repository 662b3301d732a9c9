// Building a map from an image as `envmis precompute` builds it, for every front end
// (the command's subcommands and the Python module): the options as one request, their
// checks with the command line's messages, the canonical spelling that tables record
// (TableSource::build_options), and the load and build themselves.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "envmis/build/table_writer.h"
#include "envmis/image/image.h"
#include "envmis/interrupt.h"
#include "envmis/sampling/binned.h"
#include "envmis/sampling/envmap.h"
#include "envmis/study/comparison/alpha.h"

namespace envmis {

// How to build a map from an image: the command's map flags, --bins, --cell-columns and
// --compact, by value.
struct BuildRequest {
    bool compensate = true;      // false: --no-compensate
    std::optional<float> alpha;  // empty: not given (1 for one density; auto per bin with bins)
    bool alpha_auto = false;     // --alpha auto: choose_alpha() picks it map-wide (or per bin)
    std::string axes = "z-up";
    std::string mapping = "equirect";  // or "equal-area" (a square image)
    std::string colorspace;            // input colour space; empty: from the file (an array: the working space)
    std::string working_space = "lin_rec709";
    uint32_t bins = 0;                      // K = g^2 normal bins (binned.h); 0: one density
    uint32_t cell_columns = 0;              // of the bins' cell grid; 0: width / 32
    float bin_cost = BinnedOptions{}.cost;  // BinnedOptions::cost
    bool compact = false;                   // RGBE radiance in the table (TableEncoding::compact); the build ignores it
};

inline constexpr uint32_t kMaxCellColumns = 4096;

// The request spelled canonically, as tables record it (TableSource::build_options):
// equal exactly when the request builds the same table from the same source. The
// effective alpha is recorded ("auto", the value to 9 digits, "-" without compensation),
// not how it was asked for. Under 300 bytes plus the colour space and axes names.
std::string canonical_options(const BuildRequest& request);

// The request that canonical_options spelled as `text`, or nothing where `text` is not
// exactly such a spelling (another version's, or edited): canonical_options(*parsed) ==
// text whenever this returns one. An alpha recorded as "auto" comes back as alpha_auto;
// one recorded as "-" (no compensation) as none given.
std::optional<BuildRequest> parse_canonical_options(std::string_view text);

// What is wrong with a value of a flag, in the command line's words, or "" where it is
// right. `text` is the value as written: --alpha "a number >= 0 or auto", --bins "a
// square number g*g, g 1 to 64".
std::string alpha_problem(std::string_view text);
std::string bins_problem(std::string_view text);

// Throws std::invalid_argument naming the field ("bins: 5: expected a square number
// ...", "alpha: ...", "cell_columns: Value 5000 not in range 0 to 4096", "cell_columns:
// needs bins", "bin_cost: ...") where the request is not one that precompute accepts.
void check(const BuildRequest& request);

// The bins that precompute --bins builds for the request: alpha auto per bin and lobe
// class unless a number was given or compensation is off (then 0).
BinnedOptions binned_options(const BuildRequest& request);

// A built map and what its table records.
struct BuiltMap {
    EnvMap map;                          // empty where `binned` holds it
    std::optional<BinnedEnvMap> binned;  // with request.bins > 0
    // The source, build_options = canonical_options(request).
    TableSource source;
    std::string format;  // the file's format ("openexr", "hdr", ...; "array" for pixels)
    uint32_t channels = 3;
    std::optional<AlphaChoice> alpha_choice;  // with alpha auto and one density
    // What the caller should tell the user, one line each starting with the source's
    // name: the loader's notices (io::LoadedImage::notices) and a square image read as
    // equirect.
    std::vector<std::string> notices;
    double load_ms = 0, build_ms = 0;  // reading the image; building the map (after any alpha choice)
    double bins_ms = 0;                // the bins (their alpha choices included)
};

// Loads the image at `path` (envmis::io: OpenImageIO, OpenColorIO) and builds its map
// as the request says; with bins, the BinnedEnvMap over the plain map. Errors: the
// request's (check, Axes::parse, parse_mapping) and what the image cannot be (an
// equal-area map that is not square, a power that overflows float) as
// std::invalid_argument naming the file; io's load errors as it throws them. Cost: the
// load, the build (O(texels)), with alpha auto a choice on a 128-wide copy, with bins
// their build (timings: docs/performance-log.md, 'build_map'). Once `stop` is set the
// load and builds throw Interrupted. `on_stage`, where given, is called as each stage
// starts, with its name: "reading", "choosing alpha", "building", "building bins".
using StageCallback = std::function<void(std::string_view stage)>;
BuiltMap build_map(const std::filesystem::path& path, const BuildRequest& request, StopFlag stop = nullptr,
                   const StageCallback& on_stage = {});

// The same from pixels in memory: linear RGB in request.colorspace (empty: the working
// space), converted to the working space where they differ (through the OCIO config,
// loaded only then); named "array" in errors and the source, hashed (hash64 of the
// pixels' bytes as given) as the source's content hash.
BuiltMap build_map(RgbImage pixels, const BuildRequest& request, StopFlag stop = nullptr,
                   const StageCallback& on_stage = {});

}  // namespace envmis
