#include "envmis/report/inputs.h"

#include <cstdio>

namespace envmis {

nlohmann::json inputs_json(const ComparisonInputs& in) {
    const ComparisonOptions& o = *in.options;
    nlohmann::json j = {{"map", in.map},
                        {"width", in.width},
                        {"height", in.height},
                        {"alpha", in.alpha},
                        {"alpha_auto", in.choice != nullptr},
                        {"spp", o.spp},
                        {"seed", o.seed},
                        {"threads", o.threads},
                        {"env_samples", o.allocation.env},
                        {"bsdf_samples", o.allocation.bsdf},
                        {"points_done", in.points_done.size()},
                        {"albedo", albedo_json(o.bsdfs)}};
    for (size_t b = 0; b < o.bsdfs.size(); ++b) j["bsdf_alpha"][o.bsdfs[b].name()] = in.bsdf_alphas[b];
    if (in.choice) j["alpha_choice"] = alpha_choice_json(*in.choice, o.bsdfs);
    if (in.binned)
        j["bins"] = {
            {"count", in.binned->bins()}, {"diffuse_count", in.binned->diffuse_bins()}, {"alpha_auto", in.bins_auto}};
    for (const ShadingPoint& p : in.points_done)
        j["points"].push_back({{"normal", {p.normal.x, p.normal.y, p.normal.z}}, {"view", {p.wo.x, p.wo.y, p.wo.z}}});
    return j;
}

nlohmann::json albedo_json(std::span<const Bsdf> bsdfs) {
    nlohmann::json albedo = nlohmann::json::object();
    auto value = [](float v) {
        char text[32];
        std::snprintf(text, sizeof text, "%g", v);
        return std::stod(text);
    };
    for (const Bsdf& b : bsdfs)
        albedo[b.name()] = {value(b.reflectance.r), value(b.reflectance.g), value(b.reflectance.b)};
    return albedo;
}

nlohmann::json alpha_choice_json(const AlphaChoice& choice, std::span<const Bsdf> bsdfs) {
    nlohmann::json j = {{"criterion", "exact variance of mis-balance-comp / mis-balance, geometric mean over points"},
                        {"width", choice.width},
                        {"height", choice.height},
                        {"seconds", choice.seconds},
                        {"map_alpha", choice.alpha},
                        {"candidates", nlohmann::json::array()}};
    for (size_t b = 0; b < bsdfs.size(); ++b) j["bsdf_alpha"][bsdfs[b].name()] = choice.bsdf_alphas[b];
    for (const AlphaCandidate& c : choice.candidates) {
        nlohmann::json per_bsdf;
        for (size_t b = 0; b < bsdfs.size(); ++b) per_bsdf[bsdfs[b].name()] = c.per_bsdf[b];
        j["candidates"].push_back({{"alpha", c.alpha}, {"all", c.criterion}, {"per_bsdf", per_bsdf}});
    }
    return j;
}

}  // namespace envmis
