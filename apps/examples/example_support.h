// What the two example programs (render.cpp, pathtrace/) share: the pinhole camera,
// their command-line number parsing and usage errors, and the relative MSE their
// comparisons report.
#pragma once

#include <cmath>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

#include "envmis/image/image.h"
#include "envmis/io/image_io.h"
#include "envmis/math/math.h"

namespace examples {

// A pinhole camera in a z-up world; (x, y) in [0,1)^2 across the image, y down.
struct PinholeCamera {
    envmis::Vec3 position, forward, right, up;  // right and up scaled to the image's half extent

    PinholeCamera(envmis::Vec3 from, envmis::Vec3 at, float vertical_fov_degrees, float aspect) : position(from) {
        forward = envmis::normalize(at - from);
        const float half = std::tan(0.5f * vertical_fov_degrees * envmis::kPiF / 180);
        right = envmis::normalize(envmis::cross(forward, {0, 0, 1})) * (half * aspect);
        up = envmis::cross(envmis::normalize(right), forward) * half;
    }
    // The unit direction through image point (x, y).
    envmis::Vec3 direction(float x, float y) const {
        return envmis::normalize(forward + right * (2 * x - 1) + up * (1 - 2 * y));
    }
};

// A command-line mistake: reported with the usage text, exit status 2.
struct UsageError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// An integer from lo to hi, digits only; UsageError naming the flag otherwise.
inline uint64_t parse_number(std::string_view flag, const std::string& text, uint64_t lo, uint64_t hi) {
    size_t used = 0;
    uint64_t value = 0;
    try {
        value = std::stoull(text, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    // stoull skips leading spaces and takes a sign ("-1" wraps to 2^64 - 1): digits only.
    const bool digits = !text.empty() && text.find_first_not_of("0123456789") == std::string::npos;
    if (!digits || used != text.size() || value < lo || value > hi)
        throw UsageError(std::string(flag) + " '" + text + "': expected an integer from " + std::to_string(lo) +
                         " to " + std::to_string(hi));
    return value;
}

// An EXR as written: no colour conversion (the working space to itself).
inline envmis::RgbImage read_exr(const std::filesystem::path& path) {
    return envmis::io::load_image(path, {"lin_rec709", "lin_rec709"}).image;
}

// Mean over pixels of (Y - Y_ref)^2 / (Y_ref^2 + 0.01), Y the luminance: the usual
// relative MSE, whose 0.01 keeps nearly black pixels from dominating. It assumes a
// display-like scale (the scenes under the bundled maps have mean luminance 0.05-0.4).
// Throws std::runtime_error naming `name` where the sizes differ.
inline double relative_mse(const envmis::RgbImage& image, const envmis::RgbImage& reference, const std::string& name) {
    if (image.width != reference.width || image.height != reference.height)
        throw std::runtime_error(name + ": " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                                 ", the reference " + std::to_string(reference.width) + "x" +
                                 std::to_string(reference.height));
    double sum = 0;
    for (size_t i = 0; i < image.pixels.size(); ++i) {
        const double ref = envmis::luminance(reference.pixels[i], {});
        const double d = envmis::luminance(image.pixels[i], {}) - ref;
        sum += d * d / (ref * ref + 0.01);
    }
    return sum / static_cast<double>(image.pixels.size());
}

}  // namespace examples
