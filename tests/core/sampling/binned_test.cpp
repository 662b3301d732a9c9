// Specification of the normal-aware binned sampler (binned.h): for normals at bin
// centres, on bin borders and at the poles, on synthetic maps of both mappings.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <iterator>
#include <limits>
#include <numeric>
#include <string>
#include <vector>

#include "binned_checks.h"
#include "envmis/build/bins.h"
#include "envmis/build/env_map.h"
#include "envmis/sampling/binned.h"
#include "forced_path.h"
#include "maps.h"
#include "stats.h"

namespace envmis {
namespace {

using test::Rng;

using test::expect_coverage;
using test::expect_samples_follow_pdf;
using test::plain_map;
using test::test_normals;
using test::texel_probabilities;

TEST(Binned, SamplesFollowTheirPdfForNormalsAtCentresBordersAndPoles) {
    const BinnedEnvMap sun = build_bins(plain_map(test::sun_sky_map(64, 32)));
    const BinnedEnvMap noise = build_bins(plain_map(test::random_map(48, 24, 3)));
    uint64_t seed = 1;
    for (uint32_t lobe : {0u, 2u})  // each class on its own grid's centres and borders
        for (Vec3 n : test_normals(sun.layout().side(lobe))) {
            expect_samples_follow_pdf(sun, {n}, lobe, ++seed);
            expect_samples_follow_pdf(noise, {n}, lobe, ++seed);
        }
}

TEST(Binned, EqualAreaMapsFollowTheirPdf) {
    const BinnedEnvMap map = build_bins(plain_map(test::random_map(32, 32, 8), Mapping::equal_area));
    uint64_t seed = 100;
    for (Vec3 n : test_normals(map.layout().side(1))) expect_samples_follow_pdf(map, {n}, 1, ++seed);
}

TEST(Binned, SolidAnglePdfIntegratesToOne) {
    const BinnedEnvMap map = build_bins(plain_map(test::sun_sky_map(64, 32)));
    const BinnedEnvMapView view = map.view();
    for (Vec3 n : test_normals(map.layout().side(0)))
        for (float choice : {0.1f, 0.5f, 0.9f})
            EXPECT_NEAR(test::sphere_integral(256, 512, [&](Vec3 d) { return view.pdf({n}, 0, choice, d); }), 1.0,
                        1e-3);
}

TEST(Binned, SampleAgreesWithPdfAndEvalFromItsDirection) {
    const BinnedEnvMap map = build_bins(plain_map(test::sun_sky_map(128, 64)));
    const BinnedEnvMapView view = map.view();
    Rng rng(9);
    int edge_cases = 0;
    const int n = 20000;
    for (int i = 0; i < n; ++i) {
        const Vec3 normal = octahedral_normal(rng.uniform(), rng.uniform());
        const float choice = rng.uniform();
        const EnvSample s = view.sample({normal}, i % 3, choice, rng.uniform2());
        ASSERT_GT(s.pdf, 0);
        ASSERT_NEAR(length(s.direction), 1.0f, 1e-5f);
        const EnvMapView::Lookup l = view.lookup({normal}, i % 3, choice, s.direction);
        if (std::abs(l.pdf - s.pdf) > 1e-3f * s.pdf || l.radiance.r != s.radiance.r) ++edge_cases;
    }
    EXPECT_LT(edge_cases, n / 500);
}

TEST(Binned, InsideACellTexelsArePickedByThePlainDensity) {
    const EnvMap plain = plain_map(test::random_map(64, 32, 5));
    BinnedOptions eight_columns;
    eight_columns.cell_columns = 8;
    const BinnedEnvMap map = build_bins(plain, eight_columns);
    const BinnedEnvMapView view = map.view();
    const BinView bin = view.nearest_bin({0, 0, 1}, 0);
    const std::vector<double> p = texel_probabilities(bin, map.radiance_map());
    const std::vector<float> plain_density = plain.density();
    std::vector<double> cell_mass(size_t{view.cells_w} * view.cells_h), row_mass(32);
    const auto cell_of = [&](uint32_t x, uint32_t y) {
        return size_t{view.cell_row(y)} * view.cells_w + view.cell_column(x);
    };
    for (uint32_t y = 0; y < 32; ++y)
        for (uint32_t x = 0; x < 64; ++x)
            cell_mass[cell_of(x, y)] += p[size_t{y} * 64 + x], row_mass[y] += plain_density[size_t{y} * 64 + x];
    // 31-bit fixed point, twice (the plain row CDF's widths, then the cell's CDF over
    // them): exact to 1e-4 for texels above 1e-4 of their cell and of their row; a
    // smaller texel's share is rounded to fewer units.
    const auto resolved = [&](uint32_t x, uint32_t y) {
        const size_t i = size_t{y} * 64 + x;
        return p[i] > 1e-4 * cell_mass[cell_of(x, y)] && plain_density[i] > 1e-4 * row_mass[y];
    };
    int compared = 0;
    for (uint32_t y = 0; y < 32; ++y)
        for (uint32_t x = 1; x < 64; ++x) {
            const size_t i = size_t{y} * 64 + x;
            if (cell_of(x, y) != cell_of(x - 1, y) || !resolved(x, y) || !resolved(x - 1, y)) continue;
            ++compared;
            const double expected = double{plain_density[i]} / plain_density[i - 1];
            EXPECT_NEAR(p[i] / p[i - 1], expected, 1e-4 * expected) << x << "," << y;
        }
    EXPECT_GT(compared, 500);
}

TEST(Binned, ATexelsCellIsTheExactQuotientForEveryMapAndGridSize) {
    // cell_column, cell_row and find_cell divide by a product and a shift: exact for every
    // numerator below 2^28 (texel index times cells) and every divisor to 65536.
    for (const uint32_t d :
         {1u, 2u, 3u, 7u, 32u, 112u, 724u, 1000u, 1023u, 1024u, 1025u, 4096u, 5792u, 40961u, 65535u, 65536u}) {
        const detail::ExactDivision by = detail::ExactDivision::by(d);
        const auto check = [&](uint64_t n) {
            if (n < (1u << 28)) {
                ASSERT_EQ(by.of(static_cast<uint32_t>(n)), n / d) << n << " / " << d;
            }
        };
        for (uint64_t q = 0; q * d < (1u << 28); q += 1 + q / 64)  // at quotients' edges, spread over the range
            for (const int64_t e : {int64_t{-1}, int64_t{0}, int64_t{1}, int64_t{d} - 1})
                if (static_cast<int64_t>(q * d) + e >= 0) check(q * d + e);
        check((1u << 28) - 1);
    }
    for (const auto& [w, h] : {std::pair{64u, 32u}, {100u, 50u}, {724u, 362u}}) {
        const BinnedEnvMap map = build_bins(plain_map(test::random_map(w, h, 3)));
        const BinnedEnvMapView view = map.view();
        for (uint32_t x = 0; x < w; ++x) EXPECT_EQ(view.cell_column(x), uint64_t{x} * view.cells_w / w) << x;
        for (uint32_t y = 0; y < h; ++y) EXPECT_EQ(view.cell_row(y), uint64_t{y} * view.cells_h / h) << y;
    }
}

TEST(Binned, PdfCoversWhatEveryNormalOfTheBinSeesAcrossBinBorders) {
    expect_coverage(build_bins(plain_map(test::sun_sky_map(64, 32))), 0);
    expect_coverage(build_bins(plain_map(test::random_map(64, 32, 2))), 2);
    BinnedOptions uncompensated;
    uncompensated.auto_alpha = false;
    uncompensated.alpha = 0;
    const BinnedEnvMap plain_bins = build_bins(plain_map(test::random_map(64, 32, 2)), uncompensated);
    EXPECT_TRUE(plain_bins.complete(0));
    expect_coverage(plain_bins, 0);
}

TEST(Binned, CompensatedBinsAreIncomplete) {
    BinnedOptions fixed;
    fixed.auto_alpha = false;
    fixed.alpha = 1;
    EXPECT_FALSE(build_bins(plain_map(test::sun_sky_map(64, 32)), fixed).complete(0));
}

// Counts of a lobe class's plain and compensated choices.
struct ChoiceCounts {
    uint32_t plain = 0, compensated = 0;
};
ChoiceCounts choice_counts(const BinnedEnvMap& map, uint32_t lobe) {
    const BinLayout& l = map.layout();
    ChoiceCounts counts;
    for (size_t b = 0; b < size_t{l.side(lobe)} * l.side(lobe); ++b)
        ++(l.choices[l.first(lobe) + b].plain() ? counts.plain : counts.compensated);
    return counts;
}

BinnedOptions costing(float cost) {
    BinnedOptions o;
    o.cost = cost;
    return o;
}

TEST(Binned, AHigherCostKeepsCompensationOnlyInTheBinsWhereItPaysMore) {
    const EnvMap plain = plain_map(test::sun_sky_map(64, 32));
    for (uint32_t lobe : {0u, 1u, 2u}) {
        uint32_t previous = ~0u;
        for (float cost : {1.0f, 1.5f, 3.0f, 100.0f}) {
            const ChoiceCounts c = choice_counts(build_bins(plain, costing(cost)), lobe);
            EXPECT_LE(c.compensated, previous) << "lobe " << lobe << " cost " << cost;
            previous = c.compensated;
            if (cost == 1.0f) {
                EXPECT_GT(c.compensated, 0u) << "lobe " << lobe;
            }
            if (cost == 100.0f) {
                EXPECT_EQ(c.compensated, 0u) << "lobe " << lobe;
            }
        }
    }
}

TEST(Binned, ThePlainCellTableIsThePlainMapsDensityUpToFixedPointRounding) {
    const EnvMap plain = plain_map(test::random_map(64, 32, 7));
    const BinnedEnvMap map = build_bins(plain);
    const std::vector<double> through_cells = texel_probabilities(map.view().plain_bin(), map.radiance_map());
    const std::vector<double> global = texel_probabilities(plain.view(), plain);
    double distance = 0;
    for (size_t i = 0; i < global.size(); ++i) {
        ASSERT_EQ(through_cells[i] > 0, global[i] > 0) << "texel " << i;
        distance += std::abs(through_cells[i] - global[i]);
    }
    EXPECT_LT(0.5 * distance, 1e-6);
    // The same map whole again: the plain map rebuilt from the binned one's radiance.
    const EnvMap whole = map.plain_map();
    Rng rng(23);
    for (int i = 0; i < 1000; ++i) {
        const Vec2 u = rng.uniform2();
        const EnvSample a = plain.sample(u), b = whole.sample(u);
        ASSERT_EQ(std::memcmp(&a, &b, sizeof a), 0) << "sample " << i;
    }
}

TEST(Binned, APlainChoiceSamplesAndWeighsExactlyAsThePlainCellTableDoes) {
    const BinnedEnvMap map = build_bins(plain_map(test::sun_sky_map(64, 32)), costing(100));
    const BinnedEnvMapView view = map.view();
    const BinView plain = view.plain_bin();
    Rng rng(21);
    for (int i = 0; i < 2000; ++i) {
        const Vec3 n = octahedral_normal(rng.uniform(), rng.uniform());
        const Vec2 u = rng.uniform2();
        const float c = rng.uniform();
        const EnvSample a = view.sample({n}, i % 3, c, u), b = plain.sample(u);
        ASSERT_EQ(a.pdf, b.pdf);
        ASSERT_EQ(a.direction.x, b.direction.x);
        ASSERT_EQ(a.direction.z, b.direction.z);
        const Vec3 d = equirect_direction(rng.uniform2());
        ASSERT_EQ(view.pdf({n}, i % 3, c, d), plain.pdf(d));
    }
}

// A glossy bin's view limit: seen more obliquely, the bin samples and weighs exactly as
// the plain cell table does; at its limit and above, by its own density.
TEST(Binned, AGlossyBinSeenMoreObliquelyThanItsLimitSamplesAndWeighsAsThePlainCellTableDoes) {
    const BinnedEnvMap map = build_bins(plain_map(test::sun_sky_map(128, 64)));
    const BinnedEnvMapView view = map.view();
    const BinView plain = view.plain_bin();
    const BinLayout& layout = map.layout();
    const uint32_t g = layout.bins_per_side;
    int limited = 0;
    Rng rng(22);
    for (uint32_t b = 0; b < g * g; ++b) {
        const BinChoice& choice = layout.choices[layout.first(1) + b];
        if (choice.plain() || !(choice.min_view_cos > 0)) continue;
        ++limited;
        const Vec3 centre = octahedral_normal((b % g + 0.5f) / g, (b / g + 0.5f) / g);  // picked alone
        const float below = std::nextafter(choice.min_view_cos, 0.0f);
        const BinView own = view.bin({centre, choice.min_view_cos}, 1, 0.5f);
        ASSERT_FALSE(own.plain);
        ASSERT_EQ(own.cells.start, view.bin_at(view.class_bin(1, b), 1).cells.start);
        for (int i = 0; i < 50; ++i) {
            const Vec2 u = rng.uniform2();
            const float c = rng.uniform();
            const EnvSample a = view.sample({centre, below}, 1, c, u), p = plain.sample(u);
            ASSERT_EQ(a.pdf, p.pdf);
            ASSERT_EQ(a.direction.x, p.direction.x);
            ASSERT_EQ(a.direction.z, p.direction.z);
            const Vec3 d = equirect_direction(rng.uniform2());
            ASSERT_EQ(view.pdf({centre, below}, 1, c, d), plain.pdf(d));
            EXPECT_EQ(view.sample({centre, choice.min_view_cos}, 1, c, u).pdf, own.sample(u).pdf);
        }
    }
    EXPECT_GT(limited, 0) << "no glossy bin of this map has a view limit";
}

TEST(Binned, TablesMixingPlainAndCompensatedBinsFollowTheirPdf) {
    const BinnedEnvMap map = build_bins(plain_map(test::sun_sky_map(64, 32)), costing(1.5f));
    const ChoiceCounts mixed = choice_counts(map, 1);
    ASSERT_GT(mixed.plain, 0u);
    ASSERT_GT(mixed.compensated, 0u);
    uint64_t seed = 300;
    for (Vec3 n : test_normals(map.layout().side(1))) {
        expect_samples_follow_pdf(map, {n}, 1, ++seed);
        expect_samples_follow_pdf(map, {n, 0.3f}, 1, ++seed);  // some bins' view limits passed
    }
}

uint32_t bits(float f) { return bit_cast<uint32_t>(f); }

// Random points of [0,1)^2 and, first, points at its ends, outside it (which every path
// clamps) and finer than a CDF's unit near 0.
std::vector<Vec2> batch_points(uint32_t n, uint64_t seed) {
    const float edges[] = {0.0f,
                           0x1p-24f,
                           0.5f,
                           1 - 0x1p-24f,
                           kOneMinusEpsilon,
                           1.0f,
                           -0.5f,
                           2.0f,
                           std::numeric_limits<float>::quiet_NaN()};
    std::vector<Vec2> points;
    for (const float a : edges)
        for (const float b : edges) points.push_back({a, b});
    Rng rng(seed);
    for (int i = 0; i < 40; ++i) {
        const Vec2 u = rng.uniform2();
        points.push_back({u.x * 0x1p-9f, u.y * 0x1p-9f});
    }
    while (points.size() < n) points.push_back(rng.uniform2());
    return points;
}

// The batch forms over n lanes against single calls, every output's bits: the picking
// forms (lobe class 1, view cosines in [0,1), so that some glossy bins pass their view
// limits) and the forms over bins picked beforehand.
void expect_batch_bit_identical(const BinnedEnvMapView& view, uint32_t n = 1003) {
    Rng rng(4);
    const std::vector<Vec2> points = batch_points(n, 5);
    std::vector<float> nx(n), ny(n), nz(n), vc(n), c(n), ux(n), uy(n), dx(n), dy(n), dz(n);
    std::vector<BinView> bins;
    for (uint32_t i = 0; i < n; ++i) {
        const Vec3 normal = octahedral_normal(rng.uniform(), rng.uniform());
        nx[i] = normal.x, ny[i] = normal.y, nz[i] = normal.z, ux[i] = points[i].x, uy[i] = points[i].y;
        c[i] = rng.uniform(), vc[i] = rng.uniform();
        bins.push_back(view.bin({normal, vc[i]}, 1, c[i]));
        // Directions off the sphere, the axes and poles; then ones the bin itself samples (its
        // lit cells, its seam) and uniform ones.
        const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
        const Vec3 special[] = {{nan, 0, 1}, {inf, 0, 0}, {-inf, inf, 0}, {0, 0, 0},  {0, 0, 1},     {0, 0, -1},
                                {1, 0, 0},   {-1, 0, 0},  {0, 1, 0},      {0, -1, 0}, {1, -0.0f, 0}, {0.6f, -0.8f, 0}};
        const Vec3 d = i < std::size(special) ? special[i]
                       : i % 2                ? bins.back().sample(rng.uniform2()).direction
                                              : equirect_direction(rng.uniform2());
        dx[i] = d.x, dy[i] = d.y, dz[i] = d.z;
    }
    std::vector<float> x(n), y(n), z(n), pdf(n), r(n), g(n), b(n), u(n), v(n);
    const SampleArrays samples{x.data(), y.data(), z.data(), pdf.data(), r.data(),
                               g.data(), b.data(), u.data(), v.data()};
    const LookupArrays lookups{r.data(), g.data(), b.data(), pdf.data()};
    const auto expect_samples = [&](const char* form) {
        for (uint32_t i = 0; i < n; ++i) {
            const EnvSample e = bins[i].sample(points[i]);
            const float expected[] = {e.direction.x, e.direction.y, e.direction.z, e.pdf, e.radiance.r,
                                      e.radiance.g,  e.radiance.b,  e.uv.x,        e.uv.y};
            const float got[] = {x[i], y[i], z[i], pdf[i], r[i], g[i], b[i], u[i], v[i]};
            for (int k = 0; k < 9; ++k)
                ASSERT_EQ(bits(got[k]), bits(expected[k])) << form << " lane " << i << " output " << k;
        }
    };
    const auto expect_lookups = [&](const char* form) {
        for (uint32_t i = 0; i < n; ++i) {
            const EnvMapView::Lookup e = bins[i].lookup({dx[i], dy[i], dz[i]});
            const float expected[] = {e.radiance.r, e.radiance.g, e.radiance.b, e.pdf};
            const float got[] = {r[i], g[i], b[i], pdf[i]};
            for (int k = 0; k < 4; ++k)
                ASSERT_EQ(bits(got[k]), bits(expected[k])) << form << " lane " << i << " output " << k;
        }
    };
    const LobeAxisArrays axes{nx.data(), ny.data(), nz.data(), vc.data()};
    sample_many(view, 1, axes, c.data(), {ux.data(), uy.data()}, samples, n);
    expect_samples("picking");
    lookup_many(view, 1, axes, c.data(), {dx.data(), dy.data(), dz.data()}, lookups, n);
    expect_lookups("picking");
    sample_many(bins.data(), {ux.data(), uy.data()}, samples, n);
    expect_samples("picked");
    lookup_many(bins.data(), {dx.data(), dy.data(), dz.data()}, lookups, n);
    expect_lookups("picked");
}

TEST(Binned, BatchCallsAreBitIdenticalToSingleCalls) {
    ENVMIS_SKIP_IF_FORCED_PATH_UNAVAILABLE();
    for (float cost : {1.0f, 1.5f}) {  // compensated bins; plain and compensated ones mixed
        const BinnedEnvMap map = build_bins(plain_map(test::sun_sky_map(64, 32)), costing(cost));
        expect_batch_bit_identical(map.view());
    }
}

// The AVX2 paths search each lane's own tables and place points with the map's sizes:
// sizes that are no powers of two, cells of uneven widths (ExactDivisions of several
// shifts) and heights, the equal-area mapping, another frame, black cells beside lit
// ones, and cells of one or two texels (the smallest the SIMD search takes); maps under
// 64 texels wide have one cell on the default grid, which the scalar path takes.
TEST(Binned, BatchCallsAreBitIdenticalOnMapsOfEveryShape) {
    ENVMIS_SKIP_IF_FORCED_PATH_UNAVAILABLE();
    EnvMapOptions y_up;
    y_up.compensation.enabled = false;
    y_up.axes = Axes::parse("x,z,-y");
    BinnedOptions seven_columns, cells_of_one, cells_of_two;
    seven_columns.cell_columns = 7;  // 7 x 3 cells over 100 x 50: widths 14 and 15, heights 16 and 17
    cells_of_one.cell_columns = 16;  // 16 x 8 cells over 16 x 8 texels
    cells_of_two.cell_columns = 16;  // over 32 x 8
    const BinnedEnvMap maps[] = {
        build_bins(plain_map(test::random_map(100, 50, 3))),
        build_bins(plain_map(test::random_map(100, 50, 11)), seven_columns),
        build_bins(plain_map(test::random_map(65, 33, 12))),  // columns 33 and 32 texels wide
        build_bins(plain_map(test::random_map(128, 128, 13), Mapping::equal_area)),
        build_bins(plain_map(test::random_map(37, 37, 8), Mapping::equal_area)),
        build_bins(build_env_map(test::sun_sky_map(96, 48), y_up)),
        build_bins(plain_map(test::sparse_map(64, 32, 6, 0.02f))),
        build_bins(plain_map(test::single_texel_map(64, 32, 10, 3))),
        build_bins(plain_map(test::random_map(16, 8, 4)), cells_of_one),
        build_bins(plain_map(test::random_map(32, 8, 5)), cells_of_two),
    };
    for (const BinnedEnvMap& map : maps) {
        SCOPED_TRACE(std::to_string(map.radiance_map().width()) + "x" + std::to_string(map.radiance_map().height()));
        expect_batch_bit_identical(map.view());
    }
}

// The pipelines' and the SIMD groups' start and end: every length up to 70 lanes.
TEST(Binned, BatchCallsOfEveryLengthAreBitIdentical) {
    ENVMIS_SKIP_IF_FORCED_PATH_UNAVAILABLE();
    const BinnedEnvMap map = build_bins(plain_map(test::sun_sky_map(64, 32)));
    for (uint32_t n = 0; n <= 70; ++n) {
        SCOPED_TRACE(n);
        expect_batch_bit_identical(map.view(), n);
    }
}

// Bins of two maps in one call: each lane in its own map's tables.
TEST(Binned, BatchCallsOverBinsOfTwoMapsAreBitIdentical) {
    ENVMIS_SKIP_IF_FORCED_PATH_UNAVAILABLE();
    const BinnedEnvMap a = build_bins(plain_map(test::sun_sky_map(64, 32))),
                       b = build_bins(plain_map(test::random_map(96, 48, 7)));
    const BinnedEnvMapView va = a.view(), vb = b.view();
    constexpr uint32_t n = 100;
    const std::vector<Vec2> points = batch_points(n, 8);
    Rng rng(9);
    std::vector<BinView> bins;
    std::vector<float> ux, uy, dx, dy, dz;
    for (uint32_t i = 0; i < n; ++i) {
        const Vec3 normal = octahedral_normal(rng.uniform(), rng.uniform());
        bins.push_back((i / 20) % 2 ? vb.bin({normal}, 0, rng.uniform()) : va.bin({normal}, 0, rng.uniform()));
        ux.push_back(points[i].x), uy.push_back(points[i].y);
        const Vec3 d = equirect_direction(rng.uniform2());
        dx.push_back(d.x), dy.push_back(d.y), dz.push_back(d.z);
    }
    std::vector<float> x(n), y(n), z(n), pdf(n), r(n), g(n), bl(n);
    sample_many(bins.data(), {ux.data(), uy.data()},
                {x.data(), y.data(), z.data(), pdf.data(), r.data(), g.data(), bl.data()}, n);
    for (uint32_t i = 0; i < n; ++i) {
        const EnvSample e = bins[i].sample(points[i]);
        ASSERT_EQ(bits(x[i]), bits(e.direction.x)) << i;
        ASSERT_EQ(bits(pdf[i]), bits(e.pdf)) << i;
        ASSERT_EQ(bits(g[i]), bits(e.radiance.g)) << i;
    }
    lookup_many(bins.data(), {dx.data(), dy.data(), dz.data()}, {r.data(), g.data(), bl.data(), pdf.data()}, n);
    for (uint32_t i = 0; i < n; ++i) {
        const EnvMapView::Lookup e = bins[i].lookup({dx[i], dy[i], dz[i]});
        ASSERT_EQ(bits(pdf[i]), bits(e.pdf)) << i;
        ASSERT_EQ(bits(bl[i]), bits(e.radiance.b)) << i;
    }
}

TEST(Binned, RebuildingFromTheLayoutIsBitIdentical) {
    const EnvMap plain = plain_map(test::sun_sky_map(96, 48));
    const BinnedEnvMap built = build_bins(plain);
    const BinnedEnvMap rebuilt(plain, built.layout());
    Rng rng(12);
    for (int i = 0; i < 2000; ++i) {
        const Vec3 n = octahedral_normal(rng.uniform(), rng.uniform());
        const Vec2 u = rng.uniform2();
        const float c = rng.uniform();
        const EnvSample a = built.view().sample({n}, i % 3, c, u), b = rebuilt.view().sample({n}, i % 3, c, u);
        ASSERT_EQ(a.pdf, b.pdf);
        ASSERT_EQ(a.direction.x, b.direction.x);
    }
}

TEST(Binned, NormalsFindTheirOctahedralBin) {
    Rng rng(3);
    for (int i = 0; i < 10000; ++i) {
        const float s = rng.uniform(), t = rng.uniform();
        const uint32_t expected =
            std::min(9u, static_cast<uint32_t>(t * 10)) * 10 + std::min(9u, static_cast<uint32_t>(s * 10));
        const uint32_t found = normal_bin(octahedral_normal(s, t), 10);
        // Points within float rounding of a border may land either side.
        if (found != expected) {
            const float ds = std::abs(s * 10 - std::round(s * 10)), dt = std::abs(t * 10 - std::round(t * 10));
            EXPECT_LT(std::min(ds, dt), 1e-4f);
        }
    }
    EXPECT_EQ(normal_bin({0, 0, 0}, 10), 0u);
    // With the default (odd) grid, an up-facing floor's normal is a bin centre.
    const uint32_t g = BinnedOptions{}.bins_per_side, up = normal_bin({0, 0, 1}, g);
    EXPECT_GT(dot(octahedral_normal((up % g + 0.5f) / g, (up / g + 0.5f) / g), Vec3{0, 0, 1}), 0.99999f);
    EXPECT_EQ(normal_bin({NAN, 0, 1}, 10), 0u);
}

TEST(Binned, TheDiffuseClassHasItsOwnFinerGridOfNormals) {
    const EnvMap plain = plain_map(test::sun_sky_map(64, 32));
    const BinnedEnvMap defaults = build_bins(EnvMap(plain));
    EXPECT_EQ(defaults.layout().bins_per_side, 11u);
    EXPECT_EQ(defaults.layout().diffuse_bins_per_side, 21u);
    EXPECT_EQ(defaults.layout().choices.size(), 21u * 21 + 2 * 11 * 11);
    const BinnedEnvMapView view = defaults.view();
    // A normal halfway between two glossy bin centres is a diffuse bin centre: the diffuse
    // class takes that bin alone, a glossy class blends the two.
    const Vec3 n = octahedral_normal(6.0f / 11, 5.5f / 11);
    const BinBlend diffuse = normal_blend(n, 21), glossy = normal_blend(n, 11);
    EXPECT_NEAR(*std::max_element(diffuse.weight, diffuse.weight + 4), 1.0f, 1e-5f);
    EXPECT_NEAR(*std::max_element(glossy.weight, glossy.weight + 4), 0.5f, 1e-5f);
    EXPECT_EQ(view.bin({n}, 0, 0.3f).cells.start, view.bin({n}, 0, 0.9f).cells.start);
    EXPECT_NE(view.bin({n}, 1, 0.3f).cells.start, view.bin({n}, 1, 0.9f).cells.start);
    BinnedOptions o;
    o.bins_per_side = 5;
    o.diffuse_bins_per_side = 3;
    const BinnedEnvMap chosen = build_bins(EnvMap(plain), o);
    EXPECT_EQ(chosen.diffuse_bins(), 9u);
    EXPECT_EQ(chosen.bins(), 25u);
    EXPECT_EQ(BinnedEnvMap(EnvMap(plain), chosen.layout()).layout().choices.size(), 9u + 2 * 25);
    o.diffuse_bins_per_side = 65;
    EXPECT_THROW(build_bins(EnvMap(plain), o), std::invalid_argument);
    EXPECT_EQ(diffuse_side(64), 64u);
    EXPECT_EQ(diffuse_side(1), 1u);
}

TEST(Binned, LobeClassesPickTheNearestSharpness) {
    const std::vector<float> e = {0, 20, 200};
    EXPECT_EQ(lobe_class(e, 0), 0u);
    EXPECT_EQ(lobe_class(e, 2), 0u);
    EXPECT_EQ(lobe_class(e, 10), 1u);
    EXPECT_EQ(lobe_class(e, 50), 1u);
    EXPECT_EQ(lobe_class(e, 100), 2u);
    EXPECT_EQ(lobe_class(e, 1e5f), 2u);
}

TEST(Binned, TinyBlackAndConstantMapsWork) {
    for (RgbImage image : {test::constant_map(1, 1, {1, 1, 1}), test::constant_map(3, 2, {0, 0, 0}),
                           test::constant_map(5, 3, {2, 2, 2}), test::random_map(2, 1, 9)}) {
        const BinnedEnvMap map = build_bins(plain_map(image));
        const BinnedEnvMapView view = map.view();
        Rng rng(1);
        for (Vec3 n : test_normals(map.layout().side(0))) {
            const float choice = rng.uniform();
            const EnvSample s = view.sample({n}, 0, choice, rng.uniform2());
            EXPECT_GT(s.pdf, 0) << image.width << "x" << image.height;
            EXPECT_EQ(s.pdf, view.bin({n}, 0, choice).pdf_uv(s.uv));
        }
    }
}

// Bytes the bins of `layout` add to a plain map of h texel rows, as binned.h counts them:
// the cell tables (the bins' and the plain one) and the small ones; the cell texel CDFs
// take the plain row CDFs' place, and the plain marginal (6 bytes a row) is saved.
size_t bins_bytes(const BinLayout& layout, uint32_t h) {
    const size_t cells = size_t{layout.cell_columns} * layout.cell_rows;
    return (layout.choice_count() + 1) * cells * 6 + layout.choice_count() * sizeof(float) +
           (layout.cell_columns + 1 + layout.cell_rows + 1) * sizeof(uint32_t) +
           layout.cell_columns * sizeof(detail::ExactDivision) - size_t{h} * 6;
}

TEST(Binned, TheDefaultCellsAre32TexelsWideAndAtMost112By56SoBinsStayUnderFivePercentOfAn8kMap) {
    struct Case {
        uint32_t w, h;
        Mapping mapping;
        uint32_t columns, rows;
    };
    BinnedOptions fixed;
    fixed.auto_alpha = false;
    for (const Case& c : {Case{64, 32, Mapping::equirect, 2, 1}, Case{1024, 512, Mapping::equirect, 32, 16},
                          Case{4096, 2048, Mapping::equirect, 112, 56}, Case{1024, 1024, Mapping::equal_area, 32, 32},
                          Case{2560, 2560, Mapping::equal_area, 79, 79}}) {
        const EnvMap plain = plain_map(test::constant_map(c.w, c.h, {1, 1, 1}), c.mapping);
        const BinLayout layout = choose_bin_layout(plain, fixed);
        EXPECT_EQ(layout.cell_columns, c.columns) << c.w << "x" << c.h;
        EXPECT_EQ(layout.cell_rows, c.rows) << c.w << "x" << c.h;
        if (c.w <= 1024) {
            EXPECT_EQ(BinnedEnvMap(plain, layout).bytes(), bins_bytes(layout, c.h)) << c.w << "x" << c.h;
            continue;
        }
        // The same grid at 8k (the cap): a plain map holds 18 bytes a texel (envmap.h).
        const double texels_8k = c.mapping == Mapping::equirect ? 8192.0 * 4096 : 5793.0 * 5793;
        const uint32_t rows_8k = c.mapping == Mapping::equirect ? 4096 : 5793;
        EXPECT_LT(static_cast<double>(bins_bytes(layout, rows_8k)), 0.05 * 18 * texels_8k) << c.w << "x" << c.h;
    }
}

// Every sample, pdf and lookup of random (axis, pick, point or direction, class) finite,
// the pdf >= 0 and the sample's pdf > 0 and equal to the pdf at its point.
void expect_finite_everywhere(const BinnedEnvMap& map, uint64_t seed, const std::string& what) {
    const BinnedEnvMapView view = map.view();
    Rng rng(seed);
    for (int i = 0; i < 4000; ++i) {
        const Vec3 axis = octahedral_normal(rng.uniform(), rng.uniform());
        const uint32_t lobe = static_cast<uint32_t>(i) % map.classes();
        const float choice = rng.uniform();
        const BinView bin = view.bin({axis, rng.uniform()}, lobe, choice);
        const EnvSample s = bin.sample(rng.uniform2());
        ASSERT_TRUE(s.pdf > 0 && std::isfinite(s.pdf)) << what << ": sample pdf " << s.pdf;
        ASSERT_TRUE(std::isfinite(s.direction.x + s.direction.y + s.direction.z)) << what;
        ASSERT_TRUE(std::isfinite(s.radiance.r + s.radiance.g + s.radiance.b)) << what;
        ASSERT_EQ(s.pdf, bin.pdf_uv(s.uv)) << what;
        const EnvMapView::Lookup l = bin.lookup(equirect_direction(rng.uniform2()));
        ASSERT_TRUE(l.pdf >= 0 && std::isfinite(l.pdf)) << what << ": lookup pdf " << l.pdf;
        const Vec2 uv = rng.uniform2();
        ASSERT_TRUE(bin.pdf_uv(uv) >= 0 && std::isfinite(bin.pdf_uv(uv))) << what << " at " << uv.x << "," << uv.y;
    }
}

TEST(Binned, BlackTexelsBesideLitOnesInOneCellGetPdfZeroNotNaN) {
    // Lit in one row of a cell and black in the next: the black row's segment has no
    // plain mass (0 / 0 before).
    const BinnedEnvMap one = build_bins(plain_map(test::single_texel_map(64, 32, 10, 3)));
    const BinnedEnvMapView view = one.view();  // the bin points into it
    const BinView bin = view.nearest_bin({0, 0, 1}, 0);
    for (uint32_t y = 0; y < 32; ++y)
        for (uint32_t x = 0; x < 64; ++x) {
            const float p = bin.pdf_uv({(x + 0.5f) / 64, (y + 0.5f) / 32});
            ASSERT_EQ(p > 0, x == 10 && y == 3) << x << "," << y << ": " << p;
        }
    expect_finite_everywhere(one, 1, "single texel");
    expect_finite_everywhere(build_bins(plain_map(test::softboxes_map(256, 128))), 2, "softboxes");
    expect_finite_everywhere(build_bins(plain_map(test::black_ground_map(128, 64, 3))), 3, "black ground");
    expect_finite_everywhere(build_bins(plain_map(test::black_ground_map(32, 32, 4), Mapping::equal_area)), 4,
                             "black ground, equal-area");
}

TEST(Binned, RandomSparseMapsNeverGiveANaNOrInfinitePdfOrSample) {
    Rng rng(77);
    for (uint64_t k = 0; k < 24; ++k) {
        const auto w = 4 + static_cast<uint32_t>(rng.uniform() * 120),
                   h = 2 + static_cast<uint32_t>(rng.uniform() * 60);
        const float lit = k % 3 == 0 ? 0.002f : (k % 3 == 1 ? 0.03f : 0.3f);
        const Mapping mapping = k % 4 == 3 ? Mapping::equal_area : Mapping::equirect;
        const RgbImage image = test::sparse_map(w, mapping == Mapping::equal_area ? w : h, 100 + k, lit);
        BinnedOptions o;
        o.bins_per_side = 1 + static_cast<uint32_t>(rng.uniform() * 12);
        expect_finite_everywhere(
            build_bins(plain_map(image, mapping), o), k,
            "sparse map " + std::to_string(k) + " (" + std::to_string(w) + " wide, lit " + std::to_string(lit) + ")");
    }
}

TEST(Binned, PicksFollowTheBilinearWeightsWhichChangeWithoutSteps) {
    const uint32_t g = 11;
    Rng rng(5);
    for (int i = 0; i < 20000; ++i) {
        const float s = rng.uniform(), t = rng.uniform();
        const BinBlend a = normal_blend(octahedral_normal(s, t), g);
        float sum = 0;
        for (float w : a.weight) {
            ASSERT_GE(w, 0.0f);
            sum += w;
        }
        ASSERT_NEAR(sum, 1.0f, 1e-5f);
        // A normal a hair away gives each bin nearly the same weight: no steps.
        const BinBlend b = normal_blend(octahedral_normal(std::min(s + 1e-4f, 1.0f), t), g);
        for (int k = 0; k < 4; ++k) {
            float wb = 0;
            for (int j = 0; j < 4; ++j)
                if (b.bin[j] == a.bin[k]) wb += b.weight[j];
            float wa = 0;
            for (int j = 0; j < 4; ++j)
                if (a.bin[j] == a.bin[k]) wa += a.weight[j];
            ASSERT_NEAR(wa, wb, 0.02f) << s << "," << t << " bin " << a.bin[k];
        }
    }
    // At a bin centre the bin alone; the pick of every choice is a bin of positive weight.
    const BinBlend centre = normal_blend(octahedral_normal(5.5f / g, 5.5f / g), g);
    EXPECT_EQ(pick_bin(centre, 0.999f), 5 * g + 5);
    const BinBlend border = normal_blend(octahedral_normal(6.0f / g, 5.5f / g), g);
    EXPECT_EQ(pick_bin(border, 0.25f), 5 * g + 5);
    EXPECT_EQ(pick_bin(border, 0.75f), 5 * g + 6);
    // Across the octahedral map's fold (s = 1), the bin beyond is the edge column's mirror.
    const BinBlend fold = normal_blend(octahedral_normal(0.999f, 2.5f / g), g);
    EXPECT_EQ(fold.bin[0], 2 * g + g - 1);
    EXPECT_EQ(fold.bin[1], (g - 1 - 2) * g + g - 1);
}

TEST(Binned, APickFromTheNormalAloneIsThePickFromItsBlendWithTheWeightsFrequencies) {
    // Random normals everywhere (both hemispheres, the poles, the fold) and normals one
    // grid step outside the map's edges; for each, choices on an even grid of [0,1).
    Rng rng(12);
    const int choices = 1000;
    for (uint32_t g : {1u, 2u, 11u, 21u}) {
        for (int i = 0; i < 3000; ++i) {
            const Vec3 n = i < 8 ? Vec3{i & 1 ? 0.0f : 1.0f, i & 2 ? 1.0f : -0.0f, i & 4 ? -1.0f : 1.0f}
                                 : octahedral_normal(rng.uniform(), rng.uniform());
            const BinBlend blend = normal_blend(n, g);
            float hits[4] = {};
            for (int k = 0; k < choices; ++k) {
                const float choice = (k + 0.5f) / choices;
                const uint32_t bin = pick_bin(n, g, choice);
                ASSERT_EQ(bin, pick_bin(blend, choice)) << "g " << g << " normal " << i << " choice " << choice;
                ASSERT_LT(bin, g * g);
                const uint32_t corner = pick_corner(blend.wa, blend.wb, choice);
                ASSERT_GT(blend.weight[corner], 0.0f);
                hits[corner] += 1.0f / choices;
            }
            for (int c = 0; c < 4; ++c)
                ASSERT_NEAR(hits[c], blend.weight[c], 2.0f / choices)
                    << "g " << g << " normal " << i << " corner " << c;
        }
    }
}

TEST(Binned, RejectsCompensatedMapsAndInvalidOptionsAndLayouts) {
    EXPECT_THROW(build_bins(build_env_map(test::sun_sky_map(16, 8))), std::invalid_argument);
    const EnvMap plain = plain_map(test::sun_sky_map(16, 8));
    BinnedOptions o;
    o.bins_per_side = 0;
    EXPECT_THROW(build_bins(plain, o), std::invalid_argument);
    o = {};
    o.lobe_exponents = {5, 20};
    EXPECT_THROW(build_bins(plain, o), std::invalid_argument);
    o = {};
    o.candidates = {-1};
    EXPECT_THROW(build_bins(plain, o), std::invalid_argument);
    for (float cost : {0.5f, 101.0f, std::nanf("")})
        EXPECT_THROW(build_bins(plain, costing(cost)), std::invalid_argument);
    BinLayout layout = build_bins(plain).layout();
    layout.choices.pop_back();
    EXPECT_THROW(BinnedEnvMap(plain, layout), std::invalid_argument);
    layout = build_bins(plain).layout();
    layout.cell_columns = 17;
    EXPECT_THROW(BinnedEnvMap(plain, layout), std::invalid_argument);
    layout = build_bins(plain).layout();
    layout.choices[0] = {1, 0.3f};  // not on the histogram grid
    EXPECT_THROW(BinnedEnvMap(plain, layout), std::invalid_argument);
}

TEST(Binned, ACellOfMoreThan65536TexelsIsRefusedWithItsSize) {
    const EnvMap plain = plain_map(test::constant_map(512, 256, {1, 1, 1}));
    BinnedOptions o;
    o.auto_alpha = false;
    o.cell_columns = 1;  // one cell of 512 x 256 texels: its CDF's uint16 guide cannot name them
    try {
        build_bins(plain, o);
        FAIL() << "a cell of 131072 texels was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("at most 65536 texels"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("131072"), std::string::npos) << e.what();
    }
    o.cell_columns = 2;  // 256 x 256 texels
    EXPECT_EQ(build_bins(plain, o).layout().cell_columns, 2u);
}

}  // namespace
}  // namespace envmis
