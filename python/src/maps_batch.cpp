#include "maps_batch.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <vector>

namespace envmis::python {
namespace {

// The columns of rows first .. first + m of an interleaved n x k array.
template <size_t K>
void deinterleave(const float* in, size_t first, uint32_t m, float (*out)[kChunk]) noexcept {
    const float* row = in + first * K;
    for (uint32_t i = 0; i < m; ++i, row += K)
        for (size_t k = 0; k < K; ++k) out[k][i] = row[k];
}

template <size_t K>
void interleave(float (*in)[kChunk], uint32_t m, float* out, size_t first) noexcept {
    float* row = out + first * K;
    for (uint32_t i = 0; i < m; ++i, row += K)
        for (size_t k = 0; k < K; ++k) row[k] = in[k][i];
}

// A direction (or normal) that names one: finite and not zero. Others give NaN results:
// NaN in, NaN out, where the core maps them to some texel.
bool names_a_direction(const float (*d)[kChunk], uint32_t i) noexcept {
    return std::isfinite(d[0][i]) && std::isfinite(d[1][i]) && std::isfinite(d[2][i]) &&
           (d[0][i] != 0 || d[1][i] != 0 || d[2][i] != 0);
}
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// Runs `batch(points, normals, outputs, m, first)` chunk by chunk over n points with the
// chunk's inputs deinterleaved (normals only when given) and stores its outputs.
template <class Batch>
void sample_chunks(const float* u, const float* normals, InterleavedSamples out, size_t n, Batch&& batch) noexcept {
    alignas(32) float points[2][kChunk], normal[3][kChunk], direction[3][kChunk], radiance[3][kChunk], uv[2][kChunk];
    for (size_t first = 0; first < n; first += kChunk) {
        const auto m = static_cast<uint32_t>(std::min<size_t>(kChunk, n - first));
        deinterleave<2>(u, first, m, points);
        if (normals) deinterleave<3>(normals, first, m, normal);
        batch({points[0], points[1]}, DirectionArrays{normal[0], normal[1], normal[2]},
              SampleArrays{direction[0], direction[1], direction[2], out.pdf + first, radiance[0], radiance[1],
                           radiance[2], uv[0], uv[1]},
              m, first);
        if (normals)
            for (uint32_t i = 0; i < m; ++i)
                if (!names_a_direction(normal, i)) {
                    for (auto* c : {direction, radiance}) c[0][i] = c[1][i] = c[2][i] = kNaN;
                    uv[0][i] = uv[1][i] = out.pdf[first + i] = kNaN;
                }
        interleave<3>(direction, m, out.direction, first);
        interleave<3>(radiance, m, out.radiance, first);
        interleave<2>(uv, m, out.uv, first);
    }
}

template <class Batch>
void lookup_chunks(const float* directions, const float* normals, InterleavedLookups out, size_t n,
                   Batch&& batch) noexcept {
    alignas(32) float direction[3][kChunk], normal[3][kChunk], radiance[3][kChunk], pdf[kChunk];
    for (size_t first = 0; first < n; first += kChunk) {
        const auto m = static_cast<uint32_t>(std::min<size_t>(kChunk, n - first));
        deinterleave<3>(directions, first, m, direction);
        if (normals) deinterleave<3>(normals, first, m, normal);
        batch(DirectionArrays{direction[0], direction[1], direction[2]},
              DirectionArrays{normal[0], normal[1], normal[2]},
              LookupArrays{radiance[0], radiance[1], radiance[2], out.pdf ? out.pdf + first : pdf}, m, first);
        for (uint32_t i = 0; i < m; ++i)
            if (!names_a_direction(direction, i) || (normals && !names_a_direction(normal, i))) {
                radiance[0][i] = radiance[1][i] = radiance[2][i] = kNaN;
                if (out.pdf) out.pdf[first + i] = kNaN;
            }
        if (out.radiance) interleave<3>(radiance, m, out.radiance, first);
    }
}

}  // namespace

void sample(const EnvMapView& env, const float* u, InterleavedSamples out, size_t n) noexcept {
    sample_chunks(u, nullptr, out, n, [&](PointArrays in, DirectionArrays, SampleArrays o, uint32_t m, size_t) {
        sample_many(env, in, o, m);
    });
}

void sample(const BinnedEnvMapView& env, uint32_t lobe, const float* normals, const float* view_cos,
            const float* choices, const float* u, InterleavedSamples out, size_t n) noexcept {
    sample_chunks(
        u, normals, out, n, [&](PointArrays in, DirectionArrays normal, SampleArrays o, uint32_t m, size_t first) {
            sample_many(env, lobe, {normal.x, normal.y, normal.z, view_cos + first}, choices + first, in, o, m);
        });
}

void lookup(const EnvMapView& env, const float* directions, InterleavedLookups out, size_t n) noexcept {
    lookup_chunks(directions, nullptr, out, n,
                  [&](DirectionArrays in, DirectionArrays, LookupArrays o, uint32_t m, size_t) {
                      if (out.pdf || env.distribution.start) return lookup_many(env, in, o, m);
                      // Radiance alone from a binned map's radiance map: no distribution to read.
                      for (uint32_t i = 0; i < m; ++i) {
                          const Rgb c = env.eval({in.x[i], in.y[i], in.z[i]});
                          o.r[i] = c.r, o.g[i] = c.g, o.b[i] = c.b;
                      }
                  });
}

void lookup(const BinnedEnvMapView& env, uint32_t lobe, const float* normals, const float* view_cos,
            const float* choices, const float* directions, InterleavedLookups out, size_t n) noexcept {
    lookup_chunks(
        directions, normals, out, n,
        [&](DirectionArrays in, DirectionArrays normal, LookupArrays o, uint32_t m, size_t first) {
            lookup_many(env, lobe, {normal.x, normal.y, normal.z, view_cos + first}, choices + first, in, o, m);
        });
}

double time_sample_many(const EnvMapView& env, const float* u, size_t n, int repeats, bool fresh_outputs) {
    std::vector<float> ux(n), uy(n);
    for (size_t i = 0; i < n; ++i) ux[i] = u[2 * i], uy[i] = u[2 * i + 1];
    // Reused outputs are touched once here, as an `out=` array has been by its first call;
    // fresh ones are allocated inside the timed region and never initialised, so their
    // page faults count, as a new NumPy array's do.
    std::vector<std::vector<float>> reused(fresh_outputs ? 0 : 9, std::vector<float>(n));
    std::vector<double> seconds;
    for (int r = 0; r < repeats; ++r) {
        const auto start = std::chrono::steady_clock::now();
        std::vector<std::unique_ptr<float[]>> fresh;
        float* o[9];
        for (int k = 0; k < 9; ++k) {
            if (fresh_outputs) fresh.emplace_back(new float[n]);
            o[k] = fresh_outputs ? fresh.back().get() : reused[k].data();
        }
        // The core's call takes at most 2^32 - 1 points.
        for (size_t first = 0; first < n; first += UINT32_MAX) {
            const auto m = static_cast<uint32_t>(std::min<size_t>(UINT32_MAX, n - first));
            sample_many(env, {ux.data() + first, uy.data() + first},
                        {o[0] + first, o[1] + first, o[2] + first, o[3] + first, o[4] + first, o[5] + first,
                         o[6] + first, o[7] + first, o[8] + first},
                        m);
        }
        seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    std::nth_element(seconds.begin(), seconds.begin() + seconds.size() / 2, seconds.end());
    return seconds[seconds.size() / 2];
}

}  // namespace envmis::python
