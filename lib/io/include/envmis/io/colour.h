// Colour spaces, through OpenColorIO.
//
// The config is $OCIO when set, else the one shipped in data/ocio/config.ocio (found in
// the source tree or the install prefix). The shipped config defines, among others:
//   lin_rec709 (scene_linear, the default working space), ACEScg, ACES2065-1, sRGB
//   (sRGB-encoded Rec.709), CIE-XYZ-D65, raw.
// Luma coefficients: for the config's scene_linear space, the config's declared `luma`
// (for lin_rec709 exactly BT.709's 0.2126, 0.7152, 0.0722); for other spaces the Y row
// of their RGB -> CIE XYZ matrix, found by converting the three primaries with OCIO (for
// ACEScg about 0.2677, 0.6743, 0.0580: luminance as seen under D65, the same in either
// working space); a config without an XYZ space uses its declared `luma` throughout.
#pragma once

#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "envmis/image/image.h"
#include "envmis/math/math.h"

namespace envmis::io {

class ColourConfig {
public:
    // $OCIO if set, else the shipped config. Throws ImageError if it cannot be loaded.
    ColourConfig();
    explicit ColourConfig(const std::filesystem::path& config_file);
    ~ColourConfig();
    ColourConfig(ColourConfig&&) noexcept;
    ColourConfig& operator=(ColourConfig&&) noexcept;

    std::string description() const;          // where the config came from
    std::vector<std::string> spaces() const;  // names of its colour spaces
    bool has_space(const std::string& name) const;
    // The canonical name for a file's colour-space metadata ("Linear", "scene_linear",
    // "sRGB", "lin_srgb", ...); empty if the config has no match.
    std::string resolve(const std::string& name) const;
    LumaCoefficients luma(const std::string& space) const;
    // Converts pixels in place. Throws ImageError naming an unknown space.
    void convert(std::span<Rgb> pixels, const std::string& from, const std::string& to) const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace envmis::io
