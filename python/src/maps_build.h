// Building envmis._maps' maps: from an image file or table (as `envmis precompute` and
// the other subcommands load their input, through envmis::precompute's build_map) or
// from a NumPy array's pixels, with the options of the command's map flags.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "envmis/image/image.h"
#include "envmis/precompute/build.h"
#include "envmis/sampling/binned.h"
#include "envmis/sampling/envmap.h"
#include "envmis/table/table.h"

namespace envmis::python {

// A built map and what the table file of it records.
struct Built {
    EnvMap map;                          // empty where `binned` holds the map
    std::optional<BinnedEnvMap> binned;  // with bins > 0 or a binned table
    TableSource source;
    // What built it (empty for a table): save() records canonical_options of it, with
    // its own compact.
    std::optional<BuildRequest> request;
    bool from_table = false;           // read from a table file
    bool compact = false;              // that table's payload is RGBE (TableHeader::compact)
    bool mapped = false;               // the radiance is a mapping of the table file
    std::vector<std::string> notices;  // lines the command prints as "note: ..."
};

// An image (through envmis::io) built as the request says, or a table file (recognised
// by its magic; the request is then ignored, as the commands ignore it, except that a
// table with bins > 0 is refused as precompute refuses it). Throws std::invalid_argument
// with the command's messages (check() in build.h) for a bad request.
Built load(const std::filesystem::path& path, const BuildRequest& request);

// A table file: TableLoading::map or copy (table.h).
Built load_table(const std::filesystem::path& path, bool mapped);

// A map of an image's pixels (linear RGB in `request.colorspace`, converted to the
// working space when they differ), with source "array" and the hash of the pixels' bytes
// as given; with bins, the BinnedEnvMap over them as load builds it.
Built from_pixels(RgbImage image, const BuildRequest& request);

}  // namespace envmis::python
