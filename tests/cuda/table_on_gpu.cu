// A loaded table sampled on the GPU, checked against the CPU: the map's arrays are
// uploaded as a renderer would (the view's pointers replaced by device ones; the coarse
// guide, which device code never reads, left out), a kernel draws one sample and looks up
// one direction per thread, and every result is compared with the same call on the host.
//
// Usage: envmis_cuda_table_check TABLE [N]. Exit 0 when every sample agrees, 1 when one
// does not, 77 when there is no CUDA device (ctest counts that as skipped).
// Agreement: the same texel (the radiance's bits) and the direction and pdf within a
// relative 1e-5 (nvcc contracts products into fused multiply-adds where g++ does not).
#include <cuda_runtime.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "envmis/math/random.h"
#include "envmis/sampling/envmap.h"
#include "envmis/table/table.h"

namespace {

struct Result {
    envmis::EnvSample sample;
    envmis::EnvMapView::Lookup lookup;
};

__global__ void sample_and_look_up(envmis::EnvMapView env, const envmis::Vec2* points, const envmis::Vec3* directions,
                                   Result* out, unsigned n) {
    const unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= n) return;
    out[i] = {env.sample(points[i]), env.lookup(directions[i])};
}

void check(cudaError_t e, const char* what) {
    if (e != cudaSuccess) throw std::runtime_error(std::string(what) + ": " + cudaGetErrorString(e));
}

// Device memory holding a copy of `n` host values; freed with the object.
template <class T>
struct DeviceArray {
    T* data = nullptr;
    DeviceArray(const T* host, size_t n) {
        check(cudaMalloc(&data, n * sizeof(T)), "cudaMalloc");
        if (host) check(cudaMemcpy(data, host, n * sizeof(T), cudaMemcpyHostToDevice), "cudaMemcpy");
    }
    ~DeviceArray() { cudaFree(data); }
    DeviceArray(const DeviceArray&) = delete;
    DeviceArray& operator=(const DeviceArray&) = delete;
};

// The map's arrays on the device and a view of them.
struct DeviceMap {
    const envmis::EnvMapView host;
    const size_t cells = size_t{host.distribution.w} * host.distribution.h;
    const std::vector<envmis::SinCos> turn_table = envmis::make_turn_table();
    DeviceArray<uint32_t> start{host.distribution.start, cells},
        marginal_start{host.distribution.marginal.start, host.distribution.marginal.n};
    DeviceArray<uint16_t> guide{host.distribution.guide, cells},
        marginal_guide{host.distribution.marginal.guide, host.distribution.marginal.n};
    DeviceArray<envmis::Rgb> radiance{host.radiance, cells};
    DeviceArray<envmis::SinCos> turns{turn_table.data(), turn_table.size()};

    envmis::EnvMapView view() const {
        envmis::EnvMapView v = host;
        v.distribution.start = start.data, v.distribution.guide = guide.data, v.distribution.coarse = nullptr;
        v.distribution.marginal.start = marginal_start.data, v.distribution.marginal.guide = marginal_guide.data;
        v.radiance = radiance.data, v.turns = turns.data;
        return v;
    }
};

bool close(float a, float b) { return std::abs(a - b) <= 1e-5f * std::max({1.0f, std::abs(a), std::abs(b)}); }
bool same(envmis::Rgb a, envmis::Rgb b) { return a.r == b.r && a.g == b.g && a.b == b.b; }

// Mismatches of the device's results against the host's, the first few printed.
size_t compare(const envmis::EnvMapView& env, const std::vector<envmis::Vec2>& points,
               const std::vector<envmis::Vec3>& directions, const std::vector<Result>& device) {
    size_t bad = 0;
    for (size_t i = 0; i < points.size(); ++i) {
        const envmis::EnvSample s = env.sample(points[i]);
        const envmis::EnvMapView::Lookup l = env.lookup(directions[i]);
        const Result& d = device[i];
        const bool ok = same(s.radiance, d.sample.radiance) && close(s.pdf, d.sample.pdf) &&
                        close(s.direction.x, d.sample.direction.x) && close(s.direction.y, d.sample.direction.y) &&
                        close(s.direction.z, d.sample.direction.z) && close(l.pdf, d.lookup.pdf) &&
                        same(l.radiance, d.lookup.radiance);
        if (!ok && bad++ < 5)
            std::printf("mismatch %zu: host pdf %g lookup %g, device pdf %g lookup %g\n", i, s.pdf, l.pdf, d.sample.pdf,
                        d.lookup.pdf);
    }
    return bad;
}

int run(const char* path, unsigned n) {
    int devices = 0;
    if (cudaGetDeviceCount(&devices) != cudaSuccess || devices == 0) {
        std::printf("no CUDA device: skipped\n");
        return 77;
    }
    const envmis::Table table = envmis::read_table(path);
    const envmis::EnvMapView env = table.map.view();
    std::vector<envmis::Vec2> points(n);
    std::vector<envmis::Vec3> directions(n);
    envmis::Pcg32 rng(7);
    for (unsigned i = 0; i < n; ++i) {
        points[i] = rng.uniform2();
        // Half the directions where the map samples (its own samples), half uniform.
        directions[i] =
            i % 2 ? env.sample(rng.uniform2()).direction
                  : envmis::normalize(envmis::Vec3{rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f});
    }
    const DeviceMap map{env};
    const DeviceArray<envmis::Vec2> d_points(points.data(), n);
    const DeviceArray<envmis::Vec3> d_directions(directions.data(), n);
    const DeviceArray<Result> d_out(nullptr, n);
    sample_and_look_up<<<(n + 127) / 128, 128>>>(map.view(), d_points.data, d_directions.data, d_out.data, n);
    check(cudaGetLastError(), "kernel launch");
    std::vector<Result> device(n);
    check(cudaMemcpy(device.data(), d_out.data, n * sizeof(Result), cudaMemcpyDeviceToHost), "cudaMemcpy back");
    const size_t bad = compare(env, points, directions, device);
    std::printf("%s: %u samples and lookups on the GPU, %zu differ from the CPU's\n", path, n, bad);
    return bad == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2 || argc > 3) {
        std::fprintf(stderr, "usage: envmis_cuda_table_check TABLE [N]\n");
        return 2;
    }
    try {
        return run(argv[1], argc > 2 ? static_cast<unsigned>(std::stoul(argv[2])) : 1u << 20);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "envmis_cuda_table_check: %s\n", e.what());
        return 1;
    }
}
