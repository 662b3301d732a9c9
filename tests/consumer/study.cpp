// An installed envmis::study, used as a researcher's program would: the white furnace.
// Under a constant environment of radiance 1 a Lambertian surface of albedo 0.8 reflects
// exactly 0.8, so balance-MIS estimates must average 0.8 within 4 standard errors (fixed
// seed). Exits non-zero, saying why, on a mismatch.
//
// Usage: consumer_study [WORK_FOLDER] (ignored: the program writes nothing)
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "envmis/build/env_map.h"
#include "envmis/study.h"

int main() {
    const uint32_t w = 32, h = 16;
    const envmis::EnvMap plain =
        envmis::build_env_map(envmis::RgbImage{w, h, envmis::RgbPixels(size_t{w} * h, {1, 1, 1})});
    const envmis::DirectLightingEstimator estimator(plain, envmis::Technique::parse("mis-balance"));
    const envmis::Bsdf bsdf = envmis::Bsdf::parse("lambert");
    envmis::Pcg32 rng(7, 0);
    const envmis::ShadingPoint point{envmis::normalize(envmis::Vec3{0.3f, -0.2f, 1}),
                                     envmis::normalize(envmis::Vec3{0.3f, -0.2f, 1})};
    const int n = 4096;
    double sum = 0, sum2 = 0;
    for (int i = 0; i < n; ++i) {
        const double e = estimator.estimate(point, bsdf, rng).g;
        sum += e;
        sum2 += e * e;
    }
    const double mean = sum / n, std_error = std::sqrt(std::max(0.0, sum2 / n - mean * mean) / n);
    if (!(std::abs(mean - 0.8) <= 4 * std_error + 1e-6)) {
        std::fprintf(stderr, "consumer_study: white furnace gives %.6f +- %.6f, expected 0.8\n", mean, std_error);
        return 1;
    }
    std::printf("consumer_study: ok (furnace %.6f +- %.6f)\n", mean, std_error);
    return 0;
}
