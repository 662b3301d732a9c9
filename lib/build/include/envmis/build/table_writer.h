// Writing table files (table/table.h reads them; docs/table-format.md specifies them).
// Writing goes to a temporary file in the destination's folder (an AtomicFile,
// atomic_file.h), renamed over the destination only when complete and flushed to disk:
// an interrupted run or a full disk never leaves a partial table.
#pragma once

#include <filesystem>

#include "envmis/build_export.h"
#include "envmis/interrupt.h"
#include "envmis/sampling/binned.h"
#include "envmis/sampling/envmap.h"
#include "envmis/table/table.h"

namespace envmis {

// How the payload is stored.
//   full:    float32 density and RGB radiance, 16 bytes a texel; loads bit-identical to
//            the map written.
//   compact: radiance only, in RGBE (8-bit mantissas with a shared exponent, as in
//            Radiance .hdr files), 4 bytes a texel; the density is rebuilt from it on
//            load. The table holds the RGBE-rounded map (rgbe_round): channels within
//            1/255 of the pixel's largest channel, the largest within 0.4% (values
//            above 1.7e38 saturate); it loads bit-identical to
//            build_env_map(rgbe_round(radiance), options). Lossless for .hdr sources.
enum class TableEncoding { full, compact };

// Writes atomically (temporary file, then rename; atomic_file.h). Throws TableError on
// I/O failure and where the destination exists and is not a regular file, and
// Interrupted once `stop` is set (interrupt.h; checked every few rows written), leaving
// no file.
ENVMIS_BUILD_API void write_table(const std::filesystem::path& path, const EnvMap& map, const TableSource& source,
                                  TableEncoding encoding = TableEncoding::full, StopFlag stop = nullptr);

// A binned map: its plain map (as the overload above writes it) and its BinLayout, from
// which the reader rebuilds the bins bit-identically. A compact table holds the
// RGBE-rounded plain map and loads as BinnedEnvMap(build_env_map(rgbe_round(radiance),
// options), layout).
ENVMIS_BUILD_API void write_table(const std::filesystem::path& path, const BinnedEnvMap& binned,
                                  const TableSource& source, TableEncoding encoding = TableEncoding::full,
                                  StopFlag stop = nullptr);

// The radiance a compact table stores: each pixel rounded to RGBE and back.
ENVMIS_BUILD_API RgbImage rgbe_round(RgbImageView image);

}  // namespace envmis
