#include "envmis/io/image_io.h"

#include "envmis/table/atomic_file.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <climits>
#include <fstream>
#include <span>

#include "envmis/io/colour.h"
#include "envmis/math/hash.h"
#include "envmis/table/atomic_file.h"

namespace envmis::io {
namespace {

namespace fs = std::filesystem;

// A corrupt header can claim any size; refuse before allocating (12 GiB of floats).
constexpr uint64_t kMaxPixels = uint64_t{1} << 30;

[[noreturn]] void fail(const fs::path& path, const std::string& problem) {
    throw ImageError(path.string() + ": " + problem);
}

// Parsed once per process: reading the config for every image would cost more than small images.
const ColourConfig& colour_config() {
    static const ColourConfig config;
    return config;
}

// The config's name for `name`, which must exist.
std::string require_space(const fs::path& path, const ColourConfig& colour, const std::string& name) {
    if (std::string canonical = colour.resolve(name); !canonical.empty()) return canonical;
    std::string known;
    for (const std::string& space : colour.spaces()) known += (known.empty() ? "" : ", ") + space;
    fail(path, "unknown colour space '" + name + "' (the OCIO config " + colour.description() + " has " + known + ")");
}

std::string input_space(const fs::path& path, const OIIO::ImageSpec& spec, const std::string& chosen,
                        const ColourConfig& colour) {
    if (!chosen.empty()) return require_space(path, colour, chosen);
    if (std::string tagged = colour.resolve(spec.get_string_attribute("oiio:ColorSpace")); !tagged.empty())
        return tagged;
    // Untagged: float pixels are conventionally scene-linear, integer pixels display-encoded.
    return require_space(path, colour, spec.format.is_floating_point() ? "lin_rec709" : "sRGB");
}

std::unique_ptr<OIIO::ImageInput> open_image(const fs::path& path) {
    std::error_code ec;
    const fs::file_status status = fs::status(path, ec);
    if (status.type() == fs::file_type::not_found) fail(path, "no such file");
    if (ec) fail(path, ec.message());
    if (fs::is_directory(status)) fail(path, "is a directory, not an image file");
    auto in = OIIO::ImageInput::open(path.string());
    if (!in) fail(path, "not a readable image file (" + OIIO::geterror() + ")");
    const OIIO::ImageSpec& spec = in->spec();
    if (spec.width <= 0 || spec.height <= 0)
        fail(path, "image has no pixels (" + std::to_string(spec.width) + "x" + std::to_string(spec.height) + ")");
    if (static_cast<uint64_t>(spec.width) * static_cast<uint64_t>(spec.height) > kMaxPixels)
        fail(path, "image too large (" + std::to_string(spec.width) + "x" + std::to_string(spec.height) + ")");
    if (spec.depth != 1 || spec.deep) fail(path, "volume and deep images are not supported");
    if (spec.nchannels < 1) fail(path, "unsupported channel count " + std::to_string(spec.nchannels));
    return in;
}

// OpenImageIO's progress callback: true stops the read.
bool stop_reading(void* stop, float) { return stop_requested(static_cast<StopFlag>(stop)); }

// Rows read at a time when the read may be stopped: OpenImageIO calls its progress
// callback only every few hundred megabytes (after 1.4 s, then at 69% and 100% of a
// 4096x2048 EXR), so scanline files are read a block at a time and the flag checked
// between blocks. Tiled files are read whole, stopped through the callback.
constexpr int kRowsPerRead = 256;

// The pixels of `in` into `pixels` (RGB, or grey into R): OpenImageIO's verdict, false
// also when stopped.
bool read_rows(OIIO::ImageInput& in, int channels, Rgb* pixels, StopFlag stop) {
    const OIIO::ImageSpec& spec = in.spec();
    if (!stop || spec.tile_width > 0)
        return in.read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, pixels, sizeof(Rgb), OIIO::AutoStride,
                             OIIO::AutoStride, stop ? stop_reading : nullptr, const_cast<std::atomic<bool>*>(stop));
    for (int y = 0; y < spec.height; y += kRowsPerRead) {
        const int rows = std::min(kRowsPerRead, spec.height - y);
        if (stop_requested(stop) ||
            !in.read_scanlines(0, 0, spec.y + y, spec.y + y + rows, spec.z, 0, channels, OIIO::TypeDesc::FLOAT,
                               pixels + size_t(y) * spec.width, sizeof(Rgb)))
            return false;
    }
    return true;
}

// The first subimage's top MIP level, as float RGB.
RgbImage read_pixels(const fs::path& path, OIIO::ImageInput& in, StopFlag stop) {
    const OIIO::ImageSpec& spec = in.spec();
    RgbImage image{static_cast<uint32_t>(spec.width), static_cast<uint32_t>(spec.height), {}};
    image.pixels.resize(size_t{image.width} * image.height);
    // Grey files (alpha, if any, ignored) are read into R and copied to G and B.
    const int channels = spec.nchannels >= 3 ? 3 : 1;
    const bool ok = read_rows(in, channels, image.pixels.data(), stop);
    throw_if_stopped(stop);
    // Either signal means the pixels are incomplete; the PNM reader fails on a short file
    // without a message.
    if (std::string error = in.geterror(); !ok || !error.empty())
        fail(path, "truncated or corrupt: cannot read the pixels (" + (error.empty() ? "no detail" : error) + ")");
    if (channels == 1)
        for (Rgb& p : image.pixels) p.g = p.b = p.r;
    return image;
}

uint64_t hash_file(const fs::path& path, StopFlag stop) {
    std::ifstream in(path, std::ios::binary);
    if (!in) fail(path, "cannot open to hash");
    Hasher hasher;
    std::vector<char> chunk(size_t{1} << 20);
    do {
        throw_if_stopped(stop);
        in.read(chunk.data(), static_cast<std::streamsize>(chunk.size()));
        hasher.update(std::as_bytes(std::span(chunk.data(), static_cast<size_t>(in.gcount()))));
    } while (in);
    if (in.bad()) fail(path, "read error while hashing");
    return hasher.digest();
}

// `elements` is the length of the image's pixel vector, `per_pixel` its elements per pixel.
void check_writable(const fs::path& path, uint32_t width, uint32_t height, size_t elements, size_t per_pixel) {
    const size_t expected = size_t{width} * height * per_pixel;
    if (width == 0 || height == 0 || width > INT_MAX || height > INT_MAX || elements != expected)
        fail(path, "cannot write a " + std::to_string(width) + "x" + std::to_string(height) + " image of " +
                       std::to_string(elements) + " elements (expected " + std::to_string(expected) + ")");
}

// Writes `file` in one go; returns OpenImageIO's error, empty on success. The output is
// closed on return, so that a failed file can be removed.
std::string write_file(const fs::path& file, const char* format, const OIIO::ImageSpec& spec, const void* pixels) {
    auto out = OIIO::ImageOutput::create(format);
    if (!out) return OIIO::geterror();
    if (out->open(file.string(), spec) && out->write_image(spec.format, pixels) && out->close()) return {};
    std::string error = out->geterror();
    return error.empty() ? "no detail from OpenImageIO" : error;
}

// Readers never see a partial file: AtomicFile renames it into place only when complete.
void write_atomically(const fs::path& path, const char* format, const OIIO::ImageSpec& spec, const void* pixels) {
    try {
        AtomicFile file(path);
        const std::string error = write_file(file.temporary(), format, spec, pixels);
        if (!error.empty()) fail(path, "cannot write (" + error + ")");
        file.commit();
    } catch (const ImageError&) {
        throw;
    } catch (const std::runtime_error& e) {
        throw ImageError(e.what());
    }
}

}  // namespace

