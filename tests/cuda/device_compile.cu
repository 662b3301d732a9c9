// Compile-only check that the runtime sampling path builds as CUDA device code: the
// table-backed env-map view (sample, pdf, eval, lookup), the binned view (binned.h), the
// 1D/2D distribution views, the BSDFs, the shading frame and the random number
// generator, all from the same headers the CPU tests use. Built by tests/cuda/cuda.cmake when nvcc is present; it
// need not run.
#include "envmis/math/random.h"
#include "envmis/sampling/binned.h"
#include "envmis/sampling/distribution.h"
#include "envmis/sampling/envmap.h"
#include "envmis/study/shading/bsdf.h"
#include "envmis/study/shading/frame.h"
#include "envmis/study/weights/mis_weights.h"

namespace {

__device__ envmis::Rgb add_scaled(envmis::Rgb sum, envmis::Rgb f, envmis::Rgb l, float s) {
    return {sum.r + f.r * l.r * s, sum.g + f.g * l.g * s, sum.b + f.b * l.b * s};
}

// One MIS estimate of direct lighting per thread: one environment sample, one BSDF
// sample, balance heuristic; the renderer's inner loop, written against the views only.
__global__ void direct_lighting(envmis::EnvMapView env, envmis::Bsdf bsdf, const envmis::Vec3* normals,
                                envmis::Rgb* out, unsigned n, unsigned long long seed) {
    const unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= n) return;
    envmis::Pcg32 rng(seed, i);
    const envmis::Frame frame = envmis::Frame::from_normal(normals[i]);
    const envmis::Vec3 wo{0, 0, 1};
    envmis::Rgb sum{};

    const envmis::EnvSample light = env.sample({rng.uniform(), rng.uniform()});
    const envmis::Vec3 wi_light = frame.to_local(light.direction);
    const float bsdf_pdf_light = bsdf.pdf(wo, wi_light);
    if (light.pdf > 0) {
        const float q[2] = {light.pdf, bsdf_pdf_light};
        sum = add_scaled(sum, bsdf.eval(wo, wi_light), light.radiance, envmis::balance_weight(q, 2, 0) / light.pdf);
    }

    const envmis::BsdfSample s = bsdf.sample(wo, {rng.uniform(), rng.uniform()});
    if (s.pdf > 0) {
        const envmis::EnvMapView::Lookup hit = env.lookup(frame.to_world(s.wi));
        const float q[2] = {hit.pdf, s.pdf};
        sum = add_scaled(sum, s.value, hit.radiance, envmis::balance_weight(q, 2, 1) / s.pdf);
    }
    out[i] = add_scaled(sum, env.eval(normals[i]), {1, 1, 1}, env.pdf(normals[i]));
}

// The distribution views on their own, as a renderer sampling its own tables would.
__global__ void distributions(envmis::Distribution2DView d2, envmis::Distribution1DView d1, float* out) {
    const unsigned i = threadIdx.x;
    const auto s = d2.sample({0.25f, 0.5f + 0.001f * i});
    const auto t = d1.sample(0.5f);
    out[i] = s.pdf + d2.pdf(s.p) + d2.invert(s.p).x + t.pdf + d1.pdf(t.x) + d1.invert(t.x);
}

// The normal-aware bins: a bin per thread's normal and lobe class, sampled and looked up.
__global__ void binned(envmis::BinnedEnvMapView env, const envmis::Vec3* normals, float* out, unsigned n) {
    const unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= n) return;
    const envmis::LobeAxis axis = envmis::lobe_axis(i % env.classes, normals[i], normals[i]);
    const envmis::BinView bin = env.bin(axis, i % env.classes, 0.001f * (i % 1000));
    const envmis::EnvSample s = bin.sample({0.5f, 0.25f});
    const envmis::EnvMapView::Lookup l = bin.lookup(s.direction);
    out[i] = s.pdf + l.pdf + l.radiance.r + bin.pdf(normals[i]) + bin.eval(normals[i]).g;
}

}  // namespace

// Host entry points so the kernels are instantiated and launched from host code.
void launch_direct_lighting(const envmis::EnvMapView& env, const envmis::Bsdf& bsdf, const envmis::Vec3* normals,
                            envmis::Rgb* out, unsigned n) {
    direct_lighting<<<(n + 127) / 128, 128>>>(env, bsdf, normals, out, n, 1);
}

void launch_distributions(const envmis::Distribution2DView& d2, const envmis::Distribution1DView& d1, float* out) {
    distributions<<<1, 32>>>(d2, d1, out);
}

void launch_binned(const envmis::BinnedEnvMapView& env, const envmis::Vec3* normals, float* out, unsigned n) {
    binned<<<(n + 127) / 128, 128>>>(env, normals, out, n);
}
