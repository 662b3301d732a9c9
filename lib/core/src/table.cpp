#include "envmis/table.h"

#include <bit>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <vector>

#include "envmis/atomic_file.h"
#include "envmis/hash.h"

namespace envmis {
namespace {

static_assert(std::endian::native == std::endian::little, "table files are little-endian; port the I/O first");

constexpr std::byte kMagic[8] = {std::byte{0x89}, std::byte{'E'}, std::byte{'N'}, std::byte{'V'},
                                 std::byte{'M'},  std::byte{'I'}, std::byte{'S'}, std::byte{0x1A}};
constexpr uint32_t kByteOrderMark = 0x01020304;
constexpr size_t kPreambleSize = 32;
constexpr uint32_t kMaxMetadataSize = 64 * 1024;
constexpr uint32_t kMaxStringSize = 4096;
constexpr uint64_t kMaxTexels = uint64_t{1} << 31;
constexpr uint32_t kSamplerCdf = 1;
constexpr uint32_t kFlagCompensation = 1;

class ByteWriter {
public:
    template <class T>
    void put(const T& v) {
        const auto* p = reinterpret_cast<const std::byte*>(&v);
        bytes.insert(bytes.end(), p, p + sizeof(T));
    }
    void put_string(const std::string& s) {
        put(static_cast<uint32_t>(s.size()));
        const auto* p = reinterpret_cast<const std::byte*>(s.data());
        bytes.insert(bytes.end(), p, p + s.size());
    }
    std::vector<std::byte> bytes;
};

// Reads fields from a byte span; every read is checked against what is left.
class Cursor {
public:
    Cursor(std::span<const std::byte> bytes, std::string_view name) : bytes_(bytes), name_(name) {}

