// Normal-aware environment sampling: per-bin densities, chosen by the shading normal.
//
// Why: a renderer spends 1 to 16 samples per shading point, too few for a technique
// that learns per point. A global density cannot know which hemisphere a point sees:
// half its samples land below the horizon, and its compensation subtracts the mean over
// the whole sphere rather than over what the point sees. Here the sphere of normals is
// cut into K bins; each bin samples the environment proportionally to
//
//   q_b(x) = max(L(x) - alpha_b E_b / pi, 0) * c_b(cell of x)
//
// where E_b / pi is the cosine-weighted mean radiance of the hemisphere around the bin's
// centre normal n_b, and c_b the cosine factor of the cell: that of the angle from the
// direction the cell's light comes from (its texels' directions weighted by luminance
// times solid angle: a sun's, not the centre of a cell 11 degrees tall whose cosine
// near a normal's horizon may be a fifth of the sun's) to n_b, less a quarter of the
// bin's angular radius (a typical normal of the bin rather than its centre), and at least
// a tenth of a conservative bound (the angle less the cell's radius and that of the
// normals that may pick the bin, its blend support; 0 beyond 90 degrees). So a diffuse
// bin's density is > 0 wherever any normal that may pick the bin sees compensated light,
// and 0 on cells that none of them sees. A glossy class's bins follow the lobe's axis,
// around which the surface's horizon may lie anywhere and a microfacet lobe's tails
// reach past 90 degrees: their factor is at least 0.1 everywhere. GGX 0.3 spheres rendered
// at every view angle, relative MSE over the global table's: 3.1x without it on
// rooitou_park, 0.76-0.80x with 0.05-0.15; on studio 1.27x with 0.05, 0.85x with 0.1,
// 0.75x with 0.15; a higher floor costs head-on glossy gains (GGX 0.1 over plain MIS,
// 14 maps: 1.98x, 1.87x, 1.79x).
//
// Representation (what keeps it small): the map is cut into a coarse grid of cells
// (BinLayout; 32 x 16 for a 1k map, at most 112 x 56); each bin holds only
// the masses of its cells (sum over the cell's texels of q_b times their solid angle), in
// one 1D CDF over all cells, row-major (two dependent loads to find a cell, where a
// marginal and a conditional CDF took four). Inside a cell, a texel is picked by the
// plain map's own density (its fixed-point texel probabilities), through one guided CDF
// over the cell's texels, row-major in the cell, which every bin shares: u.x picks the
// cell, u.y the texel in it, and u.x's offset in the cell places the point across the
// texel, u.y's offset down it. pdf_b(x) = P_b(cell) P(x | cell), exact in 31-bit fixed
// point as in distribution.h, so sample and pdf agree exactly. These cell texel CDFs take
// the place of the plain map's row CDFs (6 bytes a texel each): a binned map holds the
// plain map's radiance, not its distribution, and samples the plain density as one more
// cell table (its cells' plain masses) over the same texel CDFs. So a binned sample waits
// on two CDF inversions, as a global map's does; with the plain row CDFs and a CDF over
// each cell's rows it waited on three (docs/performance-log.md, 'cell texel CDFs').
// The compensation lives in the bins.
//
// Lobes: the best compensation strength depends on the BSDF (a diffuse lobe gains from
// mild compensation relative to its hemisphere, a sharp glossy one often from strong
// compensation), so each bin holds one cell table per lobe class (by default diffuse,
// Phong 20 and Phong 200), and a shading point picks the class nearest its BSDF's
// sharpness (lobe_class). alpha_b is chosen per bin and class at build time: the exact
// variance of 1 + 1 balance MIS (the class's Phong lobe, and for a glossy class a GGX
// lobe too: envmis/build/bins.h), view along the normal, at nine normals of the bin's
// blend support (weighted as the blend weighs them), on a 64-column copy of the map
// (texels grouped inside cells), over that of the plain density; the candidate with the
// lowest weighted geometric mean wins where that mean is below 1 / cost (BinnedOptions:
// what a binned estimate costs over a plain one), the plain density (alpha < 0 in
// BinChoice) elsewhere, so that each bin holds what is predicted best at equal time. A
// plain bin samples and weighs through the plain cell table, which all plain bins share.
// A glossy bin's density is shaped about the mirror direction, but a lobe seen
// obliquely reaches towards the normal: each compensated glossy bin also records the
// most oblique view at which the choice predicts it beats the plain density (Phong and
// GGX lobes seen at 45 to 85 degrees, BinChoice::min_view_cos); seen more obliquely it
// samples the plain density. Without the limits, GGX 0.1 seen at 85 degrees has 5.6x the
// variance of plain balance MIS at a point of studio.exr; with them, 1.04x at worst on
// the 14 shared maps (exact; docs/performance.md).
// docs/table-format.md defines every quantity
// (centres, radii, bounds, thresholds, the choice, the blend) so that a bin's density
// can be recomputed independently.
//
// Blending: a shading point picks one of the four bins around its normal at random
// (normal_blend, pick_bin), with weights that ramp over the middle half of the way
// between bin centres, so what it samples changes without steps across bin borders.
// Blending over the whole way (bilinear) costs diffuse surfaces much of their gain: on
// the 14 maps of ../shared/data/envmaps, Lambert variance relative to plain balance MIS
// 0.21 bilinear, 0.15 over the middle half, 0.13 with no blending (docs/performance.md).
//
// Bins: a g x g grid over the octahedral map of normals (K = g^2, 121 by default), so a
// normal finds its bin in O(1): a few adds, one division, no loop over bins. g is odd by
// default because an even g puts +z (floors, the commonest normal) on a bin corner,
// where the bin's density fits worst: on rooitou_park, a Lambertian floor facing +z has
// 1.48x the variance of plain balance MIS with 10 x 10 bins, 0.30x with 11 x 11 (exact).
// Walls (+-x, +-y) lie on the border of two bins whose centres are 5 degrees above and
// below them; -z on a corner.
//
// Measure and exactness: as EnvMapView (solid angle, world frame). pdf(n, choice, omega) is the
// density of the bin that n and the choice pick, so the MIS weight of a BSDF sample
// matches what sample(n, choice, u) would have drawn. A compensated bin is incomplete (pdf 0 where L <= its
// threshold): combine it with BSDF sampling.
//
// Cost: sample O(1) (two fixed-point CDF inversions: the bin's cells, the cell's
// texels), pdf O(1); noexcept, allocation-free, ENVMIS_HD.
// Memory on top of the plain map: 6 bytes per cell per bin per class and for the plain
// cell table; the cell texel CDFs take the plain row CDFs' 6 bytes a texel; figures in
// docs/performance.md. At most 65536 cells, and 65536 texels a cell (uint16 guides).
// Build: passes over the texels (three per node grid of the choice, one or two; the
// candidate and final cell histograms), then O(K classes cells) work and the choice
// (docs/performance.md).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "envmis/core_export.h"
#include "envmis/sampling/envmap.h"

