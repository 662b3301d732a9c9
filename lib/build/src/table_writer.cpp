#include "envmis/build/table_writer.h"

#include <algorithm>
#include <cstring>
#include <vector>

#include "detail/parallel.h"
#include "envmis/build/atomic_file.h"
#include "envmis/build/env_map.h"
#include "envmis/math/hash.h"
#include "envmis/table/format.h"

namespace envmis {
namespace {

using namespace table_format;

// Texels handed to the writer at a time: small enough that a stop is seen within
// milliseconds, large enough that the calls cost nothing.
constexpr size_t kTexelsPerWrite = size_t{1} << 17;

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

std::vector<std::byte> metadata_block(const EnvMap& map, const EnvMapStats& s, const TableSource& source,
                                      TableEncoding encoding, uint32_t bins_size) {
    const EnvMapOptions& o = map.options();
    ByteWriter w;
    w.put(map.width());
    w.put(map.height());
    w.put(kSamplerCdf);
    w.put((o.compensation.enabled ? kFlagCompensation : 0u) | (encoding == TableEncoding::compact ? kFlagCompact : 0u));
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
    w.put(bins_size);
    w.put_string(source.build_options);
    w.bytes.resize((w.bytes.size() + kMetadataAlignment - 1) / kMetadataAlignment * kMetadataAlignment);
    return std::move(w.bytes);
}

std::vector<std::byte> bins_section(const BinLayout& layout) {
    ByteWriter w;
    w.put(layout.bins_per_side);
    w.put(layout.cell_columns);
    w.put(layout.cell_rows);
    w.put(static_cast<uint32_t>(layout.lobe_exponents.size()));
    w.put(layout.diffuse_bins_per_side);
    for (float e : layout.lobe_exponents) w.put(e);
    for (const BinChoice& c : layout.choices) {
        w.put(c.alpha);
        w.put(c.threshold);
        w.put(c.min_view_cos);
    }
    return std::move(w.bytes);
}

template <class T>
std::span<const std::byte> as_bytes_of(std::span<const T> v) {
    return std::as_bytes(v);
}

}  // namespace

namespace {

// Writes the preamble, `metadata`, the header checksum, the payload of `payload_size`
// bytes that for_each_chunk(use) hands to `use` in order (it is called twice: for the
// payload checksum, then to write), the payload checksum, and `bins` with its checksum
// unless empty; atomically. Between chunks, `stop` (interrupt.h) ends it with Interrupted
// and no file.
template <class ForEachChunk>
void write_file(const std::filesystem::path& path, const std::vector<std::byte>& metadata, uint64_t payload_size,
                const std::vector<std::byte>& bins, StopFlag stop, ForEachChunk&& for_each_chunk) {
    ByteWriter head;
    for (std::byte b : kMagic) head.put(b);
    head.put(kTableVersion);
    head.put(kByteOrderMark);
    const uint64_t bins_size = bins.empty() ? 0 : bins.size() + 8;
    head.put(uint64_t{kPreambleSize + metadata.size() + 8 + payload_size + 8 + bins_size});
    head.put(static_cast<uint32_t>(metadata.size()));
    head.put(uint32_t{0});
    head.bytes.insert(head.bytes.end(), metadata.begin(), metadata.end());
    head.put(hash64(head.bytes));

    Hasher payload_hash;
    for_each_chunk([&](std::span<const std::byte> bytes) {
        throw_if_stopped(stop);
        payload_hash.update(bytes);
    });
    const uint64_t payload_digest = payload_hash.digest(), bins_digest = hash64(bins);
    try {
        write_file_atomically(path, [&](std::ostream& out) {
            auto write = [&](std::span<const std::byte> bytes) {
                throw_if_stopped(stop);
                out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
            };
            write(head.bytes);
            for_each_chunk(write);
            write(std::as_bytes(std::span(&payload_digest, 1)));
            if (!bins.empty()) {
                write(bins);
                write(std::as_bytes(std::span(&bins_digest, 1)));
            }
        });
    } catch (const Interrupted&) {
        throw;
    } catch (const std::runtime_error& e) {
        throw TableError(e.what());
    }
}

}  // namespace

RgbImage rgbe_round(RgbImageView image) {
    RgbImage out = to_image(image);
    detail::parallel_for(out.height, 16, [&](uint32_t lo, uint32_t hi) {
        for (size_t i = size_t{lo} * out.width; i < size_t{hi} * out.width; ++i) {
            BadPixels ignored;
            sanitize_pixel(out.pixels[i], ignored);
            out.pixels[i] = rgbe_decode(rgbe_encode(out.pixels[i]));
        }
    });
    return out;
}

namespace {

// The plain map's table, with `layout`'s bins section if not null.
void write_map(const std::filesystem::path& path, const EnvMap& map, const TableSource& source, TableEncoding encoding,
               const BinLayout* layout, StopFlag stop) {
    for (const std::string* s :
         {&source.name, &source.input_colorspace, &source.working_colorspace, &source.build_options})
        if (s->size() > kMaxStringSize)
            throw TableError(path.string() + ": metadata string longer than " + std::to_string(kMaxStringSize) +
                             " bytes");
    const std::vector<std::byte> bins = layout ? bins_section(*layout) : std::vector<std::byte>{};
    const auto bins_size = static_cast<uint32_t>(bins.size());
    const auto& radiance = map.radiance().pixels;
    if (encoding == TableEncoding::compact) {
        // The table holds the rounded map: its statistics (Lbar, threshold) are the
        // rounded map's, which the reader's rebuild reproduces exactly; the bad-pixel
        // counts are the source's.
        const EnvMap rounded = build_env_map(rgbe_round(map.radiance()), map.options(), stop);
        EnvMapStats stats = rounded.stats();
        stats.bad_pixels = map.stats().bad_pixels;
        std::vector<uint32_t> rgbe(radiance.size());
        const uint32_t w = map.width();
        detail::parallel_for(map.height(), 16, [&](uint32_t lo, uint32_t hi) {
            for (size_t i = size_t{lo} * w; i < size_t{hi} * w; ++i) rgbe[i] = rgbe_encode(radiance[i]);
        });
        write_file(
            path, metadata_block(map, stats, source, encoding, bins_size), rgbe.size() * sizeof(uint32_t), bins, stop,
            [&](auto&& use) {
                for (size_t i = 0; i < rgbe.size(); i += kTexelsPerWrite)
                    use(as_bytes_of<uint32_t>(std::span(rgbe).subspan(i, std::min(kTexelsPerWrite, rgbe.size() - i))));
            });
        return;
    }
    // The density is computed a row at a time, twice (for the checksum, then to write):
    // cheaper than holding a copy of the map's size.
    std::vector<float> row(map.width());
    write_file(path, metadata_block(map, map.stats(), source, encoding, bins_size),
               radiance.size() * (sizeof(float) + sizeof(Rgb)), bins, stop, [&](auto&& use) {
                   for (uint32_t y = 0; y < map.height(); ++y) {
                       map.density_row(y, row);
                       use(as_bytes_of<float>(row));
                   }
                   for (size_t i = 0; i < radiance.size(); i += kTexelsPerWrite)
                       use(as_bytes_of<Rgb>(radiance.subspan(i, std::min(kTexelsPerWrite, radiance.size() - i))));
               });
}

}  // namespace

void write_table(const std::filesystem::path& path, const EnvMap& map, const TableSource& source,
                 TableEncoding encoding, StopFlag stop) {
    write_map(path, map, source, encoding, nullptr, stop);
}

void write_table(const std::filesystem::path& path, const BinnedEnvMap& binned, const TableSource& source,
                 TableEncoding encoding, StopFlag stop) {
    // Never write what the reader would refuse (a default-constructed BinnedEnvMap has no bins).
    const BinLayout& layout = binned.layout();
    const uint32_t g = layout.bins_per_side, gd = layout.diffuse_bins_per_side, classes = layout.classes();
    if (g < 1 || g > kMaxBinsPerSide || gd < 1 || gd > kMaxBinsPerSide || classes < 1 || classes > kMaxLobeClasses ||
        layout.choices.size() != layout.choice_count())
        throw TableError(path.string() + ": the binned map has no valid bins to write");
    write_map(path, binned.radiance_map(), source, encoding, &binned.layout(), stop);
}

}  // namespace envmis
