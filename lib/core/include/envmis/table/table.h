// Table files: a built EnvMap saved to disk, readable with envmis::core alone.
//
// The format (version 7; versions 1 to 6 are read too) is specified in docs/table-format.md: a fixed preamble (magic,
// version, byte order, total size), a metadata block with the build options and the
// source's name and content hash, a header checksum, then the payload (the image
// density q sin(theta) and the RGB radiance, both float32) and a payload checksum, and,
// for a binned map (sampling/binned.h), the bins' layout with its own checksum.
// The sampling structures are derived data and are rebuilt on load by the same code
// that built them, so a loaded table samples bit-identically to the saved one, and no
// index read from a file can ever address memory.
//
// The writer is envmis::build's (envmis/build/table_writer.h); the layout both use is
// table/format.h.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>

#include "envmis/core_export.h"
#include "envmis/sampling/binned.h"
#include "envmis/sampling/envmap.h"

namespace envmis {

// Every table is written as version 7, with or without bins: version 7 gives each bin a
// view limit (BinChoice::min_view_cos, one more field per choice in the bins section),
// which a version 6 reader would misread; it refuses the newer version instead.
inline constexpr uint32_t kTableVersion = 7;

// Where a table's map came from.
struct TableSource {
    std::string name;                // file name of the source image (no folders)
    uint64_t content_hash = 0;       // hash64 of the source file's bytes
    std::string input_colorspace;    // colour space the pixels were read in
    std::string working_colorspace;  // colour space of the stored radiance
    // The options the writer built the map with, in its own canonical spelling (envmis
    // precompute: "alpha=auto bins=64 ..."), at most 4096 bytes. The reader does not
    // interpret it: it records what the stored map cannot say (that alpha was chosen
    // automatically, the flags as given), so that a tool can tell whether a table is what
    // the same options would build now. Empty where not recorded (tables before version 5).
    std::string build_options;
};

struct Table {
    EnvMap map;
    TableSource source;
    uint32_t version = 0;  // the file's format version
    bool mapped = false;   // the map borrows its radiance from a mapping of the file
    bool compact = false;  // the file holds RGBE radiance, decoded into the map
    // The bins of a binned map (tables of version 4 or later written from a BinnedEnvMap): `map` is
    // then the plain map they were built over. Checked against the map's size when read;
    // binned_map rebuilds them.
    std::optional<BinLayout> bins;
    std::string name;  // the file's path (parse_table: its `name`), for error messages
};

// A table file that cannot be read; what() names the file and the problem.
class ENVMIS_CORE_API TableError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// How read_table gets a full table's radiance (12 bytes a texel).
//   map:  borrowed from a read-only mapping of the file (POSIX mmap), which the map keeps
//         alive: no copy, pages shared with the page cache and with other processes
//         mapping the same table. Compact and version 1-2 tables are copied out of the
//         mapping into memory the map owns; without mmap, `map` reads as `copy` does.
//         write_table replaces a file by renaming, which leaves a mapping of the old one
//         intact; a program that truncates a mapped table in place makes the next
//         access to it fault (SIGBUS): read such files with `copy`.
//   copy: read into memory the map owns.
// Either way the density is read into the buffer that becomes the CDF table.
enum class TableLoading { map, copy };

// Reads and verifies a table. Throws TableError if the file is missing, truncated,
// corrupted (checksums), of another format, or of an unsupported version.
ENVMIS_CORE_API Table read_table(const std::filesystem::path& path, TableLoading loading = TableLoading::map);

// What a table's header says, without its payload.
struct TableHeader {
    uint32_t version = 0;  // the file's format version
    uint32_t width = 0, height = 0;
    EnvMapOptions options;
    EnvMapStats stats;
    TableSource source;
    bool compact = false;  // RGBE payload (table_writer.h: TableEncoding::compact)
    bool binned = false;   // has a bins section
};

// Reads and verifies a table's header only: the preamble, the metadata block and its
// checksum, and the file's size against the sizes they give (at most 64 KiB read,
// whatever the table's size). Throws TableError as read_table does for those parts; a
// payload or bins section that is corrupted is found only by read_table.
ENVMIS_CORE_API TableHeader read_table_header(const std::filesystem::path& path);

// The same checks on bytes already in memory; `name` appears in error messages.
ENVMIS_CORE_API Table parse_table(std::span<const std::byte> bytes, std::string_view name);

// Moves the table's map into the BinnedEnvMap its bins describe. Throws TableError,
// naming the table, if it has no bins or they do not fit its map.
ENVMIS_CORE_API BinnedEnvMap binned_map(Table&& table);

// True if the file is a regular file that starts with the table magic (cheap; does not
// validate the rest).
ENVMIS_CORE_API bool looks_like_table(const std::filesystem::path& path) noexcept;

}  // namespace envmis
