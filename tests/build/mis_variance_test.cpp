// Specification of the exact MIS variance kernel (build/mis_variance.h): on a discrete
// set of nodes, where each technique picks node i with probability p_t(i) omega_i, the
// kernel's variance is that of the estimator simulated draw by draw, for the balance form
// and for any weights, at any sample counts.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "envmis/build/mis_variance.h"
#include "stats.h"

namespace envmis {
namespace {

// Nodes with random solid angles, integrand and two normalised densities; the
// environment's density is zero on a quarter of the nodes, as a compensated map's is.
struct Nodes {
    std::vector<MisNode> at;
    std::discrete_distribution<size_t> pick_env, pick_bsdf;
};

Nodes random_nodes(uint64_t seed, size_t count) {
    test::Rng rng(seed);
    Nodes n;
    std::vector<double> env(count), bsdf(count);
    double env_total = 0, bsdf_total = 0;
    for (size_t i = 0; i < count; ++i) {
        const double omega = 0.1 + rng.uniform(), f = rng.uniform() * rng.uniform();
        env[i] = i % 4 == 0 ? 0 : 0.05 + rng.uniform(), bsdf[i] = 0.05 + rng.uniform();
        n.at.push_back({f, omega, env[i], bsdf[i]});
        env_total += env[i] * omega, bsdf_total += bsdf[i] * omega;
    }
    std::vector<double> env_mass, bsdf_mass;
    for (MisNode& node : n.at) {
        node.p_env /= env_total, node.p_bsdf /= bsdf_total;
        env_mass.push_back(node.p_env * node.solid_angle), bsdf_mass.push_back(node.p_bsdf * node.solid_angle);
    }
    n.pick_env = {env_mass.begin(), env_mass.end()};
    n.pick_bsdf = {bsdf_mass.begin(), bsdf_mass.end()};
    return n;
}

double balance(double n_self, double p_self, double n_other, double p_other) {
    return n_self * p_self / (n_self * p_self + n_other * p_other);
}

double power(double n_self, double p_self, double n_other, double p_other) {
    const double a = n_self * p_self, b = n_other * p_other;
    return a * a / (a * a + b * b);
}

// The variance of the estimator, simulated: `estimates` estimates of n.env + n.bsdf draws.
template <class Weight>
double simulated_variance(Nodes& nodes, MisCounts n, Weight weight, uint64_t seed, int estimates) {
    std::mt19937_64 engine(seed);
    double sum = 0, sum2 = 0;
    for (int e = 0; e < estimates; ++e) {
        double estimate = 0;
        for (int j = 0; j < n.env; ++j) {
            const MisNode& x = nodes.at[nodes.pick_env(engine)];
            estimate += x.f * weight(n.env, x.p_env, n.bsdf, x.p_bsdf) / x.p_env / n.env;
        }
        for (int j = 0; j < n.bsdf; ++j) {
            const MisNode& x = nodes.at[nodes.pick_bsdf(engine)];
            estimate += x.f * weight(n.bsdf, x.p_bsdf, n.env, x.p_env) / x.p_bsdf / n.bsdf;
        }
        sum += estimate, sum2 += estimate * estimate;
    }
    const double mean = sum / estimates;
    return (sum2 - estimates * mean * mean) / (estimates - 1);
}

// 400,000 estimates: the sample variance's relative standard error is well under 1%
// here, so 4% is more than four of them.
constexpr int kEstimates = 400000;
constexpr double kTolerance = 0.04;

TEST(MisVariance, TheBalanceFormIsTheVarianceOfTheSimulatedEstimator) {
    for (const MisCounts n : {MisCounts{1, 1}, MisCounts{2, 3}, MisCounts{3, 1}}) {
        Nodes nodes = random_nodes(11, 24);
        MisMoments m;
        for (const MisNode& node : nodes.at) m.add_balance(node, n);
        const double simulated = simulated_variance(nodes, n, balance, 21, kEstimates);
        EXPECT_NEAR(m.variance(n), simulated, kTolerance * simulated) << n.env << "+" << n.bsdf << " samples";
    }
}

TEST(MisVariance, AnyWeightsGiveTheVarianceOfTheSimulatedEstimator) {
    for (const MisCounts n : {MisCounts{1, 1}, MisCounts{2, 3}}) {
        Nodes nodes = random_nodes(12, 24);
        MisMoments m;
        for (const MisNode& node : nodes.at)
            m.add(node, n, power(n.env, node.p_env, n.bsdf, node.p_bsdf),
                  power(n.bsdf, node.p_bsdf, n.env, node.p_env));
        const double simulated = simulated_variance(nodes, n, power, 22, kEstimates);
        EXPECT_NEAR(m.variance(n), simulated, kTolerance * simulated) << n.env << "+" << n.bsdf << " samples";
    }
}

TEST(MisVariance, TheBalanceFormEqualsTheGeneralFormWithBalanceWeights) {
    const Nodes nodes = random_nodes(13, 64);
    const MisCounts n{2, 5};
    MisMoments general, balanced;
    for (const MisNode& node : nodes.at) {
        general.add(node, n, balance(n.env, node.p_env, n.bsdf, node.p_bsdf),
                    balance(n.bsdf, node.p_bsdf, n.env, node.p_env));
        balanced.add_balance(node, n);
    }
    EXPECT_NEAR(balanced.variance(n), general.variance(n), 1e-12 * general.variance(n));
    EXPECT_NEAR(balanced.env + balanced.bsdf, general.env + general.bsdf, 1e-12);
}

// A density proportional to the integrand, used alone, has no variance; the BSDF
// technique, given no samples, adds nothing whatever its density.
TEST(MisVariance, ADensityProportionalToTheIntegrandAloneHasNoVariance) {
    Nodes nodes = random_nodes(14, 16);
    double integral = 0;
    for (const MisNode& node : nodes.at) integral += (node.f + 0.01) * node.solid_angle;
    MisMoments m;
    for (MisNode node : nodes.at) {
        node.f += 0.01;
        node.p_env = node.f / integral;
        m.add(node, {1, 0}, 1, 1);
    }
    EXPECT_NEAR(m.env, integral, 1e-12 * integral);
    EXPECT_EQ(m.bsdf, 0.0);
    EXPECT_NEAR(m.variance({1, 0}), 0.0, 1e-12 * integral * integral);
}

}  // namespace
}  // namespace envmis
