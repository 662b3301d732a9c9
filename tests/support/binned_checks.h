// Test support for the binned sampler (binned.h): its maps, test normals, texel
// probabilities, and the goodness-of-fit and coverage checks that the synthetic and the
// real-map tests share.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>
#include <vector>

#include "envmis/build/env_map.h"
#include "envmis/sampling/binned.h"
#include "stats.h"

namespace envmis::test {

// The family of chi-square tests these checks make, across the binned test files.
inline const double kBinnedLevel = sidak_level(0.01, 300);

inline EnvMap plain_map(RgbImage image, Mapping mapping = Mapping::equirect) {
    EnvMapOptions o;
    o.compensation.enabled = false;
    o.mapping = mapping;
    return build_env_map(std::move(image), o);
}

// Normals that test the bins: two bin centres, points just either side of a bin border
// (on both octahedral hemispheres) and both poles.
inline std::vector<Vec3> test_normals(uint32_t g) {
    const float edge = 3.0f / g, nudge = 1e-4f;
    return {octahedral_normal(0.5f / g, 0.5f / g),
            octahedral_normal(4.5f / g, 5.5f / g),
            octahedral_normal(edge - nudge, 0.41f),
            octahedral_normal(edge + nudge, 0.41f),
            octahedral_normal(0.2f, edge - nudge),
            octahedral_normal(0.2f, edge + nudge),
            Vec3{0, 0, 1},
            Vec3{0, 0, -1},
            normalize(Vec3{0.3f, -0.5f, -0.8f})};
}

// Texel probabilities of a bin, from pdf_uv at texel centres: the image density is
// constant over a texel, and pdf_uv turns it into solid angle with the sine at uv.
template <class View>
std::vector<double> texel_probabilities(const View& bin, const EnvMap& plain) {
    const uint32_t w = plain.width(), h = plain.height();
    std::vector<double> p(size_t{w} * h);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            const Vec2 uv{(x + 0.5f) / w, (y + 0.5f) / h};
            const double jacobian = plain.options().mapping == Mapping::equal_area
                                        ? 4 * kPi
                                        : 2 * kPi * kPi * sincos_half_turns(plain.view().turns, uv.y).sin;
            p[size_t{y} * w + x] = bin.pdf_uv(uv) * jacobian / (static_cast<double>(w) * h);
        }
    return p;
}

// The bins a lobe axis's blend picks with positive weight (as its view sees them), and
// their weights.
struct PickedBin {
    BinView bin;
    float weight;
};
inline std::vector<PickedBin> picked_bins(const BinnedEnvMapView& view, LobeAxis at, uint32_t lobe) {
    const BinBlend blend = view.blend(at, lobe);
    std::vector<PickedBin> bins;
    for (int k = 0; k < 4; ++k)
        if (blend.weight[k] > 0) bins.push_back({view.bin_at(blend.bin[k], blend.view_cos), blend.weight[k]});
    return bins;
}

// Chi-square of n samples (`draw` returns one) over the texels against probabilities p.
template <class Draw>
void expect_texels_follow(const std::vector<double>& p, const EnvMap& plain, size_t n, Draw&& draw,
                          const std::string& what) {
    std::vector<double> expected(p.size()), observed(p.size());
    for (size_t i = 0; i < p.size(); ++i) expected[i] = p[i] * n;
    const uint32_t w = plain.width(), h = plain.height();
    for (size_t i = 0; i < n; ++i) {
        const EnvSample s = draw();
        observed[size_t{detail::cell_of(s.uv.y, h)} * w + detail::cell_of(s.uv.x, w)] += 1;
    }
    const auto chi = chi_square(expected, observed);
    EXPECT_GT(chi.p_value, kBinnedLevel) << what << ": " << chi.describe();
}

// Every bin the normal may pick: samples follow its pdf (chi-square), which integrates
// to 1 and is what the sample returns; and samples with random picks follow the blend's
// mixture of those pdfs (the picks' weights).
inline void expect_samples_follow_pdf(const BinnedEnvMap& binned, LobeAxis at, uint32_t lobe, uint64_t seed) {
    const BinnedEnvMapView view = binned.view();
    const std::string what = "axis " + std::to_string(at.axis.x) + "," + std::to_string(at.axis.y) + "," +
                             std::to_string(at.axis.z) + " view cosine " + std::to_string(at.view_cos) + " lobe " +
                             std::to_string(lobe);
    Rng rng(seed);
    const std::vector<PickedBin> picks = picked_bins(view, at, lobe);
    std::vector<double> mixture;
    for (const PickedBin& pick : picks) {
        const std::vector<double> p = texel_probabilities(pick.bin, binned.radiance_map());
        EXPECT_NEAR(std::accumulate(p.begin(), p.end(), 0.0), 1.0, 1e-4);
        mixture.resize(p.size());
        for (size_t i = 0; i < p.size(); ++i) mixture[i] += pick.weight * p[i];
        const size_t n = std::max<size_t>(100000, 20 * p.size());
        expect_texels_follow(
            p, binned.radiance_map(), n,
            [&] {
                const EnvSample s = pick.bin.sample(rng.uniform2());
                EXPECT_EQ(s.pdf, pick.bin.pdf_uv(s.uv));
                return s;
            },
            what);
    }
    if (picks.size() < 2) return;
    expect_texels_follow(
        mixture, binned.radiance_map(), std::max<size_t>(100000, 20 * mixture.size()),
        [&] {
            const float choice = rng.uniform();
            const EnvSample s = view.sample(at, lobe, choice, rng.uniform2());
            EXPECT_EQ(s.pdf, view.bin(at, lobe, choice).pdf_uv(s.uv));
            return s;
        },
        what + " (random picks)");
}

// Coverage: pdf > 0 at every texel centre above the normal's horizon whose luminance is
// above its bin's threshold (everywhere with light for an uncompensated bin).
inline void expect_coverage(const BinnedEnvMap& map, uint32_t lobe) {
    const BinnedEnvMapView view = map.view();
    const EnvMap& plain = map.radiance_map();
    const uint32_t w = plain.width(), h = plain.height(), g = map.layout().side(lobe);
    const std::vector<float> density = plain.density();
    int checked = 0;
    for (int k = 0; k <= 400; ++k) {  // a sweep across many bin borders
        const float t = k / 400.0f;
        const Vec3 n = octahedral_normal(t, 0.5f + 0.45f * std::sin(9 * t));
        const BinBlend blend = normal_blend(n, g);
        for (int pick = 0; pick < 4; ++pick) {
            if (!(blend.weight[pick] > 0)) continue;
            const BinChoice& c = map.layout().choices[map.layout().first(lobe) + blend.bin[pick]];
            const BinView bin = view.bin_at(view.class_bin(lobe, blend.bin[pick]), 1);
            for (uint32_t y = 0; y < h; ++y)
                for (uint32_t x = 0; x < w; ++x) {
                    const Vec2 uv{(x + 0.5f) / w, (y + 0.5f) / h};
                    const Vec3 d = equirect_direction(uv);
                    const float l = density[size_t{y} * w + x] / row_sin_theta(y, h);
                    if (dot(d, n) <= 0 || !(l > (c.plain() ? 0 : c.threshold) * 1.001f)) continue;
                    ++checked;
                    ASSERT_GT(bin.pdf_uv(uv), 0) << "texel " << x << "," << y << " bin " << blend.bin[pick];
                }
        }
    }
    EXPECT_GT(checked, 100);
}

}  // namespace envmis::test
