// Estimators of unoccluded direct lighting from an environment map at a shading point:
//
//   L_o(wo) = integral over the sphere of L(wi) f(wo, wi) cos(theta_i) dwi
//
// by environment sampling, BSDF sampling, or multiple importance sampling of both
// (Veach 1995) with the balance or power heuristic, over the plain (luminance) or the
// MIS-compensated environment density (Karlik et al. 2019).
//
// Equal sample count: every technique spends Allocation::total() samples per estimate
// (1 environment + 1 BSDF sample for MIS by default, 2 samples of its one kind for a
// single technique), so variances compare directly.
//
// A compensated density is zero where the radiance is not (envmap.h): sampling it
// alone is biased, so an environment-only technique over an incomplete map is refused
// at construction. Under MIS the BSDF technique covers what it leaves out.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "envmis/bsdf.h"
#include "envmis/envmap.h"
#include "envmis/random.h"

namespace envmis {

enum class Strategy : uint32_t { env, bsdf, mis };
enum class Heuristic : uint32_t { balance, power };

struct Technique {
    Strategy strategy = Strategy::mis;
    Heuristic heuristic = Heuristic::balance;
    bool compensated = false;  // the environment technique samples the compensated density

    // Names: env, env-comp, bsdf, mis-balance, mis-power, mis-balance-comp, mis-power-comp.
    // Throws std::invalid_argument for other text.
    static Technique parse(std::string_view name);
    std::string name() const;
    friend bool operator==(const Technique&, const Technique&) = default;
};

// Samples per estimate. A single technique spends total() samples of its own kind.
struct Allocation {
    uint32_t env = 1, bsdf = 1;
    uint32_t total() const noexcept { return env + bsdf; }
};

// World-space unit vectors: the surface normal, and the direction towards the viewer.
struct ShadingPoint {
    Vec3 normal{0, 0, 1};
    Vec3 wo{0, 0, 1};
};

// MIS weight of a technique with density-times-count a against another with b.
ENVMIS_HD inline float mis_weight(Heuristic h, float a, float b) noexcept {
    if (h == Heuristic::power) a *= a, b *= b;
    return a > 0 ? a / (a + b) : 0.0f;
}

class DirectLightingEstimator {
public:
    // `env` is the map the technique samples: plain for plain techniques, compensated for
    // compensated ones. Throws std::invalid_argument if the technique samples only the
    // environment and env is not complete (a compensated density), if the allocation
    // spends no sample, or if MIS is given a zero count for one of its techniques.
    DirectLightingEstimator(const EnvMap& env, Technique technique, Allocation allocation = {});

    // One estimate of L_o (RGB radiance), from allocation.total() samples drawn with rng.
    // noexcept and allocation-free.
    Rgb estimate(const ShadingPoint& point, const Bsdf& bsdf, Pcg32& rng) const noexcept;

    Technique technique() const noexcept { return technique_; }
    Allocation allocation() const noexcept { return allocation_; }

private:
    EnvMapView env_;
    Technique technique_;
    Allocation allocation_;
};

}  // namespace envmis
