// Internal: the fixed-point CDFs of cdf.h and distribution.h searched for eight lanes in
// AVX2 by gathers, each lane in a CDF of its own (at start + base_i, n_i cells), and the
// rest of a sample or lookup that the batch kernels of envmap_many.cpp and
// binned_many.cpp share. The same IEEE operations in the same order as the scalar code,
// so that every lane's result is bit-identical to the scalar call's.
#pragma once

#include <algorithm>

#include "detail/simd.h"
#include "envmis/sampling/binned.h"
#include "envmis/sampling/envmap.h"

#ifdef ENVMIS_AVX2_BATCHES
namespace envmis::simd {

// Cell i of the CDF at start + base, n >= 2 cells: its first unit and CdfView::width, the
// next start (kCdfUnits after the last cell) minus this one, from one pair gather at
// j = min(i, n - 2), which stays inside the table (the last cell's start is then the
// pair's second value).
struct Span8 {
    I8 start, width;
};
ENVMIS_AVX2 inline Span8 span8(const uint32_t* start, I8 base, I8 i, I8 n) noexcept {
    const I8 j = _mm256_min_epu32(i, n - 2u);
    const Pair8 p = gather_pairs(start, base + j);
    const M8 inside = i == j;  // not the last cell
    const I8 first = select(inside, p.first, p.second), end = select(inside, p.second, I8(kCdfUnits));
    return {first, end - first};
}
// The same for a CDF of n >= 1 cells, n the same in every lane.
ENVMIS_AVX2 inline Span8 span8(const uint32_t* start, I8 base, I8 i, uint32_t n) noexcept {
    if (n == 1) {  // i = 0
        const I8 first = gather(start, base);
        return {first, I8(kCdfUnits) - first};
    }
    return span8(start, base, i, I8(n));
}

// Widths to float, as static_cast<float>(uint32_t): a width is at most 2^31, which as a
// signed 32-bit value is -2^31 and converts exactly; adding 2^32 then gives 2^31.
ENVMIS_AVX2 inline F8 width_to_float(I8 w) noexcept {
    const F8 f = to_float(w);
    return f + select(f < 0.0f, 0x1p32f, 0.0f);
}

// The radiance of eight texels (row-major indices), stored from lane l on.
ENVMIS_AVX2 inline void store_radiance8(const Rgb* radiance, I8 texel, float* r, float* g, float* b,
                                        uint32_t l) noexcept {
    const I8 three = texel + texel + texel;
    const float* rgb = &radiance->r;
    const Pair8 rg = gather_pairs(rgb, three);
    store(r + l, from_bits(rg.first));
    store(g + l, from_bits(rg.second));
    store(b + l, _mm256_i32gather_ps(rgb + 2, three, 4));
}

// Lanes [0, n - n % 8) in groups of eight, up to eight groups at a time: start(first)
// for each of them (it finds what its group will read, prefetches it and returns where
// it is), then finish(started, first) for each, so that the cache misses of all of them
// overlap. Without the staging, three quarters of lookup_avx2's time went waiting on
// its first radiance gather; eight groups rather than four took a 1k map's batch lookup
// a third faster (measured: docs/performance-log.md, 'kGroups'). Returns n - n % 8.
inline constexpr uint32_t kGroups = 8;
template <class Start, class Finish>
ENVMIS_AVX2 uint32_t in_staged_groups(uint32_t n, Start&& start, Finish&& finish) noexcept {
    const uint32_t whole = n - n % 8;
    for (uint32_t first = 0; first < whole; first += 8 * kGroups) {
        const uint32_t groups = std::min(kGroups, (whole - first) / 8);
        decltype(start(first)) started[kGroups];
        for (uint32_t k = 0; k < groups; ++k) started[k] = start(first + 8 * k);
        for (uint32_t k = 0; k < groups; ++k) finish(started[k], first + 8 * k);
    }
    return whole;
}

// Eight units u of CdfView::invert over n_i cells: u in CDF units (x), its integer part
// t and its guide bucket k = t n / 2^31 (from 64-bit products of the even and odd lanes).
struct Unit8 {
    F8 x;
    I8 t, k;
};
ENVMIS_AVX2 inline Unit8 unit8(F8 u, I8 n) noexcept {
    // unit_point, in CDF units; x < 2^31, so truncate's signed conversion is exact.
    const F8 x = select(u > 0.0f, min(u, kOneMinusEpsilon), 0.0f) * static_cast<float>(kCdfUnits);
    const I8 t = truncate(x);
    const I8 even = _mm256_srli_epi64(_mm256_mul_epu32(t, n), 31);
    const I8 odd = _mm256_slli_epi64(
        _mm256_srli_epi64(_mm256_mul_epu32(_mm256_srli_epi64(t, 32), _mm256_srli_epi64(n, 32)), 31), 32);
    return {x, t, _mm256_min_epu32(_mm256_blend_epi32(even, odd, 0xAA), n - 1u)};
}
ENVMIS_AVX2 inline Unit8 unit8(F8 u, uint32_t n) noexcept { return unit8(u, I8(n)); }

// The rest of CdfView::invert for eight units, lane i searching the CDF of n_i >= 2
// cells at start + base_i (guide likewise): the cell index and the offset in it.
struct Hit8 {
    I8 index;
    F8 offset;
    I8 width;  // of the cell
};
ENVMIS_AVX2 inline Hit8 search8(const uint32_t* start, const uint16_t* guide, I8 base, I8 n,
                                const Unit8& unit) noexcept {
    const I8 t = unit.t, k = unit.k;
    // guide[k] and guide[k + 1] (or n - 1 after the last bucket) from one 32-bit gather of
    // the pair at j = min(k, n - 2), which stays inside the guide's n entries.
    const I8 j = _mm256_min_epu32(k, n - 2u);
    const I8 pair = _mm256_i32gather_epi32(reinterpret_cast<const int*>(guide), base + j, 2);
    const M8 inside = k == j;
    I8 lo = select(inside, pair & 0xffffu, pair >> 16), hi = select(inside, pair >> 16, n - 1u);
    // The scalar search, all lanes in step: a lane whose lo = hi keeps them (mid = lo,
    // whose start is <= t), so the loop runs until the longest search ends.
    for (;;) {
        const I8 open = _mm256_cmpgt_epi32(hi, lo);
        if (_mm256_testz_si256(open, open)) break;
        const I8 mid = (lo + hi + 1u) >> 1;
        const M8 at_most_t = I8(_mm256_max_epu32(gather(start, base + mid), t)) == t;  // unsigned start <= t
        lo = select(at_most_t, mid, lo);
        hi = select(at_most_t, hi, mid - 1u);
    }
    const Span8 cell = span8(start, base, lo, n);
    const F8 offset =
        (to_float(t - cell.start) + (unit.x - to_float(t))) / width_to_float(cell.width);  // t - start < 2^31
    return {lo, min(offset, kOneMinusEpsilon), cell.width};
}
ENVMIS_AVX2 inline Hit8 search8(const uint32_t* start, const uint16_t* guide, I8 base, uint32_t n,
                                const Unit8& unit) noexcept {
    return search8(start, guide, base, I8(n), unit);
}

// detail::ExactDivision::of for eight lanes, each with its own divisor's m < 2^29 and
// k < 64 in its own 32-bit lane: (n m) >> k from 64-bit products of the even lanes and
// of the odd ones (shifted down).
ENVMIS_AVX2 inline I8 divide8(I8 n, I8 m, I8 k) noexcept {
    const __m256i low = _mm256_set1_epi64x(0xffffffff);
    const I8 even = _mm256_srlv_epi64(_mm256_mul_epu32(n, m), _mm256_and_si256(k, low));
    const I8 odd = _mm256_srlv_epi64(_mm256_mul_epu32(_mm256_srli_epi64(n, 32), _mm256_srli_epi64(m, 32)),
                                     _mm256_srli_epi64(k, 32));
    return _mm256_blend_epi32(even, _mm256_slli_epi64(odd, 32), 0xAA);
}
ENVMIS_AVX2 inline I8 divide8(I8 n, const detail::ExactDivision& d) noexcept {
    return divide8(n, I8(static_cast<uint32_t>(d.m)), I8(d.k));
}

// EnvMapView::at for eight image points with their image-space density: the direction
// and its solid-angle pdf.
struct Direction8 {
    Vec3x8 d;
    F8 pdf;
};
ENVMIS_AVX2_FLAT inline Direction8 at8(const EnvMapView& env, Vec2x8 p, F8 image_pdf) noexcept {
    if (env.mapping == Mapping::equal_area)
        return {to_world<F8>(env.axes, equal_area_direction<F8>(p)), image_pdf * (1 / kFourPi)};
    const SinCos8 theta = sincos_half_turns(env.turns, p.y), phi = sincos_turns(env.turns, p.x);
    const Vec3x8 canonical{theta.sin * phi.cos, theta.sin * phi.sin, theta.cos};
    return {to_world<F8>(env.axes, canonical), EnvMapView::solid_angle_pdf(image_pdf, theta.sin)};
}

// EnvMapView::uv_of for the eight directions from lane l on.
ENVMIS_AVX2_FLAT inline Vec2x8 uv8(const EnvMapView& env, DirectionArrays in, uint32_t l) noexcept {
    const Vec3x8 d = to_canonical<F8>(env.axes, {load(in.x + l), load(in.y + l), load(in.z + l)});
    return env.mapping == Mapping::equal_area ? equal_area_uv<F8>(d) : equirect_uv<F8>(d);
}

// Stores of one sample's eight lanes from lane l on (the image point's where asked for).
ENVMIS_AVX2 inline void store_sample8(const EnvMapView& env, Vec2x8 p, const Direction8& e, I8 texel, SampleArrays out,
                                      uint32_t l) noexcept {
    if (out.u) store(out.u + l, p.x);
    if (out.v) store(out.v + l, p.y);
    store(out.x + l, e.d.x);
    store(out.y + l, e.d.y);
    store(out.z + l, e.d.z);
    store(out.pdf + l, e.pdf);
    store_radiance8(env.radiance, texel, out.r, out.g, out.b, l);
}

// The eight lanes of v from lane 0 on, to address a lane's data in scalar code.
struct Lanes8 {
    alignas(32) uint32_t at[8];
    ENVMIS_AVX2 explicit Lanes8(I8 v) noexcept { _mm256_store_si256(reinterpret_cast<__m256i*>(at), v); }
};

}  // namespace envmis::simd
#endif
