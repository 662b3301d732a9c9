// libFuzzer target for the mapped loading path: each input is written to a file and read
// with read_table(path, TableLoading::map), which borrows the radiance from a mapping of
// the file and checks it page by page, a path parse_table never takes. As for the
// in-memory target, an input must load into a usable table or throw TableError.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <span>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "table_fuzz_support.h"

namespace {

namespace fs = std::filesystem;

// One file per process, rewritten for every input, in memory where the system has
// /dev/shm, and removed when the fuzzer exits.
struct ScratchFile {
    fs::path path = (fs::is_directory("/dev/shm") ? fs::path("/dev/shm") : fs::temp_directory_path()) /
                    ("envmis_mapped_fuzz_" + std::to_string(::getpid()) + ".envmis");
    ~ScratchFile() {
        std::error_code ignored;
        fs::remove(path, ignored);
    }
};

void load_mapped(const fs::path& file, std::span<const std::byte> bytes) {
    {
        std::ofstream out(file, std::ios::binary | std::ios::trunc);
        out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
        if (!out.flush()) throw std::runtime_error("mapped_table_fuzz: cannot write " + file.string());
    }
    try {
        envmis::fuzz::use(envmis::read_table(file, envmis::TableLoading::map));
    } catch (const envmis::TableError&) {}
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static const ScratchFile scratch;
    const fs::path& file = scratch.path;
    const auto bytes = std::as_bytes(std::span(data, size));
    load_mapped(file, bytes);
    std::vector<std::byte> repaired(bytes.begin(), bytes.end());
    if (envmis::fuzz::repair_checksums(repaired)) load_mapped(file, repaired);
    return 0;
}
