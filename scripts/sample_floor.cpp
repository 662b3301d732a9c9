// Single samples timed against a reference sampler in one process, built by
// scripts/sample_floor.sh against the library's headers as they are and against copies
// with parts of the sample taken out, to show what the rest costs on the CPU at hand.
//
//   sample_floor [--no-compensate]               the 8k sky's guided sampler against the
//       textbook sampler as envmis bench times them (`speedup_vs_textbook sample`): each
//       over 2^20 points in a row, the two in turns, textbook ns / guided ns
//   sample_floor [--no-compensate] --equal-area  the sky as a 5792^2 equal-area map against
//       the 8192 x 4096 equirect one (0.02% fewer texels) as the Google Benchmark case
//       `sample/equal-area-over-equirect` times them: in turns over blocks of 1024 points,
//       equal-area ns / equirect ns
//
// Prints both samplers' ns a sample (free-running, as in a renderer's loop of calls) and
// the median of the ratios of 7 rounds; within a round the two samplers take turns, and
// which goes first alternates, so that a drifting machine speed does not bias the ratio.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <random>
#include <vector>

#include "reference.h"

using namespace envmis;

namespace {

// Sums every output a sample returns, as envmis bench does, so that none is dropped.
template <class Sampler>
__attribute__((noinline)) float sample_block(const Sampler& s, const Vec2* u, size_t n) {
    float sum = 0;
    for (size_t i = 0; i < n; ++i) {
        const EnvSample e = s.sample(u[i]);
        sum += e.direction.x + e.direction.y + e.direction.z + e.pdf + e.radiance.r + e.radiance.g + e.radiance.b;
    }
    return sum;
}

template <class Sampler>
double time_block(const Sampler& s, const Vec2* u, size_t n, volatile float& sink) {
    const auto t0 = std::chrono::steady_clock::now();
    sink = sink + sample_block(s, u, n);
    return std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count();
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

// The two samplers' ns a sample, a and b in turns over blocks of `block` points (of
// 2^20), and the median ratio b / a per round.
template <class A, class B>
void compare(const char* a_name, const A& a, const char* b_name, const B& b, size_t block) {
    constexpr size_t kPoints = size_t{1} << 20;
    constexpr int kRounds = 7;
    std::mt19937_64 rng(7);
    auto uniform = [&] { return static_cast<float>(rng() >> 40) * 0x1p-24f; };
    std::vector<Vec2> points(kPoints);
    for (Vec2& u : points) u = {uniform(), uniform()};

    volatile float sink = 0;
    std::vector<double> a_ns, b_ns, ratios;
    for (int round = 0; round < kRounds; ++round) {
        double t[2] = {0, 0};
        for (size_t first = 0; first < kPoints; first += block) {
            const bool a_first = (round + first / block) % 2 == 0;
            for (int turn = 0; turn < 2; ++turn) {
                const bool b_turn = (turn == 0) != a_first;
                t[b_turn] += b_turn ? time_block(b, points.data() + first, block, sink)
                                    : time_block(a, points.data() + first, block, sink);
            }
        }
        a_ns.push_back(t[0] / kPoints);
        b_ns.push_back(t[1] / kPoints);
        ratios.push_back(t[1] / t[0]);
    }
    std::printf("%s_ns=%.1f %s_ns=%.1f ratio=%.2f\n", a_name, median(a_ns), b_name, median(b_ns), median(ratios));
}

}  // namespace

int main(int argc, char** argv) {
    EnvMapOptions options;
    bool equal_area = false;
    for (int i = 1; i < argc; ++i) {
        if (std::strcmp(argv[i], "--no-compensate") == 0)
            options.compensation.enabled = false;
        else if (std::strcmp(argv[i], "--equal-area") == 0)
            equal_area = true;
        else {
            std::fprintf(stderr, "sample_floor: unknown argument %s\n", argv[i]);
            return 2;
        }
    }
    std::printf("compensated=%d ", options.compensation.enabled ? 1 : 0);
    const RgbImage sky = reference::synthetic_sky(8192, 4096);
    const EnvMap equirect(sky, options);
    if (!equal_area) {
        const reference::TextbookEnvMap textbook(sky, options);
        compare("guided", equirect.view(), "textbook", textbook, size_t{1} << 20);
        return 0;
    }
    EnvMapOptions square = options;
    square.mapping = Mapping::equal_area;
    const EnvMap equal_area_map(reference::synthetic_sky(5792, 5792, Mapping::equal_area), square);
    compare("equirect", equirect.view(), "equal_area", equal_area_map.view(), 1024);
}
