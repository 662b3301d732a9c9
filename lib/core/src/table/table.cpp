#include "envmis/table/table.h"

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <optional>
#include <vector>

#include "detail/mapped_file.h"
#include "detail/parallel.h"
#include "envmis/math/hash.h"
#include "envmis/table/format.h"

namespace envmis {
namespace {

using namespace table_format;

// Reads fields from a byte span; every read is checked against what is left.
class Cursor {
public:
    Cursor(std::span<const std::byte> bytes, std::string_view name) : bytes_(bytes), name_(name) {}

    [[noreturn]] void fail(const std::string& problem) const { throw TableError(std::string(name_) + ": " + problem); }
    void need(uint64_t size, const char* what) const {
        if (size > bytes_.size() - pos_)
            fail(std::string("truncated: ") + what + " needs " + std::to_string(size) + " bytes, " +
                 std::to_string(bytes_.size() - pos_) + " left");
    }
    template <class T>
    T take(const char* what) {
        need(sizeof(T), what);
        T v;
        std::memcpy(&v, bytes_.data() + pos_, sizeof(T));
        pos_ += sizeof(T);
        return v;
    }
    std::span<const std::byte> take_bytes(uint64_t size, const char* what) {
        need(size, what);
        auto s = bytes_.subspan(pos_, static_cast<size_t>(size));
        pos_ += static_cast<size_t>(size);
        return s;
    }
    std::string take_string(const char* what) {
        const auto size = take<uint32_t>(what);
        if (size > kMaxStringSize)
            fail(std::string(what) + " is " + std::to_string(size) + " bytes, above the limit of " +
                 std::to_string(kMaxStringSize));
        const auto s = take_bytes(size, what);
        return {reinterpret_cast<const char*>(s.data()), s.size()};
    }
    size_t position() const noexcept { return pos_; }

private:
    std::span<const std::byte> bytes_;
    std::string_view name_;
    size_t pos_ = 0;
};

std::string describe_errno(const std::filesystem::path& path, const char* action) {
    return path.string() + ": cannot " + action + ": " + std::strerror(errno);
}

}  // namespace

namespace {

// What the header (preamble, metadata, header checksum) says; the payload follows.
struct Header {
    uint32_t w = 0, h = 0;
    EnvMapOptions options;
    EnvMapStats stats;
    TableSource source;
    bool compact = false;  // payload: RGBE radiance only
    uint32_t version = 0;
    uint64_t payload_offset = 0;
    uint32_t bins_size = 0;  // of the bins section, without its checksum; 0: none
};

// The payload's size and the bins section's (`left` bytes follow the header), checked
// against the file before anything is allocated for them.
void check_payload_size(const Header& header, uint64_t left, const Cursor& in) {
    const uint32_t bins = header.bins_size;
    if (bins != 0 && (bins < kMinBinsSection || bins > kMaxBinsSection || bins % 4 != 0))
        in.fail("invalid bins section size " + std::to_string(bins));
    const uint64_t texels = uint64_t{header.w} * header.h;
    const uint64_t payload = texels * (header.compact ? sizeof(uint32_t) : sizeof(float) + sizeof(Rgb)) + 8 +
                             (bins == 0 ? 0 : uint64_t{bins} + 8);
    if (payload > left)
        in.fail("truncated: payload needs " + std::to_string(payload) + " bytes, " + std::to_string(left) + " left");
    if (payload < left) in.fail(std::to_string(left - payload) + " bytes of trailing data after the payload");
}

// The statistics a writer can have made (EnvMap's constructor) for the header's size and
// options: the renderer trusts them (Lbar, the threshold) and info prints them, so a
// crafted value is refused here, naming its field.
void check_stats(const Header& header, const Cursor& in) {
    const EnvMapStats& s = header.stats;
    const bool compensated = header.options.compensation.enabled;
    const uint64_t texels = uint64_t{header.w} * header.h;
    const auto field = [&](bool ok, const char* name, const std::string& value, const char* expected) {
        if (!ok) in.fail(std::string("invalid ") + name + " " + value + " (expected " + expected + ")");
    };
    const auto number = [](double v) {
        char text[32];
        std::snprintf(text, sizeof text, "%g", v);
        return std::string(text);
    };
    const float alpha = header.options.compensation.alpha;
    field(std::isfinite(alpha) && alpha >= 0, "alpha", number(alpha), "finite and >= 0");
    // EnvMap's own rule for the weights (in [0, 1], not all 0), named as the header's field.
    const LumaCoefficients k = header.options.luma;
    for (const auto& [c, name] : {std::pair{k.r, "red"}, std::pair{k.g, "green"}, std::pair{k.b, "blue"}})
        field(c >= 0 && c <= 1, "luma coefficient", std::string(name) + " " + number(c), "in [0, 1]");
    // EnvMap refuses a map whose power 4 pi Lbar overflows float.
    field(std::isfinite(s.mean_luminance) && s.mean_luminance >= 0 && 4 * kPi * s.mean_luminance <= FLT_MAX,
          "mean luminance", number(s.mean_luminance), "finite, >= 0 and 4 pi times it at most 3.4e38");
    field(std::isfinite(s.max_luminance) && s.max_luminance >= 0, "max luminance", number(s.max_luminance),
          "finite and >= 0");
    field(std::isfinite(s.min_positive_luminance) && s.min_positive_luminance >= 0 &&
              s.min_positive_luminance <= s.max_luminance,
          "min luminance", number(s.min_positive_luminance), "finite, >= 0 and at most the max luminance");
    // A mean above the maximum (beyond rounding) or of a map without radiance is made up.
    field(s.mean_luminance <= 1.001 * s.max_luminance && (s.max_luminance > 0) == (s.min_positive_luminance > 0),
          "mean luminance", number(s.mean_luminance), "at most the max luminance, 0 for a black map");
    // EnvMap falls back to uniform exactly when Lbar is 0, and to uncompensated only when compensating.
    const std::string fallback(to_string(s.fallback));
    field((s.fallback == DensityFallback::uniform) == (s.mean_luminance == 0), "fallback", fallback,
          "uniform exactly when the map is black");
    field(s.fallback != DensityFallback::uncompensated || compensated, "fallback", fallback,
          "uncompensated only when compensation was requested");
    field(std::isfinite(s.threshold) && s.threshold >= 0 &&
              (s.threshold == 0 || (compensated && s.fallback == DensityFallback::none)),
          "threshold", number(s.threshold), "finite, >= 0, and 0 unless compensated without a fallback");
    field(s.zeroed_texels <= texels && (s.zeroed_texels == 0 || s.threshold > 0), "zeroed texel count",
          std::to_string(s.zeroed_texels), "at most the texel count, 0 unless compensated");
    const uint64_t channels = 3 * texels;
    for (const auto& [count, name] :
         {std::pair{s.bad_pixels.nan, "NaN count"}, std::pair{s.bad_pixels.infinite, "Inf count"},
          std::pair{s.bad_pixels.negative, "negative count"}})
        field(count <= channels, name, std::to_string(count), "at most 3 x the texel count");
    field(s.bad_pixels.nan + s.bad_pixels.infinite + s.bad_pixels.negative <= channels, "bad pixel counts",
          std::to_string(s.bad_pixels.total()), "at most 3 x the texel count in all");
}

// The fixed fields before the metadata (magic, version, byte order, file size, metadata
// size, reserved), each checked; returns the version and the metadata's size.
struct Preamble {
    uint32_t version = 0, metadata_size = 0;
};

Preamble parse_preamble(Cursor& in, std::span<const std::byte> head, uint64_t file_size) {
    if (head.size() < sizeof kMagic || std::memcmp(head.data(), kMagic, sizeof kMagic) != 0)
        in.fail("not an envmis table (bad magic)");
    in.take_bytes(sizeof kMagic, "magic");
    const auto version = in.take<uint32_t>("version");
    const auto order = in.take<uint32_t>("byte-order mark");
    if (order == 0x04030201) in.fail("table was written on a big-endian machine; this build reads little-endian");
    if (order != kByteOrderMark) in.fail("corrupted byte-order mark");
    if (version > kTableVersion)
        in.fail("format version " + std::to_string(version) + " is newer than this envmis reads (version " +
                std::to_string(kTableVersion) + "); upgrade envmis");
    if (version == 0) in.fail("unknown format version 0");
    const auto total = in.take<uint64_t>("file size");
    if (total != file_size)
        in.fail(total > file_size ? "truncated: header says " + std::to_string(total) + " bytes, file has " +
                                        std::to_string(file_size)
                                  : "header says " + std::to_string(total) + " bytes, file has " +
                                        std::to_string(file_size) + " (trailing data)");
    const auto metadata_size = in.take<uint32_t>("metadata size");
    if (const auto reserved = in.take<uint32_t>("reserved"); reserved != 0)
        in.fail("reserved field is " + std::to_string(reserved) + ", not 0");
    if (metadata_size > kMaxMetadataSize)
        in.fail("metadata block of " + std::to_string(metadata_size) + " bytes is too large");
    return {version, metadata_size};
}

// Parses and checks the header from `head`, the first bytes of a file of `file_size`
// bytes (all of it, or at least the preamble, metadata and header checksum).
Header parse_header(std::span<const std::byte> head, uint64_t file_size, std::string_view name) {
    Cursor in(head, name);
    const auto [version, metadata_size] = parse_preamble(in, head, file_size);
    in.need(uint64_t{metadata_size} + 8, "metadata and header checksum");
    const uint64_t header_digest = hash64(head.first(kPreambleSize + metadata_size));

    Header out;
    out.version = version;
    Cursor meta(head.subspan(kPreambleSize, metadata_size), name);
    out.w = meta.take<uint32_t>("width");
    out.h = meta.take<uint32_t>("height");
    const auto sampler = meta.take<uint32_t>("sampler kind");
    const auto flags = meta.take<uint32_t>("flags");
    EnvMapOptions& options = out.options;
    options.compensation.enabled = flags & kFlagCompensation;
    out.compact = flags & kFlagCompact;
    options.compensation.alpha = meta.take<float>("alpha");
    options.luma = meta.take<LumaCoefficients>("luma coefficients");
    options.axes = meta.take<Axes>("axes");
    // Version 1 had a reserved 0 here: every version 1 table is equirectangular.
    const auto mapping = meta.take<uint8_t>("mapping");
    EnvMapStats& stats = out.stats;
    stats.mean_luminance = meta.take<double>("mean luminance");
    stats.threshold = meta.take<float>("threshold");
    stats.max_luminance = meta.take<float>("max luminance");
    stats.min_positive_luminance = meta.take<float>("min luminance");
    stats.zeroed_texels = meta.take<uint64_t>("zeroed texels");
    const auto fallback = meta.take<uint32_t>("fallback");
    stats.bad_pixels.nan = meta.take<uint64_t>("NaN count");
    stats.bad_pixels.infinite = meta.take<uint64_t>("Inf count");
    stats.bad_pixels.negative = meta.take<uint64_t>("negative count");
    TableSource& source = out.source;
    source.content_hash = meta.take<uint64_t>("source hash");
    source.name = meta.take_string("source name");
    source.input_colorspace = meta.take_string("input colour space");
    source.working_colorspace = meta.take_string("working colour space");
    if (version >= 4) out.bins_size = meta.take<uint32_t>("bins section size");
    if (version >= 5) source.build_options = meta.take_string("build options");

    in.take_bytes(metadata_size, "metadata");
    if (in.take<uint64_t>("header checksum") != header_digest) in.fail("corrupted header (checksum mismatch)");
    // Version 3 pads the block to a multiple of kMetadataAlignment with zeros; older
    // versions have no padding.
    const std::span<const std::byte> rest =
        head.subspan(kPreambleSize + meta.position(), metadata_size - meta.position());
    const bool padded = version >= 3 && metadata_size % kMetadataAlignment == 0 && rest.size() < kMetadataAlignment &&
                        std::all_of(rest.begin(), rest.end(), [](std::byte b) { return b == std::byte{0}; });
    if (!rest.empty() && !padded) in.fail("metadata block has " + std::to_string(rest.size()) + " unexpected bytes");
    const uint32_t w = out.w, h = out.h;
    if (w == 0 || h == 0 || w > kMaxCells1D || h > kMaxCells1D || uint64_t{w} * h > kMaxTexels)
        in.fail("invalid size " + std::to_string(w) + "x" + std::to_string(h));
    if (sampler != kSamplerCdf) in.fail("unknown sampler kind " + std::to_string(sampler));
    if (flags & ~(kFlagCompensation | kFlagCompact)) in.fail("unknown flags " + std::to_string(flags));
    if (version == 1 ? mapping != 0 : mapping != 1 && mapping != 2)
        in.fail("unknown mapping " + std::to_string(mapping));
    options.mapping = mapping == 2 ? Mapping::equal_area : Mapping::equirect;
    if (options.mapping == Mapping::equal_area && w != h)
        in.fail("equal-area table of size " + std::to_string(w) + "x" + std::to_string(h) + " is not square");
    if (fallback > static_cast<uint32_t>(DensityFallback::uniform))
        in.fail("unknown fallback " + std::to_string(fallback));
    stats.fallback = static_cast<DensityFallback>(fallback);
    check_stats(out, in);

    out.payload_offset = in.position();
    check_payload_size(out, file_size - out.payload_offset, in);
    return out;
}

[[noreturn]] void fail(std::string_view name, const std::string& problem) {
    throw TableError(std::string(name) + ": " + problem);
}

// Checks a bins section (`section`, whose checksum is `digest`) field by field against
// what remains of it and against the header's map, before anything is sized from it.
BinLayout parse_bins(std::span<const std::byte> section, uint64_t digest, const Header& header, std::string_view name) {
    if (hash64(section) != digest) fail(name, "corrupted bins section (checksum mismatch)");
    Cursor in(section, name);
    BinLayout layout;
    layout.bins_per_side = in.take<uint32_t>("bins per side");
    layout.cell_columns = in.take<uint32_t>("bin cell columns");
    layout.cell_rows = in.take<uint32_t>("bin cell rows");
    const auto classes = in.take<uint32_t>("lobe classes");
    const uint32_t g = layout.bins_per_side;
    layout.diffuse_bins_per_side = header.version >= 6 ? in.take<uint32_t>("diffuse bins per side") : g;
    const uint32_t gd = layout.diffuse_bins_per_side;
    if (g < 1 || g > kMaxBinsPerSide) in.fail("bins section: " + std::to_string(g) + " bins per side, not 1 to 64");
    if (gd < 1 || gd > kMaxBinsPerSide)
        in.fail("bins section: " + std::to_string(gd) + " diffuse bins per side, not 1 to 64");
    if (layout.cell_columns < 1 || layout.cell_columns > std::min(header.w, kMaxCellSide) || layout.cell_rows < 1 ||
        layout.cell_rows > std::min(header.h, kMaxCellSide))
        in.fail("bins section: cell grid " + std::to_string(layout.cell_columns) + "x" +
                std::to_string(layout.cell_rows) + " does not fit a " + std::to_string(header.w) + "x" +
                std::to_string(header.h) + " map (at most 4096 a side)");
    if (classes < 1 || classes > kMaxLobeClasses)
        in.fail("bins section: " + std::to_string(classes) + " lobe classes, not 1 to 8");
    const uint32_t expected = bins_section_size(header.version, gd, g, classes);
    if (section.size() != expected)
        in.fail("bins section of " + std::to_string(section.size()) + " bytes does not hold " +
                std::to_string(classes) + " lobe classes of " + std::to_string(gd * gd) + " diffuse and " +
                std::to_string(g * g) + " glossy bins (" + std::to_string(expected) + " bytes)");
    for (uint32_t c = 0; c < classes; ++c) {
        const auto e = in.take<float>("lobe exponent");
        if (!std::isfinite(e) || (c == 0 ? e != 0 : !(e >= layout.lobe_exponents.back())))
            in.fail("bins section: lobe exponents must be finite, ascending, the first 0");
        layout.lobe_exponents.push_back(e);
    }
    layout.choices.resize(layout.choice_count());
    for (size_t i = 0; i < layout.choices.size(); ++i) {
        BinChoice& choice = layout.choices[i];
        choice.alpha = in.take<float>("bin alpha");
        choice.threshold = in.take<float>("bin threshold");
        if (!std::isfinite(choice.alpha) || !std::isfinite(choice.threshold) || choice.threshold < 0)
            in.fail("bins section: a bin's alpha or threshold is not finite, or its threshold is negative");
        if (header.version < 7) continue;  // every view samples the bin's own density
        choice.min_view_cos = in.take<float>("bin view limit");
        if (!layout.view_limit_valid(i))
            in.fail("bins section: a bin's view limit is not in [0, 1], or not 0 for a diffuse or plain bin");
    }
    return layout;
}

// The table of the map that `build` makes, its errors reported as the file's.
template <class Build>
Table checked_table(std::string_view name, const Header& header, std::optional<BinLayout> bins, Build&& build) {
    try {
        return Table{build(), header.source, header.version, false, header.compact, std::move(bins), std::string(name)};
    } catch (const std::invalid_argument& e) {
        fail(name, std::string("inconsistent contents: ") + e.what());
    }
}

// Reads the payload with `read(destination, bytes)` (in file order) straight into the
// buffers the map keeps: the density's bits become the CDF table, the radiance the
// image; nothing else of the payload's size is held. Then checks its checksum. A
// compact payload's RGBE words are decoded into the radiance, and their buffer then
// takes the density rebuilt from it.
template <class Read>
Table read_payload(Header header, Read&& read, std::string_view name) {
    const uint64_t texels = uint64_t{header.w} * header.h;
    LargeVector<uint32_t> density(texels);
    RgbImage radiance{header.w, header.h, RgbPixels(texels)};
    uint64_t digest = 0;
    Hasher payload_hash;
    read(density.data(), texels * sizeof(uint32_t));
    payload_hash.update(std::as_bytes(std::span(density.data(), density.size())));
    if (!header.compact) {
        read(radiance.pixels.data(), texels * sizeof(Rgb));
        payload_hash.update(std::as_bytes(std::span(radiance.pixels)));
    }
    read(&digest, sizeof digest);
    if (digest != payload_hash.digest()) fail(name, "corrupted payload (checksum mismatch)");
    std::optional<BinLayout> bins;
    if (header.bins_size != 0) {
        std::vector<std::byte> section(header.bins_size);
        read(section.data(), section.size());
        read(&digest, sizeof digest);
        bins = parse_bins(section, digest, header, name);
    }
    if (header.compact) {
        const uint32_t w = header.w;
        detail::parallel_for(header.h, 16, [&](uint32_t lo, uint32_t hi) {
            std::vector<float> row(w);
            for (uint32_t y = lo; y < hi; ++y) {
                const size_t offset = size_t{y} * w;
                for (uint32_t x = 0; x < w; ++x) radiance.pixels[offset + x] = rgbe_decode(density[offset + x]);
                density_row(std::span(radiance.pixels).subspan(offset, w), y, header.h, header.options, header.stats,
                            row);
                std::memcpy(density.data() + offset, row.data(), row.size() * sizeof(float));
            }
        });
    }
    return checked_table(name, header, std::move(bins),
                         [&] { return EnvMap(std::move(radiance), std::move(density), header.options, header.stats); });
}

// A full payload (version 3 or later) in a file mapping, used in place: the map borrows the
// radiance from the mapping, which it keeps alive; only the density is copied, into the
// buffer that becomes the CDF table. Null if the payload cannot be used in place (compact,
// or an older version whose arrays may be misaligned).
std::optional<Table> read_mapped_payload(Header header, const std::shared_ptr<const detail::MappedFile>& file,
                                         std::string_view name) {
    const uint64_t texels = uint64_t{header.w} * header.h;
    const std::span<const std::byte> payload = file->bytes().subspan(static_cast<size_t>(header.payload_offset));
    const auto density_bytes = payload.first(texels * sizeof(uint32_t));
    const auto radiance_bytes = payload.subspan(density_bytes.size(), texels * sizeof(Rgb));
    if (header.compact || header.version < 3 || reinterpret_cast<uintptr_t>(radiance_bytes.data()) % alignof(Rgb) != 0)
        return std::nullopt;
    // The density a chunk at a time: hashed, copied, and its mapped pages released at
    // once, so that they and the copy are never both resident (the load's peak memory).
    constexpr size_t kChunk = size_t{32} << 20;
    LargeVector<uint32_t> density(texels);
    Hasher payload_hash;
    for (size_t at = 0; at < density_bytes.size(); at += kChunk) {
        const auto chunk = density_bytes.subspan(at, std::min(kChunk, density_bytes.size() - at));
        payload_hash.update(chunk);
        std::memcpy(reinterpret_cast<std::byte*>(density.data()) + at, chunk.data(), chunk.size());
        file->release(chunk);
    }
    payload_hash.update(radiance_bytes);
    uint64_t digest = 0;
    const size_t digest_at = density_bytes.size() + radiance_bytes.size();
    std::memcpy(&digest, payload.data() + digest_at, sizeof digest);
    if (digest != payload_hash.digest()) fail(name, "corrupted payload (checksum mismatch)");
    std::optional<BinLayout> bins;
    if (header.bins_size != 0) {
        const auto section = payload.subspan(digest_at + sizeof digest, header.bins_size);
        std::memcpy(&digest, section.data() + section.size(), sizeof digest);
        bins = parse_bins(section, digest, header, name);
    }
    const RgbImageView radiance{
        header.w, header.h,
        std::span(reinterpret_cast<const Rgb*>(radiance_bytes.data()), static_cast<size_t>(texels))};
    Table table = checked_table(name, header, std::move(bins), [&] {
        return EnvMap(radiance, file, std::move(density), header.options, header.stats);
    });
    table.mapped = true;
    return table;
}

// The payload of `bytes`, a whole table file in memory, copied out of it.
Table copy_payload(Header header, std::span<const std::byte> bytes, std::string_view name) {
    size_t pos = static_cast<size_t>(header.payload_offset);
    return read_payload(
        std::move(header),
        [&](void* destination, uint64_t size) {
            std::memcpy(destination, bytes.data() + pos, static_cast<size_t>(size));
            pos += static_cast<size_t>(size);
        },
        name);
}

// Throws naming `path` where it is missing or not a regular file.
void require_regular_file(const std::filesystem::path& path) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw TableError(path.string() + ": no such file");
    if (!std::filesystem::is_regular_file(path, ec)) throw TableError(path.string() + ": not a regular file");
}

// Opens `path` into `file` and parses its header, reading at most the preamble, 64 KiB of
// metadata and its checksum whatever the file's size; `file` is left open for the payload.
Header read_file_header(const std::filesystem::path& path, std::ifstream& file) {
    file.open(path, std::ios::binary | std::ios::ate);
    if (!file) throw TableError(describe_errno(path, "open"));
    const std::streamoff size = file.tellg();
    if (size < 0) throw TableError(path.string() + ": cannot determine the file size");
    std::vector<std::byte> head(std::min<size_t>(static_cast<size_t>(size), kPreambleSize + kMaxMetadataSize + 8));
    file.seekg(0);
    if (!file.read(reinterpret_cast<char*>(head.data()), static_cast<std::streamsize>(head.size())))
        throw TableError(describe_errno(path, "read"));
    return parse_header(head, static_cast<uint64_t>(size), path.string());
}

}  // namespace

