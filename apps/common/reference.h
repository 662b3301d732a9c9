// The plain reference that performance figures are measured against, and the
// synthetic map they are measured on.
//
// TextbookEnvMap is the classic pipeline written the obvious way: one serial pass for
// luminance and compensation, then the textbook float-CDF sampler (textbook.h). It
// samples the same density as EnvMap (up to float rounding), in either mapping, and
// returns the same EnvSample, so the two are timed doing identical work.
#pragma once

#include <cstdint>

#include "envmis/sampling/envmap.h"
#include "envmis/study/reference/textbook.h"

namespace envmis::reference {

class TextbookEnvMap {
public:
    // Expects clean pixels (no NaN, Inf or negative values). Reads the radiance from
    // `image`, which must outlive the map.
    TextbookEnvMap(const RgbImage& image, const EnvMapOptions& options);

    EnvSample sample(Vec2 u) const noexcept;
    float pdf(Vec3 direction) const noexcept;
    size_t distribution_bytes() const noexcept { return distribution_.bytes(); }

private:
    const RgbImage* image_;
    Axes axes_;
    Mapping mapping_;
    TextbookDistribution2D distribution_;
};

// What a synthetic sky holds besides its sun. `clear`: a gradient of height alone, so
// every equirect row but the sun's is constant, a sampler's easiest case (its cold rows'
// answers lie where the guide table points). `clouds`: the same gradient broken up by a
// smooth pattern of the direction (brightness 0.3x to 2x) that varies along every row
// in either mapping, as a real sky does.
enum class SkyDetail { clear, clouds };

// A w x h sky: blue, brighter towards the zenith, with a sun of ~0.5 degrees (radiance
// 1e5) at 45 degrees elevation: the shape of a typical outdoor map, 8192x4096 by default.
// Equal-area (a square w x w) for timing that mapping against equirect on the same sky.
RgbImage synthetic_sky(uint32_t w, uint32_t h, Mapping mapping = Mapping::equirect,
                       SkyDetail detail = SkyDetail::clear);

}  // namespace envmis::reference
