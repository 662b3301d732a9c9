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
    // Expects clean pixels (no NaN, Inf or negative values).
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

// A w x h sky: blue, brighter towards the zenith, with a sun of ~0.5 degrees (radiance
// 1e5) at 45 degrees elevation: the shape of a typical outdoor map, 8192x4096 by default.
// Equal-area (a square w x w) for timing that mapping against equirect on the same sky.
RgbImage synthetic_sky(uint32_t w, uint32_t h, Mapping mapping = Mapping::equirect);

}  // namespace envmis::reference
