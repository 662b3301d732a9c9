// libFuzzer target for the image reader's entry point (envmis::io::load_image) and what
// `envmis precompute` does next, building the sampler. An input's first byte picks the
// file name's extension (OpenImageIO chooses the reader by it first, then by content),
// the rest is the file. An input must load into a map that samples or throw ImageError;
// any other exception, a sanitizer report or a crash is a finding.
//
// OpenImageIO and OpenEXR are not instrumented: coverage feedback comes from envmis's own
// code, so the fuzzer explores the reader's checks rather than the codecs.
#include <OpenImageIO/imageio.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>

#include "envmis/build/env_map.h"
#include "envmis/io/image_io.h"
#include "envmis/sampling/envmap.h"

namespace {

namespace fs = std::filesystem;

constexpr std::array<const char*, 8> kExtensions = {".exr", ".hdr", ".png", ".tif", ".pfm", ".ppm", ".jpg", ""};

// Headers may declare up to the reader's limit of 2^30 pixels (12 GB as float RGB), which
// a fuzzer's memory limit cannot tell from a leak; larger declared sizes than this are
// left to the reader's own tests (tests/io/) and skipped here.
constexpr uint64_t kMaxFuzzedPixels = uint64_t{1} << 22;

// One file per extension and process, rewritten for every input, in memory where the
// system has /dev/shm, and removed when the fuzzer exits.
struct ScratchFiles {
    fs::path folder = fs::is_directory("/dev/shm") ? fs::path("/dev/shm") : fs::temp_directory_path();
    std::string stem = "envmis_image_fuzz_" + std::to_string(::getpid());
    fs::path file(size_t kind) const { return folder / (stem + kExtensions[kind]); }
    ~ScratchFiles() {
        std::error_code ignored;
        for (size_t k = 0; k < kExtensions.size(); ++k) fs::remove(file(k), ignored);
    }
};

bool declares_few_pixels(const fs::path& file) {
    const auto in = OIIO::ImageInput::open(file.string());
    if (!in) return true;  // not an image: the reader's error path, always worth taking
    // The data window is what the file stores, the display window what the reader makes.
    const OIIO::ImageSpec& spec = in->spec();
    const auto pixels = [](int w, int h) { return uint64_t(std::max(w, 0)) * uint64_t(std::max(h, 0)); };
    return pixels(spec.width, spec.height) <= kMaxFuzzedPixels &&
           pixels(spec.full_width, spec.full_height) <= kMaxFuzzedPixels;
}

volatile float sink;

void load(const fs::path& file) {
    if (!declares_few_pixels(file)) return;
    envmis::io::LoadedImage loaded;
    try {
        loaded = envmis::io::load_image(file);
    } catch (const envmis::io::ImageError&) {
        return;
    }
    try {
        const envmis::EnvMap map = envmis::build_env_map(std::move(loaded.image));
        sink = map.sample({0.37f, 0.61f}).pdf + static_cast<float>(map.stats().bad_pixels.total());
    } catch (const std::invalid_argument&) {
        // The one image a map refuses: finite pixels whose power overflows float.
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static const ScratchFiles scratch;
    if (size == 0) return 0;
    const fs::path file = scratch.file(data[0] % kExtensions.size());
    {
        std::ofstream out(file, std::ios::binary | std::ios::trunc);
        out.write(reinterpret_cast<const char*>(data + 1), static_cast<std::streamsize>(size - 1));
        if (!out.flush()) throw std::runtime_error("image_fuzz: cannot write " + file.string());
    }
    load(file);
    return 0;
}
