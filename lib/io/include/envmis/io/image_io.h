// Reading HDR images into linear RGB, and writing EXR and PNG files.
//
// Reading: anything OpenImageIO reads (OpenEXR scanline, tiled or multi-part (the first
// part), Radiance .hdr, .pfm, float TIFF, ...), with 1 (grey), 2 (grey + alpha), 3 (RGB)
// or 4+ (RGBA...: alpha and extra channels ignored) channels. Pixels are converted with
// OpenColorIO from the input colour space (the file's metadata, or the caller's choice)
// to a linear working space (colour.h). Values are returned as read: NaN, Inf and
// negative values are left for EnvMap to repair and count. The image is the display
// window (OpenEXR): pixels outside the data window are black, data outside the display
// window is cropped, and LoadedImage::notices says so. At most 2^30 pixels in either window.
//
// Writing: encoded in memory, then written through an AtomicFile (atomic_file.h): a
// temporary file in the destination folder, every write checked, renamed when complete.
// A destination that is not a regular file (device, FIFO, folder, symbolic link) is
// refused; a failure (a full disk) throws and leaves neither it nor the temporary.
//
// Errors: ImageError, whose message names the file and the problem (missing, not an
// image, truncated, unsupported, unknown colour space...).
#pragma once

#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "envmis/image/image.h"
#include "envmis/interrupt.h"
#include "envmis/math/math.h"

namespace envmis::io {

class ImageError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

struct LoadOptions {
    std::string colorspace;                    // input colour space; empty: from the file's metadata
    std::string working_space = "lin_rec709";  // a colour space of the OCIO config (colour.h)
    // Once set, the load stops within a few scanlines and throws Interrupted (interrupt.h).
    StopFlag stop = nullptr;
};

struct LoadedImage {
    RgbImage image;                  // linear RGB in the working space, raw values
    std::string input_colorspace;    // the colour space the pixels were converted from
    std::string working_colorspace;  // the colour space of `image`
    LumaCoefficients luma;           // luminance weights of the working space
    uint64_t content_hash = 0;       // envmis::hash64 of the file's bytes
    std::string format;              // OpenImageIO's format name, e.g. "openexr", "hdr"
    uint32_t channels = 0;           // channels in the file
    // What the caller should tell the user about how the file was read, one line each,
    // starting with the file's name: an OpenEXR data window that differs from the
    // display window (the map is the display window: black where there is no data, data
    // outside it cropped).
    std::vector<std::string> notices;
};

LoadedImage load_image(const std::filesystem::path& path, const LoadOptions& options = {});

// What load_image would make of a file, from its header alone (no pixel is read): the
// map's size (the display window) and the texels of its largest buffer (the display or
// the data window), for a caller to check against the memory it has before loading.
// Throws ImageError as load_image does for a file it cannot open.
struct ImageSize {
    uint32_t width = 0, height = 0;
    uint64_t largest_texels = 0;
};
ImageSize read_image_size(const std::filesystem::path& path);

// envmis::hash64 (math/hash.h) of a file's bytes, any file: LoadedImage::content_hash, the
// source hash a table records, and library mode's key for an up-to-date output. Reads the
// file once in 1 MiB blocks (about a second per GB, mostly the disk's); once `stop` is
// set, throws Interrupted before the next block. Throws ImageError naming the file where
// it is missing, not a regular file, or cannot be read.
uint64_t hash_file(const std::filesystem::path& path, StopFlag stop = nullptr);

// 8-bit sRGB-encoded RGB pixels, row-major, row 0 at the top (pictures for people).
struct Image8 {
    uint32_t width = 0, height = 0;
    std::vector<uint8_t> rgb;  // width * height * 3
};

// Writes linear float RGB as a 32-bit float OpenEXR file. Throws ImageError naming the file on failure.
void write_exr(const std::filesystem::path& path, RgbImageView image);
// Writes a PNG file. Throws ImageError naming the file on failure.
void write_png(const std::filesystem::path& path, const Image8& image);

}  // namespace envmis::io
