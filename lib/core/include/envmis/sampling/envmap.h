// An importance-sampled environment map: the radiance image, its sampling density
// (luminance, optionally MIS-compensated, times the texel's relative solid angle) and
// the distribution that samples it. Equirectangular by default, or equal-area
// octahedral (a square image; mapping.h).
//
// Measure: `sample` and `pdf` speak solid angle (per steradian) over directions in the
// world frame given by EnvMapOptions::axes (mapping.h). The density of texel (x, y) in
// image space is proportional to q(x, y) w_y, with q = L (uncompensated) or
// max(L - alpha Lbar, 0) (compensated), and w_y = sin(theta_y) (row centre) for
// equirect, 1 for equal-area; the solid-angle pdf is that image density divided by
// 2 pi^2 sin theta (equirect) or 4 pi (equal-area). Radiance is the texel's value
// (nearest), so it is constant exactly where the density is.
//
// Cost: build O(w h) (build_env_map, envmis/build/env_map.h), parallel over rows; sample, pdf
// and eval O(1), noexcept and allocation-free. Memory: 6 bytes per texel for the
// distribution plus 12 for the RGB radiance (not the map's own when it borrows a
// memory-mapped table's).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include "envmis/compensation/compensation.h"
#include "envmis/core_export.h"
#include "envmis/image/image.h"
#include "envmis/image/mapping.h"
#include "envmis/interrupt.h"
#include "envmis/math/math.h"
#include "envmis/sampling/distribution.h"

namespace envmis {

inline constexpr float kTwoPiSquared = static_cast<float>(2 * kPi * kPi);

// How the density was chosen when the requested one was unusable.
enum class DensityFallback : uint32_t {
    none = 0,
    uncompensated = 1,  // compensation zeroed every texel (a constant map): plain luminance used
    uniform = 2,        // the map is black: uniform over the sphere
};
ENVMIS_CORE_API std::string_view to_string(DensityFallback f) noexcept;

struct EnvMapOptions {
    CompensationOptions compensation;     // enabled by default, alpha = 1
    LumaCoefficients luma;                // of the radiance's colour space (Rec.709 by default)
    Axes axes;                            // world frame of directions (z up by default)
    Mapping mapping = Mapping::equirect;  // equal_area needs a square image
};

// What the build measured and did; recorded in table files.
struct EnvMapStats {
    BadPixels bad_pixels;       // channel values replaced by 0
    double mean_luminance = 0;  // Lbar, solid-angle weighted
    float threshold = 0;        // alpha Lbar if compensation was applied, else 0
    float max_luminance = 0;
    float min_positive_luminance = 0;  // 0 if the map is black
    uint64_t zeroed_texels = 0;        // texels with L > 0 whose density compensation set to 0
    DensityFallback fallback = DensityFallback::none;
};

// EnvMapStats field by field, in declaration order, under the names every writer of them
// uses (precompute's JSON summary, Python's EnvMap.stats): visit(name, value) with value
// a const BadPixels&, a double, a float, a uint64_t or (the fallback) a std::string_view.
// A new field added here reaches every writer.
template <class Visit>
void visit_stats_fields(const EnvMapStats& s, Visit&& visit) {
    visit("bad_pixels", s.bad_pixels);
    visit("mean_luminance", s.mean_luminance);
    visit("threshold", s.threshold);
    visit("max_luminance", s.max_luminance);
    visit("min_positive_luminance", s.min_positive_luminance);
    visit("zeroed_texels", s.zeroed_texels);
    visit("fallback", to_string(s.fallback));
}

// One sample: a world direction, its solid-angle pdf, the radiance arriving from it and
// its image point.
struct EnvSample {
    Vec3 direction;
    float pdf = 0;
    Rgb radiance;
    Vec2 uv;
};

// Non-owning, device-friendly view of an EnvMap (flat arrays; see distribution.h).
struct EnvMapView {
    Distribution2DView distribution;
    const Rgb* radiance = nullptr;
    Axes axes;
    const SinCos* turns = nullptr;  // make_turn_table() (fast_math.h)
    Mapping mapping = Mapping::equirect;