namespace envmis {

// Point (s, t) in [0,1]^2 of a unit vector (canonical frame) on the octahedral map of
// normals; a zero or non-finite vector gets (0, 0).
ENVMIS_HD inline Vec2 octahedral_point(Vec3 n) noexcept {
    const float l1 = std::abs(n.x) + std::abs(n.y) + std::abs(n.z);
    if (!(l1 > 0 && l1 <= 0x1.fffffep127f)) return {0, 0};
    const float u = n.x / l1, v = n.y / l1;
    // The lower hemisphere folded over the square's edges, by bits: the three signs of a
    // random normal are coin flips that jumps would mispredict.
    const float fu = from_bits(to_bits(1 - std::abs(v)) ^ (static_cast<uint32_t>(u < 0) << 31));
    const float fv = from_bits(to_bits(1 - std::abs(u)) ^ (static_cast<uint32_t>(v < 0) << 31));
    const bool lower = n.z < 0;
    return {0.5f * (select_bits(lower, fu, u) + 1), 0.5f * (select_bits(lower, fv, v) + 1)};
}

// Octahedral grid of normals: the bin (of g x g) of a unit vector in the canonical
// frame, the one whose square holds it. A zero or non-finite vector gets bin 0.
ENVMIS_HD inline uint32_t normal_bin(Vec3 n, uint32_t g) noexcept {
    const Vec2 p = octahedral_point(n);
    return detail::cell_of(p.y, g) * g + detail::cell_of(p.x, g);
}

// The bin at grid position (i, j), one step outside the grid allowed: the octahedral
// map continues across each edge point-mirrored ((s, t) beyond s = 1 is (2 - s, 1 - t)),
// so a column outside is the edge column with its rows reversed, and so on.
ENVMIS_HD inline uint32_t wrapped_bin(int i, int j, uint32_t g) noexcept {
    const int n = static_cast<int>(g);
    if (i < 0 || i >= n) i = i < 0 ? 0 : n - 1, j = n - 1 - j;
    if (j < 0 || j >= n) j = j < 0 ? 0 : n - 1, i = n - 1 - i;
    return static_cast<uint32_t>(j) * g + static_cast<uint32_t>(i);
}

// Blending (seams): the four bins around a normal with bilinear weights over the grid of
// bin centres (wrapped over the folds), continuous in the normal; weights sum to 1. A
// shading point takes bin k with probability weight[k] (pick_bin), so that what it
// samples, and the variance it gets (the weights' mixture of the bins' variances), change
// without steps as its normal crosses a bin border. The pick must serve both the light
// sample and the MIS weight of the BSDF sample: each pick then makes an ordinary
// two-technique MIS estimator, unbiased, and so is their mixture.
// The weights ramp over the middle kBlendWidth of the way between two bin centres (1:
// bilinear), so that a normal within (1 - kBlendWidth) / 2 of the spacing from a centre
// takes that bin alone, the one fitted to it.
inline constexpr float kBlendWidth = 0.5f;
ENVMIS_HD inline float blend_ramp(float t) noexcept {
    const float r = (t - 0.5f) * (1 / kBlendWidth) + 0.5f, low = select_bits(r > 0, r, 0.0f);
    return select_bits(low < 1, low, 1.0f);
}
// The square of bin centres around a normal: its lower-left centre (i, j), one step
// outside the grid at most, and the weights wa, wb of the right and upper columns.
struct BlendSquare {
    int i, j;
    float wa, wb;
};
ENVMIS_HD inline BlendSquare blend_square(Vec3 n, uint32_t g) noexcept {
    const Vec2 p = octahedral_point(n);
    const float a = p.x * static_cast<float>(g) - 0.5f, b = p.y * static_cast<float>(g) - 0.5f;
    // floor for a, b >= -0.5, without a libm call (x86-64 has no rounding instruction
    // before SSE4.1); where a + 1 rounds up to an integer, t = a - i is a hair below 0
    // and its ramp 0: the same bin, with the same weight 1.
    const int i = static_cast<int>(a + 1) - 1, j = static_cast<int>(b + 1) - 1;
    return {i, j, blend_ramp(a - static_cast<float>(i)), blend_ramp(b - static_cast<float>(j))};
}
struct BinBlend {
    uint32_t bin[4];  // (i, j), (i + 1, j), (i, j + 1), (i + 1, j + 1), wrapped
    float weight[4];  // (1 - wa)(1 - wb), wa (1 - wb), (1 - wa) wb, wa wb
    float wa = 0, wb = 0;
    float view_cos = 1;  // LobeAxis::view_cos of the shading point
};
ENVMIS_HD inline BinBlend normal_blend(Vec3 n, uint32_t g) noexcept {
    const BlendSquare q = blend_square(n, g);
    return {{wrapped_bin(q.i, q.j, g), wrapped_bin(q.i + 1, q.j, g), wrapped_bin(q.i, q.j + 1, g),
             wrapped_bin(q.i + 1, q.j + 1, g)},
            {(1 - q.wa) * (1 - q.wb), q.wa * (1 - q.wb), (1 - q.wa) * q.wb, q.wa * q.wb},
            q.wa,
            q.wb};
}
// The corner of the square a uniform `choice` in [0,1) picks (bit 0: right, bit 1: up),
// with the weights' probabilities: the upper row where choice >= 1 - wb, then the right
// column where choice passes (1 - wa) of its row's stretch. A corner of weight 0 never.
ENVMIS_HD inline uint32_t pick_corner(float wa, float wb, float choice) noexcept {
    // & of the comparisons, not &&: a && on a coin flip compiles to a jump.
    const float rest = 1 - wb;
    const uint32_t up = static_cast<uint32_t>(choice >= rest) & static_cast<uint32_t>(wb > 0);
    const float split = select_bits(up != 0, rest + (1 - wa) * wb, (1 - wa) * rest);
    const uint32_t right = static_cast<uint32_t>(choice >= split) & static_cast<uint32_t>(wa > 0);
    return right | up << 1;
}
ENVMIS_HD inline uint32_t pick_bin(const BinBlend& blend, float choice) noexcept {
    return blend.bin[pick_corner(blend.wa, blend.wb, choice)];
}
// The same bin as pick_bin(normal_blend(n, g), choice), computing only that one.
ENVMIS_HD inline uint32_t pick_bin(Vec3 n, uint32_t g, float choice) noexcept {
    const BlendSquare q = blend_square(n, g);
    const uint32_t corner = pick_corner(q.wa, q.wb, choice);
    return wrapped_bin(q.i + static_cast<int>(corner & 1), q.j + static_cast<int>(corner >> 1), g);
}

// Canonical unit normal at point (s, t) in [0,1]^2 of the octahedral map of normals.
ENVMIS_HD inline Vec3 octahedral_normal(float s, float t) noexcept {
    const float u = 2 * s - 1, v = 2 * t - 1, z = 1 - std::abs(u) - std::abs(v);
    Vec3 n{u, v, z};
    if (z < 0) {
        n.x = (1 - std::abs(v)) * (u < 0 ? -1.0f : 1.0f);
        n.y = (1 - std::abs(u)) * (v < 0 ? -1.0f : 1.0f);
    }
    return normalize(n);
}

// The same for a point up to one square beyond [0,1]^2: the map continues across each
// edge point-mirrored ((s, t) beyond s = 1 is (2 - s, 1 - t)).
inline Vec3 folded_octahedral_normal(float s, float t) noexcept {
    if (s < 0 || s > 1) s = s < 0 ? -s : 2 - s, t = 1 - t;
    if (t < 0 || t > 1) t = t < 0 ? -t : 2 - t, s = 1 - s;
    return octahedral_normal(s, t);
}

// Lobe classes: 0 is diffuse (Lambert); a positive exponent is a Phong lobe that sharp.
// The class of a BSDF with Phong exponent e among `exponents` (ascending, the first 0):
// the nearest on the scale log(1 + e). Lambert has e = 0; GGX, see ggx_lobe_exponent.
ENVMIS_CORE_API uint32_t lobe_class(std::span<const float> exponents, float phong_exponent) noexcept;

// The Phong exponent that picks the lobe class of GGX with roughness a. Below
// kGgxDiffuseRoughness, that of the Phong lobe of reflected directions as wide as GGX's:
// (2 / a^2 - 2) / 4 (the usual 2 / a^2 - 2 matches the distribution of microfacet
// normals; reflection doubles angles, so the lobe of directions is four times wider in
// exponent). From it up, 0: the diffuse class, whose bins follow the normal. A rough
// GGX lobe seen obliquely spreads about the normal more than about the mirror
// direction; the diffuse class gave lower variance at every point measured from 0.15 up,
// and a worse worst point below (measured: docs/performance-log.md, 'ggx_lobe_exponent').
inline constexpr float kGgxDiffuseRoughness = 0.15f;
inline float ggx_lobe_exponent(float a) noexcept {
    return a >= kGgxDiffuseRoughness ? 0.0f : a > 0 ? (2 / (a * a) - 2) / 4 : 1e5f;
}

// What picks a shading point's bin: the direction (`axis`) and, for a glossy class, how
// obliquely the lobe is seen (`view_cos`, the cosine of the view to the normal; 1 is
// head-on). The axis is the normal for the diffuse class (0), whose lobe is the cosine
// about it; for glossy classes the mirror direction of the view (wo, towards the viewer)
// about the normal, which their lobes follow. A glossy bin is a lobe about its centre, as
// its alpha was chosen: indexed by the normal, a Phong-200 surface seen at grazing view
// on rooitou_park keeps 1.03x the variance of plain balance MIS (its lobe near the bin's
// horizon), 0.29x by the mirror direction. Seen obliquely, a glossy lobe reaches towards
// the normal, away from the axis about which the bin's density is shaped: below its
// BinChoice::min_view_cos a bin samples the plain density instead.
struct LobeAxis {
    Vec3 axis;
    float view_cos = 1;
};
ENVMIS_HD inline LobeAxis lobe_axis(uint32_t lobe, Vec3 normal, Vec3 wo) noexcept {
    const float c = dot(normal, wo);
    return lobe == 0 ? LobeAxis{normal, 1} : LobeAxis{normal * (2 * c) - wo, c};
}
// The same for n shading points, one array per coordinate: lobe_axis's results (the
// view cosines too: a constructor, so that none is left out by accident).
struct LobeAxisArrays {
    const float *x, *y, *z, *view_cos;
    ENVMIS_HD LobeAxisArrays(const float* ax, const float* ay, const float* az, const float* cosines) noexcept
        : x(ax), y(ay), z(az), view_cos(cosines) {}
};

// The diffuse class's default g for glossy classes of g: 2 g - 1 (at most 64), so that its
// bin centres include the glossy ones and fall halfway between them too. Lambert variance
// over plain balance MIS, exact, 14 shared maps: 121 bins 0.142, 441 0.103.
inline uint32_t diffuse_side(uint32_t g) noexcept { return g == 0 ? 0 : (2 * g - 1 < 64 ? 2 * g - 1 : 64); }

struct BinnedOptions {
    uint32_t bins_per_side = 11;  // g: K = g^2 bins of each glossy class; 1 to 64; odd keeps the axes at bin centres
    // The diffuse class's g: 0 picks diffuse_side(bins_per_side). A cosine lobe is wide and
    // smooth, so its best density follows the normal closely: finer bins pay most there.
    uint32_t diffuse_bins_per_side = 0;
    // Cell grid: columns (rows: half of them for equirect, as many for equal-area).
    // 0 picks map width / 32, clamped to [1, 128], to the map's size and to at most
    // 112 x 56 cells (79 x 79 square), which keeps the bins under 5% of an 8k map.
    uint32_t cell_columns = 0;
    std::vector<float> lobe_exponents = {0, 20, 200};  // ascending, first 0 (diffuse); 1 to 8
    // Compensation per bin: the candidates auto mode chooses among (finite, >= 0), or,
    // with auto_alpha false, `alpha` for every bin and class.
    bool auto_alpha = true;
    float alpha = 1;
    std::vector<float> candidates = {0, 0.5f, 1, 1.5f, 2, 3};
    // Time of an estimate that samples a compensated bin over one that samples the plain
    // density (whole time per estimate; 1 to 100): auto mode keeps a candidate only where
    // its predicted variance is lower than the plain density's by more than this factor,
    // so that each bin holds what is predicted best at equal time. A compensated bin and
    // a plain one sample through the same tables and kernels, at about the same time; the
    // default is a margin for the choice's errors: below it, bins whose predicted gain is
    // small lose to the plain density at some points (measured: docs/performance-log.md,
    // 'BinnedOptions::cost'); 1 chooses at equal samples.
    float cost = 1.2f;
};

// What one (class, bin) samples. alpha < 0 marks the plain density (no compensation
// and no cosine bound), which auto mode keeps where nothing else was predicted better.
struct BinChoice {
    float alpha = 0;
    float threshold = 0;  // alpha E_b / pi, as applied (rounded to a histogram edge)
    // A glossy bin seen with a view cosine (LobeAxis::view_cos) below this samples the
    // plain density (in [0, 1]; 0 for the diffuse class and plain choices): where the
    // choice predicts its density loses to the plain one at some oblique view.
    float min_view_cos = 0;
    bool plain() const noexcept { return alpha < 0; }
};

// The layout and choices that rebuild a BinnedEnvMap bit-identically from its plain map
// (what table files store).
struct BinLayout {
    uint32_t bins_per_side = 0, cell_columns = 0, cell_rows = 0;  // bins_per_side: the glossy classes'
    uint32_t diffuse_bins_per_side = 0;                           // class 0's
    std::vector<float> lobe_exponents;
    std::vector<BinChoice> choices;  // class-major: choices[first(c) + b]

