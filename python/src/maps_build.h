// Building envmis._maps' maps: from an image file or table (as `envmis precompute` and
// the other subcommands load their input, apps/envmis/cli.cpp load_map) or from a
// NumPy array's pixels, with the options of the command's map flags.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "envmis/image/image.h"
#include "envmis/sampling/binned.h"
#include "envmis/sampling/envmap.h"
#include "envmis/table/table.h"

namespace envmis::python {

// The map flags of the command line (cli.h MapFlags, --bins, --cell-columns), as the
// Python keywords give them.
struct BuildOptions {
    bool compensate = true;
    std::optional<float> alpha;  // empty: not given (1 for one density, auto per bin with bins)
    bool alpha_auto = false;     // alpha="auto"
    std::string axes = "z-up";
    std::string mapping = "equirect";
    std::string colorspace;  // input colour space; empty: the file's metadata (an array: the working space)
    std::string working_space = "lin_rec709";
    uint32_t bins = 0;  // K = g^2 normal bins; 0: one density
    uint32_t cell_columns = 0;
};

// Checks what the command line's validators check (the bins a square from 1 to 4096,
// alpha >= 0 and finite, cell columns at most 4096): std::invalid_argument naming the
// keyword otherwise.
void check(const BuildOptions& options);

// A built map and what the table file of it records.
struct Built {
    EnvMap map;                          // empty where `binned` holds the map
    std::optional<BinnedEnvMap> binned;  // with bins > 0 or a binned table
    TableSource source;
    bool mapped = false;               // the radiance is a mapping of the table file
    std::vector<std::string> notices;  // lines the command prints as "note: ..."
};

// An image (through envmis::io) built as the options say, or a table file (recognised by
// its magic; the options are then ignored, as the commands ignore them, except that a
// table with bins > 0 is refused as precompute refuses it).
Built load(const std::filesystem::path& path, const BuildOptions& options);

// A table file: TableLoading::map or copy (table.h).
Built load_table(const std::filesystem::path& path, bool mapped);

// A map of an image's pixels (linear RGB in `options.colorspace`, converted to the
// working space when they differ), with source "array" and the hash of the pixels' bytes
// as given; with bins, the BinnedEnvMap over them as load builds it.
Built from_pixels(RgbImage image, const BuildOptions& options);

}  // namespace envmis::python