LoadedImage load_image(const fs::path& path, const LoadOptions& options) {
    const auto in = open_image(path);
    const ColourConfig& colour = colour_config();
    LoadedImage loaded;
    loaded.input_colorspace = input_space(path, in->spec(), options.colorspace, colour);
    loaded.working_colorspace = require_space(path, colour, options.working_space);
    loaded.format = in->format_name();
    loaded.channels = static_cast<uint32_t>(in->spec().nchannels);
    loaded.image = read_pixels(path, *in, options.stop);
    colour.convert(loaded.image.pixels, loaded.input_colorspace, loaded.working_colorspace);
    loaded.luma = colour.luma(loaded.working_colorspace);
    loaded.content_hash = hash_file(path, options.stop);
    return loaded;
}

void write_exr(const fs::path& path, RgbImageView image) {
    check_writable(path, image.width, image.height, image.pixels.size(), 1);
    OIIO::ImageSpec spec(static_cast<int>(image.width), static_cast<int>(image.height), 3, OIIO::TypeDesc::FLOAT);
    spec.attribute("compression", "zip");
    write_atomically(path, "openexr", spec, image.pixels.data());
}

void write_png(const fs::path& path, const Image8& image) {
    check_writable(path, image.width, image.height, image.rgb.size(), 3);
    OIIO::ImageSpec spec(static_cast<int>(image.width), static_cast<int>(image.height), 3, OIIO::TypeDesc::UINT8);
    spec.attribute("oiio:ColorSpace", "sRGB");
    write_atomically(path, "png", spec, image.rgb.data());
}

}  // namespace envmis::io