    uint32_t classes() const noexcept { return static_cast<uint32_t>(lobe_exponents.size()); }
    uint32_t side(uint32_t c) const noexcept { return c == 0 ? diffuse_bins_per_side : bins_per_side; }
    size_t first(uint32_t c) const noexcept {
        return c == 0 ? 0
                      : size_t{diffuse_bins_per_side} * diffuse_bins_per_side +
                            size_t{c - 1} * bins_per_side * bins_per_side;
    }
    size_t choice_count() const noexcept { return first(classes()); }
    // Choice i's view limit in its range: [0, 1] for a compensated glossy bin, 0 otherwise.
    bool view_limit_valid(size_t i) const noexcept {
        const float c = choices[i].min_view_cos;
        return c >= 0 && c <= (class_of(i) > 0 && !choices[i].plain() ? 1 : 0);
    }
    uint32_t class_of(size_t class_bin) const noexcept {
        const size_t d = size_t{diffuse_bins_per_side} * diffuse_bins_per_side;
        return class_bin < d ? 0 : 1 + static_cast<uint32_t>((class_bin - d) / (size_t{bins_per_side} * bins_per_side));
    }
};

// One bin's density; the same interface as EnvMapView (sample, pdf, lookup, eval).
struct BinnedEnvMapView;
struct BinView {
    const BinnedEnvMapView* map = nullptr;
    // Over all cells of the grid, row-major (cell cy cells_w + cx): one CDF rather than a
    // marginal and a conditional, so that a sample waits on two dependent loads, not four.
    CdfView cells;
    // The plain density (a plain choice, BinChoice::plain, or a glossy bin seen beyond its
    // view limit): the plain cell table, the same for every bin.
    bool plain = false;