    // u in [0,1)^2; a coordinate outside it (1.0, NaN) is clamped into it (unit_point).
    ENVMIS_HD ENVMIS_INLINE EnvSample sample(Vec2 u) const noexcept {
        // Prefetching the radiance near the answer overlaps its load with the search's.
        const auto s = distribution.sample(u, [this](size_t first, size_t last) { prefetch_radiance(first, last); });
        return at(s.p, s.pdf, static_cast<size_t>(s.y) * distribution.w + s.x);
    }
    // The sample at image point p of texel `texel`, drawn with image-space density
    // image_pdf (by this map's distribution or another over the same texels: binned.h).
    ENVMIS_HD ENVMIS_INLINE EnvSample at(Vec2 p, float image_pdf, size_t texel) const noexcept {
        if (mapping == Mapping::equal_area) [[unlikely]]
            return at_equal_area(p, image_pdf, texel);
        const SinCos theta = sincos_half_turns(turns, p.y), phi = sincos_turns(turns, p.x);
        const float sin_theta = theta.sin;  // >= 0 on [0, 1): see fast_math_test
        const Vec3 canonical{sin_theta * phi.cos, sin_theta * phi.sin, theta.cos};
        return {to_world(axes, canonical), solid_angle_pdf(image_pdf, sin_theta), radiance[texel], p};
    }
    // The equal-area half of at(), inline: a call, returning the sample through memory,
    // is costly, and inlining it leaves the equirectangular path as fast (measured:
    // docs/performance-log.md, 'at_equal_area').
    ENVMIS_HD EnvSample at_equal_area(Vec2 p, float image_pdf, size_t texel) const noexcept {
        return {to_world(axes, equal_area_direction(p)), image_pdf * (1 / kFourPi), radiance[texel], p};
    }
    // Solid-angle pdf of sampling `direction` (a unit vector in the world frame).
    ENVMIS_HD float pdf(Vec3 direction) const noexcept {
        if (mapping == Mapping::equal_area) [[unlikely]]
            return pdf_equal_area(to_canonical(axes, direction));
        return pdf_uv(equirect_uv(to_canonical(axes, direction)));
    }
    // pdf's equal-area half, out of line whole: its mapping and its lookup inlined together
    // (measured: docs/performance-log.md, 'pdf_equal_area').
    ENVMIS_NOINLINE ENVMIS_HD float pdf_equal_area(Vec3 canonical) const noexcept {
        return distribution.pdf(equal_area_uv(canonical)) * (1 / kFourPi);
    }
    // Solid-angle pdf at image point uv; bit-identical to sample(u).pdf when uv = sample(u).uv.
    ENVMIS_HD float pdf_uv(Vec2 uv) const noexcept { return image_to_solid_angle(distribution.pdf(uv), uv.y); }
    // An image-space density at image row v, per steradian; on one float or eight lanes.
    template <class F>
    ENVMIS_HD F image_to_solid_angle(F image_pdf, F v) const noexcept {
        if (mapping == Mapping::equal_area) return image_pdf * (1 / kFourPi);
        return solid_angle_pdf(image_pdf, sincos_half_turns(turns, v).sin);
    }
    // Image point of a world direction.
    ENVMIS_HD Vec2 uv_of(Vec3 direction) const noexcept {
        const Vec3 canonical = to_canonical(axes, direction);
        if (mapping == Mapping::equal_area) [[unlikely]]
            return equal_area_uv_out_of_line(canonical);
        return equirect_uv(canonical);
    }
    // Out of line, keeping the equirectangular lookup's code small: inlined equal-area
    // code has slowed it (measured: docs/performance-log.md,
    // 'equal_area_uv_out_of_line').
    ENVMIS_NOINLINE ENVMIS_HD static Vec2 equal_area_uv_out_of_line(Vec3 canonical) noexcept {
        return equal_area_uv(canonical);
    }
    // Radiance arriving from `direction` (nearest texel).
    ENVMIS_HD Rgb eval(Vec3 direction) const noexcept { return eval_uv(uv_of(direction)); }
    ENVMIS_HD Rgb eval_uv(Vec2 uv) const noexcept {
        const uint32_t x = detail::cell_of(uv.x, distribution.w), y = detail::cell_of(uv.y, distribution.h);
        return radiance[static_cast<size_t>(y) * distribution.w + x];
    }
    // Starts loading what eval_uv and pdf_uv read at uv, so that code with several
    // lookups to make (a batch of shading samples) overlaps their cache misses.
    ENVMIS_HD void prefetch_uv(Vec2 uv) const noexcept {
        prefetch_cell(detail::cell_of(uv.x, distribution.w), detail::cell_of(uv.y, distribution.h));
    }
    // The same for the texel in column x of row y: all a lookup there reads beyond the
    // turn table (prefetch_texel, and the row's marginal entry).
    ENVMIS_HD void prefetch_cell(uint32_t x, uint32_t y) const noexcept {
        prefetch_texel(static_cast<size_t>(y) * distribution.w + x);
        ENVMIS_PREFETCH(distribution.marginal.start + y);
    }
    // The same for texel i (row-major) but its row's marginal entry: its radiance, its
    // CDF entry and the next (its width).
    ENVMIS_HD void prefetch_texel(size_t i) const noexcept {
        prefetch_radiance(i, i);
        ENVMIS_PREFETCH(distribution.start + i);
        ENVMIS_PREFETCH(distribution.start + i + 1);  // one past the table at most: a prefetch does not fault
    }
    // The radiance of texels first to last of a row, at most five (two cache lines),
    // through both ends: a texel may straddle two lines.
    ENVMIS_HD void prefetch_radiance(size_t first, size_t last) const noexcept {
        ENVMIS_PREFETCH(radiance + first);
        ENVMIS_PREFETCH(&radiance[last].b);
    }
    // Both at once, mapping the direction to the image once (MIS needs both).
    struct Lookup {
        Rgb radiance;
        float pdf = 0;
    };
    ENVMIS_HD Lookup lookup(Vec3 direction) const noexcept {
        const Vec2 uv = uv_of(direction);
        return {eval_uv(uv), pdf_uv(uv)};
    }
    // Image density to solid angle; 0 at the poles, where the mapping degenerates.
    // On one float or eight lanes (math.h's lane types).
    template <class F>
    ENVMIS_HD static F solid_angle_pdf(F image_pdf, F sin_theta) noexcept {
        return select(sin_theta > 0.0f, image_pdf / (kTwoPiSquared * sin_theta), 0.0f);
    }
};

// EnvMapView::lookup for n directions at once, for code that holds many (an estimator's
// or a wavefront renderer's BSDF samples): directions in, one array per world
// coordinate; radiance and solid-angle pdf out, likewise. Bit-identical to n calls of
// lookup. A map in either mapping and any axes is looked up eight directions at a time
// with AVX2 where batch_paths() chose it for this CPU (envmis/cpu.h); otherwise one
// direction at a time, software-pipelined with prefetches so that the misses of many
// lookups overlap (envmap_many.cpp). Host only; noexcept and allocation-free.
struct DirectionArrays {
    const float *x, *y, *z;
};
struct LookupArrays {
    float *r, *g, *b, *pdf;
};
ENVMIS_CORE_API void lookup_many(const EnvMapView& env, DirectionArrays in, LookupArrays out, uint32_t n) noexcept;

// EnvMapView::sample for n random points at once, likewise: the points' two coordinates
// in [0,1) in, one array each; direction, solid-angle pdf and radiance out, and the
// image point (EnvSample::uv) where u and v are given (null: not written). Bit-identical
// to n calls of sample; AVX2 on the same maps as lookup_many, at least 2x2, where
// batch_paths() chose it for sampling; otherwise one point at a time, pipelined.
struct PointArrays {
    const float *x, *y;
};
struct SampleArrays {
    float *x, *y, *z, *pdf, *r, *g, *b;
    float *u = nullptr, *v = nullptr;  // optional: the image point's two coordinates
};
ENVMIS_CORE_API void sample_many(const EnvMapView& env, PointArrays in, SampleArrays out, uint32_t n) noexcept;
// The arrays from lane k on: a batch call over the lanes of a batch from k on.
inline DirectionArrays from_lane(DirectionArrays a, uint32_t k) noexcept { return {a.x + k, a.y + k, a.z + k}; }
inline LookupArrays from_lane(LookupArrays a, uint32_t k) noexcept { return {a.r + k, a.g + k, a.b + k, a.pdf + k}; }
inline PointArrays from_lane(PointArrays a, uint32_t k) noexcept { return {a.x + k, a.y + k}; }
inline SampleArrays from_lane(SampleArrays a, uint32_t k) noexcept {
    return {a.x + k,
            a.y + k,
            a.z + k,
            a.pdf + k,
            a.r + k,
            a.g + k,
            a.b + k,
            a.u ? a.u + k : nullptr,
            a.v ? a.v + k : nullptr};
}

// Row y (of h) of the image-space density that a map with these options and stats
// samples, q(x, y) w_y, from that row's radiance (row.size() values): what
// EnvMap::density() holds, for code that rebuilds a map's density without the map.
ENVMIS_CORE_API void density_row(std::span<const Rgb> radiance_row, uint32_t y, uint32_t h,
                                 const EnvMapOptions& options, const EnvMapStats& stats, std::span<float> out);

class ENVMIS_CORE_API EnvMap {
public:
    EnvMap() = default;
    // A map from a radiance image is built by envmis::build's build_env_map
    // (envmis/build/env_map.h), which ends in this constructor: `density` is the
    // distribution it built from `radiance` (repaired) with these options, and `stats`
    // what it measured. Checks the sizes and options only: the parts are trusted. Throws
    // std::invalid_argument where the sizes differ or the options are invalid.
    EnvMap(RgbImage radiance, Distribution2D density, const EnvMapOptions& options, const EnvMapStats& stats);

