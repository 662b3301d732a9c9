// Single samples of the 8k sky against the textbook sampler's, in one process: the
// measure of `envmis bench`'s `speedup_vs_textbook sample`, built by
// scripts/sample_floor.sh against the library's headers as they are and against copies
// with parts of the sample taken out, to show what the rest costs on the CPU at hand.
//
// Usage: sample_floor [--no-compensate]. Prints the guided and the textbook sampler's
// ns a sample (free-running, as in a renderer's loop of calls) and their ratio, the
// median of the ratios of 7 rounds; in each round the two samplers take turns over
// blocks of 4096 points, so that a drifting machine speed does not bias the ratio.
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

}  // namespace

int main(int argc, char** argv) {
    EnvMapOptions options;
    options.compensation.enabled = !(argc > 1 && std::strcmp(argv[1], "--no-compensate") == 0);
    const RgbImage sky = reference::synthetic_sky(8192, 4096);
    const EnvMap guided(sky, options);
    const reference::TextbookEnvMap textbook(sky, options);

    constexpr size_t kPoints = size_t{1} << 19, kBlock = 4096;
    constexpr int kRounds = 7;
    std::mt19937_64 rng(7);
    auto uniform = [&] { return static_cast<float>(rng() >> 40) * 0x1p-24f; };
    std::vector<Vec2> points(kPoints);
    for (Vec2& u : points) u = {uniform(), uniform()};

    const EnvMapView view = guided.view();
    volatile float sink = 0;
    std::vector<double> guided_ns, textbook_ns, ratios;
    for (int round = 0; round < kRounds; ++round) {
        double t[2] = {0, 0};
        for (size_t b = 0; b < kPoints; b += kBlock) {
            const bool guided_first = (b / kBlock) % 2 == 0;
            for (int turn = 0; turn < 2; ++turn) {
                const bool textbook_turn = (turn == 0) != guided_first;
                t[textbook_turn] += textbook_turn ? time_block(textbook, points.data() + b, kBlock, sink)
                                                  : time_block(view, points.data() + b, kBlock, sink);
            }
        }
        guided_ns.push_back(t[0] / kPoints);
        textbook_ns.push_back(t[1] / kPoints);
        ratios.push_back(t[1] / t[0]);
    }
    std::printf("compensated=%d guided_ns=%.1f textbook_ns=%.1f ratio=%.2f\n", options.compensation.enabled ? 1 : 0,
                median(guided_ns), median(textbook_ns), median(ratios));
}