    // sample(u) in stages, each ending on prefetches of what the next one loads, so that
    // sample_many can interleave the stages of several samples (bit-identical to sample).
    struct Cell {
        CellHit hit;  // in the bin's CDF: the cell and u.x's offset in it
        uint32_t cx = 0, cy = 0;
    };
    struct Texel {
        uint32_t x = 0, y = 0;
        uint32_t width = 0;  // in the cell's texel CDF
        float offset = 0;    // u.y's offset in it: the point's position down the texel
    };
    ENVMIS_HD Cell find_cell(float ux) const noexcept;
    ENVMIS_HD Texel find_texel(const Cell& c, float uy) const noexcept;
    ENVMIS_HD EnvSample sample_at(const Cell& c, const Texel& t) const noexcept;

    ENVMIS_HD EnvSample sample(Vec2 u) const noexcept;
    ENVMIS_HD float pdf(Vec3 direction) const noexcept;
    ENVMIS_HD float pdf_uv(Vec2 uv) const noexcept;
    ENVMIS_HD Rgb eval(Vec3 direction) const noexcept;
    ENVMIS_HD EnvMapView::Lookup lookup(Vec3 direction) const noexcept;
};

namespace detail {
// floor(n / d) for n < 2^28 and d in [1, 2^16], as a product and a shift: with
// k = 28 + ceil(log2 d) and m = ceil(2^k / d) < 2^29, n m / 2^k exceeds n / d by less than
// 1 / d, so the floor is the same, and n m < 2^57 fits. A binned pdf finds its texel's
// cell this way, a binned sample its texel's row in the cell (by_column): a division
// would sit on their critical paths.
struct ExactDivision {
    uint64_t m = 1;
    uint32_t k = 0;
    static ExactDivision by(uint32_t d) noexcept {
        uint32_t l = 0;
        while ((uint64_t{1} << l) < d) ++l;
        const uint32_t k = 28 + l;
        return {((uint64_t{1} << k) + d - 1) / d, k};
    }
    ENVMIS_HD uint32_t of(uint32_t n) const noexcept { return static_cast<uint32_t>((uint64_t{n} * m) >> k); }
};
}  // namespace detail

// Non-owning, device-friendly view of a BinnedEnvMap (flat arrays).
struct BinnedEnvMapView {
    // The radiance, the mapping and the frame; its distribution holds the sizes only
    // (the plain density is the plain cell table over the cell texel CDFs).
    EnvMapView plain;
    // Per (class, bin), then the plain cell table: cells_w cells_h, row-major.
    const uint32_t* cell_start = nullptr;
    const uint16_t* cell_guide = nullptr;
    // Per cell, the CDF over its texels (row-major in the cell) by the plain density; the
    // cells' tables follow each other row-major (cell_texels).
    const uint32_t* texel_start = nullptr;
    const uint16_t* texel_guide = nullptr;
    const uint32_t* column_edges = nullptr;            // cells_w + 1 texel columns
    const uint32_t* row_edges = nullptr;               // cells_h + 1 texel rows
    const detail::ExactDivision* by_column = nullptr;  // per cell column: by its width in texels
    // Per (class, bin): the least view cosine at which the bin samples its own density
    // (BinChoice::min_view_cos; above 1 for a plain choice, which never does).
    const float* min_view_cos = nullptr;
    uint32_t cells_w = 0, cells_h = 0, classes = 0;
    uint32_t bins_per_side = 0, bins = 0;                  // of each glossy class (1 and up)
    uint32_t diffuse_bins_per_side = 0, diffuse_bins = 0;  // of the diffuse class (0)
    uint32_t plain_table = 0;                              // the plain cell table's index
    // Divisions by the plain map's width and height (cell_column, cell_row) and by cells_w
    // (find_cell's row of a cell).
    detail::ExactDivision by_width, by_height, by_cells_w;