    // Rebuilds a saved sampler from its parts (the table reader's path): the image
    // density q(x, y) w_y exactly as density() returned it, as float bit patterns; that
    // buffer becomes the CDF table, so a load holds nothing else of the map's size. Gives
    // bit-identical samples to the map that was saved. Throws std::invalid_argument on
    // inconsistent parts.
    EnvMap(RgbImage radiance, LargeVector<uint32_t> density_bits, const EnvMapOptions& options,
           const EnvMapStats& stats);
    // The same with radiance the map borrows instead of holding (a memory-mapped table
    // file): `owner` keeps the pixels alive and unchanged for as long as the map or a
    // copy of it lives.
    EnvMap(RgbImageView radiance, std::shared_ptr<const void> owner, LargeVector<uint32_t> density_bits,
           const EnvMapOptions& options, const EnvMapStats& stats);

    EnvMapView view() const noexcept {
        return {distribution_.view(), radiance_.pixels.data(), options_.axes, turns_.data(), options_.mapping};
    }
    EnvSample sample(Vec2 u) const noexcept { return view().sample(u); }
    float pdf(Vec3 direction) const noexcept { return view().pdf(direction); }
    float pdf_uv(Vec2 uv) const noexcept { return view().pdf_uv(uv); }
    Rgb eval(Vec3 direction) const noexcept { return view().eval(direction); }

