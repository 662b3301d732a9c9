// libFuzzer target for the table reader on bytes in memory (parse_table): any input must
// either parse into a usable table or throw TableError. Any other exception, a sanitizer
// report or a crash is a finding. The mapped path is mapped_table_fuzz.cpp's.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "table_fuzz_support.h"

namespace {

void parse(std::span<const std::byte> bytes) {
    try {
        envmis::fuzz::use(envmis::parse_table(bytes, "fuzz"));
    } catch (const envmis::TableError&) {}
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const auto bytes = std::as_bytes(std::span(data, size));
    parse(bytes);
    std::vector<std::byte> repaired(bytes.begin(), bytes.end());
    if (envmis::fuzz::repair_checksums(repaired)) parse(repaired);
    return 0;
}
