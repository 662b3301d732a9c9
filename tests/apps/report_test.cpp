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

}  // namespace