Table parse_table(std::span<const std::byte> bytes, std::string_view name) {
    return copy_payload(parse_header(bytes, bytes.size(), name), bytes, name);
}

Table read_table(const std::filesystem::path& path, TableLoading loading) {
    require_regular_file(path);
    if (loading == TableLoading::map)
        if (const std::shared_ptr<const detail::MappedFile> file = detail::MappedFile::map(path)) {
            const std::span<const std::byte> bytes = file->bytes();
            Header header = parse_header(bytes, bytes.size(), path.string());
            if (std::optional<Table> table = read_mapped_payload(header, file, path.string())) return std::move(*table);
            return copy_payload(std::move(header), bytes, path.string());
        }
    std::ifstream file;
    Header header = read_file_header(path, file);
    // The payload goes straight to its place.
    file.seekg(static_cast<std::streamoff>(header.payload_offset));
    return read_payload(
        std::move(header),
        [&](void* destination, uint64_t bytes) {
            if (!file.read(static_cast<char*>(destination), static_cast<std::streamsize>(bytes)))
                throw TableError(describe_errno(path, "read"));
        },
        path.string());
}

BinnedEnvMap binned_map(Table&& table) {
    const std::string name = table.name.empty() ? "table" : table.name;
    if (!table.bins) fail(name, "has no bins (write it with precompute --bins)");
    try {
        return BinnedEnvMap(std::move(table.map), *table.bins);
    } catch (const std::invalid_argument& e) {
        fail(name, std::string("bins do not fit the map: ") + e.what());
    }
}

TableHeader read_table_header(const std::filesystem::path& path) {
    require_regular_file(path);
    std::ifstream file;
    Header h = read_file_header(path, file);
    return {h.version, h.w, h.h, h.options, h.stats, std::move(h.source), h.compact, h.bins_size != 0};
}

bool looks_like_table(const std::filesystem::path& path) noexcept {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) return false;  // never block on a FIFO
    std::ifstream file(path, std::ios::binary);
    char magic[sizeof kMagic] = {};
    return file.read(magic, sizeof magic) && std::memcmp(magic, kMagic, sizeof kMagic) == 0;
}

}  // namespace envmis
