// Specification of the compensation-strength and allocation studies of `envmis compare`
// (--alpha auto, --alpha-sweep, --exact, --allocation-sweep, --plots), run on the built
// command with a small synthetic sun map, a few points and few estimates.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_run.h"
#include "envmis/io/image_io.h"
#include "maps.h"

namespace envmis {
namespace {

namespace fs = std::filesystem;
using test::read_file;
using test::Result;

// Each test works in a folder of its own holding map.exr (64 x 32 sky with a sun).
class Sweep : public test::TempFolder {
public:
    Sweep() : TempFolder("envmis_sweep_test_") {}

    void SetUp() override {
        TempFolder::SetUp();
        io::write_exr(dir_ / "map.exr", test::sun_sky_map(64, 32));
    }

    // `envmis compare map.exr` with a small study and `args` (no quoting needed); its
    // output stays in out.txt and err.txt.
    Result compare(const std::string& args) const {
        return test::run_shell("cd '" + dir_.string() + "' && '" + ENVMIS_CLI +
                                   "' compare map.exr --points 4 --spp 64 --threads 2 " + args,
                               file("out.txt"), file("err.txt"));
    }

    // The same at the one shading point `args` give (--normal excludes --points).
    Result compare_at(const std::string& args) const {
        return test::run_shell(
            "cd '" + dir_.string() + "' && '" + ENVMIS_CLI + "' compare map.exr --spp 64 --threads 2 " + args,
            file("out.txt"), file("err.txt"));
    }