    // The density a shading point samples in lobe class `lobe`: among the bins around
    // `at.axis` (world frame; lobe_axis), the one a uniform `choice` in [0,1) picks
    // (normal_blend), or the plain density where the view is more oblique than that
    // bin's limit. A renderer draws `choice` once per shading point and keeps the
    // returned view for its light samples and its BSDF samples' MIS weights alike.
    ENVMIS_HD BinView bin(LobeAxis at, uint32_t lobe, float choice) const noexcept {
        return bin_at(class_bin(lobe, pick_bin(to_canonical(plain.axes, at.axis), side(lobe), choice)), at.view_cos);
    }
    // The same in two steps, for a shading point that draws several choices: the bins
    // around `at.axis` (their indices among all, class_bin) with their weights, and the
    // one a choice picks among them.
    ENVMIS_HD BinBlend blend(LobeAxis at, uint32_t lobe) const noexcept {
        BinBlend b = normal_blend(to_canonical(plain.axes, at.axis), side(lobe));
        for (uint32_t& k : b.bin) k = class_bin(lobe, k);
        b.view_cos = at.view_cos;
        return b;
    }
    ENVMIS_HD BinView bin(const BinBlend& blend, float choice) const noexcept {
        return bin_at(pick_bin(blend, choice), blend.view_cos);
    }
    // The bin whose square holds `axis`, without blending, seen head-on (for showing one
    // bin's density).
    ENVMIS_HD BinView nearest_bin(Vec3 axis, uint32_t lobe) const noexcept {
        return bin_at(class_bin(lobe, normal_bin(to_canonical(plain.axes, axis), side(lobe))), 1);
    }
    // g of lobe class `lobe`'s grid, and the index of its bin b among all (class-major).
    ENVMIS_HD uint32_t side(uint32_t lobe) const noexcept { return lobe == 0 ? diffuse_bins_per_side : bins_per_side; }
    ENVMIS_HD uint32_t class_bin(uint32_t lobe, uint32_t b) const noexcept {
        const uint32_t c = min(lobe, classes - 1);
        return c == 0 ? b : diffuse_bins + (c - 1) * bins + b;
    }
    // Bin `class_bin` seen with view cosine `view_cos`: its own density, or the plain one.
    // A branch, not a select: the table's address then waits for no load of the limit
    // (predicted: a point's bins seldom reach their limits).
    ENVMIS_HD BinView bin_at(uint32_t class_bin, float view_cos) const noexcept {
        if (view_cos >= min_view_cos[class_bin]) [[likely]]
            return table(class_bin);
        return table(plain_table);
    }
    // The plain density (the map's luminance times solid angle) through the cells.
    ENVMIS_HD BinView plain_bin() const noexcept { return table(plain_table); }
    ENVMIS_HD BinView table(uint32_t t) const noexcept {
        const uint32_t cells = cells_w * cells_h;
        const size_t at = size_t{t} * cells;
        return {this, {cell_start + at, cell_guide + at, cells}, t == plain_table};
    }
    ENVMIS_HD EnvSample sample(LobeAxis at, uint32_t lobe, float choice, Vec2 u) const noexcept {
        return bin(at, lobe, choice).sample(u);
    }
    ENVMIS_HD float pdf(LobeAxis at, uint32_t lobe, float choice, Vec3 direction) const noexcept {
        return bin(at, lobe, choice).pdf(direction);
    }
    ENVMIS_HD EnvMapView::Lookup lookup(LobeAxis at, uint32_t lobe, float choice, Vec3 direction) const noexcept {
        return bin(at, lobe, choice).lookup(direction);
    }
    ENVMIS_HD Rgb eval(Vec3 direction) const noexcept { return plain.eval(direction); }

