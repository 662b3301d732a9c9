// Specification of `envmis report`: the Markdown summary of several compare runs.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

class Report : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() /
               ("envmis_report_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }

    // A compare result with the given variance ratios against mis-balance for one BSDF.
    fs::path write_run(const std::string& map, const std::vector<std::pair<std::string, double>>& ratios) {
        json j = {
            {"inputs", {{"map", map}, {"width", 8}, {"height", 4}, {"alpha", 1.0}, {"spp", 64}, {"points_done", 4}}},
            {"results", json::array()}};
        for (const auto& [technique, ratio] : ratios)
            j["results"].push_back({{"bsdf", "lambert"},
                                    {"technique", technique},
                                    {"mean", 1.0},
                                    {"reference", 1.0},
                                    {"variance", ratio},
                                    {"std_error", 0.01},
                                    {"rel_mse", 0.1},
                                    {"ns_per_estimate", 100.0},
                                    {"efficiency", 1e7 / ratio},
                                    {"variance_ratio_vs_mis", ratio},
                                    {"estimates", 256},
                                    {"point_variances", {ratio, ratio}},
                                    {"point_variance_rel_se", {0.01, 0.01}}});
        const fs::path path = dir_ / (map + ".json");
        std::ofstream(path) << j.dump();
        return path;
    }

    int run(const std::string& args, std::string* output = nullptr) {
        const fs::path out = dir_ / "stdout.txt";
        const int status =
            std::system((std::string(ENVMIS_CLI) + " report " + args + " > " + out.string() + " 2>&1").c_str());
        if (output) {
            std::stringstream s;
            s << std::ifstream(out).rdbuf();
            *output = s.str();
        }
        return status;
    }

    std::string read(const fs::path& path) const {
        std::stringstream s;
        s << std::ifstream(path).rdbuf();
        return s.str();
    }

    fs::path dir_;
};

TEST_F(Report, SummarisesCasesWithGeometricMeansAndNamesTheBestMisTechnique) {
    const fs::path a =
        write_run("a", {{"mis-balance", 1}, {"bsdf", 0.01}, {"mis-optimal", 0.5}, {"mis-balance-comp", 0.8}});
    const fs::path b = write_run("b", {{"mis-balance", 1},
                                       {"bsdf", 0.01},
                                       {"mis-optimal", 0.8},
                                       {"mis-balance-comp", 0.2},
                                       {"mis-optimal-comp", 0.3}});
    ASSERT_EQ(run(a.string() + " " + b.string() + " -o " + (dir_ / "r.md").string() + " --command 'bash x.sh'"), 0);
    const std::string md = read(dir_ / "r.md");
    EXPECT_NE(md.find("Made by `bash x.sh`"), std::string::npos);
    // The techniques' columns are code: `bsdf` (a technique) is not the BSDF column.
    EXPECT_NE(md.find("| map | BSDF | `bsdf` | `mis-optimal` | `mis-balance-comp` | `mis-optimal-comp` |"),
              std::string::npos)
        << md;
    EXPECT_NE(md.find("| a | lambert | 0.010 | 0.500 | 0.800 |"), std::string::npos) << md;
    // sqrt(0.5 * 0.8) = 0.632, sqrt(0.8 * 0.2) = 0.4: compensation wins; bsdf is not a candidate.
    // mis-optimal-comp, measured on one map only, is no candidate either.
    EXPECT_NE(md.find("| **geometric mean** | | **0.010** | **0.632** | **0.400** | **0.300** |"), std::string::npos)
        << md;
    EXPECT_NE(md.find("`mis-balance-comp`, 2.50x lower variance than balance MIS"), std::string::npos) << md;
    // Paired per point: log standard error sqrt(2 (0.01^2 + 0.01^2)) / 2 = 0.01.
    EXPECT_NE(md.find("| a | lambert | mis-optimal | mis-balance | 0.500 | 0.010 | yes |"), std::string::npos) << md;
    EXPECT_NE(md.find("| b | lambert | mis-optimal-comp | mis-balance-comp | 1.500 | 0.010 | **no** |"),
              std::string::npos)
        << md;
    EXPECT_NE(md.find("within error in 2 of 3 cases"), std::string::npos) << md;
    EXPECT_NE(md.find("## a (8x4)"), std::string::npos);
}

