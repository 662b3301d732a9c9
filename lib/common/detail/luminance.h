// Private to envmis::core and envmis::build: the luminance that the density builds
// (envmap.cpp), the bins' histograms (binned.cpp) and the bins' choice (bins.cpp) take
// from a repaired pixel, one definition so that all read the same value from a texel.
#pragma once

#include <algorithm>
#include <limits>

#include "envmis/math/math.h"

namespace envmis::detail {

// Kept finite when the channels are near float's maximum.
inline float texel_luminance(const Rgb& p, const LumaCoefficients& k) noexcept {
    return std::min(luminance(p, k), std::numeric_limits<float>::max());
}

}  // namespace envmis::detail
