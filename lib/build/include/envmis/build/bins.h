// The build of a normal-aware map (envmis/sampling/binned.h): the layout of its bins,
// each bin's threshold (the compensation's alpha over the bin's hemisphere mean) chosen
// by the exact variance of balance MIS at normals spread over the bin, and the map built
// from it. What a renderer loads (a table's layout) the runtime rebuilds alone:
// BinnedEnvMap(plain, layout).
//
// The choice, per bin of each lobe class: a grid of nodes (cells cut finer, up to twice
// as finely for the glossy classes, the brightest texels apart) stands for the map; for
// each candidate alpha the bin's cell masses give a density, and the variance of one
// environment plus one BSDF sample, balance heuristic, a Phong lobe of the class's
// exponent, is summed exactly over the nodes at 9 normals of the bin (for a glossy class
// also that of a GGX lobe of the roughness the class takes at the bin's centre, whose
// tails a Phong lobe lacks: each candidate scores the worse of the two); a candidate wins
// where it lowers the geometric mean of the ratio to the plain density's by more than
// options.cost (BinnedOptions), else the bin stays plain.
//
// Cost: three passes over the texels per node grid (its sums and the brightest texels),
// then O(bins x candidates x normals x nodes); parallel over bins (detail/parallel.h),
// deterministic for any number of threads.
#pragma once

#include "envmis/build_export.h"
#include "envmis/interrupt.h"
#include "envmis/sampling/binned.h"

namespace envmis {

// The layout build_bins builds over `plain`: its grids, classes and every bin's choice.
// Throws std::invalid_argument for a compensated map or invalid options; throws
// Interrupted once `stop` is set (interrupt.h).
ENVMIS_BUILD_API BinLayout choose_bin_layout(const EnvMap& plain, const BinnedOptions& options = {},
                                             StopFlag stop = nullptr);

// The bins over `plain`, which must be uncompensated (its density is the texel level of
// every bin), as `options` ask; choice_seconds() reports the choice's time.
ENVMIS_BUILD_API BinnedEnvMap build_bins(EnvMap plain, const BinnedOptions& options = {}, StopFlag stop = nullptr);

}  // namespace envmis