TEST_F(Report, SingleTechniquesTakeTheirExactRatioWhereTheRunHasIt) {
    // Measured, BSDF sampling looks 100x better than balance MIS: the sun it rarely finds
    // is missing from the run. With --exact's figures the summary shows the exact ratio,
    // for single techniques only (an MIS column stays measured), and says so.
    const fs::path measured = write_run("a", {{"mis-balance", 1}, {"bsdf", 0.01}, {"mis-balance-comp", 0.8}});
    json j = json::parse(read(measured));
    j["exact"] = {{"lambert", {{"bsdf", {{"ratio", 210.0}}}, {"mis-balance-comp", {{"ratio", 0.7}}}}}};
    const fs::path with_exact = dir_ / "exact.json";
    std::ofstream(with_exact) << j.dump();
    ASSERT_EQ(run(with_exact.string() + " -o " + (dir_ / "r.md").string()), 0);
    const std::string md = read(dir_ / "r.md");
    EXPECT_NE(md.find("| a | lambert | 210.000 | 0.800 |"), std::string::npos) << md;
    EXPECT_NE(md.find("exact here: `--exact`, quadrature"), std::string::npos) << md;
    ASSERT_EQ(run(measured.string() + " -o " + (dir_ / "m.md").string()), 0);
    const std::string m = read(dir_ / "m.md");
    EXPECT_NE(m.find("| a | lambert | 0.010 | 0.800 |"), std::string::npos) << m;
    EXPECT_NE(m.find("may understate it by orders of magnitude"), std::string::npos) << m;
}

TEST_F(Report, EachRunsTableListsItsFiguresAndNoTimingLeavesOutOnlyTheTimedOnes) {
    const fs::path a = write_run("a", {{"mis-balance", 1}, {"mis-optimal", 0.5}});
    ASSERT_EQ(run(a.string() + " -o " + (dir_ / "timed.md").string()), 0);
    ASSERT_EQ(run(a.string() + " -o " + (dir_ / "untimed.md").string() + " --no-timing"), 0);
    const std::string timed = read(dir_ / "timed.md");
    const std::string untimed = read(dir_ / "untimed.md");
    EXPECT_NE(timed.find("| bsdf | technique | mean | reference | variance | std_error | rel_mse | ns/estimate | "
                         "efficiency | var/mis |"),
              std::string::npos)
        << timed;
    // variance 0.5, ns/estimate 100, efficiency 1e7 / 0.5, var/mis 0.5.
    EXPECT_NE(timed.find("| lambert | mis-optimal | 1 | 1 | 0.5 | 0.01 | 0.1 | 100 | 2e+07 | 0.500 |"),
              std::string::npos)
        << timed;
    EXPECT_NE(untimed.find("| bsdf | technique | mean | reference | variance | std_error | rel_mse | var/mis |"),
              std::string::npos)
        << untimed;
    EXPECT_NE(untimed.find("| lambert | mis-optimal | 1 | 1 | 0.5 | 0.01 | 0.1 | 0.500 |"), std::string::npos)
        << untimed;
    EXPECT_EQ(untimed.find("ns/estimate"), std::string::npos) << untimed;
    EXPECT_EQ(untimed.find("efficiency"), std::string::npos) << untimed;
}

TEST_F(Report, RejectsFilesThatAreNotCompareResults) {
    std::ofstream(dir_ / "text.json") << "not json";
    std::ofstream(dir_ / "other.json") << R"({"samplers": []})";
    std::string out;
    EXPECT_NE(run((dir_ / "text.json").string() + " -o " + (dir_ / "r.md").string(), &out), 0);
    EXPECT_NE(out.find("text.json: not JSON"), std::string::npos) << out;
    EXPECT_NE(run((dir_ / "other.json").string() + " -o " + (dir_ / "r.md").string(), &out), 0);
    EXPECT_NE(out.find("not the JSON of envmis compare"), std::string::npos) << out;
    EXPECT_NE(run((dir_ / "missing.json").string() + " -o " + (dir_ / "r.md").string(), &out), 0);
    EXPECT_NE(out.find("missing.json: cannot open"), std::string::npos) << out;
    EXPECT_FALSE(fs::exists(dir_ / "r.md"));
}

