#include "envmis/io/image_io.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstring>
#include <fstream>
#include <span>

#include "envmis/build/atomic_file.h"
#include "envmis/io/colour.h"
#include "envmis/math/hash.h"

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

// An input must be a regular file (through symbolic links) that this process may read:
// a FIFO without a writer or a device such as /dev/zero would block or never end a read,
// and the readers' own messages for a file they may not open do not say why.
void require_regular_file(const fs::path& path) {
    std::error_code ec;
    const fs::file_status status = fs::status(path, ec);
    if (status.type() == fs::file_type::not_found) fail(path, "no such file");
    if (ec) fail(path, ec.message());
    if (fs::is_directory(status)) fail(path, "is a directory, not a regular file");
    if (!fs::is_regular_file(status)) fail(path, "not a regular file");
    if (::access(path.c_str(), R_OK) != 0) fail(path, std::string("cannot read (") + std::strerror(errno) + ")");
}

std::unique_ptr<OIIO::ImageInput> open_image(const fs::path& path) {
    require_regular_file(path);
    auto in = OIIO::ImageInput::open(path.string());
    if (!in) fail(path, "not a readable image file (" + OIIO::geterror() + ")");
    const OIIO::ImageSpec& spec = in->spec();
    if (spec.width <= 0 || spec.height <= 0)
        fail(path, "image has no pixels (" + std::to_string(spec.width) + "x" + std::to_string(spec.height) + ")");
    if (static_cast<uint64_t>(spec.width) * static_cast<uint64_t>(spec.height) > kMaxPixels)
        fail(path, "image too large (" + std::to_string(spec.width) + "x" + std::to_string(spec.height) + ")");
    if (uint64_t(std::max(spec.full_width, 0)) * uint64_t(std::max(spec.full_height, 0)) > kMaxPixels)
        fail(path, "display window too large (" + std::to_string(spec.full_width) + "x" +
                       std::to_string(spec.full_height) + ")");
    if (spec.depth != 1 || spec.deep) fail(path, "volume and deep images are not supported");
    if (spec.nchannels < 1) fail(path, "unsupported channel count " + std::to_string(spec.nchannels));
    return in;
}

// A rectangle of pixels in OpenEXR's image coordinates.
struct Window {
    int64_t x = 0, y = 0, width = 0, height = 0;
    std::string to_string() const {
        return std::to_string(width) + "x" + std::to_string(height) + " at (" + std::to_string(x) + ", " +
               std::to_string(y) + ")";
    }
};

// OpenImageIO's progress callback: true stops the read.
bool stop_reading(void* stop, float) { return stop_requested(static_cast<StopFlag>(stop)); }

// Rows read at a time when the read may be stopped: OpenImageIO calls its progress
// callback only every few hundred megabytes (measured: docs/performance-log.md,
// 'kRowsPerRead'), so scanline files are read a block at a time and the flag checked
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

