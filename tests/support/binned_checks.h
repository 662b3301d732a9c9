// Test support for the binned sampler (binned.h): its maps, test normals, texel
// probabilities, and the goodness-of-fit and coverage checks that the synthetic and the
// real-map tests share.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include "envmis/sampling/binned.h"
#include "stats.h"

namespace envmis::test {

// The family of chi-square tests these checks make, across the binned test files.
inline const double kBinnedLevel = sidak_level(0.01, 60);

inline EnvMap plain_map(RgbImage image, Mapping mapping = Mapping::equirect) {
    EnvMapOptions o;
    o.compensation.enabled = false;
    o.mapping = mapping;
    return EnvMap(std::move(image), o);
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
inline std::vector<double> texel_probabilities(const BinView& bin, const EnvMap& plain) {
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

inline void expect_samples_follow_pdf(const BinnedEnvMap& binned, Vec3 normal, uint32_t lobe, uint64_t seed) {
    const BinnedEnvMapView view = binned.view();
    const BinView bin = view.bin(normal, lobe);
    const std::vector<double> p = texel_probabilities(bin, binned.plain());
    EXPECT_NEAR(std::accumulate(p.begin(), p.end(), 0.0), 1.0, 1e-4);
    const size_t n = std::max<size_t>(100000, 20 * p.size());
    std::vector<double> expected(p.size()), observed(p.size());
    for (size_t i = 0; i < p.size(); ++i) expected[i] = p[i] * n;
    Rng rng(seed);
    const uint32_t w = binned.plain().width(), h = binned.plain().height();
    for (size_t i = 0; i < n; ++i) {
        const EnvSample s = bin.sample(rng.uniform2());
        ASSERT_EQ(s.pdf, bin.pdf_uv(s.uv));
        observed[size_t{detail::cell_of(s.uv.y, h)} * w + detail::cell_of(s.uv.x, w)] += 1;
    }
    const auto chi = chi_square(expected, observed);
    EXPECT_GT(chi.p_value, kBinnedLevel) << "normal " << normal.x << "," << normal.y << "," << normal.z << " lobe "
                                         << lobe << ": " << chi.describe();
}

// Coverage: pdf > 0 at every texel centre above the normal's horizon whose luminance is
// above its bin's threshold (everywhere with light for an uncompensated bin).
inline void expect_coverage(const BinnedEnvMap& map, uint32_t lobe) {
    const BinnedEnvMapView view = map.view();
    const EnvMap& plain = map.plain();
    const uint32_t w = plain.width(), h = plain.height(), g = map.layout().bins_per_side;
    const std::vector<float> density = plain.density();
    int checked = 0;
    for (int k = 0; k <= 400; ++k) {  // a sweep across many bin borders
        const float t = k / 400.0f;
        const Vec3 n = octahedral_normal(t, 0.5f + 0.45f * std::sin(9 * t));
        const BinChoice& c = map.layout().choices[size_t{lobe} * g * g + normal_bin(n, g)];
        for (uint32_t y = 0; y < h; ++y)
            for (uint32_t x = 0; x < w; ++x) {
                const Vec2 uv{(x + 0.5f) / w, (y + 0.5f) / h};
                const Vec3 d = equirect_direction(uv);
                const float l = density[size_t{y} * w + x] / row_sin_theta(y, h);
                if (dot(d, n) <= 0 || !(l > (c.plain() ? 0 : c.threshold) * 1.001f)) continue;
                ++checked;
                ASSERT_GT(view.bin(n, lobe).pdf_uv(uv), 0)
                    << "texel " << x << "," << y << " normal bin " << normal_bin(n, g);
            }
    }
    EXPECT_GT(checked, 100);
}

}  // namespace envmis::test
