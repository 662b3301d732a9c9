// Specification of the piecewise-constant distributions (distribution.h, textbook.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "envmis/sampling/distribution.h"
#include "envmis/study/reference/textbook.h"
#include "maps.h"
#include "stats.h"

namespace envmis {
namespace {

using test::Rng;

// Chi-square tests in this file; each runs at the Sidak level for a 1% family-wise rate.
const double kLevel = test::sidak_level(0.01, 40);

struct Grid {
    uint32_t w, h;
    std::vector<float> func;
};

std::vector<Grid> test_grids() {
    std::vector<Grid> grids;
    grids.push_back({1, 1, {3.0f}});
    grids.push_back({7, 3, test::random_function(21, 1)});
    grids.push_back({64, 32, test::random_function(64 * 32, 2)});
    grids.push_back({33, 17, test::random_function(33 * 17, 3, 8)});  // 8 decades
    Grid sun{48, 24, std::vector<float>(48 * 24, 0.01f)};
    sun.func[5 * 48 + 40] = 1e5f;  // one cell holds nearly all the mass
    grids.push_back(sun);
    Grid rows{16, 16, test::random_function(256, 4)};
    std::fill(rows.func.begin() + 3 * 16, rows.func.begin() + 9 * 16, 0.0f);  // empty rows
    grids.push_back(rows);
    return grids;
}

template <class D>
class Distribution2DTest : public ::testing::Test {};
using Samplers2D = ::testing::Types<Distribution2D, TextbookDistribution2D>;
TYPED_TEST_SUITE(Distribution2DTest, Samplers2D);

TYPED_TEST(Distribution2DTest, SamplesFollowTheFunction) {
    uint64_t seed = 10;
    for (const Grid& g : test_grids()) {
        const TypeParam d(g.func, g.w, g.h);
        const size_t n = std::max<size_t>(50000, 20 * g.func.size());
        std::vector<double> observed(g.func.size()), expected(g.func.size());
        Rng rng(seed++);
        for (size_t i = 0; i < n; ++i) {
            const auto s = d.sample(rng.uniform2());
            ASSERT_EQ(detail::cell_of(s.p.x, g.w), s.x);
            ASSERT_EQ(detail::cell_of(s.p.y, g.h), s.y);
            observed[size_t{s.y} * g.w + s.x] += 1;
        }
        const double sum = std::accumulate(g.func.begin(), g.func.end(), 0.0);
        for (size_t i = 0; i < g.func.size(); ++i) expected[i] = n * g.func[i] / sum;
        const auto chi = test::chi_square(expected, observed);
        EXPECT_GT(chi.p_value, kLevel) << g.w << "x" << g.h << ": " << chi.describe();
    }
}

TYPED_TEST(Distribution2DTest, PdfIntegratesToOne) {
    for (const Grid& g : test_grids()) {
        const TypeParam d(g.func, g.w, g.h);
        // Midpoint rule on a grid 3x finer than the cells: exact for a piecewise-constant pdf.
        const uint32_t nx = 3 * g.w, ny = 3 * g.h;
        double integral = 0;
        for (uint32_t y = 0; y < ny; ++y)
            for (uint32_t x = 0; x < nx; ++x) integral += d.pdf({(x + 0.5f) / nx, (y + 0.5f) / ny});
        EXPECT_NEAR(integral / (static_cast<double>(nx) * ny), 1.0, 1e-3) << g.w << "x" << g.h;
    }
}

TYPED_TEST(Distribution2DTest, SampledPdfEqualsPdfAtThePoint) {
    for (const Grid& g : test_grids()) {
        const TypeParam d(g.func, g.w, g.h);
        Rng rng(7);
        for (int i = 0; i < 20000; ++i) {
            const auto s = d.sample(rng.uniform2());
            ASSERT_EQ(s.pdf, d.pdf(s.p));
            ASSERT_GT(s.pdf, 0.0f);
        }
    }
}

TYPED_TEST(Distribution2DTest, InvertUndoesSample) {
    for (const Grid& g : test_grids()) {
        const TypeParam d(g.func, g.w, g.h);
        Rng rng(8);
        for (int i = 0; i < 20000; ++i) {
            const Vec2 u = rng.uniform2();
            const auto s = d.sample(u);
            const Vec2 back = d.invert(s.p);
            // The point is a float: its position inside a cell is known to n ulps of 1,
            // which the cell's probability scales back into u.
            const float tol_x = 1e-6f + 4 * g.w * 0x1p-24f, tol_y = 1e-6f + 4 * g.h * 0x1p-24f;
            ASSERT_NEAR(back.x, u.x, tol_x) << g.w << "x" << g.h << " u=" << u.x << "," << u.y;
            ASSERT_NEAR(back.y, u.y, tol_y) << g.w << "x" << g.h << " u=" << u.x << "," << u.y;
        }
    }
}

TYPED_TEST(Distribution2DTest, IntegralIsTheMeanOfTheFunction) {
    for (const Grid& g : test_grids()) {
        const TypeParam d(g.func, g.w, g.h);
        const double mean = std::accumulate(g.func.begin(), g.func.end(), 0.0) / g.func.size();
        EXPECT_NEAR(d.integral(), mean, 1e-5 * mean);
        EXPECT_FALSE(d.uniform_fallback());
    }
}

TYPED_TEST(Distribution2DTest, AllZeroFunctionGivesUniformWithFlag) {
    const std::vector<float> zero(12 * 5, 0.0f);
    const TypeParam d(zero, 12, 5);
    EXPECT_TRUE(d.uniform_fallback());
    EXPECT_EQ(d.integral(), 0.0);
    Rng rng(9);
    for (int i = 0; i < 1000; ++i) EXPECT_FLOAT_EQ(d.sample(rng.uniform2()).pdf, 1.0f);
}

TYPED_TEST(Distribution2DTest, RejectsInvalidInput) {
    const std::vector<float> four(4, 1.0f);
    EXPECT_THROW(TypeParam(four, 3, 2), std::invalid_argument);
    EXPECT_THROW(TypeParam(std::vector<float>{}, 0, 0), std::invalid_argument);
    EXPECT_THROW(TypeParam(std::vector<float>(65537, 1.0f), 65537, 1), std::invalid_argument);
    for (float bad : {-1.0f, NAN, INFINITY}) {
        std::vector<float> f = four;
        f[2] = bad;
        EXPECT_THROW(TypeParam(f, 2, 2), std::invalid_argument) << bad;
    }
}

TEST(Distribution2D, ExtremeAspectRatiosWork) {
    for (auto [w, h] : {std::pair{16384u, 1u}, std::pair{1u, 8192u}}) {
        const auto f = test::random_function(size_t{w} * h, 11);
        const Distribution2D d(f, w, h);
        Rng rng(12);
        for (int i = 0; i < 1000; ++i) {
            const auto s = d.sample(rng.uniform2());
            ASSERT_LT(s.x, w);
            ASSERT_LT(s.y, h);
            ASSERT_EQ(s.pdf, d.pdf(s.p));
        }
    }
}

TEST(Distribution2D, KeepsCellsFarBelowFloatResolution) {
    // Cells 1e-12 of their row's mass, after a large one: a float CDF loses them; here
    // they keep a positive pdf (their one unit of 2^-31 is below the 2^-24 grid of a float
    // u, so they are practically never sampled, as their mass says).
    std::vector<float> f(4, 0.0f);
    f[0] = 1e12f, f[1] = 1.0f, f[3] = 1.0f;
    const Distribution2D d(f, 4, 1);
    EXPECT_GT(d.pdf({0.3f, 0.5f}), 0.0f);
    EXPECT_GT(d.pdf({0.8f, 0.5f}), 0.0f);
    EXPECT_EQ(d.pdf({0.6f, 0.5f}), 0.0f);
}

TEST(Distribution2D, ProbabilitiesMatchTheFunctionToFixedPointResolution) {
    const auto f = test::random_function(300 * 200, 13, 6);
    const Distribution2D d(f, 300, 200);
    const double mean = std::accumulate(f.begin(), f.end(), 0.0) / f.size();
    for (uint32_t y = 0; y < 200; ++y)
        for (uint32_t x = 0; x < 300; ++x) {
            const double expected = f[y * 300 + x] / mean;
            // Two fixed-point widths, each within one unit (2^-31) of the ideal probability.
            ASSERT_NEAR(d.pdf({(x + 0.5f) / 300, (y + 0.5f) / 200}), expected, 1e-6 * expected + 300.0 * 200 * 0x1p-30)
                << x << "," << y;
        }
}

TEST(Distribution2D, BuildDoesNotDependOnThreads) {
    // Rows are built in parallel; a second build must give identical tables.
    const auto f = test::random_function(300 * 200, 13);
    const Distribution2D a(f, 300, 200), b(f, 300, 200);
    for (size_t i = 0; i < f.size(); ++i) {
        ASSERT_EQ(a.view().start[i], b.view().start[i]);
        ASSERT_EQ(a.view().guide[i], b.view().guide[i]);
    }
}

// The coarse guide only steers prefetches, on tables beyond the cache; what it must hold
// is every kCoarseGuideStep-th guide entry of each row, the last partial step included.
// Tables of at least kCoarseGuideMinBytes (6 bytes a cell): 2057 x 1400 cells.
constexpr uint32_t kCoarseW = 32 * kCoarseGuideStep + 9, kCoarseH = 1400;

// The tuned sample (distribution.h: prefetches, the coarse guide's prediction, hot rows
// searched from it) is the plain algorithm of cdf.h, sample for sample: the same point,
// pdf and cell, bit for bit, for points across [0,1)^2 and at its edges, on the small
// grids above, on a table large enough for a coarse guide whose sun makes hot rows, and
// on one with empty cells and rows. Rows invert alike too: guided, from the coarse
// guide, and without prefetches.
TEST(Distribution2D, TheTunedSampleIsThePlainSearchBitForBit) {
    std::vector<Grid> grids = test_grids();
    Grid sun{kCoarseW, kCoarseH, test::random_function(size_t{kCoarseW} * kCoarseH, 67, 2)};
    for (uint32_t y = 300; y < 304; ++y)
        for (uint32_t x = 900; x < 1000; ++x) sun.func[size_t{y} * kCoarseW + x] = 1e6f;  // hot rows
    grids.push_back(sun);
    Grid holes{kCoarseW, kCoarseH, test::random_function(size_t{kCoarseW} * kCoarseH, 71, 8)};
    for (size_t i = 0; i < holes.func.size(); i += 3) holes.func[i] = 0;
    std::fill(holes.func.begin(), holes.func.begin() + 5 * kCoarseW, 0.0f);
    grids.push_back(holes);
    const float edges[] = {0.0f, 0x1p-31f, 0.5f, 1 - 0x1p-20f, kOneMinusEpsilon, 1.0f};
    size_t hot = 0;
    for (const Grid& g : grids) {
        const Distribution2D d(g.func, g.w, g.h);
        const Distribution2DView v = d.view();
        const Cdf2DTable& plain = v;
        Rng rng(73);
        for (int i = 0; i < 100000; ++i) {
            const Vec2 u = i < 36 ? Vec2{edges[i % 6], edges[i / 6]} : Vec2{rng.uniform(), rng.uniform()};
            const Distribution2DView::Sample tuned = v.sample(u), reference = plain.search(u);
            ASSERT_EQ(bit_cast<uint32_t>(tuned.p.x), bit_cast<uint32_t>(reference.p.x)) << g.w << "x" << g.h;
            ASSERT_EQ(bit_cast<uint32_t>(tuned.p.y), bit_cast<uint32_t>(reference.p.y)) << g.w << "x" << g.h;
            ASSERT_EQ(bit_cast<uint32_t>(tuned.pdf), bit_cast<uint32_t>(reference.pdf)) << g.w << "x" << g.h;
            ASSERT_EQ(tuned.x, reference.x);
            ASSERT_EQ(tuned.y, reference.y);
            const CellHit r = v.sample_row(u.y);
            hot += v.row_is_hot(r.width);
            const CdfView row = v.row(r.index);
            const CellHit want = row.search(u.x);
            for (const CellHit c : {row.invert(u.x), row.invert<false>(u.x)}) {
                ASSERT_EQ(c.index, want.index);
                ASSERT_EQ(bit_cast<uint32_t>(c.offset), bit_cast<uint32_t>(want.offset));
                ASSERT_EQ(c.width, want.width);
            }
            if (row.coarse) {
                ASSERT_EQ(row.invert_cached(u.x).index, want.index);
            }
        }
    }
    EXPECT_GT(hot, 10000u);  // the sun's rows (and the small grids' one-cell sun) take the hot path
}

TEST(Distribution2D, LargeTablesHoldEveryStepthGuideEntryOfEachRowInTheCoarseGuide) {
    const Distribution2D d(test::random_function(size_t{kCoarseW} * kCoarseH, 31, 6), kCoarseW, kCoarseH);
    const Distribution2DView v = d.view();
    ASSERT_NE(v.coarse, nullptr);
    ASSERT_EQ(v.coarse_row_size(), 33u);
    for (uint32_t y = 0; y < kCoarseH; ++y)
        for (uint32_t j = 0; j < 33; ++j)
            ASSERT_EQ(v.row(y).coarse[j], v.guide[size_t{y} * kCoarseW + j * kCoarseGuideStep]) << y << "," << j;
    EXPECT_EQ(d.bytes(), (size_t{kCoarseW} * kCoarseH + kCoarseH) * 6 + size_t{33} * kCoarseH * 2);
}

TEST(Distribution2D, SmallTablesHaveNoCoarseGuide) {
    const Distribution2D d(test::random_function(1000 * 500, 33), 1000, 500);
    EXPECT_EQ(d.view().coarse, nullptr);
    EXPECT_EQ(d.view().row(7).coarse, nullptr);
    EXPECT_EQ(d.bytes(), (1000 * 500 + 500) * 6);
}

// Its prediction lies in the span of cells between the coarse entries around the
// guide bucket, which holds the answer, whatever the function; where the CDF is linear
// (a constant row) it is the answer itself, give or take one cell.
TEST(Distribution2D, TheCoarsePredictionLiesInTheSpanThatHoldsTheAnswer) {
    const uint32_t w = kCoarseW, h = kCoarseH;
    std::vector<float> f = test::random_function(size_t{w} * h, 37, 8);
    std::fill(f.begin() + w, f.begin() + 2 * w, 1.0f);  // row 1 constant
    const Distribution2D d(f, w, h);
    Rng rng(41);
    for (const uint32_t y : {0u, 1u, 2u, h - 1}) {
        const CdfView row = d.view().row(y);
        for (int i = 0; i < 20000; ++i) {
            const float u = i < 3 ? (i == 0 ? 0.0f : (i == 1 ? 0.5f : kOneMinusEpsilon)) : rng.uniform();
            const uint64_t b = row.bucket_position(unit_of(u));
            const uint32_t j = row.bucket(u) / kCoarseGuideStep;
            const uint32_t first = row.coarse[j], last = (j + 1) * kCoarseGuideStep < w ? row.coarse[j + 1] : w - 1;
            const uint32_t answer = row.invert(u).index, predicted = row.predicted_cell(b);
            ASSERT_LE(first, answer) << y << " " << u;
            ASSERT_LE(answer, last) << y << " " << u;
            ASSERT_LE(first, predicted) << y << " " << u;
            ASSERT_LE(predicted, last) << y << " " << u;
            if (y == 1) {
                ASSERT_LE(std::max(answer, predicted) - std::min(answer, predicted), 1u) << u;
            }
        }
    }
}

// invert_cached starts the search from the coarse entries around the bucket instead of
// the guide's where those are at most a cell apart: rows with a few cells bright enough
// to span many buckets each. It finds the same cell and offset as invert for every
// point, on such rows (with a dim rest, and with empty cells) and on rows where the
// coarse span is never that narrow.
TEST(Distribution2D, ASearchFromTheCoarseGuideFindsWhatTheGuideFinds) {
    const uint32_t w = kCoarseW, h = kCoarseH;
    std::vector<float> f = test::random_function(size_t{w} * h, 43, 8);
    for (uint32_t x = 0; x < w; ++x) f[x] = 1e-3f, f[w + x] = 0;
    for (const uint32_t x : {5u, 700u, w - 1}) f[x] = f[w + x] = 1e3f;  // the last in the row's shorter last step
    const Distribution2D d(f, w, h);
    Rng rng(47);
    size_t narrow = 0;
    for (const uint32_t y : {0u, 1u, 2u, h - 1}) {
        const CdfView row = d.view().row(y);
        for (int i = 0; i < 20000; ++i) {
            const float u = i < 3 ? (i == 0 ? 0.0f : (i == 1 ? 0.5f : kOneMinusEpsilon)) : rng.uniform();
            const CellHit cached = row.invert_cached(u), guided = row.invert(u);
            ASSERT_EQ(cached.index, guided.index) << y << " " << u;
            ASSERT_EQ(cached.offset, guided.offset) << y << " " << u;
            ASSERT_EQ(cached.width, guided.width) << y << " " << u;
            const CdfView::Span s = row.coarse_span(row.bucket(u));
            narrow += s.hi - s.lo <= 1;
        }
    }
    EXPECT_GT(narrow, 30000u);  // rows 0 and 1 mostly start from the coarse guide
}

// A 4096 x 1024 distribution (large enough for a coarse guide) of a rough function
// (eight decades) with every third cell empty, whose neighbours share a start.
Distribution2D rough_with_empty_cells(uint64_t seed) {
    const uint32_t w = 4096, h = 1024;
    std::vector<float> f = test::random_function(size_t{w} * h, seed, 8);
    for (size_t i = 0; i < f.size(); i += 3) f[i] = 0;
    return Distribution2D(f, w, h);
}

// An inversion reports the width of the cell it found, which the sampler's pdf takes
// instead of reading the CDF again: the marginal's, and each row's from the guide and
// from the coarse guide.
TEST(Distribution2D, AnInversionReportsTheWidthOfTheCellItFinds) {
    const Distribution2D d = rough_with_empty_cells(53);
    const Distribution2DView v = d.view();
    ASSERT_NE(v.coarse, nullptr);
    Rng rng(59);
    for (int i = 0; i < 20000; ++i) {
        const Vec2 u{rng.uniform(), rng.uniform()};
        const CellHit r = v.sample_row(u.y);
        ASSERT_EQ(r.width, v.marginal.width(r.index));
        ASSERT_GT(r.width, 0u);
        const CdfView row = v.row(r.index);
        for (const CellHit c : {row.invert(u.x), row.invert_cached(u.x)}) {
            ASSERT_EQ(c.width, row.width(c.index)) << "row " << r.index << " u.x " << u.x;
            ASSERT_GT(c.width, 0u);
        }
    }
}

// invert tries the cells it prefetched before the guide: the cell it finds there is the
// one the guide's search finds, where the coarse guide's prediction is right, next to
// the answer, or far from it (then the guide decides).
TEST(Distribution2D, ASearchNearThePrefetchedCellsFindsWhatTheGuideFinds) {
    const Distribution2D d = rough_with_empty_cells(61);
    const Distribution2DView v = d.view();
    ASSERT_NE(v.coarse, nullptr);
    Rng rng(67);
    size_t near = 0, far = 0;
    for (int i = 0; i < 200000; ++i) {
        const CdfView row = v.row(static_cast<uint32_t>(rng.uniform() * v.h));
        const float u = i < 3 ? (i == 0 ? 0.0f : (i == 1 ? 0.5f : kOneMinusEpsilon)) : rng.uniform();
        const float x = unit_point(u) * static_cast<float>(kCdfUnits);
        const auto t = static_cast<uint32_t>(x);
        const CellHit guided = row.find(row.guide_span(row.bucket_of_unit(t)), x, t), hit = row.invert(u);
        ASSERT_EQ(hit.index, guided.index) << u;
        ASSERT_EQ(hit.offset, guided.offset) << u;
        ASSERT_EQ(hit.width, guided.width) << u;
        uint32_t cell;
        (row.find_near(row.prefetch_unit(t, NoHint{}), t, cell) ? near : far) += 1;
    }
    EXPECT_GT(near, 10000u);  // both ways met (near: 14% on this rough function)
    EXPECT_GT(far, 10000u);
}

// A row is hot (its data stays in cache, so samples in it prefetch nothing) when it holds
// more than kHotRowFactor times the mean row's units. Single calls test it with a product
// (row_is_hot), the AVX2 kernel with a threshold in units (hot_row_units): the same rule,
// on both sides of the threshold, for any number of rows.
TEST(Distribution2D, HotRowsAreTheSameByTheProductAndByTheUnitThreshold) {
    for (uint32_t h : {2u, 3u, 63u, 64u, 65u, 127u, 1000u, 4096u, 5792u, 65535u, 65536u}) {
        std::vector<uint32_t> start(h);
        Distribution2DView d;
        d.h = h, d.marginal = {start.data(), nullptr, h};
        const auto threshold = static_cast<int64_t>((uint64_t{kHotRowFactor} << 31) / h);
        for (const int64_t width :
             {threshold - 2, threshold - 1, threshold, threshold + 1, threshold + 2, int64_t{kCdfUnits}, int64_t{0}}) {
            if (width > int64_t{kCdfUnits}) continue;  // more than a CDF holds (few rows)
            std::fill(start.begin() + 1, start.end(), static_cast<uint32_t>(width));  // row 0's width
            EXPECT_EQ(d.row_is_hot(d.marginal.width(0)), d.marginal.width(0) > d.hot_row_units())
                << "h=" << h << " width=" << width;
        }
    }
}

TEST(Distribution2D, RowFunctionExceptionsReachTheCaller) {
    EXPECT_THROW(Distribution2D(8, 64,
                                [](uint32_t y, std::span<float>) {
                                    if (y == 40) throw std::runtime_error("row 40");
                                }),
                 std::runtime_error);
}

TEST(Distribution1D, SamplesFollowTheFunction) {
    const auto f = test::random_function(500, 14, 5);
    const Distribution1D d(f);
    std::vector<double> observed(f.size()), expected(f.size());
    Rng rng(15);
    const size_t n = 100000;
    for (size_t i = 0; i < n; ++i) {
        const auto s = d.sample(rng.uniform());
        ASSERT_EQ(detail::cell_of(s.x, 500), s.index);
        ASSERT_EQ(s.pdf, d.pdf(s.x));
        observed[s.index] += 1;
    }
    const double sum = std::accumulate(f.begin(), f.end(), 0.0);
    for (size_t i = 0; i < f.size(); ++i) expected[i] = n * f[i] / sum;
    const auto chi = test::chi_square(expected, observed);
    EXPECT_GT(chi.p_value, kLevel) << chi.describe();
}

TEST(Distribution1D, PdfIntegratesToOneAndInvertUndoesSample) {
    const auto f = test::random_function(37, 16);
    const Distribution1D d(f);
    double integral = 0;
    for (int i = 0; i < 37 * 5; ++i) integral += d.pdf((i + 0.5f) / (37 * 5));
    EXPECT_NEAR(integral / (37 * 5), 1.0, 1e-4);
    Rng rng(17);
    for (int i = 0; i < 10000; ++i) {
        const float u = rng.uniform();
        ASSERT_NEAR(d.invert(d.sample(u).x), u, 1e-5f);
    }
}

TEST(Distribution1D, SingleCellAndAllZero) {
    const Distribution1D one(std::vector<float>{2.0f});
    EXPECT_EQ(one.sample(0.3f).index, 0u);
    EXPECT_FLOAT_EQ(one.sample(0.3f).x, 0.3f);
    EXPECT_FLOAT_EQ(one.pdf(0.7f), 1.0f);
    const Distribution1D zero(std::vector<float>(5, 0.0f));
    EXPECT_TRUE(zero.uniform_fallback());
    EXPECT_FLOAT_EQ(zero.pdf(0.5f), 1.0f);
}

// Points outside [0,1) sample as the nearest point inside it (NaN as 0) instead of reading
// outside the tables: 1.0 is what a float conversion of a random integer can round to.
TEST(Distribution2D, PointsOutsideTheUnitSquareSampleAsTheNearestPointInside) {
    const Distribution2D d(test::random_function(37 * 19, 61), 37, 19);
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    const std::pair<float, float> cases[] = {{1.0f, kOneMinusEpsilon},
                                             {2.0f, kOneMinusEpsilon},
                                             {inf, kOneMinusEpsilon},
                                             {-0.5f, 0.0f},
                                             {-inf, 0.0f},
                                             {nan, 0.0f}};
    for (const auto& [outside, inside] : cases) {
        for (const Vec2 u : {Vec2{outside, 0.3f}, Vec2{0.3f, outside}, Vec2{outside, outside}}) {
            const Vec2 clamped{u.x == 0.3f ? 0.3f : inside, u.y == 0.3f ? 0.3f : inside};
            const auto got = d.sample(u), expected = d.sample(clamped);
            EXPECT_EQ(got.x, expected.x) << outside;
            EXPECT_EQ(got.y, expected.y) << outside;
            EXPECT_EQ(got.pdf, expected.pdf) << outside;
        }
        const Distribution1D one(std::vector<float>{1, 0, 3, 2});
        EXPECT_EQ(one.sample(outside).index, one.sample(inside).index) << outside;
    }
}

// The point of a sample is the float nearest (index + offset) / n inside cell `index`.
// Power-of-two n take a float-only path: it must give the very same float.
TEST(PointInCell, IsTheNearestFloatInsideTheCellForEverySize) {
    const auto reference = [](uint32_t index, float offset, uint32_t n) {
        float x = static_cast<float>((index + static_cast<double>(offset)) / n);
        while (detail::cell_of(x, n) > index) x = std::nextafter(x, 0.0f);
        while (detail::cell_of(x, n) < index) x = std::nextafter(x, 1.0f);
        return std::min(x, kOneMinusEpsilon);  // cell_of counts 1 in the last cell
    };
    Rng rng(17);
    for (uint32_t n : {1u, 2u, 3u, 7u, 64u, 1000u, 1024u, 4096u, 8191u, 8192u, 65535u, 65536u}) {
        for (int i = 0; i < 20000; ++i) {
            const uint32_t index = std::min(static_cast<uint32_t>(rng.uniform() * n), n - 1);
            // At the edges, a few float ulps of x from them (where rounding x can cross an
            // edge), and anywhere.
            const float near_edge = static_cast<float>(n) * 0x1p-24f * (0.25f + 2 * rng.uniform());
            const float offsets[5] = {kOneMinusEpsilon, 0.0f, near_edge, 1.0f - near_edge, rng.uniform()};
            const float offset = std::min(offsets[i % 5], kOneMinusEpsilon);
            const float x = detail::point_in_cell(index, offset, n);
            ASSERT_EQ(x, reference(index, offset, n)) << "n=" << n << " index=" << index << " offset=" << offset;
            ASSERT_EQ(detail::cell_of(x, n), index);
        }
    }
}

// Points are placed with a multiplication by 1/n where the division would wait longer;
// the two differ exactly when the quotient lies next to a midpoint between floats,
// which is where the helper must fall back on the division. Quotients are aimed at
// such midpoints (a few double ulps off), and the test checks that it met cases where
// the product alone rounds the other way.
TEST(QuotientToFloat, RoundsAsTheDoubleDivisionEvenNextToMidpointsBetweenFloats) {
    Rng rng(29);
    int product_alone_wrong = 0;
    for (int i = 0; i < 200000; ++i) {
        const uint32_t n = static_cast<uint32_t>(rng.engine()() % 65536) + 1;
        const float f = rng.uniform(), next = std::nextafter(f, 2.0f);
        double a = (static_cast<double>(f) + next) / 2 * n;
        for (int step = static_cast<int>(rng.engine()() % 33) - 16; step != 0; step -= step > 0 ? 1 : -1)
            a = std::nextafter(a, step > 0 ? 1e300 : -1e300);
        if (i % 4 == 1) a = (rng.uniform() + static_cast<double>(rng.uniform()) * 0x1p-24) * n;  // anywhere
        if (i % 4 == 3) {  // next to a midpoint between subnormal floats
            const auto bits = static_cast<uint32_t>(rng.engine()() % ((1u << 23) - 1)) + 1;
            a = (bit_cast<float>(bits) + static_cast<double>(bit_cast<float>(bits + 1))) / 2 * n;
            a = std::nextafter(a, rng.uniform() < 0.5f ? 0.0 : 1e300);
        }
        const float expected = static_cast<float>(a / n);
        product_alone_wrong += static_cast<float>(a * (1.0 / n)) != expected;
        ASSERT_EQ(detail::quotient_to_float(a, n), expected) << "a=" << a << " n=" << n;
    }
    EXPECT_GT(product_alone_wrong, 50);
}

TEST(Distribution1D, RejectsInvalidInput) {
    EXPECT_THROW(Distribution1D(std::vector<float>{}), std::invalid_argument);
    EXPECT_THROW(Distribution1D(std::vector<float>(65537, 1.0f)), std::invalid_argument);
    EXPECT_THROW(Distribution1D(std::vector<float>{1.0f, -0.5f}), std::invalid_argument);
    EXPECT_THROW(Distribution1D(std::vector<float>{NAN}), std::invalid_argument);
}

}  // namespace
// A NaN coordinate (a NaN direction's) must not become an integer by an undefined
// conversion (UBSan: float-cast-overflow); out-of-range ones clamp.
TEST(Distribution, CellOfANaNOrOutOfRangeCoordinateIsAnEdgeCell) {
    EXPECT_EQ(detail::cell_of(std::nanf(""), 16), 0u);
    EXPECT_EQ(detail::cell_of(-3.0f, 16), 0u);
    EXPECT_EQ(detail::cell_of(7.0f, 16), 15u);
    EXPECT_EQ(detail::cell_of(std::numeric_limits<float>::infinity(), 16), 15u);
}

}  // namespace envmis
