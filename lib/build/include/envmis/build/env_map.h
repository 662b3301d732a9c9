// The build of an environment map (envmis/sampling/envmap.h) from a radiance image: the
// luminance of every texel, the map's statistics, the density q w_y (optionally
// compensated) and its distribution, in two passes over the image. What a renderer loads
// (a table file) the runtime rebuilds alone, from the density the table holds.
//
// Numbers: luminance and density in float, row sums and the mean in double. Cost: two
// passes over the texels, parallel over rows (detail/parallel.h), the second reading 4
// bytes a texel instead of the 12 of RGB; deterministic for any number of threads.
#pragma once

#include "envmis/build_export.h"
#include "envmis/image/image.h"
#include "envmis/interrupt.h"
#include "envmis/sampling/envmap.h"

namespace envmis {

// The sampler of a radiance image, bad pixels repaired (counted in stats().bad_pixels).
// A black map is sampled uniformly; one that compensation zeroes whole (a constant map)
// is built uncompensated (stats().fallback). Throws std::invalid_argument for an empty
// image, a pixel count that does not match the size, more than 2^31 texels, invalid
// options, or finite pixels whose power overflows float (4 pi Lbar above 3.4e38:
// "luminance overflows", with the factor to scale the map by), which would make every
// estimate Inf or NaN; throws Interrupted once `stop` is set (interrupt.h; checked every
// block of rows).
ENVMIS_BUILD_API EnvMap build_env_map(RgbImage image, const EnvMapOptions& options = {}, StopFlag stop = nullptr);

}  // namespace envmis
