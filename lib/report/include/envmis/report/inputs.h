// compare --json's "inputs": what a comparison ran on, written by one function for the
// command (`envmis compare --json`) and envmis.compare's Comparison.inputs.
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include <nlohmann/json.hpp>

#include "envmis/sampling/binned.h"
#include "envmis/study/comparison/alpha.h"
#include "envmis/study/comparison/comparison.h"

namespace envmis {

// What a comparison ran on; the pointers may be null, the spans refer to the caller's data.
struct ComparisonInputs {
    std::string map;                             // the map's name
    uint32_t width = 0, height = 0;              // of the plain map, texels
    float alpha = 0;                             // the map-wide compensation strength
    const AlphaChoice* choice = nullptr;         // with alpha auto: the choice that gave the alphas
    const ComparisonOptions* options = nullptr;  // spp, seed, threads, allocation, BSDFs
    std::span<const float> bsdf_alphas;          // per BSDF of options->bsdfs, in order
    const BinnedEnvMap* binned = nullptr;        // the -bins techniques' bins
    bool bins_auto = false;                      // their alpha chosen per bin
    std::span<const ShadingPoint> points_done;   // the shading points the results cover
};

// {"map", "width", "height", "alpha", "alpha_auto", "spp", "seed", "threads",
// "env_samples", "bsdf_samples", "points_done" (a count), "albedo", "bsdf_alpha" {bsdf:
// alpha}, "alpha_choice" (with a choice), "bins" {"count", "alpha_auto"} (with bins),
// "points" [{"normal", "view"}]}. The command adds "source_hash" and "options".
nlohmann::json inputs_json(const ComparisonInputs& inputs);

// Each BSDF's reflectance: [r, g, b] by BSDF name, each rounded to "%g" (6 digits).
nlohmann::json albedo_json(std::span<const Bsdf> bsdfs);

// alpha auto's choice: {"criterion" (in words), "width", "height" (the copy it ran on),
// "seconds", "map_alpha", "bsdf_alpha" {bsdf: alpha}, "candidates" [{"alpha", "all",
// "per_bsdf" {bsdf: ratio}}]}; `bsdfs` are the choice's AlphaOptions::bsdfs, in order.
nlohmann::json alpha_choice_json(const AlphaChoice& choice, std::span<const Bsdf> bsdfs);

}  // namespace envmis