    [[noreturn]] void fail(const std::string& problem) const {
        throw TableError(std::string(name_) + ": " + problem);
    }
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

std::vector<std::byte> metadata_block(const EnvMap& map, const TableSource& source) {
    const EnvMapOptions& o = map.options();
    const EnvMapStats& s = map.stats();
    ByteWriter w;
    w.put(map.width());
    w.put(map.height());
    w.put(kSamplerCdf);
    w.put(o.compensation.enabled ? kFlagCompensation : 0u);
    w.put(o.compensation.alpha);
    w.put(o.luma);
    w.put(o.axes);
    w.put(static_cast<uint8_t>(o.mapping));
    w.put(s.mean_luminance);
    w.put(s.threshold);
    w.put(s.max_luminance);
    w.put(s.min_positive_luminance);
    w.put(s.zeroed_texels);
    w.put(static_cast<uint32_t>(s.fallback));
    w.put(s.bad_pixels.nan);
    w.put(s.bad_pixels.infinite);
    w.put(s.bad_pixels.negative);
    w.put(source.content_hash);
    w.put_string(source.name);
    w.put_string(source.input_colorspace);
    w.put_string(source.working_colorspace);
    return std::move(w.bytes);
}

template <class T>
std::span<const std::byte> as_bytes_of(const std::vector<T>& v) {
    return std::as_bytes(std::span<const T>(v));
}

std::string describe_errno(const std::filesystem::path& path, const char* action) {
    return path.string() + ": cannot " + action + ": " + std::strerror(errno);
}

}  // namespace

void write_table(const std::filesystem::path& path, const EnvMap& map, const TableSource& source) {
    for (const std::string* s : {&source.name, &source.input_colorspace, &source.working_colorspace})
        if (s->size() > kMaxStringSize)
            throw TableError(path.string() + ": metadata string longer than " + std::to_string(kMaxStringSize) + " bytes");
    const std::vector<std::byte> metadata = metadata_block(map, source);
    const std::vector<float> density = map.density();
    const auto& radiance = map.radiance().pixels;
    const uint64_t payload = density.size() * sizeof(float) + radiance.size() * sizeof(Rgb);
    const uint64_t total = kPreambleSize + metadata.size() + 8 + payload + 8;

    ByteWriter head;
    for (std::byte b : kMagic) head.put(b);
    head.put(kTableVersion);
    head.put(kByteOrderMark);
    head.put(total);
    head.put(static_cast<uint32_t>(metadata.size()));
    head.put(uint32_t{0});
    head.bytes.insert(head.bytes.end(), metadata.begin(), metadata.end());
    head.put(hash64(head.bytes));

    Hasher payload_hash;
    payload_hash.update(as_bytes_of(density));
    payload_hash.update(as_bytes_of(radiance));
    const uint64_t payload_digest = payload_hash.digest();

    try {
        write_file_atomically(path, [&](std::ostream& out) {
            auto write = [&](std::span<const std::byte> bytes) {
                out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
            };
            write(head.bytes);
            write(as_bytes_of(density));
            write(as_bytes_of(radiance));
            write(std::as_bytes(std::span(&payload_digest, 1)));
        });
    } catch (const std::runtime_error& e) {
        throw TableError(e.what());
    }
}

Table parse_table(std::span<const std::byte> bytes, std::string_view name) {
    Cursor in(bytes, name);
    if (bytes.size() < sizeof kMagic || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0)
        in.fail("not an envmis table (bad magic)");
    in.take_bytes(sizeof kMagic, "magic");
    const auto version = in.take<uint32_t>("version");
    const auto order = in.take<uint32_t>("byte-order mark");
    if (order == 0x04030201) in.fail("table was written on a big-endian machine; this build reads little-endian");
    if (order != kByteOrderMark) in.fail("corrupted byte-order mark");
    if (version > kTableVersion)
        in.fail("format version " + std::to_string(version) + " is newer than this envmis reads (version " +
                std::to_string(kTableVersion) + "); upgrade envmis");
    if (version != kTableVersion && version != 1) in.fail("unknown format version " + std::to_string(version));
    const auto total = in.take<uint64_t>("file size");
    if (total != bytes.size())
        in.fail(total > bytes.size() ? "truncated: header says " + std::to_string(total) + " bytes, file has " +
                                           std::to_string(bytes.size())
                                     : "header says " + std::to_string(total) + " bytes, file has " +
                                           std::to_string(bytes.size()) + " (trailing data)");
    const auto metadata_size = in.take<uint32_t>("metadata size");
    in.take<uint32_t>("reserved");
    if (metadata_size > kMaxMetadataSize) in.fail("metadata block of " + std::to_string(metadata_size) + " bytes is too large");
    in.need(uint64_t{metadata_size} + 8, "metadata and header checksum");
    const uint64_t header_digest = hash64(bytes.first(kPreambleSize + metadata_size));

    Cursor meta(bytes.subspan(kPreambleSize, metadata_size), name);
    const auto w = meta.take<uint32_t>("width");
    const auto h = meta.take<uint32_t>("height");
    const auto sampler = meta.take<uint32_t>("sampler kind");
    const auto flags = meta.take<uint32_t>("flags");
    EnvMapOptions options;
    options.compensation.enabled = flags & kFlagCompensation;
    options.compensation.alpha = meta.take<float>("alpha");
    options.luma = meta.take<LumaCoefficients>("luma coefficients");
    options.axes = meta.take<Axes>("axes");
    // Version 1 had a reserved 0 here: every version 1 table is equirectangular.
    const auto mapping = meta.take<uint8_t>("mapping");
    EnvMapStats stats;
    stats.mean_luminance = meta.take<double>("mean luminance");
    stats.threshold = meta.take<float>("threshold");
    stats.max_luminance = meta.take<float>("max luminance");
    stats.min_positive_luminance = meta.take<float>("min luminance");
    stats.zeroed_texels = meta.take<uint64_t>("zeroed texels");
    const auto fallback = meta.take<uint32_t>("fallback");
    stats.bad_pixels.nan = meta.take<uint64_t>("NaN count");
    stats.bad_pixels.infinite = meta.take<uint64_t>("Inf count");
    stats.bad_pixels.negative = meta.take<uint64_t>("negative count");
    TableSource source;
    source.content_hash = meta.take<uint64_t>("source hash");
    source.name = meta.take_string("source name");
    source.input_colorspace = meta.take_string("input colour space");
    source.working_colorspace = meta.take_string("working colour space");

    in.take_bytes(metadata_size, "metadata");
    if (in.take<uint64_t>("header checksum") != header_digest) in.fail("corrupted header (checksum mismatch)");
    if (meta.position() != metadata_size) in.fail("metadata block has " + std::to_string(metadata_size - meta.position()) + " unexpected bytes");
    if (w == 0 || h == 0 || w > kMaxCells1D || h > kMaxCells1D || uint64_t{w} * h > kMaxTexels)
        in.fail("invalid size " + std::to_string(w) + "x" + std::to_string(h));
    if (sampler != kSamplerCdf) in.fail("unknown sampler kind " + std::to_string(sampler));
    if (version == 1 ? mapping != 0 : mapping != 1 && mapping != 2)
        in.fail("unknown mapping " + std::to_string(mapping));
    options.mapping = mapping == 2 ? Mapping::equal_area : Mapping::equirect;
    if (options.mapping == Mapping::equal_area && w != h)
        in.fail("equal-area table of size " + std::to_string(w) + "x" + std::to_string(h) + " is not square");
    if (fallback > static_cast<uint32_t>(DensityFallback::uniform)) in.fail("unknown fallback " + std::to_string(fallback));
    stats.fallback = static_cast<DensityFallback>(fallback);

    const uint64_t texels = uint64_t{w} * h;
    const auto density_bytes = in.take_bytes(texels * sizeof(float), "density");
    const auto radiance_bytes = in.take_bytes(texels * sizeof(Rgb), "radiance");
    Hasher payload_hash;
    payload_hash.update(density_bytes);
    payload_hash.update(radiance_bytes);
    if (in.take<uint64_t>("payload checksum") != payload_hash.digest()) in.fail("corrupted payload (checksum mismatch)");
    if (in.position() != bytes.size())
        in.fail(std::to_string(bytes.size() - in.position()) + " bytes of trailing data after the payload");

    std::vector<float> density(texels);
    std::memcpy(density.data(), density_bytes.data(), density_bytes.size());
    RgbImage radiance{w, h, std::vector<Rgb>(texels)};
    std::memcpy(radiance.pixels.data(), radiance_bytes.data(), radiance_bytes.size());
    try {
        return {EnvMap(std::move(radiance), density, options, stats), std::move(source)};
    } catch (const std::invalid_argument& e) {
        in.fail(std::string("inconsistent contents: ") + e.what());
    }
}

Table read_table(const std::filesystem::path& path) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw TableError(path.string() + ": no such file");
    if (!std::filesystem::is_regular_file(path, ec)) throw TableError(path.string() + ": not a regular file");
    std::ifstream file(path, std::ios::binary | std::ios::ate);
    if (!file) throw TableError(describe_errno(path, "open"));
    const std::streamoff size = file.tellg();
    if (size < 0) throw TableError(path.string() + ": cannot determine the file size");
    std::vector<std::byte> bytes(static_cast<size_t>(size));
    file.seekg(0);
    if (!file.read(reinterpret_cast<char*>(bytes.data()), size)) throw TableError(describe_errno(path, "read"));
    return parse_table(bytes, path.string());
}

bool looks_like_table(const std::filesystem::path& path) noexcept {
    std::ifstream file(path, std::ios::binary);
    char magic[sizeof kMagic] = {};
    return file.read(magic, sizeof magic) && std::memcmp(magic, kMagic, sizeof kMagic) == 0;
}

}  // namespace envmis