    // Cell column and row of texel (x, y): the cell whose edges hold it.
    ENVMIS_HD uint32_t cell_column(uint32_t x) const noexcept { return by_width.of(x * cells_w); }
    ENVMIS_HD uint32_t cell_row(uint32_t y) const noexcept { return by_height.of(y * cells_h); }
    // The CDF over the texels of cell (cx, cy): the cells before it in its row of cells
    // hold all the texels left of it in its texel rows.
    ENVMIS_HD CdfView cell_texels(uint32_t cx, uint32_t cy) const noexcept {
        const uint32_t y0 = row_edges[cy], rows = row_edges[cy + 1] - y0, x0 = column_edges[cx];
        const size_t at = size_t{y0} * plain.distribution.w + size_t{rows} * x0;
        return {texel_start + at, texel_guide + at, (column_edges[cx + 1] - x0) * rows};
    }
    // Index of texel (x, y) in its cell (cx, cy)'s texel CDF (row-major in the cell).
    ENVMIS_HD uint32_t texel_in_cell(uint32_t x, uint32_t y, uint32_t cx, uint32_t cy) const noexcept {
        return (y - row_edges[cy]) * (column_edges[cx + 1] - column_edges[cx]) + x - column_edges[cx];
    }
    // Image-space density of a texel under a bin, from the fixed-point widths of its cell
    // in the bin's CDF and of the texel in its cell's CDF; one expression for sample and
    // pdf. Products of widths, no quotient: a black cell's texels get 0, never 0 / 0.
    ENVMIS_HD float texel_pdf(uint32_t cell_width, uint32_t texel_width) const noexcept {
        const float texels = static_cast<float>(uint64_t{plain.distribution.w} * plain.distribution.h);
        return static_cast<float>(cell_width) * static_cast<float>(texel_width) * 0x1p-62f * texels;
    }
};

// Both for n (axis, choice, direction or point) at once, one array per world coordinate:
// the batch forms of BinnedEnvMapView::lookup and sample, bit-identical to n single
// calls. Host only; noexcept and allocation-free. On the path envmis/cpu.h chose for
// EnvMap's batch forms: AVX2 searches each lane's bin and cell by gathers, eight lanes at
// a time, where the map fits 32-bit gather indices and its cells hold two texels or more
// (maps 64 texels wide or more on the default grid); the scalar pipeline elsewhere.
ENVMIS_CORE_API void lookup_many(const BinnedEnvMapView& env, uint32_t lobe, LobeAxisArrays axes, const float* choices,
                                 DirectionArrays in, LookupArrays out, uint32_t n) noexcept;
ENVMIS_CORE_API void sample_many(const BinnedEnvMapView& env, uint32_t lobe, LobeAxisArrays axes, const float* choices,
                                 PointArrays in, SampleArrays out, uint32_t n) noexcept;
// The same for n directions or points each in its own bin, picked beforehand (a renderer's
// or a study's shading points, each with the bin it keeps for its samples). Bins of
// several maps may share a call; a run of lanes on the first lane's map takes AVX2.
ENVMIS_CORE_API void lookup_many(const BinView* bins, DirectionArrays in, LookupArrays out, uint32_t n) noexcept;
ENVMIS_CORE_API void sample_many(const BinView* bins, PointArrays in, SampleArrays out, uint32_t n) noexcept;

namespace detail {
struct Geometries;  // bin_cells.h
}

class ENVMIS_CORE_API BinnedEnvMap {
public:
    BinnedEnvMap() = default;
    // Builds the bins a layout describes over `plain` (a table's layout, or the one
    // envmis::build chose: envmis/build/bins.h), bit-identical to the build that chose
    // it; choice_seconds is what choosing it took (choice_seconds()). Throws
    // std::invalid_argument on a layout that does not fit the map; throws Interrupted once
    // `stop` is set (interrupt.h; checked every bin and block of rows).
    BinnedEnvMap(EnvMap plain, const BinLayout& layout, StopFlag stop = nullptr, double choice_seconds = 0);
    // The same with the cells' geometry over `plain` that the choice computed
    // (bin_cells.h; build_bins passes it rather than have it computed twice).
    BinnedEnvMap(EnvMap plain, const BinLayout& layout, const detail::Geometries& geometries, StopFlag stop,
                 double choice_seconds);

