// Internal: the software pipeline of the scalar batch paths (envmap_many.cpp, binned_many.cpp).
// A lane's first stage finds what it will read and prefetches it; its last stage runs a
// fixed number of lanes later, so that that many lanes' cache misses are in flight at
// once. The stages are the single calls' own functions, so the results stay
// bit-identical to them.
#pragma once

#include <algorithm>
#include <cstdint>

#include "envmis/sampling/envmap.h"

namespace envmis::detail {

// Lanes first..n of a two-stage pipeline: start(l) for lane l (it returns what finish
// needs), finish(started, l) kDistance lanes later.
template <uint32_t kDistance, class Start, class Finish>
void pipelined(uint32_t first, uint32_t n, Start&& start, Finish&& finish) noexcept {
    static_assert((kDistance & (kDistance - 1)) == 0);
    decltype(start(first)) started[kDistance];
    const uint32_t primed = std::min(n - first, kDistance);
    for (uint32_t k = 0; k < primed; ++k) started[k] = start(first + k);
    for (uint32_t l = first, slot = 0; l < n; ++l, slot = (slot + 1) & (kDistance - 1)) {
        const auto s = started[slot];
        if (l + kDistance < n) started[slot] = start(l + kDistance);
        finish(s, l);
    }
}

// A sample's outputs in lane l (the image point's where asked for).
inline void store_sample(SampleArrays out, uint32_t l, const EnvSample& e) noexcept {
    out.x[l] = e.direction.x, out.y[l] = e.direction.y, out.z[l] = e.direction.z, out.pdf[l] = e.pdf;
    out.r[l] = e.radiance.r, out.g[l] = e.radiance.g, out.b[l] = e.radiance.b;
    if (out.u) out.u[l] = e.uv.x;
    if (out.v) out.v[l] = e.uv.y;
}

}  // namespace envmis::detail
