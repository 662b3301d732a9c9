// The AVX2 placement of sample_many's points (lib/core/src/detail/cell8.h) against the
// scalar detail::point_in_cell, lane by lane and bit for bit, where its rare branches
// decide: offsets at a cell's edges, quotients next to a midpoint between floats, and
// quotients below 2^-126. Random points of a map reach the midpoint branch about once in
// 2^24 samples, too rarely for the sampling tests to meet it. Builds without the AVX2
// path have no such tests.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "detail/cell8.h"
#include "envmis/cpu.h"
#include "stats.h"

#ifdef ENVMIS_AVX2_BATCHES
namespace envmis {
namespace {

using test::Rng;

struct Lanes {
    std::vector<uint32_t> index;
    std::vector<float> offset;
    void add(uint32_t i, float o) { index.push_back(i), offset.push_back(std::min(o, kOneMinusEpsilon)); }
};

// point_in_cell8 over the lanes, eight at a time (the last group padded with cell 0).
ENVMIS_AVX2 std::vector<float> points8(const Lanes& lanes, uint32_t n) {
    std::vector<uint32_t> index = lanes.index;
    std::vector<float> offset = lanes.offset, out(index.size() + 8);
    index.resize(index.size() + 8), offset.resize(offset.size() + 8);
    for (size_t l = 0; l < lanes.index.size(); l += 8) {
        simd::store(out.data() + l,
                    simd::point_in_cell8(simd::load(index.data() + l), simd::load(offset.data() + l), n));
    }
    out.resize(lanes.index.size());
    return out;
}

// Every lane's point has the scalar call's bits.
void expect_scalar_points(const Lanes& lanes, uint32_t n) {
    const std::vector<float> points = points8(lanes, n);
    for (size_t l = 0; l < points.size(); ++l)
        ASSERT_EQ(bit_cast<uint32_t>(points[l]),
                  bit_cast<uint32_t>(detail::point_in_cell(lanes.index[l], lanes.offset[l], n)))
            << "n=" << n << " index=" << lanes.index[l] << " offset=" << lanes.offset[l];
}

// The lanes where the quotient's product with 1/n rounds to another float than the
// division: where point_in_cell8 must divide.
int product_alone_wrong(const Lanes& lanes, uint32_t n) {
    int wrong = 0;
    for (size_t l = 0; l < lanes.index.size(); ++l) {
        const double sum = lanes.index[l] + static_cast<double>(lanes.offset[l]);
        wrong += static_cast<float>(sum * (1.0 / n)) != static_cast<float>(sum / n);
    }
    return wrong;
}

// The float offset that puts (index + offset) / n on the midpoint between float f and
// the next float up, and the offsets four ulps either side of it. For f in [0.5, 1) the
// midpoint is an odd multiple of 2^-25, and so is the midpoint times n minus index: for
// an offset in [0.25, 0.5), a float, the quotient lands on the midpoint exactly.
void add_aimed_at_midpoint(Lanes& lanes, uint32_t index, uint32_t n, float f) {
    const double midpoint = (static_cast<double>(f) + std::nextafter(f, 2.0f)) / 2;
    const double target = midpoint * n - index;
    if (!(target >= 0 && target < 1)) return;
    float o = static_cast<float>(target);
    for (int k = 0; k < 4; ++k) o = std::nextafter(o, 0.0f);
    for (int k = 0; k < 9; ++k, o = std::nextafter(o, 1.0f)) lanes.add(index, o);
}

class PointInCell8 : public ::testing::Test {
protected:
    void SetUp() override {
        if (!cpu_info().avx2) GTEST_SKIP() << "no AVX2 on this CPU";
    }
};

TEST_F(PointInCell8, PlacesEveryLaneAsTheScalarCodeAtEdgesAndAnywhere) {
    Rng rng(41);
    for (uint32_t n : {1u, 2u, 3u, 7u, 64u, 1000u, 1024u, 4096u, 5792u, 8191u, 8192u, 65535u, 65536u}) {
        Lanes lanes;
        for (int i = 0; i < 8000; ++i) {
            const uint32_t index = std::min(static_cast<uint32_t>(rng.uniform() * n), n - 1);
            const float near_edge = static_cast<float>(n) * 0x1p-24f * (0.25f + 2 * rng.uniform());
            const float offsets[5] = {kOneMinusEpsilon, 0.0f, near_edge, 1.0f - near_edge, rng.uniform()};
            lanes.add(index, offsets[i % 5]);
        }
        expect_scalar_points(lanes, n);
    }
}

TEST_F(PointInCell8, DividesWhereTheProductWithTheReciprocalRoundsTheOtherWay) {
    Rng rng(43);
    int wrong = 0;
    for (int round = 0; round < 40; ++round) {
        const uint32_t n = 32769 + 2 * static_cast<uint32_t>(rng.engine()() % 16383);  // odd: not a power of two
        Lanes lanes;
        for (int i = 0; i < 2000; ++i) {
            const uint32_t index = n / 2 + static_cast<uint32_t>(rng.engine()() % (n / 2));
            const double offset = 0.3 + 0.15 * rng.uniform();
            add_aimed_at_midpoint(lanes, index, n, static_cast<float>((index + offset) / n));
        }
        wrong += product_alone_wrong(lanes, n);
        expect_scalar_points(lanes, n);
    }
    EXPECT_GT(wrong, 1000);  // the test met the branch it is for
}

// Quotients below 2^-126 (cell 0, offsets below 2^-126 n) round to subnormal floats, whose
// midpoints lie elsewhere in a double's bits than where the guard of the test above looks.
// A float offset is a multiple of 2^-149, so the quotient is either exactly on a subnormal
// midpoint or at least 2^-40 of its size away from one: only the exact hits can round
// the other way by the product. For n = 2^s m (s >= 1, m odd) they are the offsets
// (2j + 1) m 2^(s - 150) with (2j + 1) m < 2^24 (odd n have none); the lanes hold all of them, and random
// tiny offsets. For n = 98 and 246 the product alone rounds wrongly in tens of thousands.
TEST_F(PointInCell8, DividesBelowTheSmallestNormalFloat) {
    Rng rng(47);
    int wrong = 0;
    for (uint32_t n : {98u, 246u, 1000u, 5792u}) {
        const int s = __builtin_ctz(n);
        const uint32_t m = n >> s;
        Lanes lanes;
        for (uint32_t odd = 1; odd * m < (1u << 24); odd += 2)
            lanes.add(0, std::ldexp(static_cast<float>(odd * m), s - 150));
        for (int i = 0; i < 2000; ++i)  // below 2^-100
            lanes.add(0, bit_cast<float>(static_cast<uint32_t>(rng.engine()() % (27u << 23)) + 1));
        wrong += product_alone_wrong(lanes, n);
        expect_scalar_points(lanes, n);
    }
    EXPECT_GT(wrong, 1000);  // the test met the branch it is for
}

}  // namespace
}  // namespace envmis
#endif
