// Specification of the analytic BSDFs (bsdf.h): sampling matches pdf, pdf integrates to
// 1 over the sphere, energy is conserved.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "envmis/math/random.h"
#include "envmis/study/shading/bsdf.h"
#include "stats.h"

namespace envmis {
namespace {

const double kLevel = test::sidak_level(0.01, 12);

std::vector<Bsdf> bsdfs() {
    return {Bsdf::lambert(), Bsdf::phong(5), Bsdf::phong(50), Bsdf::ggx(0.5f), Bsdf::ggx(0.1f)};
}
std::vector<Vec3> views() {
    return {normalize(Vec3{0, 0, 1}), normalize(Vec3{0.6f, 0.1f, 0.5f}), normalize(Vec3{-0.9f, 0.2f, 0.15f})};
}

// Direction at the centre of cell (i, j) of an nz x nphi grid equal-area in (z, phi).
constexpr int kZ = 48, kPhi = 96, kSub = 6;
Vec3 grid_direction(double zi, double pj) {
    const double z = -1 + 2 * zi / kZ, phi = 2 * kPi * pj / kPhi, r = std::sqrt(std::max(0.0, 1 - z * z));
    return {static_cast<float>(r * std::cos(phi)), static_cast<float>(r * std::sin(phi)), static_cast<float>(z)};
}
int grid_cell(Vec3 d) {
    const int zi = std::clamp(static_cast<int>((d.z + 1) / 2 * kZ), 0, kZ - 1);
    double phi = std::atan2(d.y, d.x);
    if (phi < 0) phi += 2 * kPi;
    return zi * kPhi + std::clamp(static_cast<int>(phi / (2 * kPi) * kPhi), 0, kPhi - 1);
}
// Probability of each grid cell under bsdf.pdf, by the midpoint rule on sub-cells.
std::vector<double> cell_probabilities(const Bsdf& bsdf, Vec3 wo) {
    std::vector<double> p(kZ * kPhi);
    const double sub_area = 4 * kPi / (double{kZ} * kPhi * kSub * kSub);
    for (int zi = 0; zi < kZ; ++zi)
        for (int pj = 0; pj < kPhi; ++pj)
            for (int a = 0; a < kSub; ++a)
                for (int b = 0; b < kSub; ++b)
                    p[zi * kPhi + pj] +=
                        bsdf.pdf(wo, grid_direction(zi + (a + 0.5) / kSub, pj + (b + 0.5) / kSub)) * sub_area;
    return p;
}

TEST(Bsdf, SamplesFollowThePdf) {
    uint64_t seed = 1;
    for (const Bsdf& bsdf : bsdfs())
        for (Vec3 wo : views()) {
            const std::vector<double> p = cell_probabilities(bsdf, wo);
            const int n = 300000;
            std::vector<double> observed(p.size()), expected(p.size());
            Pcg32 rng(seed++);
            for (int i = 0; i < n; ++i) {
                const BsdfSample s = bsdf.sample(wo, rng.uniform2());
                if (s.pdf > 0) observed[grid_cell(s.wi)] += 1;
            }
            for (size_t c = 0; c < p.size(); ++c) expected[c] = n * p[c];
            const auto chi = test::chi_square(expected, observed);
            EXPECT_GT(chi.p_value, kLevel / 15) << bsdf.name() << " wo.z=" << wo.z << ": " << chi.describe();
        }
}

TEST(Bsdf, PdfIntegratesToOneOverTheSphere) {
    // Midpoint rule, equal-area in (z, phi), fine enough for the sharpest lobe here.
    constexpr int nz = 3000, nphi = 1000;
    for (const Bsdf& bsdf : bsdfs())
        for (Vec3 wo : views()) {
            double integral = 0;
            for (int i = 0; i < nz; ++i) {
                const double z = -1 + 2 * (i + 0.5) / nz, r = std::sqrt(1 - z * z);
                for (int j = 0; j < nphi; ++j) {
                    const double phi = 2 * kPi * (j + 0.5) / nphi;
                    integral += bsdf.pdf(wo, {static_cast<float>(r * std::cos(phi)),
                                              static_cast<float>(r * std::sin(phi)), static_cast<float>(z)});
                }
            }
            integral *= 4 * kPi / (double{nz} * nphi);
            Pcg32 rng(3);
            int usable = 0;
            const int n = 200000;
            for (int i = 0; i < n; ++i) usable += bsdf.sample(wo, rng.uniform2()).pdf > 0;
            // Every BSDF samples with a density, also where the direction goes below the
            // surface (and carries no value): the pdf integrates to 1 over the sphere.
            EXPECT_NEAR(integral, 1.0, 1e-3) << bsdf.name() << " wo.z=" << wo.z;
            EXPECT_GT(usable, n - 10) << bsdf.name();
        }
}

TEST(Bsdf, ASharpGgxLobesPdfIntegratesToOne) {
    // The sphere in polar angles about the mirror direction, theta = pi s^4: steps of
    // 1e-5 rad across a lobe 0.002 rad wide. The textbook form of D lost the peak to
    // float rounding here (1.08 at roughness 0.001 seen head-on).
    for (float alpha : {0.001f, 0.002f, 0.01f})
        for (Vec3 wo : views()) {
            const Bsdf bsdf = Bsdf::ggx(alpha);
            const Vec3 r{-wo.x, -wo.y, wo.z};
            const Vec3 t1 = normalize(cross(r, std::abs(r.z) < 0.9f ? Vec3{0, 0, 1} : Vec3{1, 0, 0}));
            const Vec3 t2 = cross(r, t1);
            constexpr int ns = 4000, nphi = 256;
            double integral = 0;
            for (int i = 0; i < ns; ++i) {
                const double s = (i + 0.5) / ns, theta = kPi * s * s * s * s, dtheta = 4 * kPi * s * s * s / ns;
                const auto st = static_cast<float>(std::sin(theta)), ct = static_cast<float>(std::cos(theta));
                double ring = 0;
                for (int j = 0; j < nphi; ++j) {
                    const double phi = 2 * kPi * (j + 0.5) / nphi;
                    const Vec3 d = r * ct + t1 * (st * static_cast<float>(std::cos(phi))) +
                                   t2 * (st * static_cast<float>(std::sin(phi)));
                    ring += bsdf.pdf(wo, normalize(d));
                }
                integral += ring * std::sin(theta) * dtheta * 2 * kPi / nphi;
            }
            EXPECT_NEAR(integral, 1.0, 2e-3) << "ggx " << alpha << " wo.z=" << wo.z;
        }
}

TEST(Bsdf, SampleReturnsEvalAndPdfOfItsDirection) {
    for (const Bsdf& bsdf : bsdfs())
        for (Vec3 wo : views()) {
            Pcg32 rng(4);
            for (int i = 0; i < 2000; ++i) {
                const BsdfSample s = bsdf.sample(wo, rng.uniform2());
                EXPECT_NEAR(length(s.wi), 1.0f, 1e-4f);
                EXPECT_FLOAT_EQ(s.pdf, bsdf.pdf(wo, s.wi));
                EXPECT_FLOAT_EQ(s.value.g, bsdf.eval(wo, s.wi).g);
            }
        }
}

TEST(Bsdf, WhiteFurnaceAlbedoIsAtMostOne) {
    const Rgb white{1, 1, 1};
    for (Bsdf bsdf : {Bsdf::lambert(white), Bsdf::phong(1, white), Bsdf::phong(50, white), Bsdf::ggx(0.1f, white),
                      Bsdf::ggx(0.3f, white), Bsdf::ggx(1, white)})
        for (Vec3 wo : views()) {
            // Importance-sampled estimate of the directional albedo, integral of f cos.
            Pcg32 rng(5);
            double sum = 0;
            const int n = 200000;
            for (int i = 0; i < n; ++i) {
                const BsdfSample s = bsdf.sample(wo, rng.uniform2());
                if (s.pdf > 0) sum += s.value.g / s.pdf;
            }
            const double albedo = sum / n;
            EXPECT_LE(albedo, 1.0 + 1e-2) << bsdf.name() << " wo.z=" << wo.z;
            if (bsdf.kind == BsdfKind::lambert) {
                EXPECT_NEAR(albedo, 1.0, 1e-6) << "a white Lambertian reflects everything";
            }
            if (bsdf.kind == BsdfKind::ggx && bsdf.alpha <= 0.1f && wo.z == 1) {
                // 0.988 by independent quadrature: a smooth conductor loses little to multiple scattering.
                EXPECT_NEAR(albedo, 0.988, 5e-3) << bsdf.name();
            }
        }
}

TEST(Bsdf, NothingBelowTheSurface) {
    for (const Bsdf& bsdf : bsdfs()) {
        EXPECT_EQ(bsdf.eval({0, 0, 1}, {0, 0.6f, -0.8f}).g, 0.0f);
        EXPECT_EQ(bsdf.eval({0, 0.6f, -0.8f}, {0, 0, 1}).g, 0.0f);
        EXPECT_EQ(bsdf.sample({0, 0.6f, -0.8f}, {0.3f, 0.3f}).pdf, 0.0f);
    }
}

TEST(Bsdf, ParseAndName) {
    EXPECT_EQ(Bsdf::parse("lambert").kind, BsdfKind::lambert);
    EXPECT_EQ(Bsdf::parse("phong:50").exponent, 50.0f);
    EXPECT_EQ(Bsdf::parse("ggx:0.1").alpha, 0.1f);
    for (const Bsdf& b : bsdfs()) EXPECT_EQ(Bsdf::parse(b.name()).name(), b.name());
    for (const char* bad : {"", "lambert:x", "phong", "phong:-1", "ggx:0", "ggx:2", "ggx:x", "metal"})
        EXPECT_THROW(Bsdf::parse(bad), std::invalid_argument) << bad;
}

TEST(Bsdf, ParseAlbedo) {
    EXPECT_EQ(Bsdf::parse("lambert:0.5").reflectance.g, 0.5f);
    EXPECT_EQ(Bsdf::parse("lambert:0.5").kind, BsdfKind::lambert);
    const Bsdf phong = Bsdf::parse("phong:50:0.25");
    EXPECT_EQ(phong.exponent, 50.0f);
    EXPECT_EQ(phong.reflectance.r, 0.25f);
    EXPECT_EQ(phong.reflectance.b, 0.25f);
    const Bsdf ggx = Bsdf::parse("ggx:0.1:0.5");
    EXPECT_EQ(ggx.alpha, 0.1f);
    EXPECT_EQ(ggx.reflectance.r, 0.5f);
    EXPECT_EQ(ggx.reflectance.g, 0.5f);
    EXPECT_EQ(Bsdf::parse("lambert:1").reflectance.r, 1.0f);
    EXPECT_EQ(Bsdf::parse("lambert:0").reflectance.r, 0.0f);

    // The default albedo keeps today's names (keys of tables, JSON and CSV); any other
    // is part of the name, which parse() reads back.
    EXPECT_EQ(Bsdf::lambert().name(), "lambert");
    EXPECT_EQ(Bsdf::phong(50).name(), "phong:50");
    EXPECT_EQ(Bsdf::ggx(0.1f).name(), "ggx:0.1");
    EXPECT_EQ(Bsdf::parse("lambert:0.8").name(), "lambert");
    EXPECT_EQ(Bsdf::parse("lambert:0.5").name(), "lambert:0.5");
    EXPECT_EQ(Bsdf::parse("phong:50:0.5").name(), "phong:50:0.5");
    EXPECT_EQ(Bsdf::parse("ggx:0.1:0.5").name(), "ggx:0.1:0.5");
    EXPECT_EQ(Bsdf::parse("ggx:0.1:0.8").name(), "ggx:0.1:0.8") << "GGX's default F0 is not grey";
    for (const char* text : {"lambert:0.5", "phong:5:0.3", "ggx:0.5:1", "lambert:0"})
        EXPECT_EQ(Bsdf::parse(Bsdf::parse(text).name()).name(), text);
    EXPECT_EQ(Bsdf::parse("lambert:0.4").albedo_text(), "0.4");
    EXPECT_EQ(Bsdf::ggx(0.1f).albedo_text(), "0.95/0.64/0.54");

    for (const char* bad : {"lambert:-0.1", "lambert:1.5", "lambert:abc", "lambert:", "phong:50:-0.1", "phong:50:1.5",
                            "phong:50:x", "phong:50:", "phong:50:0.5:1", "ggx:0.1:-0.1", "ggx:0.1:1.5", "ggx:0.1:nan",
                            "ggx:0.1:0.5x", "lambert:0.5:0.5"})
        EXPECT_THROW(Bsdf::parse(bad), std::invalid_argument) << bad;
    try {
        Bsdf::parse("lambert:1.5");
        FAIL();
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("albedo"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace envmis