    BinnedEnvMapView view() const noexcept;
    // The plain map's radiance, options, stats and size, without its distribution
    // (EnvMap::without_density: not to be sampled); the plain density is
    // view().plain_bin().
    const EnvMap& radiance_map() const noexcept { return plain_; }
    // The plain map whole, its distribution rebuilt (EnvMap::with_density; 6 bytes a
    // texel more), for callers that sample it as a global map.
    EnvMap plain_map() const { return plain_.with_density(); }
    const BinLayout& layout() const noexcept { return layout_; }
    // Bins of each glossy class (what `precompute --bins` names), and of the diffuse class.
    uint32_t bins() const noexcept { return layout_.bins_per_side * layout_.bins_per_side; }
    uint32_t diffuse_bins() const noexcept { return layout_.diffuse_bins_per_side * layout_.diffuse_bins_per_side; }
    uint32_t classes() const noexcept { return static_cast<uint32_t>(layout_.lobe_exponents.size()); }
    uint32_t lobe_class(float phong_exponent) const noexcept {
        return envmis::lobe_class(layout_.lobe_exponents, phong_exponent);
    }
    // True if every bin of the class samples where its normals see light (no bin zeroes
    // texels by compensation); a compensated class is incomplete (envmap.h).
    bool complete(uint32_t lobe) const noexcept;
    // Bytes the bins add to the plain map: their tables less the plain distribution they
    // replace; and the plain map's own (radiance and distribution).
    size_t bytes() const noexcept;
    size_t plain_bytes() const noexcept { return plain_density_bytes_ + plain_.radiance().pixels.size_bytes(); }
    // Seconds the build spent choosing alphas (0 when rebuilt from a layout).
    double choice_seconds() const noexcept { return choice_seconds_; }

private:
    // Throws std::invalid_argument where layout_ does not fit plain_.
    void check_layout() const;
    // The flat tables over layout_'s cells, with the given geometry (null: computed here).
    void build(const detail::Geometries* given, StopFlag stop);