// Each field report reads, missing or of another type: refused naming the file and the
// field, with no report and no temporary file left (an empty result once read past a buffer).
TEST_F(Report, RejectsCompareResultsWithAMissingOrMistypedFieldNamingIt) {
    const json good = json::parse(read(write_run("good", {{"mis-balance", 1.0}})));
    const auto broken = [&](auto change) {
        json j = good;
        change(j);
        return j;
    };
    const std::pair<json, std::string> cases[] = {
        {json::parse(R"({"inputs": {}, "results": [{}]})"), "results[0].bsdf: expected present"},
        {broken([](json& j) { j["results"][0] = 3; }), "results[0]: expected an object"},
        {broken([](json& j) { j["results"][0]["bsdf"] = 7; }), "results[0].bsdf: expected a string"},
        {broken([](json& j) { j["results"][0]["mean"] = "high"; }), "results[0].mean: expected a number"},
        {broken([](json& j) { j["results"][0]["point_variance_rel_se"] = {0.1}; }),
         "results[0].point_variance_rel_se: expected one per point"},
        {broken([](json& j) { j["inputs"] = 5; }), "inputs: expected an object"},
        {broken([](json& j) { j["inputs"]["spp"] = "many"; }), "inputs.spp: expected an integer"},
        {broken([](json& j) {
             j["sweep_best"] = {{{"bsdf", "lambert"}, {"best_alpha", 1}, {"best_ratio", 1}, {"auto_alpha", 1}}};
         }),
         "sweep_best[0].auto_vs_best: expected present"},
        {broken([](json& j) {
             j["allocation"] = {{{"bsdf", "lambert"},
                                 {"technique", "mis-balance"},
                                 {"efficiency", 1},
                                 {"env_samples", "1"},
                                 {"bsdf_samples", 1}}};
         }),
         "allocation[0].env_samples: expected an integer"},
        // Counts beyond what compare writes would overflow the writer's arithmetic.
        {broken([](json& j) {
             j["allocation"] = {{{"bsdf", "lambert"},
                                 {"technique", "mis-balance"},
                                 {"efficiency", 1},
                                 {"env_samples", 9223372036854775807LL},
                                 {"bsdf_samples", -1}}};
         }),
         "allocation[0].env_samples: expected an integer from 0 to 4294967295"},
        {broken([](json& j) { j["inputs"]["spp"] = -3; }), "inputs.spp: expected an integer from 0"},
    };
    for (const auto& [j, message] : cases) {
        std::ofstream(dir_ / "bad.json") << j.dump();
        std::string out;
        EXPECT_NE(run((dir_ / "bad.json").string() + " -o " + (dir_ / "r.md").string(), &out), 0) << j.dump();
        EXPECT_NE(out.find("bad.json: " + message), std::string::npos) << out;
        for (const auto& entry : fs::directory_iterator(dir_))
            EXPECT_EQ(entry.path().extension() == ".md", false) << entry.path();
    }
}

TEST_F(Report, ReadsNullFiguresAsNotANumber) {
    json j = json::parse(read(write_run("nulls", {{"mis-balance", 1.0}, {"env", 2.0}})));
    j["results"][1]["efficiency"] = nullptr;
    std::ofstream(dir_ / "nulls.json") << j.dump();
    std::string out;
    EXPECT_EQ(run((dir_ / "nulls.json").string() + " -o " + (dir_ / "r.md").string(), &out), 0) << out;
    EXPECT_NE(read(dir_ / "r.md").find("nan"), std::string::npos);
}

}  // namespace