    nlohmann::json json(const std::string& name) const { return nlohmann::json::parse(std::ifstream(file(name))); }
};

// Width and height from a PNG's IHDR chunk (big-endian, bytes 16 to 23).
std::pair<uint32_t, uint32_t> png_size(const fs::path& path) {
    const std::string bytes = read_file(path);
    if (bytes.size() < 24 || bytes.substr(1, 3) != "PNG") return {0, 0};
    auto be32 = [&](size_t at) {
        uint32_t v = 0;
        for (size_t i = 0; i < 4; ++i) v = v << 8 | static_cast<uint8_t>(bytes[at + i]);
        return v;
    };
    return {be32(16), be32(20)};
}

size_t csv_data_rows(const std::string& text, std::string* header) {
    std::istringstream in(text);
    std::getline(in, *header);
    size_t rows = 0;
    for (std::string line; std::getline(in, line);) rows += !line.empty();
    return rows;
}

TEST_F(Sweep, AlphaAutoPrintsItsCandidatesAndRecordsTheChoiceInJson) {
    const Result r = compare("--alpha auto --techniques mis-balance,mis-balance-comp --json r.json");
    ASSERT_EQ(r.exit_code, 0) << r;
    EXPECT_NE(r.out.find("alpha auto:"), std::string::npos) << r;
    EXPECT_LT(r.out.find("alpha auto:"), r.out.find("\nbsdf ")) << "the candidates come before the results" << r;

    const nlohmann::json j = json("r.json");
    const nlohmann::json& in = j["inputs"];
    EXPECT_EQ(in["alpha_auto"], true);
    const nlohmann::json& candidates = in["alpha_choice"]["candidates"];
    ASSERT_EQ(candidates.size(), 9u);
    EXPECT_EQ(candidates[0]["alpha"], 0.0);
    EXPECT_EQ(candidates[0]["all"], 1.0);
    std::set<double> tried;
    for (const auto& c : candidates) tried.insert(c["alpha"].get<double>());
    EXPECT_TRUE(tried.count(in["alpha"].get<double>()));
    ASSERT_EQ(in["bsdf_alpha"].size(), 3u);
    // The synthetic sun: compensation pays for the diffuse lobe.
    EXPECT_GT(in["bsdf_alpha"]["lambert"].get<double>(), 0.0);
    // Each result row says which alpha its BSDF's compensated map used.
    ASSERT_EQ(j["results"].size(), 6u);
    for (const auto& row : j["results"]) {
        EXPECT_TRUE(tried.count(row["alpha"].get<double>()));
        EXPECT_EQ(row["alpha"], in["bsdf_alpha"][row["bsdf"].get<std::string>()]) << row;
    }

    const Result fixed = compare("--alpha 0.5 --techniques mis-balance,mis-balance-comp --json f.json");
    ASSERT_EQ(fixed.exit_code, 0) << fixed;
    EXPECT_EQ(json("f.json")["inputs"]["alpha_auto"], false);
    EXPECT_EQ(json("f.json")["inputs"]["alpha"], 0.5);
}

TEST_F(Sweep, AlphaSweepReportsEveryAlphaBsdfAndTechniqueWithExactRatios) {
    const Result r =
        compare("--alpha-sweep 0:1:0.5 --exact --techniques mis-balance,mis-balance-comp --json r.json --csv r.csv");
    ASSERT_EQ(r.exit_code, 0) << r;
    const nlohmann::json j = json("r.json");
    EXPECT_FALSE(j.contains("results")) << "a sweep replaces the normal table";
    const nlohmann::json& sweep = j["sweep"];
    ASSERT_EQ(sweep.size(), 3u * 3u * 2u);                  // alphas x BSDFs x techniques
    std::map<std::string, std::map<double, double>> exact;  // bsdf -> alpha -> exact ratio
    std::map<std::string, int> best;
    for (const auto& row : sweep) {
        if (row["technique"] != "mis-balance-comp") continue;
        const double ratio = row["exact_variance_ratio_vs_mis"].get<double>();
        EXPECT_TRUE(std::isfinite(ratio) && ratio > 0) << row;
        exact[row["bsdf"]][row["alpha"].get<double>()] = ratio;
        best[row["bsdf"]] += row["best"].get<bool>();
    }
    ASSERT_EQ(exact.size(), 3u);
    for (const auto& [bsdf, ratios] : exact) {
        ASSERT_EQ(ratios.size(), 3u) << bsdf;
        // alpha = 0 compensates nothing: the plain density, exactly.
        EXPECT_NEAR(ratios.at(0.0), 1.0, 1e-9) << bsdf;
        EXPECT_EQ(best[bsdf], 1) << bsdf;
    }
    for (const auto& s : j["sweep_best"]) {
        EXPECT_EQ(s["ratio_by"], "exact");
        const auto& ratios = exact[s["bsdf"].get<std::string>()];
        for (const auto& [alpha, ratio] : ratios) EXPECT_LE(s["best_ratio"].get<double>(), ratio) << s;
    }
    std::string header;
    EXPECT_EQ(csv_data_rows(read_file(file("r.csv")), &header), 18u);
    EXPECT_NE(header.find("exact_variance_ratio_vs_mis"), std::string::npos) << header;
    EXPECT_NE(r.out.find("best alpha"), std::string::npos) << r;
}

TEST_F(Sweep, AlphaSweepWithAutoSaysWhereAutoStands) {
    const Result r = compare("--alpha auto --alpha-sweep 0.5:1:0.5 --exact --bsdf lambert --json r.json");
    ASSERT_EQ(r.exit_code, 0) << r;
    const nlohmann::json j = json("r.json");
    std::set<double> alphas;
    std::set<std::string> techniques;
    for (const auto& row : j["sweep"]) alphas.insert(row["alpha"].get<double>()), techniques.insert(row["technique"]);
    // 0 and auto's choice are swept besides 0.5 and 1.
    EXPECT_TRUE(alphas.count(0.0));
    EXPECT_TRUE(alphas.count(j["inputs"]["bsdf_alpha"]["lambert"].get<double>()));
    // The default techniques: those that depend on alpha, and the baseline.
    for (const char* t : {"mis-balance", "mis-balance-comp", "mis-power-comp"}) EXPECT_TRUE(techniques.count(t)) << t;
    EXPECT_FALSE(techniques.count("bsdf"));
    ASSERT_EQ(j["sweep_best"].size(), 1u);
    const auto& s = j["sweep_best"][0];
    // The map is small enough to choose on as it is, at the same points: among the swept
    // alphas, all candidates or auto's own, auto's is the best.
    EXPECT_NEAR(s["auto_vs_best"].get<double>(), 1.0, 1e-12) << s;
    EXPECT_LE(s["auto_vs_alpha0"].get<double>(), 1.0) << s;
    EXPECT_NE(r.out.find("auto alpha"), std::string::npos) << r;
}

TEST_F(Sweep, AllocationSweepMarksTheMostEfficientSplit) {
    const Result r = compare("--allocation-sweep 4 --json r.json --csv r.csv");
    ASSERT_EQ(r.exit_code, 0) << r;
    const nlohmann::json j = json("r.json");
    const nlohmann::json& rows = j["allocation"];
    ASSERT_EQ(rows.size(), 3u * 3u * 2u);  // allocations x BSDFs x (mis-balance, mis-balance-comp)
    std::map<std::string, std::vector<nlohmann::json>> cases;
    for (const auto& row : rows) {
        EXPECT_EQ(row["env_samples"].get<int>() + row["bsdf_samples"].get<int>(), 4) << row;
        cases[row["bsdf"].get<std::string>() + " " + row["technique"].get<std::string>()].push_back(row);
    }
    ASSERT_EQ(cases.size(), 6u);
    for (const auto& [name, list] : cases) {
        ASSERT_EQ(list.size(), 3u) << name;
        std::set<int> env;
        double highest = 0;
        for (const auto& row : list)
            env.insert(row["env_samples"].get<int>()), highest = std::max(highest, row["efficiency"].get<double>());
        EXPECT_EQ(env, (std::set<int>{1, 2, 3})) << name;
        int marked = 0;
        for (const auto& row : list)
            if (row["best"].get<bool>()) {
                ++marked;
                EXPECT_EQ(row["efficiency"].get<double>(), highest) << name;
            }
        EXPECT_EQ(marked, 1) << name;
    }
    std::string header;
    EXPECT_EQ(csv_data_rows(read_file(file("r.csv")), &header), 18u);
    EXPECT_NE(r.out.find("best allocation"), std::string::npos) << r;
}

TEST_F(Sweep, ExactRatiosWithNoPointToCompareAreNoneRatherThanOne) {
    // Seen from below its surface a point reflects nothing: every variance is 0, and no
    // technique is as good as balance MIS there, nor worse.
    const Result r = compare_at(
        "--normal 0,0,1 --view 0,1,-0.2 --exact --techniques env,mis-balance --bsdf lambert "
        "--json below.json");
    ASSERT_EQ(r.exit_code, 0) << r;
    EXPECT_NE(r.out.find("env - (no point with a variance)"), std::string::npos) << r;
    EXPECT_TRUE(json("below.json")["exact"]["lambert"]["env"]["ratio"].is_null());
}

TEST_F(Sweep, AReferenceThatDidNotConvergeIsReported) {
    // A GGX lobe of roughness 0.001 is far sharper than this map's texels, subdivided 32
    // times; Lambert's cosine is not. compare's tolerance: 1e-3.
    const Result r = compare_at("--normal 0,0,1 --bsdf ggx:0.001,lambert --techniques mis-balance --json ref.json");
    ASSERT_EQ(r.exit_code, 0) << r;
    EXPECT_NE(r.out.find("warning: ggx:0.001: the quadrature reference did not converge"), std::string::npos) << r;
    EXPECT_EQ(r.out.find("warning: lambert"), std::string::npos) << r;
    const nlohmann::json j = json("ref.json");
    EXPECT_GT(j["reference_error"]["ggx:0.001"].get<double>(), 1e-3);
    EXPECT_LE(j["reference_error"]["lambert"].get<double>(), 1e-3);
}

TEST_F(Sweep, AllocationSweepSamplesTheBinsAskedFor) {
    // One bin (every normal alike) and 49: the same seeds, so the variances differ only
    // if each split samples the bins --bins built.
    std::vector<double> variances[2];
    for (int k = 0; k < 2; ++k) {
        const Result r =
            compare(std::string("--allocation-sweep 3 --techniques mis-balance-bins --bsdf lambert --bins ") +
                    (k ? "49" : "1") + " --json bins.json");
        ASSERT_EQ(r.exit_code, 0) << r;
        const nlohmann::json j = json("bins.json");
        for (const auto& row : j["allocation"]) variances[k].push_back(row["variance"].get<double>());
    }
    ASSERT_EQ(variances[0].size(), 2u);
    EXPECT_NE(variances[0], variances[1]);
}

TEST_F(Sweep, PlotsAreWrittenAsPngsOfTheDocumentedSize) {
    const Result normal = compare("--techniques env,mis-balance,mis-balance-comp --plots plots");
    ASSERT_EQ(normal.exit_code, 0) << normal;
    EXPECT_EQ(png_size(file("plots/variance_vs_balance.png")), std::make_pair(720u, 440u));

    const Result sweeps = compare("--alpha-sweep 0:1:1 --allocation-sweep 3 --plots more/plots");
    ASSERT_EQ(sweeps.exit_code, 0) << sweeps;
    EXPECT_EQ(png_size(file("more/plots/alpha_sweep.png")), std::make_pair(720u, 440u));
    EXPECT_EQ(png_size(file("more/plots/allocation.png")), std::make_pair(720u, 440u));
    EXPECT_NE(sweeps.out.find("alpha_sweep.png"), std::string::npos) << sweeps;
}

// The bins sample at each swept alpha, fixed for every bin: their variance moves with it.
TEST_F(Sweep, AlphaSweepSweepsTheBinsFixedAlphaToo) {
    const Result r = compare("--alpha-sweep 0:1:1 --bins 4 --techniques mis-balance-bins --json r.json");
    ASSERT_EQ(r.exit_code, 0) << r;
    const nlohmann::json j = json("r.json");
    std::map<double, double> lambert;  // alpha -> variance of mis-balance-bins
    for (const auto& row : j["sweep"])
        if (row["technique"] == "mis-balance-bins" && row["bsdf"] == "lambert")
            lambert[row["alpha"].get<double>()] = row["variance"].get<double>();
    ASSERT_EQ(lambert.size(), 2u) << r;
    EXPECT_NE(lambert[0], lambert[1]);
}

TEST_F(Sweep, MalformedSweepsFailWithOneLineNamingTheFlag) {
    for (const char* sweep :
         {"x", "0:1", "0:1:0", "0:1:-0.5", "1:0:0.5", "-1:1:0.5", "0:200:1", "0:1:0.5:2", "0:nan:1"}) {
        const Result r = compare(std::string("--alpha-sweep ") + sweep);
        EXPECT_NE(r.exit_code, 0) << sweep << r;
        EXPECT_EQ(r.out, "") << sweep << r;
        EXPECT_NE(r.err.find("--alpha-sweep"), std::string::npos) << sweep << r;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << sweep << r;
    }
    for (const char* args : {"--allocation-sweep 1", "--alpha often", "--allocation-sweep 4 --techniques bsdf"}) {
        const Result r = compare(args);
        EXPECT_NE(r.exit_code, 0) << args << r;
        EXPECT_FALSE(r.err.empty()) << args << r;
    }
}

}  // namespace
}  // namespace envmis
