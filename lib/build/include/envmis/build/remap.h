// Conversion of an environment image from one mapping to another (mapping.h):
// equirectangular to equal-area octahedral (the square maps pbrt-v4's `imagemap`
// infinite light reads) and back.
//
// Power-conserving splatting: every input texel's power (radiance times its exact
// solid angle) is split over s x s sub-samples spread evenly over its solid angle, and
// each sub-sample's share goes to the four output texels around it with bilinear
// weights that sum to one, across the mapping's seams (equirect: wrap in u, over the
// poles; equal-area: the octahedral mirror at the square's edges). Output radiance is
// the power received over the solid angle received through the same weights, so a
// constant map stays constant (texels no sub-sample reaches, at an equirect output's
// poles, take the input's radiance at their centre); a final scale per channel (1 within a fraction of a
// percent) makes the total power equal the input's. A one-texel sun stays a compact
// blob of a few texels instead of being missed or aliased, and the tent filter smooths
// the sub-sample pattern. Sums in double.
//
// Cost: O(W H s^2) for a W x H input, serial; memory: 32 bytes per output texel.
#pragma once

#include <array>
#include <cstdint>

#include "envmis/build_export.h"
#include "envmis/image/image.h"
#include "envmis/image/mapping.h"
#include "envmis/interrupt.h"

namespace envmis {

// Exact solid angle of the texels of row y of a w x h image under mapping m.
ENVMIS_BUILD_API double texel_solid_angle(Mapping m, uint32_t y, uint32_t w, uint32_t h) noexcept;

// Total power of an image, sum of radiance times texel solid angle, per channel
// (NaN, infinite and negative values count as 0).
ENVMIS_BUILD_API std::array<double, 3> total_power(const RgbImage& image, Mapping m);

struct RemapResult {
    RgbImage image;
    BadPixels bad_pixels;        // input channel values replaced by 0
    uint32_t supersampling = 0;  // s: s x s sub-samples per input texel
};

// Converts `in` (mapping `from`) into a width x height image under mapping `to`.
// supersampling = 0 picks s so that output texels of average size receive at least 16
// sub-samples where the input texels are largest (s from 2 to 16). Throws std::invalid_argument for an empty or
// inconsistent image, a zero or too large output size, or a non-square equal-area size;
// Interrupted once `stop` is set (interrupt.h; checked every input row).
ENVMIS_BUILD_API RemapResult remap(const RgbImage& in, Mapping from, Mapping to, uint32_t width, uint32_t height,
                                   uint32_t supersampling = 0, StopFlag stop = nullptr);

}  // namespace envmis