    uint32_t width() const noexcept { return radiance_.width; }
    uint32_t height() const noexcept { return radiance_.height; }
    const EnvMapOptions& options() const noexcept { return options_; }
    const EnvMapStats& stats() const noexcept { return stats_; }
    // The repaired radiance, as built (owned) or loaded (possibly a file mapping).
    RgbImageView radiance() const noexcept { return radiance_; }
    const Distribution2D& distribution() const noexcept { return distribution_; }
    // The same map without its distribution's tables (Distribution2D::without_tables):
    // radiance, options, stats and sizes, for a holder that samples the map's density
    // through tables of its own (BinnedEnvMap). Its sample and pdf must not be called.
    EnvMap without_density() && {
        EnvMap m = std::move(*this);
        m.distribution_ = m.distribution_.without_tables();
        return m;
    }
    // The same map with its distribution rebuilt from the radiance (density()), sharing
    // the pixels: bit-identical samples to the map built or loaded.
    EnvMap with_density() const;
    // The image-space density function, q(x, y) w_y, row-major, recomputed
    // from the radiance exactly as the build computed it.
    std::vector<float> density() const;
    // Row y of density() (w values), for writers that stream it.
    void density_row(uint32_t y, std::span<float> row) const;

    // True if the density was compensated (and no fallback replaced it).
    bool compensated() const noexcept {
        return options_.compensation.enabled && stats_.fallback == DensityFallback::none;
    }
    // True if pdf > 0 wherever the radiance is non-zero, so that the map can be sampled
    // alone without bias. A compensated density is usually incomplete: combine it with a
    // technique that covers the whole sphere (BSDF sampling) through MIS.
    bool complete() const noexcept { return stats_.zeroed_texels == 0; }

private:
    // Makes the image's pixels the map's own radiance.
    void adopt(RgbImage image);
    // The table constructors' common part: checks the radiance, builds the distribution.
    void rebuild(LargeVector<uint32_t> density_bits);

    // The pixels are immutable once built, so copies of a map share them.
    std::shared_ptr<const void> radiance_owner_;
    RgbImageView radiance_;
    Distribution2D distribution_;
    std::vector<SinCos> turns_ = make_turn_table();
    EnvMapOptions options_;
    EnvMapStats stats_;
};

}  // namespace envmis
