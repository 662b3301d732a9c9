#include "envmis/study/comparison/setup.h"
#include "envmis/build/bins.h"
#include "envmis/build/env_map.h"
#include "envmis/cpu.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace envmis {

uint32_t worker_threads(uint32_t asked, std::string* note) {
    const uint32_t cores = usable_cores();
    if (asked == 0) return cores;
    if (asked <= kThreadsPerCore * cores) return asked;
    if (note)
        *note = "threads " + std::to_string(asked) + ": more than " + std::to_string(kThreadsPerCore) +
                " per usable core (" + std::to_string(cores) + "); using " + std::to_string(kThreadsPerCore * cores);
    return kThreadsPerCore * cores;
}

uint32_t bins_per_side(uint32_t bins, std::span<const Technique> techniques) {
    const uint32_t k = bins ? bins : (uses_bins(techniques) ? kDefaultStudyBins : 0);
    const auto g = static_cast<uint32_t>(std::lround(std::sqrt(static_cast<double>(k))));
    if (g * g != k || (k && g > 64))
        throw std::invalid_argument("bins " + std::to_string(k) +
                                    ": expected a square number g*g of normal bins, g 1 to 64 (e.g. 64, 100, 144)");
    return uses_bins(techniques) ? g : 0;
}

std::vector<std::string> split_list(std::string_view text) {
    std::vector<std::string> items;
    std::stringstream in{std::string(text)};
    for (std::string item; std::getline(in, item, ',');)
        if (!item.empty()) items.push_back(item);
    return items;
}

float CompareSetup::alpha_of(const Bsdf& bsdf) const {
    for (size_t b = 0; b < options.bsdfs.size(); ++b)
        if (options.bsdfs[b].name() == bsdf.name()) return bsdf_alphas[b];
    return map_alpha;
}

namespace {

std::shared_ptr<const EnvMap> without_compensation(std::shared_ptr<const EnvMap> map, StopFlag stop) {
    if (!map->options().compensation.enabled) return map;
    EnvMapOptions plain = map->options();
    plain.compensation.enabled = false;
    return std::make_shared<const EnvMap>(build_env_map(to_image(map->radiance()), plain, stop));
}

std::shared_ptr<const BinnedEnvMap> study_bins(const EnvMap& plain, uint32_t g, const CompareRequest& request,
                                               StopFlag stop) {
    if (g == 0) return nullptr;
    BinnedOptions options;
    options.bins_per_side = g;
    options.auto_alpha = !request.bin_alpha;
    options.alpha = request.bin_alpha.value_or(options.alpha);
    options.cost = request.bin_cost;
    options.cell_columns = request.cell_columns;
    return std::make_shared<const BinnedEnvMap>(build_bins(EnvMap(plain), options, stop));
}

}  // namespace

CompareSetup prepare_compare(std::shared_ptr<const EnvMap> map, CompareRequest request, StopFlag stop) {
    CompareSetup s;
    const uint32_t g = bins_per_side(request.bins, request.options.techniques);
    s.plain = without_compensation(std::move(map), stop);
    s.points = std::move(request.points);
    s.options = std::move(request.options);
    if (!request.alpha) {
        AlphaOptions search;
        search.bsdfs = s.options.bsdfs;
        search.points = s.points;
        search.allocation = s.options.allocation;
        s.choice = choose_alpha(s.plain->radiance(), s.plain->options(), search);
    }
    s.map_alpha = s.choice ? s.choice->alpha : *request.alpha;
    s.bsdf_alphas = s.choice ? s.choice->bsdf_alphas : std::vector<float>(s.options.bsdfs.size(), s.map_alpha);
    s.compensated = compensated_maps(*s.plain, s.bsdf_alphas, stop);
    s.binned = study_bins(*s.plain, g, request, stop);
    s.bins_auto = !request.bin_alpha;
    return s;
}

std::vector<ExactRatio> exact_ratios(const CompareSetup& setup, const RunControl& control) {
    const StudyInputs inputs = setup.inputs();
    const Technique balance = Technique::parse("mis-balance");
    std::vector<Technique> fixed;
    for (const Technique& t : setup.options.techniques)
        if (!t.adaptive() && !t.mixture) fixed.push_back(t);
    const size_t total = setup.options.bsdfs.size() * (fixed.size() + 1);
    size_t done = 0;
    const auto step = [&] {
        if (control.progress) control.progress(++done, total);
    };
    std::vector<ExactRatio> ratios;
    for (size_t b = 0; b < setup.options.bsdfs.size(); ++b) {
        const std::vector<double> baseline = exact_point_variances(inputs, balance, b, 1, control.stop);
        step();
        for (const Technique& t : fixed) {
            const std::vector<double> v = exact_point_variances(inputs, t, b, 1, control.stop);
            std::vector<double> points(v.size(), 0.0);
            bool any = false;
            for (size_t p = 0; p < v.size(); ++p)
                if (v[p] > 0 && baseline[p] > 0) points[p] = v[p] / baseline[p], any = true;
            // No point to compare (every variance 0: a view below the surface): no ratio,
            // rather than the neutral 1 the alpha choice ranks with.
            const double ratio = any ? geometric_mean_ratios(v, baseline, 1).front() : NAN;
            ratios.push_back({b, t, ratio, std::move(points)});
            step();
        }
    }
    return ratios;
}

}  // namespace envmis
