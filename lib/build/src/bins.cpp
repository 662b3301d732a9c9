// The bins' build (envmis/build/bins.h): the grid for the options, the choice of every
// bin's threshold by exact variance, and the map built from the layout.
#include "envmis/build/bins.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "detail/luminance.h"
#include "detail/parallel.h"
#include "envmis/build/mis_variance.h"
#include "envmis/sampling/bin_cells.h"

namespace envmis {
namespace {

using namespace detail;

// Node grid for the choice: each cell cut into k x k nodes (k <= 4), at most `columns`
// wide: 64 for the diffuse class, whose cosine lobe is smooth, 128 for the glossy
// classes, whose narrow lobes need nodes finer than 64 columns give (5.6 degrees at 1k)
// for the variances the choice compares to rank its candidates as the exact study does
// (docs/performance.md, "The glossy classes' nodes").
// The brightest texels (at least kHotShare of the brightest, at most kMaxHotTexels of
// them) are nodes of their own, out of their grid node: a sun smeared over a node of
// 16 x 16 texels misplaces it by degrees, and where it grazes a normal's horizon the
// variances the choice compares are then wrong (on rooitou_park, a diffuse bin near +z
// chosen so had 2.2x the variance of plain balance MIS where the sun stood 5 degrees
// above the normal's horizon).
constexpr uint32_t kDiffuseNodeColumns = 64, kGlossyNodeColumns = 128, kMaxHotTexels = 2048;
constexpr float kHotShare = 1e-2f;

struct Nodes {
    uint32_t w = 0, h = 0, k = 1;
    std::vector<double> sum_l, sum_w;  // per node: sum of L w and of w
    std::vector<Vec3> direction;
    std::vector<uint32_t> cell;
    double steradians_per_weight = 0;  // solid angle of a texel of weight 1
    // Per node, set by weigh_nodes once the cells' luminance is known: its mean luminance,
    // its solid angle, and the environment's solid-angle density there per unit
    // probability of its cell (a cell's texels share their cell's probability by
    // luminance, bin_cells.h).
    std::vector<double> luminance, solid_angle, density_per_probability;
};

// Moves the brightest texels out of their grid nodes into nodes of their own.
void add_hot_texels(const EnvMap& plain, const CellGrid& grid, Nodes& n) {
    const Rgb* pixels = plain.radiance().pixels.data();
    const LumaCoefficients luma = plain.options().luma;
    const size_t texels = size_t{grid.w} * grid.h;
    float brightest = 0;
    for (size_t i = 0; i < texels; ++i) brightest = std::max(brightest, texel_luminance(pixels[i], luma));
    if (!(brightest > 0)) return;
    std::vector<std::pair<float, size_t>> hot;
    for (size_t i = 0; i < texels; ++i) {
        const float l = texel_luminance(pixels[i], luma);
        if (l >= kHotShare * brightest) hot.emplace_back(l, i);
    }
    if (hot.size() > kMaxHotTexels) {
        std::nth_element(hot.begin(), hot.begin() + kMaxHotTexels, hot.end(), std::greater<>());
        hot.resize(kMaxHotTexels);
    }
    std::sort(hot.begin(), hot.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
    for (const auto& [l, i] : hot) {
        const auto x = static_cast<uint32_t>(i % grid.w), y = static_cast<uint32_t>(i / grid.w);
        const double w = row_weight(grid.mapping, y, grid.h);
        const auto ny = static_cast<uint32_t>(uint64_t{y} * n.h / grid.h);
        const size_t node = size_t{ny} * n.w + static_cast<uint32_t>(uint64_t{x} * n.w / grid.w);
        n.sum_w[node] -= w;
        // A node left without texels (its weight gone to rounding) adds nothing.
        n.sum_l[node] = n.sum_w[node] > 1e-9 * w ? std::max(0.0, n.sum_l[node] - l * w) : 0.0;
        n.sum_l.push_back(l * w);
        n.sum_w.push_back(w);
        n.direction.push_back(image_direction(grid.mapping, {(x + 0.5f) / grid.w, (y + 0.5f) / grid.h}));
        n.cell.push_back(n.cell[node]);
    }
}

uint32_t node_k(const CellGrid& grid, uint32_t columns) {
    return std::max(1u, std::min({columns / grid.cw, grid.w / grid.cw, grid.h / grid.ch, 4u}));
}

Nodes nodes_of(const EnvMap& plain, const CellGrid& grid, uint32_t columns, StopFlag stop) {
    Nodes n;
    n.k = node_k(grid, columns);
    n.w = grid.cw * n.k, n.h = grid.ch * n.k;
    n.sum_l.assign(size_t{n.w} * n.h, 0);
    n.sum_w.assign(n.sum_l.size(), 0);
    const Rgb* pixels = plain.radiance().pixels.data();
    const LumaCoefficients luma = plain.options().luma;
    parallel_for(n.h, 1, stop, [&](uint32_t lo, uint32_t hi) {
        for (uint32_t ny = lo; ny < hi; ++ny) {
            const auto y0 = static_cast<uint32_t>((uint64_t{ny} * grid.h + n.h - 1) / n.h);
            const auto y1 = static_cast<uint32_t>((uint64_t{ny + 1} * grid.h + n.h - 1) / n.h);
            for (uint32_t y = y0; y < y1; ++y) {
                const double w = row_weight(grid.mapping, y, grid.h);
                for (uint32_t x = 0; x < grid.w; ++x) {
                    const size_t node = size_t{ny} * n.w + static_cast<uint32_t>(uint64_t{x} * n.w / grid.w);
                    n.sum_l[node] += texel_luminance(pixels[size_t{y} * grid.w + x], luma) * w;
                    n.sum_w[node] += w;
                }
            }
        }
    });
    for (uint32_t ny = 0; ny < n.h; ++ny)
        for (uint32_t nx = 0; nx < n.w; ++nx) {
            n.direction.push_back(image_direction(grid.mapping, {(nx + 0.5f) / n.w, (ny + 0.5f) / n.h}));
            n.cell.push_back(ny / n.k * grid.cw + nx / n.k);
        }
    add_hot_texels(plain, grid, n);
    const double texels = static_cast<double>(grid.w) * grid.h;
    n.steradians_per_weight = (grid.mapping == Mapping::equal_area ? 4 * kPi : 2 * kPi * kPi) / texels;
    return n;
}

// Node i holds sum_l[i] / cell_l of its cell's luminance cell_l, over its solid angle.
void weigh_nodes(Nodes& n, std::span<const double> cell_l) {
    const size_t nodes = n.sum_l.size();
    n.luminance.resize(nodes), n.solid_angle.resize(nodes), n.density_per_probability.resize(nodes);
    for (size_t i = 0; i < nodes; ++i) {
        const double share = cell_l[n.cell[i]] > 0 ? n.sum_l[i] / cell_l[n.cell[i]] : 0;
        const double omega = n.sum_w[i] * n.steradians_per_weight;
        n.luminance[i] = n.sum_w[i] > 0 ? n.sum_l[i] / n.sum_w[i] : 0;
        n.solid_angle[i] = omega;
        n.density_per_probability[i] = omega > 0 ? share / omega : 0;
    }
}

// Cosine-weighted mean luminance of the hemisphere around each bin's normal: E_b / pi.
std::vector<double> hemisphere_means(const Nodes& n, const Geometry& geometry) {
    std::vector<double> means(geometry.bin_normal.size());
    for (size_t b = 0; b < means.size(); ++b) {
        double l = 0, w = 0;
        for (size_t i = 0; i < n.direction.size(); ++i) {
            const double c = std::max(0.0f, dot(n.direction[i], geometry.bin_normal[b]));
            l += n.sum_l[i] * c, w += n.sum_w[i] * c;
        }
        means[b] = w > 0 ? l / w : 0;
    }
    return means;
}

// The threshold alpha * mean on the histogram grid; within 2^-9 of the window's top
// bucket count below the highest, so that a map of any dynamic range keeps its
// histograms small (thresholds that low select nearly every texel anyway).
float threshold_of(float alpha, double mean, float floor) noexcept {
    if (alpha == 0 || !(mean > 0)) return 0;
    return std::max(histogram_edge(static_cast<float>(alpha * mean)), floor);
}

// The lowest threshold a window ending at `highest` allows.
float window_floor(float highest) noexcept {
    constexpr uint32_t kMaxBuckets = 510;
    const uint32_t id = std::bit_cast<uint32_t>(highest) >> kHistogramShift;
    return id > kMaxBuckets ? std::bit_cast<float>((id - kMaxBuckets) << kHistogramShift) : 0.0f;
}

// The lobe of a class at one normal, on the nodes it sees: per node the integrand f, the
// node's solid angle, the BSDF's density, and what mis_variance needs for the
// environment's density given its cells' probabilities.
struct LobeNode {
    double f, solid_angle, p_bsdf, density_per_probability;
    uint32_t cell;
};
using Lobe = std::vector<LobeNode>;

LobeNode lobe_node(const Nodes& n, uint32_t i, double f, double p_bsdf) {
    return {f, n.solid_angle[i], p_bsdf, n.density_per_probability[i], n.cell[i]};
}

constexpr double kNegligibleLog = -9.2;  // log(1e-4)

// Where a lobe is seen from: the surface normal and the direction to the viewer.
struct View {
    Vec3 normal, wo;
};

// A Phong lobe of `exponent` about the mirror direction of the view (the study's: value
// (e + 2) / (2 pi) cos^e cos_i, density (e + 1) / (2 pi) cos^e), or for exponent 0 the
// cosine lobe about the normal.
Lobe phong_lobe_seen(const Nodes& n, View v, float exponent) {
    const Vec3 mirror = v.normal * (2 * dot(v.normal, v.wo)) - v.wo;
    // Directions where a glossy lobe is below 1e-4 of its peak (c^exponent <
    // exp(kNegligibleLog)) add nothing that could rank candidates, and skipping them makes
    // sharp lobes cheap to evaluate.
    const double least_c = exponent > 0 ? std::exp(kNegligibleLog / exponent) : 0;
    Lobe lobe;
    lobe.reserve(static_cast<size_t>(0.5 * (1 - least_c) * static_cast<double>(n.direction.size())) + 1);
    for (uint32_t i = 0; i < n.direction.size(); ++i) {
        const double ci = dot(n.direction[i], v.normal), c = exponent == 0 ? ci : dot(n.direction[i], mirror);
        if (!(ci > 0) || !(c > least_c) || !(n.sum_l[i] > 0)) continue;
        const double l = n.luminance[i], ce = exponent == 0 ? 0 : std::pow(c, exponent);
        const double p = exponent == 0 ? c / kPi : (exponent + 1) / (2 * kPi) * ce;
        const double fc = exponent == 0 ? c / kPi : (exponent + 2) / (2 * kPi) * ce * ci;
        lobe.push_back(lobe_node(n, i, l * fc, p));
    }
    return lobe;
}

// The GGX lobe of roughness a (the study's, Fresnel 1): value D G2 / (4 cos_o) with
// Smith's height-correlated G2 = 1 / (1 + Lambda(wo) + Lambda(wi)), density of
// reflected visible normals G1(wo) D / (4 cos_o). No cut: its tails fall as a power,
// where a Phong lobe's fall exponentially, and a light far off the axis may still send
// most of its light through them.
Lobe ggx_lobe_seen(const Nodes& n, View v, double a) {
    Lobe lobe;
    const double a2 = a * a;
    const auto lambda = [a2](double c) { return 0.5 * (std::sqrt(1 + a2 * (1 - c * c) / (c * c)) - 1); };
    const double co = dot(v.normal, v.wo), lambda_o = lambda(co);
    for (uint32_t i = 0; i < n.direction.size(); ++i) {
        const double ci = dot(n.direction[i], v.normal);
        if (!(ci > 0) || !(n.sum_l[i] > 0)) continue;
        const Vec3 h = normalize(n.direction[i] + v.wo);
        const double ch = dot(h, v.normal), t = ch * ch * (a2 - 1) + 1, d = a2 / (kPi * t * t);
        lobe.push_back(lobe_node(n, i, n.luminance[i] * d / (4 * co * (1 + lambda_o + lambda(ci))),
                                 d / (4 * co * (1 + lambda_o))));
    }
    return lobe;
}

Lobe lobe_at(const Nodes& n, Vec3 normal, float exponent) { return phong_lobe_seen(n, {normal, normal}, exponent); }

// Views of a glossy bin's lobes at `angle` from the normal: normals `angle` away from
// the bin's axis on four sides, each with the view whose mirror direction is the axis.
std::vector<View> views_about(Vec3 axis, double angle) {
    const Vec3 t1 = normalize(cross(axis, std::abs(axis.z) < 0.9f ? Vec3{0, 0, 1} : Vec3{1, 0, 0}));
    const Vec3 t2 = cross(axis, t1);
    const auto c = static_cast<float>(std::cos(angle)), s = static_cast<float>(std::sin(angle));
    std::vector<View> views;
    for (Vec3 t : {t1, t2, t1 * -1.0f, t2 * -1.0f}) {
        const Vec3 normal = axis * c + t * s;
        views.push_back({normal, normal * (2 * dot(normal, axis)) - axis});
    }
    return views;
}

// Exact variance of one 1 + 1 balance MIS estimate at the lobe's normal (mis_variance.h).
double mis_variance(const Lobe& lobe, std::span<const double> cell_probability) {
    MisMoments m;
    for (const LobeNode& x : lobe)
        m.add_balance({x.f, x.solid_angle, cell_probability[x.cell] * x.density_per_probability, x.p_bsdf}, {});
    return m.variance({});
}

// Cell probabilities of a density given by cell masses; empty if it has no mass.
std::vector<double> probabilities(std::vector<double> mass) {
    double total = 0;
    for (double m : mass) total += m;
    if (!(total > 0)) return {};
    for (double& m : mass) m /= total;
    return mass;
}

// The GGX roughness a glossy class's choice weighs besides its Phong lobe: GGX lobes
// take the class of their ggx_lobe_exponent (binned.h), and their tails, which a Phong
// lobe lacks, can make compensation lose where a Phong lobe's choice predicts a gain
// (GGX 0.08 on night.exr: 2.45x the variance of plain balance MIS, 14 shared maps,
// docs/performance.md). The roughness is that of the exponent midway, on lobe_class's
// scale, between the lowest and highest exponents of GGX lobes the class takes (the top
// class's own exponent bounds it, or the roughest GGX); 0 where it takes none.
double ggx_roughness_of(std::span<const float> exponents, uint32_t c) {
    const auto key = [](double e) { return std::log1p(e); };
    const double roughest = key(ggx_lobe_exponent(std::nextafter(kGgxDiffuseRoughness, 0.0f)));
    const double lo = std::max(0.5 * (key(exponents[c - 1]) + key(exponents[c])), roughest);
    const double hi =
        c + 1 < exponents.size() ? 0.5 * (key(exponents[c]) + key(exponents[c + 1])) : std::max(key(exponents[c]), lo);
    if (hi < lo) return 0;
    const double e = std::expm1(0.5 * (lo + hi));
    return std::sqrt(2 / (4 * e + 2));
}

// Normals the choice weighs a bin's candidates at: a 3 x 3 grid over its blend support
// (the bin's centre, and its borders' middles and corners, across the octahedral map's
// folds), each with the blend weight a normal there gives the bin.
struct WeightedNormal {
    Vec3 normal;
    double weight;
};
Vec3 bin_centre(uint32_t bin, uint32_t g) {
    return folded_octahedral_normal((bin % g + 0.5f) / static_cast<float>(g), (bin / g + 0.5f) / static_cast<float>(g));
}

std::vector<WeightedNormal> bin_samples(uint32_t bin, uint32_t g) {
    std::vector<WeightedNormal> samples;
    for (int dt = -1; dt <= 1; ++dt)
        for (int ds = -1; ds <= 1; ++ds) {
            const double s = (bin % g + 0.5 + 0.5 * ds) / g, t = (bin / g + 0.5 + 0.5 * dt) / g;
            const double weight = (ds == 0 ? 1 : 0.5) * (dt == 0 ? 1 : 0.5);
            samples.push_back({folded_octahedral_normal(static_cast<float>(s), static_cast<float>(t)), weight});
        }
    return samples;
}

// The lobes a glossy class's choice weighs: its Phong exponent, and GGX of roughness
// ggx_a (0: none).
struct Lobes {
    float exponent;
    double ggx_a;
};

// The least cosine between normal and view at which a glossy bin about `axis` samples
// its density `p` rather than the plain one `plain_p`: seen obliquely, a lobe reaches
// towards the normal, where the bin's cosine factor about its axis may starve a bright
// light. The views are those at kViewAngles from the axis on four sides; the limit lies
// halfway between the last angle at which every view's variance is below the plain
// density's and the first at which one is not.
float view_limit(const Nodes& n, std::span<const double> plain_p, std::span<const double> p, Vec3 axis, Lobes lobes) {
    constexpr double kViewAngles[] = {0.7854, 1.0472, 1.309, 1.4835};  // 45, 60, 75, 85 degrees
    const auto loses = [&](const Lobe& lobe) {
        const double base = mis_variance(lobe, plain_p);
        return base > 0 && mis_variance(lobe, p) > base;
    };
    double passed = 0;
    for (double angle : kViewAngles) {
        for (const View& v : views_about(axis, angle))
            if (loses(phong_lobe_seen(n, v, lobes.exponent)) ||
                (lobes.ggx_a > 0 && loses(ggx_lobe_seen(n, v, lobes.ggx_a))))
                return static_cast<float>(std::cos(0.5 * (passed + angle)));
        passed = angle;
    }
    return 0;
}

// What every bin of one lobe class is chosen from.
struct ClassChoice {
    const Nodes& nodes;  // the class's grid's
    const Geometry& geometry;
    const CellHistogram& hist;
    std::span<const double> plain_p;    // the plain density's cell probabilities
    std::span<const float> alphas;      // the candidates
    std::span<const float> thresholds;  // per bin of the class's grid, per candidate
    uint32_t g;                         // bins per side
    bool glossy;
    Lobes lobes;
    double cost;  // BinnedOptions::cost
};

// One bin's choice: the candidate of the lowest weighted mean of log(variance / the
// plain density's) at the bin's 9 normals, if it beats the plain density by the cost.
// `weight` and `mass` are the caller's scratch, one entry per cell.
BinChoice choose_bin(const ClassChoice& k, uint32_t b, std::vector<float>& weight, std::vector<double>& mass) {
    const size_t count = k.alphas.size(), cells = weight.size();
    for (size_t cell = 0; cell < cells; ++cell) weight[cell] = k.geometry.weight(b, cell, k.glossy);
    std::vector<std::vector<double>> p(count);  // the candidates' cell probabilities
    for (size_t j = 0; j < count; ++j) {
        for (size_t cell = 0; cell < cells; ++cell)
            mass[cell] = weight[cell] * k.hist.above(cell, k.thresholds[b * count + j]);
        p[j] = probabilities(mass);
    }
    std::vector<double> log_ratio(count, 0);
    const auto add = [&](const Lobe& lobe, double normal_weight, std::vector<double>& to) {
        const double base = mis_variance(lobe, k.plain_p);
        for (size_t j = 0; j < count; ++j) {
            const double v = p[j].empty() ? 0 : mis_variance(lobe, p[j]);
            if (base > 0) to[j] += normal_weight * (v > 0 ? std::log(v / base) : (p[j].empty() ? 1e9 : 0));
        }
    };
    double weights = 0;
    for (const WeightedNormal& at : bin_samples(b, k.g)) {
        weights += at.weight;
        add(lobe_at(k.nodes, at.normal, k.lobes.exponent), at.weight, log_ratio);
    }
    for (double& r : log_ratio) r /= weights;
    // A glossy class serves GGX lobes too, whose tails reach lights its Phong lobe does
    // not: a candidate must do for both. GGX at the bin's centre only: its lobe covers the
    // whole hemisphere, the choice's dearest, and weighing it at the 9 normals changed no
    // figure measured (docs/performance-log.md).
    const Vec3 centre = bin_centre(b, k.g);
    if (k.glossy && k.lobes.ggx_a > 0) {
        std::vector<double> ggx(count, 0);
        add(ggx_lobe_seen(k.nodes, {centre, centre}, k.lobes.ggx_a), 1, ggx);
        for (size_t j = 0; j < count; ++j) log_ratio[j] = std::max(log_ratio[j], ggx[j]);
    }
    const size_t best = std::min_element(log_ratio.begin(), log_ratio.end()) - log_ratio.begin();
    if (!(log_ratio[best] < -std::log(k.cost) - 1e-6)) return {-1, 0};
    BinChoice choice{k.alphas[best], k.thresholds[b * count + best]};
    if (k.glossy) choice.min_view_cos = view_limit(k.nodes, k.plain_p, p[best], centre, k.lobes);
    return choice;
}

std::vector<BinChoice> choose_bins(const EnvMap& plain, const CellGrid& grid, const Geometries& geometries,
                                   const BinLayout& shape, const BinnedOptions& options, StopFlag stop) {
    // Per grid (0: the diffuse class's, 1: the glossy classes'), the nodes; one grid
    // serves both where the cells are too wide or too narrow for the two to differ.
    Nodes nodes[2] = {nodes_of(plain, grid, kDiffuseNodeColumns, stop), {}};
    nodes[1] =
        node_k(grid, kGlossyNodeColumns) == nodes[0].k ? nodes[0] : nodes_of(plain, grid, kGlossyNodeColumns, stop);
    const auto classes = static_cast<uint32_t>(shape.lobe_exponents.size());
    const std::vector<float> alphas = options.auto_alpha ? options.candidates : std::vector<float>{options.alpha};
    // Per grid, each bin's hemisphere mean and its candidates' thresholds, bin-major.
    const std::vector<double> means[2] = {hemisphere_means(nodes[0], geometries.diffuse),
                                          hemisphere_means(nodes[1], geometries.glossy)};
    double highest_mean = 0;
    for (const auto& m : means) highest_mean = std::max(highest_mean, *std::max_element(m.begin(), m.end()));
    const float highest_alpha = *std::max_element(alphas.begin(), alphas.end());
    const float floor = window_floor(static_cast<float>(highest_alpha * highest_mean));
    std::vector<float> thresholds[2];
    for (int grid_of = 0; grid_of < 2; ++grid_of)
        for (double mean : means[grid_of])
            for (float a : alphas) thresholds[grid_of].push_back(threshold_of(a, mean, floor));
    std::vector<BinChoice> choices(shape.choice_count());
    if (!options.auto_alpha) {
        for (uint32_t c = 0; c < classes; ++c)
            for (uint32_t b = 0; b < shape.side(c) * shape.side(c); ++b)
                choices[shape.first(c) + b] = {options.alpha, thresholds[c > 0][b]};
        return choices;
    }
    std::vector<float> every_threshold = thresholds[0];
    every_threshold.insert(every_threshold.end(), thresholds[1].begin(), thresholds[1].end());
    const CellHistogram hist = histogram(plain, grid, every_threshold, stop);
    const std::vector<double> plain_p = probabilities(hist.total_l);
    for (Nodes& n : nodes) weigh_nodes(n, hist.total_l);
    for (uint32_t c = 0; c < classes; ++c) {
        const bool glossy = c > 0;
        const Lobes lobes{shape.lobe_exponents[c], glossy ? ggx_roughness_of(shape.lobe_exponents, c) : 0};
        const ClassChoice k{.nodes = nodes[glossy],
                            .geometry = geometries.of(c),
                            .hist = hist,
                            .plain_p = plain_p,
                            .alphas = alphas,
                            .thresholds = thresholds[glossy],
                            .g = shape.side(c),
                            .glossy = glossy,
                            .lobes = lobes,
                            .cost = options.cost};
        parallel_for(k.g * k.g, 1, stop, [&](uint32_t lo, uint32_t hi) {
            std::vector<float> weight(size_t{grid.cw} * grid.ch);
            std::vector<double> mass(weight.size());
            for (uint32_t b = lo; b < hi; ++b) choices[shape.first(c) + b] = choose_bin(k, b, weight, mass);
        });
    }
    return choices;
}

// The default cell columns of a map w texels wide: cells 32 texels wide, at most
// kMaxDefaultCells of them. Past 4k the cap, not the cells' width, sets the bins'
// memory: 6 bytes per cell per bin, 683 (class, bin) pairs by default, so 112 x 56
// cells keep the bins under 5% of an 8k map (a square grid: 79 x 79).
constexpr uint32_t kMaxDefaultCells = 112 * 56;
uint32_t default_cell_columns(uint32_t w, bool square) {
    uint32_t columns = std::clamp(w / 32, 1u, 128u);
    while (uint64_t{columns} * (square ? columns : std::max(1u, columns / 2)) > kMaxDefaultCells) --columns;
    return columns;
}

// The cell grid for the options over `plain`, after the checks every build makes.
CellGrid grid_for(const EnvMap& plain, const BinnedOptions& options) {
    if (plain.options().compensation.enabled && plain.stats().fallback == DensityFallback::none)
        throw std::invalid_argument("a binned map is built over the plain (uncompensated) map");
    check_options(options);
    const uint32_t w = plain.width(), h = plain.height();
    const bool square = plain.options().mapping == Mapping::equal_area;
    const auto rows_of = [&](uint32_t columns) { return std::min(square ? columns : std::max(1u, columns / 2), h); };
    uint32_t columns = options.cell_columns;
    if (columns == 0) {
        // Past about 28k texels wide the cap's cells would outgrow a cell texel CDF.
        columns = default_cell_columns(w, square);
        while (columns < w && largest_cell(w, h, columns, rows_of(columns)) > kMaxCells1D) ++columns;
    }
    if (columns > 4096)
        throw std::invalid_argument("cell columns must be at most 4096, got " + std::to_string(columns));
    columns = std::min(columns, w);
    const uint32_t rows = rows_of(columns);
    check_cells(w, h, columns, rows);
    return CellGrid(w, h, columns, rows, plain.options().mapping);
}

// The layout's grids and classes, its choices not yet made.
BinLayout shape_of(const BinnedOptions& options, const CellGrid& grid) {
    BinLayout layout;
    layout.bins_per_side = options.bins_per_side;
    layout.diffuse_bins_per_side =
        options.diffuse_bins_per_side ? options.diffuse_bins_per_side : diffuse_side(options.bins_per_side);
    layout.cell_columns = grid.cw, layout.cell_rows = grid.ch;
    layout.lobe_exponents = options.lobe_exponents;
    return layout;
}

// The layout over `grid` with its geometries, as choose_bin_layout documents.
BinLayout choose_layout(const EnvMap& plain, const BinnedOptions& options, const CellGrid& grid,
                        const Geometries& geometries, StopFlag stop) {
    BinLayout layout = shape_of(options, grid);
    layout.choices = choose_bins(plain, grid, geometries, layout, options, stop);
    return layout;
}

}  // namespace

BinLayout choose_bin_layout(const EnvMap& plain, const BinnedOptions& options, StopFlag stop) {
    const CellGrid grid = grid_for(plain, options);
    return choose_layout(plain, options, grid, Geometries(plain, grid, shape_of(options, grid)), stop);
}

BinnedEnvMap build_bins(EnvMap plain, const BinnedOptions& options, StopFlag stop) {
    const auto started = std::chrono::steady_clock::now();
    const CellGrid grid = grid_for(plain, options);
    const Geometries geometries(plain, grid, shape_of(options, grid));
    const BinLayout layout = choose_layout(plain, options, grid, geometries, stop);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    return BinnedEnvMap(std::move(plain), layout, geometries, stop, seconds);
}

}  // namespace envmis