    EnvMap plain_;
    BinLayout layout_;
    LargeVector<uint32_t> cell_start_, texel_start_;
    LargeVector<uint16_t> cell_guide_, texel_guide_;
    std::vector<uint32_t> column_edges_, row_edges_;
    std::vector<detail::ExactDivision> by_column_;
    std::vector<float> min_view_cos_;
    size_t plain_density_bytes_ = 0;
    double choice_seconds_ = 0;
};

// ---- inline definitions ----

// The cell of u.x in the bin's CDF.
ENVMIS_HD inline BinView::Cell BinView::find_cell(float ux) const noexcept {
    const BinnedEnvMapView& m = *map;
    const CellHit hit = cells.invert(ux);
    const uint32_t cy = m.by_cells_w.of(hit.index);
    return {hit, hit.index - cy * m.cells_w, cy};
}

// A prefetch, once the cell is known, of its texel CDF where u.y's guide bucket points.
ENVMIS_HD inline void prefetch_texels(const BinnedEnvMapView& m, const BinView::Cell& c, float uy) noexcept {
    const CdfView texels = m.cell_texels(c.cx, c.cy);
    const uint32_t k = texels.bucket(uy);
    ENVMIS_PREFETCH(texels.guide + k);
    ENVMIS_PREFETCH(texels.start + k);
}

// Once that guide entry has arrived: prefetches of the first and last CDF entries it
// names, where the search will look (a large cell's answer lies far from its bucket).
ENVMIS_HD inline void prefetch_texel_span(const BinnedEnvMapView& m, const BinView::Cell& c, float uy) noexcept {
    const CdfView texels = m.cell_texels(c.cx, c.cy);
    const CdfTable::Span s = texels.guide_span(texels.bucket(uy));
    ENVMIS_PREFETCH(texels.start + s.lo);
    ENVMIS_PREFETCH(texels.start + s.hi);
}

// The texel, by the cell's texel CDF; then a prefetch of its radiance.
ENVMIS_HD inline BinView::Texel BinView::find_texel(const Cell& c, float uy) const noexcept {
    const BinnedEnvMapView& m = *map;
    const CellHit t = m.cell_texels(c.cx, c.cy).invert(uy);
    const uint32_t dy = m.by_column[c.cx].of(t.index);
    const uint32_t y = m.row_edges[c.cy] + dy,
                   x = m.column_edges[c.cx] + t.index - dy * (m.column_edges[c.cx + 1] - m.column_edges[c.cx]);
    ENVMIS_PREFETCH(m.plain.radiance + static_cast<size_t>(y) * m.plain.distribution.w + x);
    return {x, y, t.width, t.offset};
}

ENVMIS_HD inline EnvSample BinView::sample_at(const Cell& c, const Texel& t) const noexcept {
    const BinnedEnvMapView& m = *map;
    const uint32_t w = m.plain.distribution.w;
    const Vec2 p{detail::point_in_cell(t.x, c.hit.offset, w),
                 detail::point_in_cell(t.y, t.offset, m.plain.distribution.h)};
    const float image_pdf = m.texel_pdf(cells.width(c.hit.index), t.width);
    return m.plain.at(p, image_pdf, static_cast<size_t>(t.y) * w + t.x);
}

// u.x picks the cell, u.y the texel in it.
ENVMIS_HD inline EnvSample BinView::sample(Vec2 u) const noexcept {
    const Cell c = find_cell(u.x);
    return sample_at(c, find_texel(c, u.y));
}

ENVMIS_HD inline float BinView::pdf_uv(Vec2 uv) const noexcept {
    const BinnedEnvMapView& m = *map;
    const uint32_t x = detail::cell_of(uv.x, m.plain.distribution.w), y = detail::cell_of(uv.y, m.plain.distribution.h);
    const uint32_t cx = m.cell_column(x), cy = m.cell_row(y);
    const float image_pdf =
        m.texel_pdf(cells.width(cy * m.cells_w + cx), m.cell_texels(cx, cy).width(m.texel_in_cell(x, y, cx, cy)));
    return m.plain.image_to_solid_angle(image_pdf, uv.y);
}

ENVMIS_HD inline float BinView::pdf(Vec3 direction) const noexcept { return pdf_uv(map->plain.uv_of(direction)); }
ENVMIS_HD inline Rgb BinView::eval(Vec3 direction) const noexcept { return map->plain.eval(direction); }
ENVMIS_HD inline EnvMapView::Lookup BinView::lookup(Vec3 direction) const noexcept {
    const Vec2 uv = map->plain.uv_of(direction);
    return {map->plain.eval_uv(uv), pdf_uv(uv)};
}

}  // namespace envmis
