// Pictures for `envmis compare --images`: a row of spheres, one per BSDF, lit by the
// map, rendered with each technique at equal sample count next to a reference, with
// per-pixel relative squared error maps and one labelled montage.
#pragma once

#include <atomic>
#include <filesystem>
#include <string>

#include "envmis/study/comparison/comparison.h"

namespace envmis::cli {

struct RenderOptions {
    std::string size = "768x256";  // WxH
    uint32_t spp = 16;             // estimates per pixel for each technique
    uint32_t reference_spp = 512;  // estimates per pixel of the reference (mis-power)
};

// Writes reference.{exr,png}, <technique>.{exr,png}, <technique>-relmse.png and
// montage.png into `folder` (created if missing). Returns the montage's path.
std::filesystem::path render_comparison(const EnvMap& plain, const EnvMap& compensated,
                                        const ComparisonOptions& options, const RenderOptions& render,
                                        const std::filesystem::path& folder, const std::string& map_name,
                                        const std::atomic<bool>* stop);

}  // namespace envmis::cli
