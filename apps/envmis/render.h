// Pictures for `envmis compare --images`: a row of spheres, one per BSDF, lit by the
// map, rendered with each technique at equal sample count next to a reference, with
// per-pixel relative squared error maps and one labelled montage.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <string>

#include "envmis/study/comparison/comparison.h"

namespace envmis::cli {

// The rendered image's sides: wide enough for the spheres, small enough to render.
constexpr uint32_t kMinImageSide = 16, kMaxImageSide = 8192;

struct RenderOptions {
    std::string size = "768x256";  // WxH, each side kMinImageSide to kMaxImageSide
    uint32_t spp = 16;             // estimates per pixel for each technique
    uint32_t reference_spp = 512;  // estimates per pixel of the reference (mis-power)
};

// Renders every technique of inputs.options, every sphere sampling the first map of
// inputs.compensated (inputs.points are not used: the pixels are the points), and writes
// reference.{exr,png}, <technique>.{exr,png}, <technique>-relmse.png, montage.png and
// montage.json (where each cell lies, and each sphere's relMSE) into
// `folder` (created if missing). At control.stop (checked every pixel) it throws
// Interrupted: the pictures written by then are whole, the one under way and the
// montage are not written. Returns the montage's path. Cost: pixels x (spp x techniques + reference_spp)
// estimates.
std::filesystem::path render_comparison(const StudyInputs& inputs, const RenderOptions& render,
                                        const std::filesystem::path& folder, const std::string& map_name,
                                        const RunControl& control);

}  // namespace envmis::cli
