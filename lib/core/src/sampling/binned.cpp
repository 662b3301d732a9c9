// BinnedEnvMap (binned.h) from a layout: geometry of bins and cells, cell histograms and
// masses (bin_cells.h), and the flat tables. The layout's choice is envmis::build's
// (lib/build/src/bins.cpp).
#include "envmis/sampling/binned.h"

#include "envmis/sampling/bin_cells.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

#include "detail/luminance.h"
#include "detail/parallel.h"

namespace envmis {

uint32_t lobe_class(std::span<const float> exponents, float phong_exponent) noexcept {
    const double key = std::log1p(std::max(0.0, static_cast<double>(phong_exponent)));
    uint32_t best = 0;
    double best_distance = std::numeric_limits<double>::infinity();
    for (uint32_t i = 0; i < exponents.size(); ++i) {
        const double distance = std::abs(std::log1p(static_cast<double>(exponents[i])) - key);
        if (distance < best_distance) best = i, best_distance = distance;
    }
    return best;
}

namespace detail {

CellGrid::CellGrid(uint32_t w_, uint32_t h_, uint32_t columns, uint32_t rows, Mapping m)
    : w(w_), h(h_), cw(columns), ch(rows), mapping(m), column_edges(columns + 1), row_edges(rows + 1) {
    for (uint32_t c = 0; c <= cw; ++c) column_edges[c] = static_cast<uint32_t>((uint64_t{c} * w + cw - 1) / cw);
    for (uint32_t r = 0; r <= ch; ++r) row_edges[r] = static_cast<uint32_t>((uint64_t{r} * h + ch - 1) / ch);
}

namespace {

// The largest angle between `centre` and the curve through point(i / steps), i = 0 ..
// steps, plus half the largest step between consecutive points (the curve between two
// points lies within that of one of them), so an upper bound of the region's radius
// when the curve is its boundary.
template <class Point>
float boundary_radius(Vec3 centre, uint32_t steps, Point&& point) {
    double largest = 0, step = 0;
    Vec3 previous = point(0.0);
    for (uint32_t i = 0; i <= steps; ++i) {
        const Vec3 p = point(static_cast<double>(i) / steps);
        largest = std::max(largest, std::acos(std::clamp(static_cast<double>(dot(p, centre)), -1.0, 1.0)));
        step = std::max(step, std::acos(std::clamp(static_cast<double>(dot(p, previous)), -1.0, 1.0)));
        previous = p;
    }
    return static_cast<float>(largest + 0.6 * step + 1e-5);
}

// Radius of the region that a map (s, t) -> direction takes the square
// [s0, s1] x [t0, t1] to, from its boundary walked edge by edge.
template <class Direction>
float square_radius(Vec3 centre, double s0, double s1, double t0, double t1, Direction&& direction) {
    constexpr uint32_t kSteps = 64;  // per edge
    auto at = [&](double s, double t) { return direction(static_cast<float>(s), static_cast<float>(t)); };
    const float edges[4] = {
        boundary_radius(centre, kSteps, [&](double f) { return at(s0 + f * (s1 - s0), t0); }),
        boundary_radius(centre, kSteps, [&](double f) { return at(s1, t0 + f * (t1 - t0)); }),
        boundary_radius(centre, kSteps, [&](double f) { return at(s1 - f * (s1 - s0), t1); }),
        boundary_radius(centre, kSteps, [&](double f) { return at(s0, t1 - f * (t1 - t0)); }),
    };
    return *std::max_element(edges, edges + 4);
}

}  // namespace

// Per cell: the normalised sum over its texels of luminance times relative solid angle
// times the texel centre's direction; the cell's centre where that is zero.
std::vector<Vec3> cell_lights(const EnvMap& plain, const CellGrid& grid, const std::vector<Vec3>& centres) {
    std::vector<Vec3> light(centres.size());
    const Rgb* pixels = plain.radiance().pixels.data();
    const LumaCoefficients luma = plain.options().luma;
    parallel_for(grid.ch, 1, nullptr, [&](uint32_t lo, uint32_t hi) {
        for (uint32_t cy = lo; cy < hi; ++cy)
            for (uint32_t cx = 0; cx < grid.cw; ++cx) {
                double sum[3] = {0, 0, 0};
                for (uint32_t y = grid.row_edges[cy]; y < grid.row_edges[cy + 1]; ++y) {
                    const double w = row_weight(grid.mapping, y, grid.h);
                    for (uint32_t x = grid.column_edges[cx]; x < grid.column_edges[cx + 1]; ++x) {
                        const double l = texel_luminance(pixels[size_t{y} * grid.w + x], luma) * w;
                        if (!(l > 0)) continue;
                        const Vec3 d = image_direction(grid.mapping, {(x + 0.5f) / grid.w, (y + 0.5f) / grid.h});
                        sum[0] += l * d.x, sum[1] += l * d.y, sum[2] += l * d.z;
                    }
                }
                const Vec3 s{static_cast<float>(sum[0]), static_cast<float>(sum[1]), static_cast<float>(sum[2])};
                const size_t i = size_t{cy} * grid.cw + cx;
                light[i] = length(s) > 0 ? normalize(s) : centres[i];
            }
    });
    return light;
}

Geometry::Geometry(const EnvMap& plain, const CellGrid& grid, uint32_t g) {
    cell_direction.resize(size_t{grid.cw} * grid.ch);
    cell_radius.resize(cell_direction.size());
    const auto dir = [&](float u, float v) { return image_direction(grid.mapping, {u, v}); };
    for (uint32_t r = 0; r < grid.ch; ++r)
        for (uint32_t c = 0; c < grid.cw; ++c) {
            const double u0 = static_cast<double>(grid.column_edges[c]) / grid.w,
                         u1 = static_cast<double>(grid.column_edges[c + 1]) / grid.w;
            const double v0 = static_cast<double>(grid.row_edges[r]) / grid.h,
                         v1 = static_cast<double>(grid.row_edges[r + 1]) / grid.h;
            const size_t i = size_t{r} * grid.cw + c;
            cell_direction[i] = dir(static_cast<float>(0.5 * (u0 + u1)), static_cast<float>(0.5 * (v0 + v1)));
            cell_radius[i] = square_radius(cell_direction[i], u0, u1, v0, v1, dir);
        }
    cell_light = cell_lights(plain, grid, cell_direction);
    set_bins(g);
}

Geometry::Geometry(const Geometry& cells, uint32_t g)
    : cell_direction(cells.cell_direction), cell_light(cells.cell_light), cell_radius(cells.cell_radius) {
    set_bins(g);
}

void Geometry::set_bins(uint32_t g) {
    bin_normal.resize(size_t{g} * g);
    bin_radius.resize(bin_normal.size());
    for (uint32_t t = 0; t < g; ++t)
        for (uint32_t s = 0; s < g; ++s) {
            const size_t b = size_t{t} * g + s;
            bin_normal[b] = octahedral_normal((s + 0.5f) / g, (t + 0.5f) / g);
            bin_radius[b] = square_radius(bin_normal[b], static_cast<double>(s) / g, (s + 1.0) / g,
                                          static_cast<double>(t) / g, (t + 1.0) / g, octahedral_normal);
        }
    // The blend support: the bin's square widened by half the blend's ramp on each side,
    // its points beyond the map's edges taken across the folds.
    support_radius.resize(bin_normal.size());
    const double e = 0.5 * kBlendWidth / g;
    for (uint32_t t = 0; t < g; ++t)
        for (uint32_t s = 0; s < g; ++s)
            support_radius[size_t{t} * g + s] =
                square_radius(bin_normal[size_t{t} * g + s], s * 1.0 / g - e, (s + 1.0) / g + e, t * 1.0 / g - e,
                              (t + 1.0) / g + e, [](float u, float v) { return folded_octahedral_normal(u, v); });
}

float Geometry::bound(uint32_t bin, size_t cell) const noexcept {
    const float angle = std::acos(std::clamp(dot(bin_normal[bin], cell_direction[cell]), -1.0f, 1.0f)) -
                        support_radius[bin] - cell_radius[cell];
    if (angle <= 0) return 1;
    return angle >= kPiF / 2 ? 0.0f : std::cos(angle);
}

float Geometry::weight(uint32_t bin, size_t cell, bool glossy) const noexcept {
    // A glossy class's bin follows the lobe's axis, not the normal: the surface's horizon
    // may lie anywhere around it, and a microfacet lobe's tails reach past 90 degrees
    // from it (at grazing views most of all), where a bright source then arrives only
    // through rare BSDF samples. So no cell of a glossy bin is left out.
    constexpr float kGlossyFloor = 0.1f;
    const float b = bound(bin, cell);
    if (b == 0) return glossy ? kGlossyFloor : 0.0f;
    // The cosine seen from a quarter of the way from the bin's centre to its edge, to the
    // cell's centre: a typical normal of the bin rather than its most favourable one
    // (binned.h gives the figures); the floor keeps every cell that some normal of the
    // bin may see positive, as coverage needs.
    constexpr float kBinShare = 0.25f, kFloor = 0.1f;
    const float angle =
        std::acos(std::clamp(dot(bin_normal[bin], cell_light[cell]), -1.0f, 1.0f)) - kBinShare * bin_radius[bin];
    const float typical = angle <= 0 ? 1.0f : (angle >= kPiF / 2 ? 0.0f : std::cos(angle));
    return std::max({typical, kFloor * b, glossy ? kGlossyFloor : 0.0f});
}

void check_options(const BinnedOptions& o) {
    if (o.bins_per_side < 1 || o.bins_per_side > 64)
        throw std::invalid_argument("bins per side must be 1 to 64, got " + std::to_string(o.bins_per_side));
    if (o.diffuse_bins_per_side > 64)
        throw std::invalid_argument("diffuse bins per side must be 1 to 64 (or 0: the default), got " +
                                    std::to_string(o.diffuse_bins_per_side));
    const auto& e = o.lobe_exponents;
    if (e.empty() || e.size() > 8 || e[0] != 0 || !std::is_sorted(e.begin(), e.end()) ||
        !std::all_of(e.begin(), e.end(), [](float x) { return x >= 0 && x <= 1e5f; }))
        throw std::invalid_argument("lobe exponents: 1 to 8, ascending, the first 0, each at most 1e5");
    const auto valid_alpha = [](float a) { return a >= 0 && a <= 1e3f; };
    if (o.auto_alpha ? (o.candidates.empty() || !std::all_of(o.candidates.begin(), o.candidates.end(), valid_alpha))
                     : !valid_alpha(o.alpha))
        throw std::invalid_argument("bin alphas must be finite, 0 to 1000");
    if (!(o.cost >= 1 && o.cost <= 100))
        throw std::invalid_argument("the binned cost must be 1 to 100, got " + std::to_string(o.cost));
}

uint64_t largest_cell(uint32_t w, uint32_t h, uint32_t columns, uint32_t rows) noexcept {
    return uint64_t{(w + columns - 1) / columns} * ((h + rows - 1) / rows);
}

// A bin's cells form one CDF, and a cell's texels another, whose uint16 guide entries
// name at most 65536 cells or texels.
void check_cells(uint32_t w, uint32_t h, uint32_t columns, uint32_t rows) {
    if (uint64_t{columns} * rows > kMaxCells1D)
        throw std::invalid_argument("a cell grid has at most 65536 cells, got " + std::to_string(columns) + "x" +
                                    std::to_string(rows));
    if (largest_cell(w, h, columns, rows) > kMaxCells1D)
        throw std::invalid_argument("a cell holds at most 65536 texels: " + std::to_string(columns) + "x" +
                                    std::to_string(rows) + " cells over a " + std::to_string(w) + "x" +
                                    std::to_string(h) + " map hold up to " +
                                    std::to_string(largest_cell(w, h, columns, rows)));
}

CellHistogram histogram(const EnvMap& plain, const CellGrid& grid, std::span<const float> thresholds, StopFlag stop) {
    CellHistogram hist;
    int64_t lo = std::numeric_limits<int64_t>::max(), hi = 0;
    for (float t : thresholds) {
        const int64_t id = std::bit_cast<uint32_t>(t) >> kHistogramShift;
        if (t > 0) lo = std::min(lo, id), hi = std::max(hi, id);
    }
    hist.first = lo > hi ? 0 : lo;
    hist.buckets = lo > hi ? 1 : static_cast<uint32_t>(hi - lo + 2);
    const size_t cells = size_t{grid.cw} * grid.ch, b = hist.buckets;
    hist.suffix_l.assign(cells * b, 0);
    hist.suffix_w.assign(cells * b, 0);
    hist.total_l.assign(cells, 0);
    hist.max_l.assign(cells, 0);
    const Rgb* pixels = plain.radiance().pixels.data();
    const LumaCoefficients luma = plain.options().luma;
    parallel_for(grid.ch, 1, stop, [&](uint32_t r0, uint32_t r1) {
        for (uint32_t cy = r0; cy < r1; ++cy)
            for (uint32_t y = grid.row_edges[cy]; y < grid.row_edges[cy + 1]; ++y) {
                const double w = row_weight(grid.mapping, y, grid.h);
                for (uint32_t cx = 0; cx < grid.cw; ++cx) {
                    const size_t cell = size_t{cy} * grid.cw + cx;
                    for (uint32_t x = grid.column_edges[cx]; x < grid.column_edges[cx + 1]; ++x) {
                        const float l = texel_luminance(pixels[size_t{y} * grid.w + x], luma);
                        if (!(l > 0)) continue;
                        hist.total_l[cell] += l * w;
                        hist.max_l[cell] = std::max(hist.max_l[cell], l);
                        const int64_t k =
                            static_cast<int64_t>(std::bit_cast<uint32_t>(l) >> kHistogramShift) - hist.first;
                        if (k < 0) continue;
                        const size_t at = cell * b + static_cast<size_t>(std::min<int64_t>(k, b - 1));
                        hist.suffix_l[at] += l * w;
                        hist.suffix_w[at] += w;
                    }
                }
            }
        for (size_t cell = size_t{r0} * grid.cw; cell < size_t{r1} * grid.cw; ++cell)
            for (size_t k = b - 1; k-- > 0;) {
                hist.suffix_l[cell * b + k] += hist.suffix_l[cell * b + k + 1];
                hist.suffix_w[cell * b + k] += hist.suffix_w[cell * b + k + 1];
            }
    });
    return hist;
}

std::vector<std::vector<float>> bin_masses(const EnvMap& plain, const CellGrid& grid, const Geometries& geometries,
                                           const BinLayout& layout, StopFlag stop) {
    std::vector<float> thresholds;
    for (const BinChoice& c : layout.choices) thresholds.push_back(c.plain() ? 0.0f : c.threshold);
    const CellHistogram hist = histogram(plain, grid, thresholds, stop);
    const size_t cells = size_t{grid.cw} * grid.ch;
    std::vector<std::vector<float>> masses(layout.choices.size(), std::vector<float>(cells));
    parallel_for(static_cast<uint32_t>(masses.size()), 1, stop, [&](uint32_t lo, uint32_t hi) {
        for (uint32_t cb = lo; cb < hi; ++cb) {
            const uint32_t c = layout.class_of(cb), b = static_cast<uint32_t>(cb - layout.first(c));
            const BinChoice& choice = layout.choices[cb];
            for (size_t cell = 0; cell < cells; ++cell) {
                const double bound = choice.plain() ? 1.0 : geometries.of(c).weight(b, cell, c > 0);
                const double s = hist.above(cell, choice.plain() ? 0.0f : choice.threshold);
                const auto m = static_cast<float>(bound * s);
                masses[cb][cell] = bound > 0 && s > 0 ? std::max(m, std::numeric_limits<float>::min()) : 0.0f;
            }
        }
    });
    return masses;
}

}  // namespace detail

using detail::CellGrid;

BinnedEnvMap::BinnedEnvMap(EnvMap plain, const BinLayout& layout, StopFlag stop, double choice_seconds)
    : plain_(std::move(plain)), layout_(layout), choice_seconds_(choice_seconds) {
    check_layout();
    build(nullptr, stop);
}

BinnedEnvMap::BinnedEnvMap(EnvMap plain, const BinLayout& layout, const detail::Geometries& geometries, StopFlag stop,
                           double choice_seconds)
    : plain_(std::move(plain)), layout_(layout), choice_seconds_(choice_seconds) {
    check_layout();
    build(&geometries, stop);
}

void BinnedEnvMap::check_layout() const {
    const BinLayout& layout = layout_;
    const uint32_t g = layout.bins_per_side, gd = layout.diffuse_bins_per_side, w = plain_.width(), h = plain_.height();
    if (g < 1 || g > 64 || gd < 1 || gd > 64 || layout.cell_columns < 1 || layout.cell_columns > std::min(w, 4096u) ||
        layout.cell_rows < 1 || layout.cell_rows > h)
        throw std::invalid_argument("bin layout " + std::to_string(gd) + " diffuse and " + std::to_string(g) +
                                    " glossy bins per side, " + std::to_string(layout.cell_columns) + "x" +
                                    std::to_string(layout.cell_rows) + " cells does not fit a " + std::to_string(w) +
                                    "x" + std::to_string(h) + " map");
    detail::check_cells(w, h, layout.cell_columns, layout.cell_rows);
    BinnedOptions check;
    check.lobe_exponents = layout.lobe_exponents;
    detail::check_options(check);
    if (layout.choices.size() != layout.choice_count())
        throw std::invalid_argument("bin layout: " + std::to_string(layout.choices.size()) + " choices for " +
                                    std::to_string(layout.choice_count()) + " bins");
    for (size_t i = 0; i < layout.choices.size(); ++i) {
        const BinChoice& c = layout.choices[i];
        if (!(std::isfinite(c.alpha) && c.threshold >= 0 && std::isfinite(c.threshold) &&
              detail::on_histogram_edge(c.threshold)))
            throw std::invalid_argument("bin layout: invalid alpha or threshold");
        if (!layout.view_limit_valid(i))
            throw std::invalid_argument("bin layout: a view limit outside [0, 1], or not 0 for a diffuse or plain bin");
    }
}

namespace {

// Fills the cell texel CDFs (BinnedEnvMapView::cell_texels) from the plain map's
// distribution, each texel weighed by its fixed-point probability (marginal width times
// row width), and returns each cell's plain mass, their sum.
std::vector<double> build_cell_texels(const Distribution2DView& plain, const CellGrid& grid, uint32_t* start,
                                      uint16_t* guide, StopFlag stop) {
    std::vector<double> masses(size_t{grid.cw} * grid.ch);
    detail::parallel_for(grid.ch, 1, stop, [&](uint32_t lo, uint32_t hi) {
        std::vector<double> mass;
        detail::CdfScratch scratch(0);
        for (uint32_t cy = lo; cy < hi; ++cy) {
            const uint32_t y0 = grid.row_edges[cy], rows = grid.row_edges[cy + 1] - y0;
            for (uint32_t cx = 0; cx < grid.cw; ++cx) {
                const uint32_t x0 = grid.column_edges[cx], columns = grid.column_edges[cx + 1] - x0;
                const uint32_t n = columns * rows;
                mass.resize(n);
                if (scratch.prefix.size() < n) scratch = detail::CdfScratch(n);
                for (uint32_t dy = 0; dy < rows; ++dy) {
                    const CdfView row = plain.row(y0 + dy);
                    const auto marginal = static_cast<double>(plain.marginal.width(y0 + dy));
                    for (uint32_t dx = 0; dx < columns; ++dx)
                        mass[size_t{dy} * columns + dx] = marginal * static_cast<double>(row.width(x0 + dx));
                }
                const size_t at = size_t{y0} * grid.w + size_t{rows} * x0;
                uint32_t invalid = 0;
                masses[size_t{cy} * grid.cw + cx] =
                    detail::build_cdf(mass.data(), n, start + at, guide + at, invalid, scratch);
            }
        }
    });
    return masses;
}

}  // namespace

void BinnedEnvMap::build(const detail::Geometries* given, StopFlag stop) {
    const CellGrid grid(plain_.width(), plain_.height(), layout_.cell_columns, layout_.cell_rows,
                        plain_.options().mapping);
    std::optional<detail::Geometries> own;
    const detail::Geometries& geometries = given ? *given : own.emplace(plain_, grid, layout_);
    std::vector<std::vector<float>> masses = detail::bin_masses(plain_, grid, geometries, layout_, stop);
    column_edges_ = grid.column_edges;
    row_edges_ = grid.row_edges;
    by_column_.clear();
    for (uint32_t cx = 0; cx < grid.cw; ++cx)
        by_column_.push_back(detail::ExactDivision::by(grid.column_edges[cx + 1] - grid.column_edges[cx]));
    min_view_cos_.clear();
    for (const BinChoice& c : layout_.choices) min_view_cos_.push_back(c.plain() ? 2.0f : c.min_view_cos);
    const size_t cells = size_t{grid.cw} * grid.ch, texels = size_t{grid.w} * grid.h;
    texel_start_.resize(texels);
    texel_guide_.resize(texels);
    const std::vector<double> plain_masses =
        build_cell_texels(plain_.distribution().view(), grid, texel_start_.data(), texel_guide_.data(), stop);
    // The plain cell table last; the plain map's distribution is then the cells' and
    // their texels'.
    masses.emplace_back(plain_masses.begin(), plain_masses.end());
    plain_density_bytes_ = plain_.distribution().bytes();
    plain_ = std::move(plain_).without_density();
    cell_start_.resize(cells * masses.size());
    cell_guide_.resize(cells * masses.size());
    detail::CdfScratch cell_scratch(static_cast<uint32_t>(cells));
    for (size_t cb = 0; cb < masses.size(); ++cb) {
        uint32_t invalid = 0;
        detail::build_cdf(masses[cb].data(), static_cast<uint32_t>(cells), cell_start_.data() + cb * cells,
                          cell_guide_.data() + cb * cells, invalid, cell_scratch);
        if (invalid) throw std::invalid_argument("bin masses: negative or non-finite value");
    }
}

BinnedEnvMapView BinnedEnvMap::view() const noexcept {
    return {plain_.view(),
            cell_start_.data(),
            cell_guide_.data(),
            texel_start_.data(),
            texel_guide_.data(),
            column_edges_.data(),
            row_edges_.data(),
            by_column_.data(),
            min_view_cos_.data(),
            layout_.cell_columns,
            layout_.cell_rows,
            classes(),
            layout_.bins_per_side,
            bins(),
            layout_.diffuse_bins_per_side,
            diffuse_bins(),
            static_cast<uint32_t>(layout_.choices.size()),
            detail::ExactDivision::by(plain_.width()),
            detail::ExactDivision::by(plain_.height()),
            detail::ExactDivision::by(layout_.cell_columns)};
}

bool BinnedEnvMap::complete(uint32_t lobe) const noexcept {
    lobe = std::min(lobe, classes() - 1);
    const uint32_t k = layout_.side(lobe) * layout_.side(lobe);
    for (uint32_t b = 0; b < k; ++b) {
        const BinChoice& c = layout_.choices[layout_.first(lobe) + b];
        if (!c.plain() && c.threshold > 0) return false;
    }
    return true;
}

size_t BinnedEnvMap::bytes() const noexcept {
    const size_t tables = (cell_start_.size() + texel_start_.size()) * sizeof(uint32_t) +
                          (cell_guide_.size() + texel_guide_.size()) * sizeof(uint16_t) +
                          (column_edges_.size() + row_edges_.size()) * sizeof(uint32_t) +
                          by_column_.size() * sizeof(detail::ExactDivision) + min_view_cos_.size() * sizeof(float);
    // Never below 0: a coarse grid over a map large enough for a coarse guide may save
    // more than it adds.
    return tables - std::min(tables, plain_density_bytes_);
}

}  // namespace envmis
