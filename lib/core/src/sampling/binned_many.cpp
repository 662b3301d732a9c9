// lookup_many and sample_many (binned.h): BinView::lookup and BinView::sample for many
// directions or random points, each in its own bin, on the path envmis/cpu.h chooses for
// the CPU (that of EnvMap's batch calls, envmap_many.cpp).
//
// The scalar paths call the single calls' own functions, split into stages that
// prefetch what the next one loads: bit-identical to the single calls by construction.
// The AVX2 paths search the bins' cell CDFs and the cells' texel CDFs by gathers, each
// lane in its own table (detail/cdf8.h), and place, map and convert with the single
// calls' functions instantiated on eight lanes: bit-identical to the scalar calls
// (tests/core/sampling/binned_test.cpp checks it on every path the CPU has).
#include "envmis/sampling/binned.h"

#include <algorithm>
#include <cstddef>

#include "detail/cdf8.h"
#include "detail/cell8.h"
#include "detail/pipeline.h"
#include "envmis/cpu.h"

namespace envmis {
namespace {

// A direction of lookup_many located: its bin, its image point, and prefetches of all
// that BinView::pdf_uv and eval_uv read there but the small edge tables.
struct Located {
    BinView bin;
    Vec2 uv;
};

Located locate(const BinView& bin, Vec3 direction) noexcept {
    const BinnedEnvMapView& env = *bin.map;
    const Located at{bin, env.plain.uv_of(direction)};
    const Distribution2DView& d = env.plain.distribution;
    const uint32_t x = detail::cell_of(at.uv.x, d.w), y = detail::cell_of(at.uv.y, d.h);
    const uint32_t cx = env.cell_column(x), cy = env.cell_row(y);
    const uint32_t k = env.texel_in_cell(x, y, cx, cy);
    const CdfView texels = env.cell_texels(cx, cy);
    env.plain.prefetch_radiance(static_cast<size_t>(y) * d.w + x, static_cast<size_t>(y) * d.w + x);
    ENVMIS_PREFETCH(texels.start + k);
    ENVMIS_PREFETCH(texels.start + k + 1);
    ENVMIS_PREFETCH(bin.cells.start + cy * env.cells_w + cx);
    ENVMIS_PREFETCH(bin.cells.start + cy * env.cells_w + cx + 1);
    return at;
}

// Lanes first..n, software-pipelined (detail/pipeline.h) as EnvMap's lookup_many: each
// direction located and its data prefetched 32 directions before its pdf is computed from
// them, so that the misses of 32 directions are in flight at once. Bit-identical to
// BinView::lookup, whose functions it calls.
void lookup_scalar(const BinView* bins, DirectionArrays in, LookupArrays out, uint32_t first, uint32_t n) noexcept {
    detail::pipelined<32>(
        first, n,
        [&](uint32_t i) noexcept {
            return locate(bins[i], {in.x[i], in.y[i], in.z[i]});
        },
        [&](const Located& l, uint32_t i) noexcept {
            const Rgb c = l.bin.map->plain.eval_uv(l.uv);
            out.r[i] = c.r, out.g[i] = c.g, out.b[i] = c.b, out.pdf[i] = l.bin.pdf_uv(l.uv);
        });
}

// Lanes from..n, software-pipelined: a block of samples goes through each stage of
// BinView::sample in turn (a prefetch of the bin's CDF at u.x's guide bucket; cell; the
// texel CDF's guide span; texel; radiance), each stage prefetching what the next loads,
// so that the misses of a block's samples overlap instead of each sample waiting on its
// chain of dependent loads. The stages are the single call's own functions, so the
// results are bit-identical to it.
void sample_scalar(const BinView* lanes, PointArrays in, SampleArrays out, uint32_t from, uint32_t n) noexcept {
    constexpr uint32_t kBlock = 16;
    BinView::Cell cells[kBlock];
    BinView::Texel texels[kBlock];
    for (uint32_t first = from; first < n; first += kBlock) {
        const uint32_t m = std::min(kBlock, n - first);
        const BinView* bins = lanes + first;
        for (uint32_t j = 0; j < m; ++j) {
            const CdfView& c = bins[j].cells;
            const uint32_t k = c.bucket(in.x[first + j]);
            ENVMIS_PREFETCH(c.guide + k);
            ENVMIS_PREFETCH(c.start + k);
        }
        for (uint32_t j = 0; j < m; ++j) {
            cells[j] = bins[j].find_cell(in.x[first + j]);
            prefetch_texels(*bins[j].map, cells[j], in.y[first + j]);
        }
        for (uint32_t j = 0; j < m; ++j) prefetch_texel_span(*bins[j].map, cells[j], in.y[first + j]);
        for (uint32_t j = 0; j < m; ++j) texels[j] = bins[j].find_texel(cells[j], in.y[first + j]);
        for (uint32_t j = 0; j < m; ++j) detail::store_sample(out, first + j, bins[j].sample_at(cells[j], texels[j]));
    }
}

#ifdef ENVMIS_AVX2_BATCHES
using namespace simd;

// Lanes [0, n) whose bins all belong to one map the AVX2 paths can take: 32-bit gather
// indices for the three floats of every texel and every cell table's entries, two cells
// or more in a bin's table and two texels or more in every cell (search8's guide pairs;
// CellGrid's columns are w / cw texels wide or one more, its rows likewise). Returns how
// many leading lanes qualify, the map in `env`.
uint32_t avx2_lanes(const BinView* bins, uint32_t n, const BinnedEnvMapView*& env) noexcept {
    if (n == 0) return 0;
    env = bins[0].map;
    const uint64_t w = env->plain.distribution.w, h = env->plain.distribution.h,
                   cells = uint64_t{env->cells_w} * env->cells_h;
    if (w * h * 3 >= (uint64_t{1} << 31) || cells < 2 ||
        (env->plain_table + uint64_t{1}) * cells >= (uint64_t{1} << 31) || (w / env->cells_w) * (h / env->cells_h) < 2)
        return 0;
    uint32_t same = 1;
    while (same < n && bins[same].map == env) ++same;
    return same;
}

// The eight bins' tables from lane l on, as offsets of their cell CDFs in the map's.
ENVMIS_AVX2 I8 tables8(const BinnedEnvMapView& env, const BinView* bins, uint32_t l) noexcept {
    alignas(32) uint32_t at[8];
    for (uint32_t i = 0; i < 8; ++i) at[i] = static_cast<uint32_t>(bins[l + i].cells.start - env.cell_start);
    return _mm256_load_si256(reinterpret_cast<const __m256i*>(at));
}

// BinnedEnvMapView::cell_texels for eight cells: where each cell's texel CDF starts, its
// texels (n), and the cell's first texel column and row and width in texels.
struct CellTexels8 {
    I8 at, n, x0, y0, columns;
};
ENVMIS_AVX2 CellTexels8 cell_texels8(const BinnedEnvMapView& env, I8 cx, I8 cy) noexcept {
    const Pair8 x = gather_pairs(env.column_edges, cx), y = gather_pairs(env.row_edges, cy);
    const I8 columns = x.second - x.first, rows = y.second - y.first;
    return {y.first * I8(env.plain.distribution.w) + rows * x.first, columns * rows, x.first, y.first, columns};
}

// Eight directions of BinView::lookup located: what pdf_uv and eval_uv read (texel,
// the texel's entry k in its cell's CDF, the cell's in its bin's), all prefetched.
struct Located8 {
    I8 texel, k, cell, table;
    CellTexels8 texels;
    F8 v;
};
ENVMIS_AVX2_FLAT Located8 locate8(const BinnedEnvMapView& env, const BinView* bins, DirectionArrays in,
                                  uint32_t l) noexcept {
    const Distribution2DView& d = env.plain.distribution;
    const Vec2x8 p = uv8(env.plain, in, l);
    const I8 x = cell8(p.x, d.w), y = cell8(p.y, d.h);
    const I8 cx = divide8(x * I8(env.cells_w), env.by_width), cy = divide8(y * I8(env.cells_h), env.by_height);
    const CellTexels8 t = cell_texels8(env, cx, cy);
    const Located8 at{
        y * I8(d.w) + x, (y - t.y0) * t.columns + x - t.x0, cy * I8(env.cells_w) + cx, tables8(env, bins, l), t, p.y};
    const Lanes8 texel(at.texel), entry(t.at + at.k), cell(at.table + at.cell);
    for (int i = 0; i < 8; ++i) {
        env.plain.prefetch_radiance(texel.at[i], texel.at[i]);
        ENVMIS_PREFETCH(env.texel_start + entry.at[i]);
        ENVMIS_PREFETCH(env.texel_start + entry.at[i] + 1);
        ENVMIS_PREFETCH(env.cell_start + cell.at[i]);
        ENVMIS_PREFETCH(env.cell_start + cell.at[i] + 1);
    }
    return at;
}

// BinnedEnvMapView::texel_pdf for eight lanes.
ENVMIS_AVX2 F8 texel_pdf8(const BinnedEnvMapView& env, I8 cell_width, I8 texel_width) noexcept {
    const float texels = static_cast<float>(uint64_t{env.plain.distribution.w} * env.plain.distribution.h);
    return width_to_float(cell_width) * width_to_float(texel_width) * 0x1p-62f * texels;
}

// Radiance and solid-angle pdf at eight located directions, stored from lane l on.
ENVMIS_AVX2_FLAT void fetch8(const BinnedEnvMapView& env, const Located8& at, LookupArrays out, uint32_t l) noexcept {
    store_radiance8(env.plain.radiance, at.texel, out.r, out.g, out.b, l);
    const I8 texel_width = span8(env.texel_start, at.texels.at, at.k, at.texels.n).width;
    const I8 cell_width = span8(env.cell_start, at.table, at.cell, env.cells_w * env.cells_h).width;
    store(out.pdf + l, env.plain.image_to_solid_angle(texel_pdf8(env, cell_width, texel_width), at.v));
}

ENVMIS_AVX2 uint32_t lookup_avx2(const BinView* bins, DirectionArrays in, LookupArrays out, uint32_t n) noexcept {
    const BinnedEnvMapView* env = nullptr;
    const uint32_t lanes = avx2_lanes(bins, n, env);
    return in_staged_groups(
        lanes, [&](uint32_t first) ENVMIS_AVX2 { return locate8(*env, bins, in, first); },
        [&](const Located8& at, uint32_t first) ENVMIS_AVX2 { fetch8(*env, at, out, first); });
}

// Eight points of BinView::sample through its stages: the bins' tables and u.x's unit;
// the cells (find_cell), their texel CDFs and u.y's unit in them; the texels.
struct Sample8 {
    I8 table, cx, x, y;
    Unit8 ux, uy;
    Hit8 cell, texel;
    CellTexels8 texels;
};

// Stage 1: the tables, and prefetches of their CDFs at u.x's guide bucket.
ENVMIS_AVX2 void bins8(const BinnedEnvMapView& env, const BinView* bins, PointArrays in, uint32_t l,
                       Sample8& s) noexcept {
    s.table = tables8(env, bins, l);
    s.ux = unit8(load(in.x + l), env.cells_w * env.cells_h);
    const Lanes8 at(s.table + s.ux.k);
    for (int i = 0; i < 8; ++i) {
        ENVMIS_PREFETCH(env.cell_guide + at.at[i]);
        ENVMIS_PREFETCH(env.cell_start + at.at[i]);
    }
}

// Stage 2: the cells (BinView::find_cell), and prefetches of their texel CDFs at u.y's
// guide bucket (prefetch_texels).
ENVMIS_AVX2 void cells8(const BinnedEnvMapView& env, PointArrays in, uint32_t l, Sample8& s) noexcept {
    s.cell = search8(env.cell_start, env.cell_guide, s.table, env.cells_w * env.cells_h, s.ux);
    const I8 cy = divide8(s.cell.index, env.by_cells_w);
    s.cx = s.cell.index - cy * I8(env.cells_w);
    s.texels = cell_texels8(env, s.cx, cy);
    s.uy = unit8(load(in.y + l), s.texels.n);
    const Lanes8 at(s.texels.at + s.uy.k);
    for (int i = 0; i < 8; ++i) {
        ENVMIS_PREFETCH(env.texel_guide + at.at[i]);
        ENVMIS_PREFETCH(env.texel_start + at.at[i]);
    }
}

// Stage 3: once those guide entries have arrived, prefetches of the first and last CDF
// entries they name (prefetch_texel_span).
ENVMIS_AVX2 void texel_spans8(const BinnedEnvMapView& env, const Sample8& s) noexcept {
    const Lanes8 at(s.texels.at), n(s.texels.n), k(s.uy.k);
    for (int i = 0; i < 8; ++i) {
        const CdfTable texels{env.texel_start + at.at[i], env.texel_guide + at.at[i], n.at[i]};
        const CdfTable::Span span = texels.guide_span(k.at[i]);
        ENVMIS_PREFETCH(texels.start + span.lo);
        ENVMIS_PREFETCH(texels.start + span.hi);
    }
}

// Stage 4: the texels (BinView::find_texel: the row in the cell by the cell column's
// ExactDivision), and prefetches of their radiance.
static_assert(sizeof(detail::ExactDivision) == 16 && offsetof(detail::ExactDivision, k) == 8);
ENVMIS_AVX2 void texels8(const BinnedEnvMapView& env, Sample8& s) noexcept {
    s.texel = search8(env.texel_start, env.texel_guide, s.texels.at, s.texels.n, s.uy);
    const int* by_column = reinterpret_cast<const int*>(env.by_column);
    const I8 four = s.cx << 2;
    const I8 dy = divide8(s.texel.index, _mm256_i32gather_epi32(by_column, four, 4),
                          _mm256_i32gather_epi32(by_column + 2, four, 4));
    s.y = s.texels.y0 + dy;
    s.x = s.texels.x0 + s.texel.index - dy * s.texels.columns;
    const Lanes8 texel(s.y * I8(env.plain.distribution.w) + s.x);
    for (int i = 0; i < 8; ++i) env.plain.prefetch_radiance(texel.at[i], texel.at[i]);
}

// Stage 5: BinView::sample_at, stored from lane l on.
ENVMIS_AVX2_FLAT void place8(const BinnedEnvMapView& env, const Sample8& s, SampleArrays out, uint32_t l) noexcept {
    const Distribution2DView& d = env.plain.distribution;
    const Vec2x8 p{point_in_cell8(s.x, s.cell.offset, d.w), point_in_cell8(s.y, s.texel.offset, d.h)};
    const Direction8 e = at8(env.plain, p, texel_pdf8(env, s.cell.width, s.texel.width));
    store_sample8(env.plain, p, e, s.y * I8(d.w) + s.x, out, l);
}

// Up to kGroups groups of eight through each of the five stages before the next, as
// in_staged_groups takes them through its two, so that the misses of their loads overlap.
ENVMIS_AVX2 uint32_t sample_avx2(const BinView* bins, PointArrays in, SampleArrays out, uint32_t n) noexcept {
    const BinnedEnvMapView* env = nullptr;
    const uint32_t lanes = avx2_lanes(bins, n, env), whole = lanes - lanes % 8;
    Sample8 s[kGroups];
    for (uint32_t first = 0; first < whole; first += 8 * kGroups) {
        const uint32_t groups = std::min(kGroups, (whole - first) / 8);
        for (uint32_t k = 0; k < groups; ++k) bins8(*env, bins, in, first + 8 * k, s[k]);
        for (uint32_t k = 0; k < groups; ++k) cells8(*env, in, first + 8 * k, s[k]);
        for (uint32_t k = 0; k < groups; ++k) texel_spans8(*env, s[k]);
        for (uint32_t k = 0; k < groups; ++k) texels8(*env, s[k]);
        for (uint32_t k = 0; k < groups; ++k) place8(*env, s[k], out, first + 8 * k);
    }
    return whole;
}
#endif

// The bins of the picking batch forms: lane i's, by its lobe axis and choice.
struct PickedBins {
    const BinnedEnvMapView& env;
    uint32_t lobe;
    LobeAxisArrays axes;
    const float* choices;
    BinView operator()(uint32_t i) const noexcept {
        return env.bin({{axes.x[i], axes.y[i], axes.z[i]}, axes.view_cos[i]}, lobe, choices[i]);
    }
};

// A picking batch form as the form over picked bins, `many`, a chunk of lanes at a time.
template <class In, class Out, class Many>
void in_picked_chunks(const PickedBins& pick, In in, Out out, uint32_t n, Many&& many) noexcept {
    constexpr uint32_t kChunk = 64;
    BinView bins[kChunk];
    for (uint32_t first = 0; first < n; first += kChunk) {
        const uint32_t m = std::min(kChunk, n - first);
        for (uint32_t i = 0; i < m; ++i) bins[i] = pick(first + i);
        many(bins, from_lane(in, first), from_lane(out, first), m);
    }
}

}  // namespace

void lookup_many(const BinView* bins, DirectionArrays in, LookupArrays out, uint32_t n) noexcept {
    uint32_t done = 0;
#ifdef ENVMIS_AVX2_BATCHES
    if (batch_paths().lookup == BatchPath::avx2) done = lookup_avx2(bins, in, out, n);
#endif
    lookup_scalar(bins, in, out, done, n);
}

void sample_many(const BinView* bins, PointArrays in, SampleArrays out, uint32_t n) noexcept {
    uint32_t done = 0;
#ifdef ENVMIS_AVX2_BATCHES
    if (batch_paths().sample == BatchPath::avx2) done = sample_avx2(bins, in, out, n);
#endif
    sample_scalar(bins, in, out, done, n);
}

void lookup_many(const BinnedEnvMapView& env, uint32_t lobe, LobeAxisArrays axes, const float* choices,
                 DirectionArrays in, LookupArrays out, uint32_t n) noexcept {
    in_picked_chunks(PickedBins{env, lobe, axes, choices}, in, out, n,
                     [](const BinView* bins, DirectionArrays i, LookupArrays o, uint32_t m) noexcept {
                         lookup_many(bins, i, o, m);
                     });
}

void sample_many(const BinnedEnvMapView& env, uint32_t lobe, LobeAxisArrays axes, const float* choices, PointArrays in,
                 SampleArrays out, uint32_t n) noexcept {
    in_picked_chunks(
        PickedBins{env, lobe, axes, choices}, in, out, n,
        [](const BinView* bins, PointArrays i, SampleArrays o, uint32_t m) noexcept { sample_many(bins, i, o, m); });
}

}  // namespace envmis
