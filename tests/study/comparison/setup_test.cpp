// Specification of the study's set-up (setup.h), which the command and Python share: the
// limits and list rules both front ends refuse with, the maps a request builds and the
// exact figures of --exact.
#include "envmis/study/comparison/setup.h"
#include "envmis/build/env_map.h"
#include "envmis/cpu.h"

#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <string>
#include <thread>

#include "maps.h"

namespace envmis {
namespace {

std::vector<Technique> techniques(std::initializer_list<const char*> names) {
    std::vector<Technique> list;
    for (const char* name : names) list.push_back(Technique::parse(name));
    return list;
}

std::shared_ptr<const EnvMap> sky(bool compensated) {
    EnvMapOptions options;
    options.compensation.enabled = compensated;
    return std::make_shared<const EnvMap>(build_env_map(test::sun_sky_map(64, 32), options));
}

// Two BSDFs, few points and estimates: a set-up in milliseconds.
CompareRequest quick_request(std::initializer_list<const char*> names = {"mis-balance", "mis-balance-comp"}) {
    CompareRequest request;
    request.options.bsdfs = {Bsdf::lambert(), Bsdf::phong(50)};
    request.options.techniques = techniques(names);
    request.options.spp = 16;
    request.points = sphere_points(4);
    request.alpha = 1.0f;
    return request;
}

TEST(CompareSetup, BinsAreASquareCountAndOnlyWhereABinnedTechniqueRuns) {
    const auto plain = techniques({"mis-balance"}), binned = techniques({"mis-balance-bins"});
    EXPECT_EQ(bins_per_side(0, plain), 0u);
    EXPECT_EQ(bins_per_side(64, plain), 0u);
    EXPECT_EQ(bins_per_side(0, binned), 11u);  // kDefaultStudyBins
    EXPECT_EQ(bins_per_side(4096, binned), 64u);
    for (uint32_t bad : {5u, 65u * 65u}) {
        try {
            bins_per_side(bad, binned);
            ADD_FAILURE() << bad << " bins were accepted";
        } catch (const std::invalid_argument& e) {
            EXPECT_EQ(std::string(e.what()).rfind("bins " + std::to_string(bad) + ": expected a square number", 0), 0u)
                << e.what();
        }
    }
    // A count that is no square is refused even where no binned technique would use it.
    EXPECT_THROW(bins_per_side(5, plain), std::invalid_argument);
}

TEST(CompareSetup, WorkersAreAtMostFourPerUsableCoreAndANoteSaysSo) {
    const uint32_t cores = usable_cores();
    std::string note;
    EXPECT_EQ(worker_threads(0, &note), cores);
    EXPECT_EQ(worker_threads(1, &note), 1u);
    EXPECT_TRUE(note.empty());
    EXPECT_EQ(worker_threads(kMaxStudyThreads, &note), std::min(kMaxStudyThreads, kThreadsPerCore * cores));
    if (kThreadsPerCore * cores < kMaxStudyThreads) {
        EXPECT_NE(note.find("threads 1024: more than 4 per usable core"), std::string::npos) << note;
    }
}

TEST(CompareSetup, ListsSplitAtCommasAndSkipEmptyItems) {
    EXPECT_EQ(split_list("lambert,,phong:50,"), (std::vector<std::string>{"lambert", "phong:50"}));
    EXPECT_TRUE(split_list("").empty());
    EXPECT_TRUE(split_list(",,").empty());
}

TEST(CompareSetup, AnUncompensatedMapIsStudiedAsGivenAndACompensatedOneRebuiltWithout) {
    const auto plain = sky(false);
    EXPECT_EQ(prepare_compare(plain, quick_request()).plain, plain);
    const CompareSetup rebuilt = prepare_compare(sky(true), quick_request());
    EXPECT_FALSE(rebuilt.plain->options().compensation.enabled);
    EXPECT_EQ(rebuilt.plain->density(), plain->density());
}

TEST(CompareSetup, AFixedAlphaCompensatesEveryBsdfAndNoneChoosesPerBsdf) {
    CompareRequest request = quick_request();
    request.alpha = 0.5f;
    const CompareSetup fixed = prepare_compare(sky(false), request);
    EXPECT_FALSE(fixed.choice);
    EXPECT_EQ(fixed.bsdf_alphas, (std::vector<float>{0.5f, 0.5f}));
    EXPECT_EQ(fixed.compensated.maps.size(), 1u);
    EXPECT_EQ(fixed.alpha_of(Bsdf::phong(50)), 0.5f);
    request.alpha.reset();
    const CompareSetup chosen = prepare_compare(sky(false), request);
    ASSERT_TRUE(chosen.choice);
    EXPECT_EQ(chosen.bsdf_alphas, chosen.choice->bsdf_alphas);
    EXPECT_EQ(chosen.map_alpha, chosen.choice->alpha);
    EXPECT_EQ(chosen.alpha_of(Bsdf::lambert()), chosen.bsdf_alphas[0]);
}

TEST(CompareSetup, BinsAreBuiltForABinnedTechniqueWithTheirAlphaFixedOnlyWhenGivenAndTheCellGridAsked) {
    EXPECT_EQ(prepare_compare(sky(false), quick_request()).binned, nullptr);
    CompareRequest request = quick_request({"mis-balance", "mis-balance-bins"});
    request.bins = 9;
    const CompareSetup automatic = prepare_compare(sky(false), request);
    ASSERT_NE(automatic.binned, nullptr);
    EXPECT_EQ(automatic.binned->bins(), 9u);
    EXPECT_TRUE(automatic.bins_auto);
    request.bin_alpha = 0.5f;
    const CompareSetup fixed = prepare_compare(sky(false), request);
    EXPECT_FALSE(fixed.bins_auto);
    for (const BinChoice& c : fixed.binned->layout().choices) EXPECT_EQ(c.alpha, 0.5f);
    EXPECT_EQ(automatic.binned->layout().cell_columns, 2u);  // width / 32
    request.cell_columns = 8;
    EXPECT_EQ(prepare_compare(sky(false), request).binned->layout().cell_columns, 8u);
}

TEST(CompareSetup, ExactRatiosCoverTheFixedWeightTechniquesAndBalanceIsOneOverItself) {
    const CompareSetup setup =
        prepare_compare(sky(false), quick_request({"env", "mis-balance", "mis-optimal-comp", "mis-var"}));
    size_t steps = 0, last_total = 0;
    const std::vector<ExactRatio> ratios = exact_ratios(setup, {nullptr, [&](size_t done, size_t total) {
                                                                    steps = done;
                                                                    last_total = total;
                                                                }});
    ASSERT_EQ(ratios.size(), 2u * 2u);  // env and mis-balance per BSDF; the adaptive ones have none
    EXPECT_EQ(steps, last_total);
    EXPECT_EQ(last_total, 2u * 3u);
    for (const ExactRatio& r : ratios) {
        EXPECT_TRUE(r.technique.name() == "env" || r.technique.name() == "mis-balance") << r.technique.name();
        if (r.technique.name() == "mis-balance") {
            EXPECT_EQ(r.ratio, 1.0);
            EXPECT_EQ(r.worst(), 1.0);
        } else {
            EXPECT_GT(r.ratio, 0.0);
        }
    }
    std::atomic<bool> stop{true};
    EXPECT_THROW(exact_ratios(setup, {&stop, {}}), Interrupted);
}

}  // namespace
}  // namespace envmis
