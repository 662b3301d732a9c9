// lookup_many and sample_many (envmap.h): EnvMapView::lookup and EnvMapView::sample
// for many directions or random points, on the path envmis/cpu.h chooses for the CPU.
//
// The scalar paths call the single calls' own functions, split into the stages of
// detail/pipeline.h: bit-identical to the single calls by construction.
//
// The AVX2 paths (eight lanes at a time, hardware gathers) map, turn angles and convert
// densities with the single calls' own functions, instantiated on eight lanes
// (detail/simd.h). What they write apart is the CDF search by gathers (span8, unit8,
// search8: CdfView::width and invert, Distribution2DView::pdf_of) and the placement
// (detail/cell8.h): the same IEEE operations in the same order as the scalar code, so
// every lane's result is bit-identical to the scalar call (tests/core/sampling/
// envmap_test.cpp checks it on maps of several sizes, in both mappings and several axes,
// at the poles, the seam and the last column, on every path the CPU has).
#include "envmis/sampling/envmap.h"

#include <algorithm>

#include "detail/cell8.h"
#include "detail/pipeline.h"
#include "detail/simd.h"
#include "envmis/cpu.h"

namespace envmis {
namespace {

// How many lanes ahead the first stage of the scalar paths runs: the misses in flight.
// Fewer for samples, whose second stage's misses are fewer and nearer the first's
// (measured: docs/performance-log.md, 'kLookupDistance').
constexpr uint32_t kLookupDistance = 32, kSampleDistance = 16;

void lookup_scalar(const EnvMapView& env, DirectionArrays in, LookupArrays out, uint32_t first, uint32_t n) noexcept {
    detail::pipelined<kLookupDistance>(
        first, n,
        [&](uint32_t l) noexcept {
            const Vec2 uv = env.uv_of({in.x[l], in.y[l], in.z[l]});
            env.prefetch_uv(uv);
            return uv;
        },
        [&](Vec2 uv, uint32_t l) noexcept {
            const Rgb c = env.eval_uv(uv);
            out.r[l] = c.r, out.g[l] = c.g, out.b[l] = c.b, out.pdf[l] = env.pdf_uv(uv);
        });
}

// What the column search in row y reads for unit t (unit_of): the guide entry, the CDF
// where CdfView::invert would prefetch it, and the radiance there.
void prefetch_column(const EnvMapView& env, uint32_t y, uint32_t t) noexcept {
    const CdfView row = env.distribution.row(y);
    const size_t row_start = static_cast<size_t>(y) * env.distribution.w;
    ENVMIS_PREFETCH(row.guide + row.bucket_of_unit(t));
    row.prefetch_unit(
        t, [&](uint32_t first, uint32_t last) { env.prefetch_radiance(row_start + first, row_start + last); });
}

// EnvMapView::sample in the two stages of Distribution2DView::sample: the row (the
// marginal is small and stays in cache) with the column's prefetches (none in hot rows:
// Distribution2DView::row_is_hot); then the column and the rest.
CellHit find_row(const EnvMapView& env, Vec2 u) noexcept {
    const Distribution2DView& d = env.distribution;
    const CellHit r = d.sample_row(u.y);
    if (!d.row_is_hot(r.width)) prefetch_column(env, r.index, unit_of(u.x));
    return r;
}

EnvSample sample_in_row(const EnvMapView& env, CellHit r, Vec2 u) noexcept {
    const auto s =
        env.distribution.sample_in_row(r, u.x, [&](size_t first, size_t last) { env.prefetch_radiance(first, last); });
    return env.at(s.p, s.pdf, static_cast<size_t>(s.y) * env.distribution.w + s.x);
}

void sample_scalar(const EnvMapView& env, PointArrays in, SampleArrays out, uint32_t first, uint32_t n) noexcept {
    detail::pipelined<kSampleDistance>(
        first, n,
        [&](uint32_t l) noexcept {
            return find_row(env, {in.x[l], in.y[l]});
        },
        [&](CellHit r, uint32_t l) noexcept {
            const EnvSample e = sample_in_row(env, r, {in.x[l], in.y[l]});
            out.x[l] = e.direction.x, out.y[l] = e.direction.y, out.z[l] = e.direction.z, out.pdf[l] = e.pdf;
            out.r[l] = e.radiance.r, out.g[l] = e.radiance.g, out.b[l] = e.radiance.b;
            if (out.u) out.u[l] = e.uv.x;
            if (out.v) out.v[l] = e.uv.y;
        });
}

#ifdef ENVMIS_AVX2_BATCHES
using namespace simd;

// The SIMD path's precondition: 32-bit gather indices for the three floats of every texel.
bool avx2_applies(const EnvMapView& env) noexcept {
    return uint64_t{env.distribution.w} * env.distribution.h * 3 < (uint64_t{1} << 31);
}

// Cell i of the CDF at `start`, n cells: its first unit and CdfView::width, the next
// start (kCdfUnits after the last cell) minus this one; for n >= 2 one pair gather at
// j = min(i, n - 2), which stays inside the table (the last cell's start is then the
// pair's second value).
struct Span8 {
    I8 start, width;
};
ENVMIS_AVX2 Span8 span8(const uint32_t* start, I8 base, I8 i, uint32_t n) noexcept {
    I8 first, end = kCdfUnits;
    if (n == 1) {  // i = 0
        first = gather(start, base);
    } else {
        const I8 j = _mm256_min_epu32(i, I8(n - 2));
        const Pair8 p = gather_pairs(start, base + j);
        const M8 inside = i == j;  // not the last cell
        first = select(inside, p.first, p.second);
        end = select(inside, p.second, end);
    }
    return {first, end - first};
}

// Widths to float, as static_cast<float>(uint32_t): a width is at most 2^31, which as a
// signed 32-bit value is -2^31 and converts exactly; adding 2^32 then gives 2^31.
ENVMIS_AVX2 F8 width_to_float(I8 w) noexcept {
    const F8 f = to_float(w);
    return f + select(f < 0.0f, 0x1p32f, 0.0f);
}

// Distribution2DView::pdf_of: a cell's image-space density from its row's and its own
// widths.
ENVMIS_AVX2 F8 image_pdf8(const Distribution2DView& d, I8 row_width, I8 cell_width) noexcept {
    return width_to_float(row_width) * width_to_float(cell_width) * d.pdf_scale;
}

// The radiance of eight texels (row-major indices), stored from lane l on.
ENVMIS_AVX2 void store_radiance8(const Rgb* radiance, I8 texel, float* r, float* g, float* b, uint32_t l) noexcept {
    const I8 three = texel + texel + texel;
    const float* rgb = &radiance->r;
    const Pair8 rg = gather_pairs(rgb, three);
    store(r + l, from_bits(rg.first));
    store(g + l, from_bits(rg.second));
    store(b + l, _mm256_i32gather_ps(rgb + 2, three, 4));
}

// Where eight directions fall: their cells, the first texel of their rows (y w) and
// the image v (for sin theta, on equirect maps).
struct Cells8 {
    I8 x, y, row;
    F8 v;
};

// EnvMapView::uv_of and the cells of eval_uv and pdf_uv (envmap.h), for the eight
// directions from lane l on; starts loading all that fetch8 reads there (prefetch_cell).
// Both lines of a texel that straddles two, and the next CDF entry's where it starts a
// line: a gather waits for its slowest lane, and with one line a texel prefetched, most
// groups of eight had a lane whose line nobody had asked for (measured:
// docs/performance-log.md, 'locate8').
ENVMIS_AVX2_FLAT Cells8 locate8(const EnvMapView& env, DirectionArrays in, uint32_t l) noexcept {
    const Vec3x8 d = to_canonical<F8>(env.axes, {load(in.x + l), load(in.y + l), load(in.z + l)});
    const Vec2x8 p = env.mapping == Mapping::equal_area ? equal_area_uv<F8>(d) : equirect_uv<F8>(d);
    const I8 x = cell8(p.x, env.distribution.w), y = cell8(p.y, env.distribution.h);
    alignas(32) uint32_t column[8], row[8];
    _mm256_store_si256(reinterpret_cast<__m256i*>(column), x);
    _mm256_store_si256(reinterpret_cast<__m256i*>(row), y);
    for (int lane = 0; lane < 8; ++lane) env.prefetch_cell(column[lane], row[lane]);
    return {x, y, y * I8(env.distribution.w), p.y};
}

// Radiance and solid-angle pdf at eight located directions, stored from lane l on.
ENVMIS_AVX2_FLAT void fetch8(const EnvMapView& env, const Cells8& c, LookupArrays out, uint32_t l) noexcept {
    const Distribution2DView& d = env.distribution;
    store_radiance8(env.radiance, c.row + c.x, out.r, out.g, out.b, l);
    const I8 row_width = span8(d.marginal.start, I8(0u), c.y, d.h).width;
    store(out.pdf + l, env.image_to_solid_angle(image_pdf8(d, row_width, span8(d.start, c.row, c.x, d.w).width), c.v));
}

// Lanes [0, n - n % 8) in groups of eight, up to four groups at a time: start(first)
// for each of them (it finds what its group will read, prefetches it and returns where
// it is), then finish(started, first) for each, so that the cache misses of all four
// overlap. Without the staging, three quarters of lookup_avx2's time went waiting on
// its first radiance gather. Returns n - n % 8.
template <class Start, class Finish>
ENVMIS_AVX2 uint32_t in_staged_groups(uint32_t n, Start&& start, Finish&& finish) noexcept {
    constexpr uint32_t kGroups = 4;
    const uint32_t whole = n - n % 8;
    for (uint32_t first = 0; first < whole; first += 8 * kGroups) {
        const uint32_t groups = std::min(kGroups, (whole - first) / 8);
        decltype(start(first)) started[kGroups];
        for (uint32_t k = 0; k < groups; ++k) started[k] = start(first + 8 * k);
        for (uint32_t k = 0; k < groups; ++k) finish(started[k], first + 8 * k);
    }
    return whole;
}

ENVMIS_AVX2 uint32_t lookup_avx2(const EnvMapView& env, DirectionArrays in, LookupArrays out, uint32_t n) noexcept {
    return in_staged_groups(
        n, [&](uint32_t first) ENVMIS_AVX2 { return locate8(env, in, first); },
        [&](const Cells8& cells, uint32_t first) ENVMIS_AVX2 { fetch8(env, cells, out, first); });
}

// Eight units u of CdfView::invert over n cells: u in CDF units (x), its integer part t
// and its guide bucket k = t n / 2^31 (from 64-bit products of the even and odd lanes).
struct Unit8 {
    F8 x;
    I8 t, k;
};
ENVMIS_AVX2 Unit8 unit8(F8 u, uint32_t n) noexcept {
    // unit_point, in CDF units; x < 2^31, so truncate's signed conversion is exact.
    const F8 x = select(u > 0.0f, min(u, kOneMinusEpsilon), 0.0f) * static_cast<float>(kCdfUnits);
    const I8 t = truncate(x);
    const I8 nn(n);
    const I8 even = _mm256_srli_epi64(_mm256_mul_epu32(t, nn), 31);
    const I8 odd = _mm256_slli_epi64(_mm256_srli_epi64(_mm256_mul_epu32(_mm256_srli_epi64(t, 32), nn), 31), 32);
    return {x, t, _mm256_min_epu32(_mm256_blend_epi32(even, odd, 0xAA), I8(n - 1))};
}

// The rest of CdfView::invert for eight units, lane i searching the CDF of n >= 2 cells
// at start + base_i (guide likewise): the cell index and the offset in it.
struct Hit8 {
    I8 index;
    F8 offset;
    I8 width;  // of the cell
};
ENVMIS_AVX2 Hit8 search8(const uint32_t* start, const uint16_t* guide, I8 base, uint32_t n,
                         const Unit8& unit) noexcept {
    const I8 t = unit.t, k = unit.k;
    // guide[k] and guide[k + 1] (or n - 1 after the last bucket) from one 32-bit gather of
    // the pair at j = min(k, n - 2), which stays inside the guide's n entries.
    const I8 j = _mm256_min_epu32(k, I8(n - 2));
    const I8 pair = _mm256_i32gather_epi32(reinterpret_cast<const int*>(guide), base + j, 2);
    const M8 inside = k == j;
    I8 lo = select(inside, pair & 0xffffu, pair >> 16), hi = select(inside, pair >> 16, I8(n - 1));
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

// Eight points of EnvMapView::sample with their rows found (the marginal is small and
// stays in cache) and their columns' guide bucket.
struct Rows8 {
    Hit8 r;
    I8 row;  // r.index w: the row's first cell
    Unit8 column;
};

// The rows of the eight points from lane l on; starts loading what the column search
// reads (prefetch_column) in the lanes whose rows hold at most hot_units
// (Distribution2DView::hot_row_units).
ENVMIS_AVX2 Rows8 rows8(const EnvMapView& env, PointArrays in, uint32_t l, uint32_t hot_units) noexcept {
    const Distribution2DView& d = env.distribution;
    const Hit8 r = search8(d.marginal.start, d.marginal.guide, I8(0u), d.h, unit8(load(in.y + l), d.h));
    const Rows8 rows{r, r.index * I8(d.w), unit8(load(in.x + l), d.w)};
    alignas(32) uint32_t y[8], t[8];
    _mm256_store_si256(reinterpret_cast<__m256i*>(y), r.index);
    _mm256_store_si256(reinterpret_cast<__m256i*>(t), rows.column.t);
    const M8 cold = I8(_mm256_min_epu32(r.width, I8(hot_units))) == r.width;  // unsigned width <= hot_units
    for (auto m = static_cast<uint32_t>(_mm256_movemask_ps(cold.v)); m != 0; m &= m - 1) {
        const int lane = __builtin_ctz(m);
        prefetch_column(env, y[lane], t[lane]);
    }
    return rows;
}

// EnvMapView::at for eight image points with their image-space density: the direction
// and its solid-angle pdf.
struct Direction8 {
    Vec3x8 d;
    F8 pdf;
};
ENVMIS_AVX2_FLAT Direction8 at8(const EnvMapView& env, Vec2x8 p, F8 image_pdf) noexcept {
    if (env.mapping == Mapping::equal_area)
        return {to_world<F8>(env.axes, equal_area_direction<F8>(p)), image_pdf * (1 / kFourPi)};
    const SinCos8 theta = sincos_half_turns(env.turns, p.y), phi = sincos_turns(env.turns, p.x);
    const Vec3x8 canonical{theta.sin * phi.cos, theta.sin * phi.sin, theta.cos};
    return {to_world<F8>(env.axes, canonical), EnvMapView::solid_angle_pdf(image_pdf, theta.sin)};
}

// EnvMapView::sample for the eight points from lane l on, their rows found.
ENVMIS_AVX2 void sample8(const EnvMapView& env, const Rows8& rows, SampleArrays out, uint32_t l) noexcept {
    const Distribution2DView& d = env.distribution;
    const Hit8& r = rows.r;
    const Hit8 c = search8(d.start, d.guide, rows.row, d.w, rows.column);
    const Vec2x8 p{point_in_cell8(c.index, c.offset, d.w), point_in_cell8(r.index, r.offset, d.h)};
    const Direction8 e = at8(env, p, image_pdf8(d, r.width, c.width));
    if (out.u) store(out.u + l, p.x);
    if (out.v) store(out.v + l, p.y);
    store(out.x + l, e.d.x);
    store(out.y + l, e.d.y);
    store(out.z + l, e.d.z);
    store(out.pdf + l, e.pdf);
    store_radiance8(env.radiance, rows.row + c.index, out.r, out.g, out.b, l);
}

// Rows found and columns' data prefetched for up to four groups before the first
// group's column search.
ENVMIS_AVX2 uint32_t sample_avx2(const EnvMapView& env, PointArrays in, SampleArrays out, uint32_t n) noexcept {
    const uint32_t hot_units = env.distribution.hot_row_units();
    return in_staged_groups(
        n, [&](uint32_t first) ENVMIS_AVX2 { return rows8(env, in, first, hot_units); },
        [&](const Rows8& rows, uint32_t first) ENVMIS_AVX2 { sample8(env, rows, out, first); });
}
#endif

}  // namespace

void lookup_many(const EnvMapView& env, DirectionArrays in, LookupArrays out, uint32_t n) noexcept {
    uint32_t done = 0;
#ifdef ENVMIS_AVX2_BATCHES
    if (batch_paths().lookup == BatchPath::avx2 && avx2_applies(env)) done = lookup_avx2(env, in, out, n);
#endif
    lookup_scalar(env, in, out, done, n);
}

void sample_many(const EnvMapView& env, PointArrays in, SampleArrays out, uint32_t n) noexcept {
    uint32_t done = 0;
#ifdef ENVMIS_AVX2_BATCHES
    // The guide pairs of search8 need two cells in each dimension.
    if (batch_paths().sample == BatchPath::avx2 && avx2_applies(env) && env.distribution.w > 1 &&
        env.distribution.h > 1)
        done = sample_avx2(env, in, out, n);
#endif
    sample_scalar(env, in, out, done, n);
}

}  // namespace envmis
