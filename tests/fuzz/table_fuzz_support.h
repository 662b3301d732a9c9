// Shared by the table fuzz targets (in memory and mapped): what makes a mutated table
// worth parsing, and what a table that loads must survive.
//
// Mutations almost never keep a 64-bit checksum valid, so each target parses every input
// twice: as given, and with its size field and checksums recomputed; without the second
// pass the fuzzer would never get past the header into the metadata checks and the
// rebuild of the sampler from the stored density.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <utility>
#include <vector>

#include "envmis/math/hash.h"
#include "envmis/table/table.h"

namespace envmis::fuzz {

// Layout of the table format (docs/table-format.md): a 32-byte preamble whose bytes
// 16..23 hold the file size and 24..27 the metadata size, then the metadata, the header
// checksum, the payload and the payload checksum. Version 4 adds, after the metadata's
// 100 fixed bytes and three strings, the bins-section size B; when B > 0 the bins section
// and its checksum follow the payload's.
constexpr size_t kPreamble = 32, kVersionField = 8, kSizeField = 16, kMetadataSizeField = 24, kFixedMetadata = 100;

template <class T>
void store(std::vector<std::byte>& bytes, size_t at, T value) {
    std::memcpy(bytes.data() + at, &value, sizeof value);
}

template <class T>
T load(const std::vector<std::byte>& bytes, size_t at) {
    T value;
    std::memcpy(&value, bytes.data() + at, sizeof value);
    return value;
}

// The bins-section size a version 4 or later header gives (right after the three strings) (bytes up to header_end); 0
// where there is none or the metadata is too damaged to find it.
inline size_t bins_size(const std::vector<std::byte>& bytes, size_t header_end) {
    if (load<uint32_t>(bytes, kVersionField) < 4) return 0;
    size_t at = kPreamble + kFixedMetadata;
    for (int i = 0; i < 3 && at + 4 <= header_end; ++i) at += 4 + size_t{load<uint32_t>(bytes, at)};
    return at + 4 <= header_end ? load<uint32_t>(bytes, at) : 0;
}

// Returns false when the input is too short to hold the fields being repaired.
inline bool repair_checksums(std::vector<std::byte>& bytes) {
    if (bytes.size() < kPreamble + 16) return false;
    const size_t header_end = kPreamble + size_t{load<uint32_t>(bytes, kMetadataSizeField)};
    if (header_end + 16 > bytes.size()) return false;
    store<uint64_t>(bytes, kSizeField, bytes.size());
    const auto all = std::span<const std::byte>(bytes);
    store(bytes, header_end, hash64(all.first(header_end)));
    size_t payload_end = bytes.size() - 8;
    if (const size_t bins = bins_size(bytes, header_end); bins > 0 && header_end + 24 + bins <= bytes.size()) {
        payload_end -= bins + 8;
        store(bytes, bytes.size() - 8, hash64(all.subspan(payload_end + 8, bins)));
    }
    store(bytes, payload_end, hash64(all.subspan(header_end + 8, payload_end - header_end - 8)));
    return true;
}

// The results go to a volatile so that the optimiser cannot drop the memory reads.
inline volatile float sink;

// A table that loads must be safe to use: sample, evaluate and query its pdf, and read
// every density value (on a mapped table, every page the reader kept).
inline void exercise(const Table& table) {
    const EnvMap& map = table.map;
    float sum = 0;
    for (float u : {0.0f, 0.37f, kOneMinusEpsilon})
        for (float v : {0.0f, 0.61f, kOneMinusEpsilon}) {
            const EnvSample s = map.sample({u, v});
            const Rgb c = map.eval(s.direction);
            sum += s.pdf + map.pdf(s.direction) + map.pdf_uv(s.uv) + c.r + c.g + c.b;
        }
    for (float d : map.density()) sum += d;
    sink = sum;
}

// A table with bins that fit its map must give a binned map that is safe to sample.
inline void exercise_bins(Table&& table) {
    const BinnedEnvMap binned = binned_map(std::move(table));
    const BinnedEnvMapView view = binned.view();
    float sum = 0;
    for (float s : {0.0f, 0.37f, kOneMinusEpsilon})
        for (uint32_t lobe = 0; lobe < binned.classes(); ++lobe) {
            const LobeAxis at{octahedral_normal(s, 1 - s), s};  // views head-on to edge-on
            const EnvSample x = view.sample(at, lobe, s, {s, 0.61f});
            sum += x.pdf + view.pdf(at, lobe, s, x.direction);
        }
    sink = sum;
}

// Uses a loaded table as above; rejecting a bad file (TableError) is the reader's job,
// anything else escapes and is reported.
inline void use(Table&& table) {
    exercise(table);
    if (table.bins) exercise_bins(std::move(table));
}

}  // namespace envmis::fuzz
