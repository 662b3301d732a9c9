// Compiled to assembly by prefetch_kept.sh (not linked): each function below does
// nothing but prefetch, as a renderer's code that calls envmis's prefetches ahead of its
// lookups does. Each must still contain a prefetch instruction once optimised (see
// envmis::prefetch in envmis/math/math.h for how GCC deleted them).
#include "envmis/sampling/binned.h"
#include "envmis/sampling/envmap.h"

extern "C" {
void envmis_prefetch_uv(const envmis::EnvMapView& view, envmis::Vec2 uv) { view.prefetch_uv(uv); }
void envmis_prefetch_texel(const envmis::EnvMapView& view, size_t texel) { view.prefetch_texel(texel); }
void envmis_prefetch_unit(const envmis::CdfView& cdf, uint32_t t) { cdf.prefetch_unit(t, envmis::NoHint{}); }
void envmis_prefetch_texels(const envmis::BinnedEnvMapView& map, const envmis::BinView::Cell& cell, float uy) {
    envmis::prefetch_texels(map, cell, uy);
}
}
