// lookup_many and sample_many (envmap.h): EnvMapView::lookup and EnvMapView::sample
// for many directions or random points, on the path envmis/cpu.h chooses for the CPU.
//
// The scalar paths call the single calls' own functions, split into the stages of
// detail/pipeline.h: bit-identical to the single calls by construction.
//
// The AVX2 paths (eight lanes at a time, hardware gathers) map, turn angles and convert
// densities with the single calls' own functions, instantiated on eight lanes
// (detail/simd.h). What they write apart is the CDF search by gathers (detail/cdf8.h:
// CdfView::width and invert; Distribution2DView::pdf_of here) and the placement
// (detail/cell8.h): the same IEEE operations in the same order as the scalar code, so
// every lane's result is bit-identical to the scalar call (tests/core/sampling/
// envmap_test.cpp checks it on maps of several sizes, in both mappings and several axes,
// at the poles, the seam and the last column, on every path the CPU has).
#include "envmis/sampling/envmap.h"

#include <algorithm>

#include "detail/cdf8.h"
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
            detail::store_sample(out, l, sample_in_row(env, r, {in.x[l], in.y[l]}));
        });
}

#ifdef ENVMIS_AVX2_BATCHES
using namespace simd;

// The SIMD path's precondition: 32-bit gather indices for the three floats of every texel.
bool avx2_applies(const EnvMapView& env) noexcept {
    return uint64_t{env.distribution.w} * env.distribution.h * 3 < (uint64_t{1} << 31);
}

// Distribution2DView::pdf_of: a cell's image-space density from its row's and its own
// widths.
ENVMIS_AVX2 F8 image_pdf8(const Distribution2DView& d, I8 row_width, I8 cell_width) noexcept {
    return width_to_float(row_width) * width_to_float(cell_width) * d.pdf_scale;
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
    const Vec2x8 p = uv8(env, in, l);
    const I8 x = cell8(p.x, env.distribution.w), y = cell8(p.y, env.distribution.h);
    const Lanes8 column(x), row(y);
    for (int lane = 0; lane < 8; ++lane) env.prefetch_cell(column.at[lane], row.at[lane]);
    return {x, y, y * I8(env.distribution.w), p.y};
}

// Radiance and solid-angle pdf at eight located directions, stored from lane l on.
ENVMIS_AVX2_FLAT void fetch8(const EnvMapView& env, const Cells8& c, LookupArrays out, uint32_t l) noexcept {
    const Distribution2DView& d = env.distribution;
    store_radiance8(env.radiance, c.row + c.x, out.r, out.g, out.b, l);
    const I8 row_width = span8(d.marginal.start, I8(0u), c.y, d.h).width;
    store(out.pdf + l, env.image_to_solid_angle(image_pdf8(d, row_width, span8(d.start, c.row, c.x, d.w).width), c.v));
}

ENVMIS_AVX2 uint32_t lookup_avx2(const EnvMapView& env, DirectionArrays in, LookupArrays out, uint32_t n) noexcept {
    return in_staged_groups(
        n, [&](uint32_t first) ENVMIS_AVX2 { return locate8(env, in, first); },
        [&](const Cells8& cells, uint32_t first) ENVMIS_AVX2 { fetch8(env, cells, out, first); });
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
    const Lanes8 y(r.index), t(rows.column.t);
    const M8 cold = I8(_mm256_min_epu32(r.width, I8(hot_units))) == r.width;  // unsigned width <= hot_units
    for (auto m = static_cast<uint32_t>(_mm256_movemask_ps(cold.v)); m != 0; m &= m - 1) {
        const int lane = __builtin_ctz(m);
        prefetch_column(env, y.at[lane], t.at[lane]);
    }
    return rows;
}

// EnvMapView::sample for the eight points from lane l on, their rows found.
ENVMIS_AVX2 void sample8(const EnvMapView& env, const Rows8& rows, SampleArrays out, uint32_t l) noexcept {
    const Distribution2DView& d = env.distribution;
    const Hit8& r = rows.r;
    const Hit8 c = search8(d.start, d.guide, rows.row, d.w, rows.column);
    const Vec2x8 p{point_in_cell8(c.index, c.offset, d.w), point_in_cell8(r.index, r.offset, d.h)};
    store_sample8(env, p, at8(env, p, image_pdf8(d, r.width, c.width)), rows.row + c.index, out, l);
}

// Rows found and columns' data prefetched for up to eight groups before the first
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
