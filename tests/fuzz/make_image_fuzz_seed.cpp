// Writes a few small images into a folder: the seed corpus for envmis_image_fuzz. Each
// seed is a file as OpenImageIO writes it, behind the byte that image_fuzz.cpp reads as
// the extension's index, so the fuzzer starts inside every reader envmis meets in
// practice: scanline and tiled float EXR (one with a data window inside its display
// window), Radiance .hdr, 8-bit PNG, float TIFF and PPM, in 1, 3 and 4 channels.
#include <OpenImageIO/imageio.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

struct Seed {
    const char* name;
    uint8_t kind;  // index of the extension in image_fuzz.cpp's kExtensions
    const char* extension;
    int channels;
    OIIO::TypeDesc format;
    bool tiled = false, cropped = false;
};

// A gradient with one bright pixel and, in float files, one NaN.
std::vector<float> pixels(int w, int h, int channels, bool with_nan) {
    std::vector<float> p(size_t(w) * h * channels);
    for (size_t i = 0; i < p.size(); ++i) p[i] = 0.05f + 0.9f * float(i % 97) / 97.0f;
    p[size_t(w / 2) * channels] = with_nan ? 50.0f : 1.0f;
    if (with_nan) p[1] = std::numeric_limits<float>::quiet_NaN();
    return p;
}

std::string encode(const Seed& s, const fs::path& scratch) {
    const int w = 8, h = 4;
    OIIO::ImageSpec spec(w, h, s.channels, s.format);
    if (s.tiled) spec.tile_width = spec.tile_height = 4;
    if (s.cropped) {
        spec.full_width = 12, spec.full_height = 6, spec.x = 2, spec.y = 1;
    }
    const bool floats = s.format == OIIO::TypeDesc::FLOAT || s.format == OIIO::TypeDesc::HALF;
    const std::vector<float> data = pixels(w, h, s.channels, floats);
    const fs::path file = scratch.string() + s.extension;
    auto out = OIIO::ImageOutput::create(file.string());
    if (!out || !out->open(file.string(), spec) || !out->write_image(OIIO::TypeDesc::FLOAT, data.data()) ||
        !out->close())
        throw std::runtime_error(std::string("cannot write the ") + s.name + " seed: " + OIIO::geterror());
    std::ifstream in(file, std::ios::binary);
    std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    fs::remove(file);
    return std::string(1, static_cast<char>(s.kind)) + bytes;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: %s FOLDER\n", argv[0]);
        return 2;
    }
    const Seed seeds[] = {
        {"scanline_rgb.exr", 0, ".exr", 3, OIIO::TypeDesc::FLOAT},
        {"tiled_rgba_half.exr", 0, ".exr", 4, OIIO::TypeDesc::HALF, true},
        {"cropped_grey.exr", 0, ".exr", 1, OIIO::TypeDesc::FLOAT, false, true},
        {"radiance.hdr", 1, ".hdr", 3, OIIO::TypeDesc::FLOAT},
        {"srgb.png", 2, ".png", 3, OIIO::TypeDesc::UINT8},
        {"float.tif", 3, ".tif", 3, OIIO::TypeDesc::FLOAT},
        {"rgb.ppm", 5, ".ppm", 3, OIIO::TypeDesc::UINT8},
    };
    try {
        const fs::path dir = argv[1];
        fs::create_directories(dir);
        const fs::path scratch = dir / ("scratch" + std::to_string(::getpid()));
        for (const Seed& s : seeds) {
            std::ofstream out(dir / s.name, std::ios::binary | std::ios::trunc);
            out << encode(s, scratch);
            if (!out.flush()) throw std::runtime_error(std::string("cannot write ") + (dir / s.name).string());
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "envmis_make_image_fuzz_seed: %s\n", e.what());
        return 1;
    }
    return 0;
}
