// libFuzzer target for the table reader: any input must either parse or throw
// TableError. Any other exception, a sanitizer report or a crash is a finding.
//
// Every input is parsed twice: as given, and with its size field and both checksums
// recomputed. Mutations almost never keep a 64-bit checksum valid, so without the
// second pass the fuzzer would never get past the header into the metadata checks and
// the rebuild of the sampler from the stored density.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <vector>

#include "envmis/math/hash.h"
#include "envmis/table/table.h"

namespace {

// Layout of table format version 1 (docs/table-format.md): a 32-byte preamble whose bytes
// 16..23 hold the file size and 24..27 the metadata size, then the metadata, the header
// checksum, the payload and the payload checksum.
constexpr size_t kPreamble = 32, kSizeField = 16, kMetadataSizeField = 24;

template <class T>
void store(std::vector<std::byte>& bytes, size_t at, T value) {
    std::memcpy(bytes.data() + at, &value, sizeof value);
}

// Returns false when the input is too short to hold the fields being repaired.
bool repair_checksums(std::vector<std::byte>& bytes) {
    if (bytes.size() < kPreamble + 16) return false;
    uint32_t metadata_size;
    std::memcpy(&metadata_size, bytes.data() + kMetadataSizeField, sizeof metadata_size);
    const size_t header_end = kPreamble + size_t{metadata_size};
    if (header_end + 16 > bytes.size()) return false;
    store<uint64_t>(bytes, kSizeField, bytes.size());
    const auto all = std::span<const std::byte>(bytes);
    store(bytes, header_end, envmis::hash64(all.first(header_end)));
    const size_t payload_end = bytes.size() - 8;
    store(bytes, payload_end, envmis::hash64(all.subspan(header_end + 8, payload_end - header_end - 8)));
    return true;
}

// A table that loads must be safe to use: sample, evaluate and query its pdf. The
// results go to a volatile so that the optimiser cannot drop the memory reads.
volatile float sink;

void exercise(const envmis::Table& table) {
    const envmis::EnvMap& map = table.map;
    float sum = 0;
    for (float u : {0.0f, 0.37f, envmis::kOneMinusEpsilon})
        for (float v : {0.0f, 0.61f, envmis::kOneMinusEpsilon}) {
            const envmis::EnvSample s = map.sample({u, v});
            const envmis::Rgb c = map.eval(s.direction);
            sum += s.pdf + map.pdf(s.direction) + map.pdf_uv(s.uv) + c.r + c.g + c.b;
        }
    for (float d : map.density()) sum += d;
    sink = sum;
}

void parse(std::span<const std::byte> bytes) {
    try {
        exercise(envmis::parse_table(bytes, "fuzz"));
    } catch (const envmis::TableError&) {
        // Rejecting a bad file is the reader's job; anything else escapes and is reported.
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const auto bytes = std::as_bytes(std::span(data, size));
    parse(bytes);
    std::vector<std::byte> repaired(bytes.begin(), bytes.end());
    if (repair_checksums(repaired)) parse(repaired);
    return 0;
}
