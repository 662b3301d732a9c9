#include "envmis/study/comparison/comparison.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <thread>

#include "envmis/build/bins.h"
#include "envmis/build/env_map.h"
#include "envmis/cpu.h"
#include "envmis/math/hash.h"
#include "envmis/study/shading/frame.h"
#include "envmis/study/statistics/statistics.h"

namespace envmis {
namespace {

// Interleaved batches per cell: the spread of their variances is the noise of the
// cell's variance estimate, whatever the estimates' distribution.
constexpr uint32_t kBatches = 8;
// Estimates asked of an estimator at a time: enough for it to run them side by side.
constexpr uint32_t kChunk = 64;
// Chunks between two looks at the stop flag: 4096 estimates, well under a millisecond
// for the fixed-weight techniques and a few for optimal MIS, against one relaxed load.
constexpr uint64_t kChunksPerStopCheck = 64;

// What one (point, BSDF, technique) cell of the study measured.
struct Cell {
    RunningStats estimates, squared_relative_error;
    RunningStats batches[kBatches];
    bool ill_conditioned = false;  // optimal MIS ended on balance weights
};

double square(double x) { return x * x; }

// Standard error of a cell's variance estimate relative to it, from its batches.
double relative_standard_error(const Cell& c) {
    RunningStats variances;
    for (const RunningStats& b : c.batches) variances.add(b.variance());
    const double v = c.estimates.variance();
    return v > 0 ? variances.standard_error() / v : 0.0;
}

}  // namespace

std::vector<Technique> ComparisonOptions::default_techniques() {
    std::vector<Technique> t;
    for (const char* name :
         {"env", "bsdf", "mis-balance", "mis-power", "mis-balance-comp", "mis-power-comp", "mis-optimal-comp",
          "mis-optimal-all", "mis-balance-bins", "mis-power-bins", "mis-optimal-bins"})
        t.push_back(Technique::parse(name));
    return t;
}

const TechniqueStats* BsdfComparison::find(std::string_view technique) const {
    for (const TechniqueStats& t : techniques)
        if (t.technique.name() == technique) return &t;
    return nullptr;
}

std::vector<ShadingPoint> sphere_points(uint32_t k, double view_degrees) {
    if (!(view_degrees >= 0 && view_degrees <= 89.9))
        throw std::invalid_argument("a view angle must be 0 to 89.9 degrees, got " + std::to_string(view_degrees));
    constexpr double kGoldenAngle = 2.39996322972865332;
    const double view = view_degrees * kPi / 180;
    std::vector<ShadingPoint> points(k);
    for (uint32_t i = 0; i < k; ++i) {
        const double z = 1 - (2 * i + 1.0) / k, r = std::sqrt(1 - z * z), phi = kGoldenAngle * i;
        const Vec3 n{static_cast<float>(r * std::cos(phi)), static_cast<float>(r * std::sin(phi)),
                     static_cast<float>(z)};
        if (view_degrees == 0) {
            points[i] = {n, n};
            continue;
        }
        const Frame f = Frame::from_normal(n);
        const double psi = kGoldenAngle * (i + 1) * 7;
        const Vec3 tangent = f.x * static_cast<float>(std::cos(psi)) + f.y * static_cast<float>(std::sin(psi));
        points[i] = {n,
                     normalize(n * static_cast<float>(std::cos(view)) + tangent * static_cast<float>(std::sin(view)))};
    }
    return points;
}

Rgb average_estimate(const DirectLightingEstimator& estimator, const ShadingPoint& point, const Bsdf& bsdf,
                     uint32_t spp, uint64_t seed, uint64_t stream) {
    Pcg32 rng(seed, stream);
    PointState state;
    double r = 0, g = 0, b = 0;
    Rgb chunk[kChunk];
    for (uint64_t first = 0; first < spp; first += kChunk) {
        const std::span<Rgb> estimates(chunk, std::min<uint64_t>(kChunk, spp - first));
        estimator.estimate(point, bsdf, rng, state, estimates);
        for (const Rgb& e : estimates) r += e.r, g += e.g, b += e.b;
    }
    return {static_cast<float>(r / spp), static_cast<float>(g / spp), static_cast<float>(b / spp)};
}

bool uses_bins(std::span<const Technique> techniques) {
    return std::any_of(techniques.begin(), techniques.end(), [](const Technique& t) { return t.bins; });
}

DirectLightingEstimator study_estimator(const EnvMap& plain, const EnvMap& compensated, const BinnedEnvMap* binned,
                                        const Technique& technique, Allocation allocation) {
    if (!technique.bins) return {plain, compensated, technique, allocation};
    if (!binned) throw std::invalid_argument(technique.name() + ": the study has no binned map");
    return {*binned, technique, allocation};
}

std::vector<double> exact_point_variances(const StudyInputs& inputs, const Technique& technique, size_t bsdf,
                                          int subdivisions, StopFlag stop) {
    const Bsdf& b = inputs.options.bsdfs.at(bsdf);
    if (technique.bins && !inputs.binned)
        throw std::invalid_argument("exact_point_variances: " + technique.name() + " needs the binned map");
    const EnvMap& sampled =
        technique.compensated ? inputs.compensated.maps.at(inputs.compensated.of_bsdf.at(bsdf)) : inputs.plain;
    std::vector<double> variances;
    for (const ShadingPoint& point : inputs.points)
        variances.push_back(
            technique.bins
                ? exact_variance(*inputs.binned, technique, inputs.options.allocation, b, point, subdivisions, stop)
                : exact_variance(sampled, technique, inputs.options.allocation, b, point, subdivisions, stop));
    return variances;
}

namespace {

// A cell's random stream, from the point's index and the technique's name rather than
// its place in the list, so that a technique's numbers are the same whichever others run
// beside it; the BSDFs at a point share it, so that one differing only in albedo gives
// estimates in exact proportion.
uint64_t cell_stream(size_t point, const Technique& technique) {
    const std::string key = std::to_string(point) + "/" + technique.name();
    return hash64(std::as_bytes(std::span(key.data(), key.size())));
}

// The timing, on one thread once the run's cells are done (cells timed while they share
// the cores vary by +-20% from run to run): at up to kTimedPoints of the run's points,
// spread evenly over them, every technique in turn at each (round, point, BSDF), for
// the run's spp estimates rounded up to whole chunks but at most kTimedEstimates.
constexpr size_t kTimedPoints = 8, kTimingRounds = 5;
constexpr uint64_t kTimedEstimates = 256;
static_assert(kTimedEstimates % kChunk == 0);

// Each technique's seconds per estimate on each BSDF, [b * nt + t]: per point the median
// of its rounds, then the mean over the points (a normal facing the sun costs more than
// one facing the ground); all 0 once `stop` is set (checked every cell).
std::vector<double> timed_seconds(const std::vector<DirectLightingEstimator>& estimators,
                                  std::span<const ShadingPoint> points, const ComparisonOptions& options,
                                  const std::atomic<bool>* stop) {
    const size_t nb = options.bsdfs.size(), nt = estimators.size(), np = std::min(points.size(), kTimedPoints);
    const uint64_t estimates = std::min(kTimedEstimates, (uint64_t{options.spp} + kChunk - 1) / kChunk * kChunk);
    std::vector<std::vector<double>> rounds(nb * nt * np);  // [(b * nt + t) * np + i], one value a round
    Rgb chunk[kChunk];
    for (size_t round = 0; round < kTimingRounds; ++round)
        for (size_t i = 0; i < np; ++i)
            for (size_t b = 0; b < nb; ++b)
                for (size_t t = 0; t < nt; ++t) {
                    if (stop && stop->load()) return std::vector<double>(nb * nt);
                    const size_t p = i * points.size() / np;
                    Pcg32 rng(options.seed + round, cell_stream(p, options.techniques[t]));
                    PointState state;
                    const auto start = std::chrono::steady_clock::now();
                    for (uint64_t done = 0; done < estimates; done += kChunk)
                        estimators[t].estimate(points[p], options.bsdfs[b], rng, state, {chunk, kChunk});
                    const std::chrono::duration<double> elapsed = std::chrono::steady_clock::now() - start;
                    rounds[(b * nt + t) * np + i].push_back(elapsed.count() / static_cast<double>(estimates));
                }
    std::vector<double> seconds(nb * nt);
    for (size_t c = 0; c < nb * nt; ++c) {
        for (size_t i = 0; i < np; ++i) seconds[c] += median(rounds[c * np + i]);
        seconds[c] /= static_cast<double>(np);
    }
    return seconds;
}

// The cells of a run over `done` points: one per (point, BSDF, technique), the
// reference of each (point, BSDF) and each (BSDF, technique)'s timed seconds per estimate.
struct CellTable {
    const std::vector<Cell>& cells;
    const std::vector<double>& references;
    const std::vector<double>& seconds;
    size_t done, nb, nt;
    const Cell& at(size_t p, size_t b, size_t t) const { return cells[(p * nb + b) * nt + t]; }
};

// Technique t's statistics on BSDF b over the points, with its variance ratio to
// mis-balance (the technique at mis_index; nt where the run has none).
TechniqueStats technique_stats(const CellTable& table, size_t b, size_t t, size_t mis_index,
                               const Technique& technique) {
    const size_t done = table.done, nt = table.nt;
    TechniqueStats s;
    s.technique = technique;
    RunningStats rel;
    double variance_sum = 0, log_ratio = 0, log_ratio_se2 = 0;
    size_t ratios = 0;
    for (size_t p = 0; p < done; ++p) {
        const Cell& c = table.at(p, b, t);
        s.mean += c.estimates.mean() / done;
        s.reference += table.references[p * table.nb + b] / done;
        s.variance += c.estimates.variance() / done;
        variance_sum += c.estimates.variance() / c.estimates.count();
        rel.merge(c.squared_relative_error);
        s.estimates += c.estimates.count();
        s.ill_conditioned_points += c.ill_conditioned;
        s.point_variances.push_back(c.estimates.variance());
        s.point_variance_rel_se.push_back(relative_standard_error(c));
        if (mis_index < nt && t != mis_index) {
            const Cell& mis = table.at(p, b, mis_index);
            const double v = c.estimates.variance(), v_mis = mis.estimates.variance();
            if (v > 0 && !(v_mis > 0)) s.variance_ratio_worst = std::numeric_limits<double>::infinity();
            if (v > 0 && v_mis > 0) {
                log_ratio += std::log(v / v_mis), ++ratios;
                log_ratio_se2 += square(relative_standard_error(c)) + square(relative_standard_error(mis));
                s.variance_ratio_worst = std::max(s.variance_ratio_worst, v / v_mis);
            }
        }
    }
    s.std_error = std::sqrt(variance_sum) / done;
    s.rel_mse = rel.mean();
    const double seconds = table.seconds[b * nt + t];
    s.ns_per_estimate = 1e9 * seconds;
    s.efficiency = s.variance > 0 && seconds > 0 ? 1 / (s.variance * seconds) : 0;
    s.variance_ratio_vs_mis = t == mis_index ? 1.0 : (ratios ? std::exp(log_ratio / ratios) : 0);
    if (t == mis_index) s.variance_ratio_worst = 1.0;
    if (mis_index < nt && s.variance_ratio_vs_mis > 0 && seconds > 0)
        s.efficiency_ratio_vs_mis = table.seconds[b * nt + mis_index] / (s.variance_ratio_vs_mis * seconds);
    s.variance_ratio_log_std_error = ratios ? std::sqrt(log_ratio_se2) / static_cast<double>(ratios) : 0;
    return s;
}

// Appends the point's reference for each BSDF, and raises each BSDF's largest relative
// error; false, with nothing appended, once `stop` is set (an 8k map's quadrature takes
// seconds: it stops within a row).
bool add_references(const EnvMap& plain, const ShadingPoint& point, const ComparisonOptions& options, StopFlag stop,
                    std::vector<double>& references, std::vector<double>& worst_error) {
    const size_t first = references.size();
    try {
        for (size_t b = 0; b < options.bsdfs.size(); ++b) {
            const QuadratureResult r = reflected_radiance(plain, options.bsdfs[b], point, options.quadrature, stop);
            references.push_back(r.luminance);
            if (r.luminance > 0) worst_error[b] = std::max(worst_error[b], r.error / r.luminance);
        }
        return true;
    } catch (const Interrupted&) {
        references.resize(first);
        return false;
    }
}

// The study with one compensated map for every BSDF.
Comparison compare_one(const EnvMap& plain, const EnvMap& compensated, const BinnedEnvMap* binned,
                       std::span<const ShadingPoint> points, const ComparisonOptions& options,
                       const std::atomic<bool>* stop, const std::function<void(size_t, size_t)>& progress) {
    if (options.bsdfs.empty() || options.techniques.empty() || options.spp == 0 || points.empty())
        throw std::invalid_argument("compare: needs at least one BSDF, technique, shading point and sample");
    std::vector<DirectLightingEstimator> estimators;
    for (const Technique& t : options.techniques)
        estimators.push_back(study_estimator(plain, compensated, binned, t, options.allocation));
    const size_t nb = options.bsdfs.size(), nt = options.techniques.size();
    const uint32_t threads = options.threads ? options.threads : usable_cores();
    const LumaCoefficients luma = plain.options().luma;

    // cells[(p * nb + b) * nt + t]; references[p * nb + b].
    std::vector<Cell> cells;
    std::vector<double> references, reference_error(nb, 0.0);
    size_t done = 0;
    if (progress) progress(0, points.size());
    for (; done < points.size() && !(stop && stop->load()); ++done) {
        const ShadingPoint& point = points[done];
        if (!add_references(plain, point, options, stop, references, reference_error)) break;
        const size_t first = cells.size();
        cells.resize(first + nb * nt);
        std::atomic<size_t> next{0};
        auto work = [&] {
            for (size_t job; (job = next.fetch_add(1)) < nb * nt;) {
                const size_t b = job / nt, t = job % nt;
                const double reference = references[done * nb + b];
                Cell& cell = cells[first + job];
                Pcg32 rng(options.seed, cell_stream(done, options.techniques[t]));
                PointState state;
                Rgb chunk[kChunk];
                for (uint64_t begin = 0; begin < options.spp; begin += kChunk) {
                    if (begin % (kChunk * kChunksPerStopCheck) == 0 && stop && stop->load(std::memory_order_relaxed))
                        return;
                    const uint64_t count = std::min<uint64_t>(kChunk, options.spp - begin);
                    estimators[t].estimate(point, options.bsdfs[b], rng, state, {chunk, count});
                    for (uint64_t i = begin; i < begin + count; ++i) {
                        const double x = luminance(chunk[i - begin], luma);
                        cell.estimates.add(x);
                        cell.batches[i % kBatches].add(x);
                        if (reference > 0)
                            cell.squared_relative_error.add((x - reference) * (x - reference) /
                                                            (reference * reference));
                    }
                }
                cell.ill_conditioned = options.techniques[t].heuristic == Heuristic::optimal && state.estimates >= 8 &&
                                       !state.optimal.solved;
            }
        };
        std::vector<std::jthread> pool;
        for (uint32_t i = 1; i < threads; ++i) pool.emplace_back(work);
        work();
        pool.clear();
        // A point cut short by the stop is dropped: its cells hold fewer estimates.
        if (stop && stop->load()) {
            cells.resize(first);
            references.resize(done * nb);
            break;
        }
        if (progress) progress(done + 1, points.size());
    }

    Comparison result{{}, done, points.size()};
    if (done == 0) return result;
    const std::vector<double> seconds = timed_seconds(estimators, points.first(done), options, stop);
    const CellTable table{cells, references, seconds, done, nb, nt};
    size_t mis_index = nt;
    for (size_t t = 0; t < nt; ++t)
        if (options.techniques[t] == Technique::parse("mis-balance")) mis_index = t;
    for (size_t b = 0; b < nb; ++b) {
        BsdfComparison bc{options.bsdfs[b], {}, reference_error[b]};
        for (size_t t = 0; t < nt; ++t)
            bc.techniques.push_back(technique_stats(table, b, t, mis_index, options.techniques[t]));
        result.bsdfs.push_back(std::move(bc));
    }
    return result;
}

}  // namespace

EnvMap compensated_map(const EnvMap& plain, float alpha, StopFlag stop) {
    EnvMapOptions options = plain.options();
    options.compensation = {true, alpha};
    return build_env_map(to_image(plain.radiance()), options, stop);
}

CompensatedMaps compensated_maps(const EnvMap& plain, std::span<const float> bsdf_alphas, StopFlag stop) {
    CompensatedMaps result;
    for (float alpha : bsdf_alphas) {
        const size_t i =
            static_cast<size_t>(std::find(result.alphas.begin(), result.alphas.end(), alpha) - result.alphas.begin());
        if (i == result.alphas.size()) {
            result.alphas.push_back(alpha);
            result.maps.push_back(compensated_map(plain, alpha, stop));
        }
        result.of_bsdf.push_back(i);
    }
    return result;
}

Comparison compare(const StudyInputs& inputs, const RunControl& control) {
    const ComparisonOptions& options = inputs.options;
    if (inputs.compensated.of_bsdf.size() != options.bsdfs.size())
        throw std::invalid_argument("compare: needs one compensated map per BSDF");
    const size_t runs = inputs.compensated.maps.size();
    // Callers that only name the techniques get the default bins.
    std::optional<BinnedEnvMap> own_bins;
    if (!inputs.binned && uses_bins(options.techniques)) own_bins.emplace(build_bins(EnvMap(inputs.plain)));
    const BinnedEnvMap* binned = inputs.binned ? inputs.binned : (own_bins ? &*own_bins : nullptr);
    std::vector<std::optional<BsdfComparison>> slots(options.bsdfs.size());
    Comparison merged{{}, inputs.points.size(), inputs.points.size()};
    for (size_t m = 0; m < runs; ++m) {
        if (control.stopped()) {
            merged.points_done = 0;
            break;
        }
        ComparisonOptions run = options;
        run.bsdfs.clear();
        std::vector<size_t> slot;
        for (size_t b = 0; b < options.bsdfs.size(); ++b)
            if (inputs.compensated.of_bsdf[b] == m) run.bsdfs.push_back(options.bsdfs[b]), slot.push_back(b);
        const Comparison c = compare_one(inputs.plain, inputs.compensated.maps[m], binned, inputs.points, run,
                                         control.stop, [&](size_t done, size_t total) {
                                             if (control.progress) control.progress(m * total + done, runs * total);
                                         });
        merged.points_done = std::min(merged.points_done, c.points_done);
        for (size_t i = 0; i < c.bsdfs.size(); ++i) slots[slot[i]] = c.bsdfs[i];
    }
    for (auto& s : slots)
        if (s) merged.bsdfs.push_back(std::move(*s));
    return merged;
}

}  // namespace envmis