// The first subimage's data window (the pixels stored) at its top MIP level, as float RGB.
RgbImage read_data_window(const fs::path& path, OIIO::ImageInput& in, StopFlag stop) {
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

// The image is the display window, as the OpenEXR specification defines it: its pixels
// outside the data window are black, and data outside it (overscan) is cropped away.
// Formats without windows have both the same, and keep the pixels as read.
RgbImage read_pixels(const fs::path& path, OIIO::ImageInput& in, std::vector<std::string>& notices, StopFlag stop) {
    const OIIO::ImageSpec& spec = in.spec();
    const Window data{spec.x, spec.y, spec.width, spec.height};
    const Window display{spec.full_x, spec.full_y, spec.full_width, spec.full_height};
    if (display.width <= 0 || display.height <= 0 ||
        (display.x == data.x && display.y == data.y && display.width == data.width && display.height == data.height))
        return read_data_window(path, in, stop);
    const RgbImage stored = read_data_window(path, in, stop);
    RgbImage image{static_cast<uint32_t>(display.width), static_cast<uint32_t>(display.height), {}};
    image.pixels.resize(size_t{image.width} * image.height);
    const int64_t x0 = std::max(data.x, display.x), x1 = std::min(data.x + data.width, display.x + display.width);
    const int64_t y0 = std::max(data.y, display.y), y1 = std::min(data.y + data.height, display.y + display.height);
    for (int64_t y = y0; y < y1 && x0 < x1; ++y)
        std::copy_n(stored.pixels.begin() + ((y - data.y) * data.width + (x0 - data.x)), x1 - x0,
                    image.pixels.begin() + ((y - display.y) * display.width + (x0 - display.x)));
    const bool black_border = x0 > display.x || y0 > display.y || x1 < display.x + display.width ||
                              y1 < display.y + display.height || x0 >= x1 || y0 >= y1;
    const bool cropped = data.x < x0 || data.y < y0 || data.x + data.width > x1 || data.y + data.height > y1;
    std::string notice = path.string() + ": data window " + data.to_string() + " differs from the display window " +
                         display.to_string() + ": the map is the display window";
    if (black_border) notice += ", black where it has no data";
    if (cropped) notice += ", data outside it cropped";
    notices.push_back(notice);
    return image;
}

// `elements` is the length of the image's pixel vector, `per_pixel` its elements per pixel.
void check_writable(const fs::path& path, uint32_t width, uint32_t height, size_t elements, size_t per_pixel) {
    const size_t expected = size_t{width} * height * per_pixel;
    if (width == 0 || height == 0 || width > INT_MAX || height > INT_MAX || elements != expected)
        fail(path, "cannot write a " + std::to_string(width) + "x" + std::to_string(height) + " image of " +
                       std::to_string(elements) + " elements (expected " + std::to_string(expected) + ")");
}

// The file's bytes, encoded in memory: OpenImageIO's writers do not all report a failed
// write (2.4's PNG writer ignores a short fwrite), so the bytes reach the disk through
// AtomicFile, which checks every write. Empty with `error` set on failure.
std::vector<unsigned char> encode(const char* format, const OIIO::ImageSpec& spec, const void* pixels,
                                  std::string& error) {
    std::vector<unsigned char> bytes;
    OIIO::Filesystem::IOVecOutput proxy(bytes);
    auto out = OIIO::ImageOutput::create(format);
    if (!out) {
        error = OIIO::geterror();
        return {};
    }
    if (!out->supports("ioproxy") || !out->set_ioproxy(&proxy)) {
        error = std::string("the ") + format + " writer cannot write to memory";
        return {};
    }
    if (out->open("memory." + std::string(format), spec) && out->write_image(spec.format, pixels) && out->close())
        return bytes;
    error = out->geterror();
    if (error.empty()) error = "no detail from OpenImageIO";
    return {};
}

// Readers never see a partial file: AtomicFile renames it into place only when complete.
void write_atomically(const fs::path& path, const char* format, const OIIO::ImageSpec& spec, const void* pixels) {
    try {
        AtomicFile file(path);
        std::string error;
        const std::vector<unsigned char> bytes = encode(format, spec, pixels, error);
        if (!error.empty()) fail(path, "cannot write (" + error + ")");
        file.write(std::as_bytes(std::span(bytes)));
        file.commit();
    } catch (const ImageError&) {
        throw;
    } catch (const std::runtime_error& e) {
        throw ImageError(e.what());
    }
}

}  // namespace

uint64_t hash_file(const fs::path& path, StopFlag stop) {
    require_regular_file(path);
    std::ifstream in(path, std::ios::binary);
    if (!in) fail(path, std::string("cannot open to hash (") + std::strerror(errno) + ")");
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

ImageSize read_image_size(const fs::path& path) {
    const auto in = open_image(path);
    const OIIO::ImageSpec& spec = in->spec();
    const bool windowed = spec.full_width > 0 && spec.full_height > 0;
    ImageSize size;
    size.width = static_cast<uint32_t>(windowed ? spec.full_width : spec.width);
    size.height = static_cast<uint32_t>(windowed ? spec.full_height : spec.height);
    size.largest_texels = std::max(uint64_t{size.width} * size.height, uint64_t(spec.width) * uint64_t(spec.height));
    return size;
}

LoadedImage load_image(const fs::path& path, const LoadOptions& options) {
    const auto in = open_image(path);
    const ColourConfig& colour = colour_config();
    LoadedImage loaded;
    loaded.input_colorspace = input_space(path, in->spec(), options.colorspace, colour);
    loaded.working_colorspace = require_space(path, colour, options.working_space);
    loaded.format = in->format_name();
    loaded.channels = static_cast<uint32_t>(in->spec().nchannels);
    loaded.image = read_pixels(path, *in, loaded.notices, options.stop);
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
