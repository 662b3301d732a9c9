// Specification of `envmis compare` against an independent exact computation: the
// variances it reports for one shading point agree, within statistical error, with
// quadrature over the map (quadrature.h), which shares no code with the estimators'
// sampling.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_run.h"
#include "envmis/build/env_map.h"
#include "envmis/io/image_io.h"
#include "envmis/study/reference/quadrature.h"
#include "maps.h"

namespace envmis {
namespace {

namespace fs = std::filesystem;

TEST(Compare, SinglePointVariancesMatchTheExactVariances) {
    const fs::path dir = fs::temp_directory_path() / "envmis_compare_test";
    fs::remove_all(dir);
    fs::create_directories(dir);
    const RgbImage image = test::random_map(64, 32, 21, 2);
    io::write_exr(dir / "map.exr", image);
    const std::string command = std::string(ENVMIS_CLI) + " compare " + (dir / "map.exr").string() +
                                " --normal 0.2,-0.3,1 --view 0.6,0.1,1 --bsdf lambert,phong:20 --spp 200000 --threads 2"
                                " --techniques env,bsdf,mis-balance,mis-power,mis-balance-comp --json " +
                                (dir / "r.json").string() + " > " + (dir / "out.txt").string();
    ASSERT_EQ(std::system(command.c_str()), 0);
    const nlohmann::json results = nlohmann::json::parse(std::ifstream(dir / "r.json"));

    EnvMapOptions plain_options;
    plain_options.compensation.enabled = false;
    const EnvMap plain = build_env_map(image, plain_options), compensated = build_env_map(image);
    const ShadingPoint point{normalize(Vec3{0.2f, -0.3f, 1}), normalize(Vec3{0.6f, 0.1f, 1})};
    ASSERT_EQ(results["results"].size(), 10u);
    for (const auto& r : results["results"]) {
        const Technique t = Technique::parse(r["technique"].get<std::string>());
        const double exact = exact_variance(t.compensated ? compensated : plain, t, {},
                                            Bsdf::parse(r["bsdf"].get<std::string>()), point, 8);
        // 200000 estimates of a map spanning two decades: the sample variance is within a
        // few percent; 8% is several of its standard errors.
        EXPECT_NEAR(r["variance"].get<double>(), exact, 0.08 * exact) << r["bsdf"] << " " << r["technique"];
        EXPECT_NEAR(r["mean"].get<double>(), r["reference"].get<double>(), 4 * r["std_error"].get<double>())
            << r["bsdf"] << " " << r["technique"];
    }
    fs::remove_all(dir);
}

struct CliRun {
    int exit_code = -1;
    std::string out;  // stdout and stderr together
};

// `envmis compare map.exr ARGS` in `dir`, with stdout and stderr.
CliRun run_compare(const fs::path& dir, const std::string& args) {
    const std::string command =
        "cd '" + dir.string() + "' && '" + ENVMIS_CLI + "' compare map.exr " + args + " > out.txt 2>&1";
    const int status = std::system(command.c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : 128, test::read_file(dir / "out.txt")};
}

fs::path small_map_folder(const char* name) {
    const fs::path dir = fs::temp_directory_path() / (std::string(name) + "_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    io::write_exr(dir / "map.exr", test::random_map(32, 16, 5, 2));
    return dir;
}

// Every count, size and seed flag rejects a negative and an out-of-range value with one
// line naming the flag, before any work (CLI11 would otherwise read "-5" into an unsigned
// as 2^64 - 5).
TEST(Compare, CountAndSeedFlagsRejectNegativeAndOutOfRangeValues) {
    const fs::path dir = small_map_folder("envmis_compare_flags_test");
    const std::vector<std::pair<std::string, std::vector<std::string>>> cases = {
        {"--spp", {"-5", "0", "4294967296"}},        {"--points", {"-5", "0", "1000001"}},
        {"--threads", {"-1", "0", "1025"}},          {"--env-samples", {"-1", "65537"}},
        {"--bsdf-samples", {"-1", "65537"}},         {"--seed", {"-1", "18446744073709551616", "x"}},
        {"--allocation-sweep", {"-4", "1", "1025"}}, {"--image-spp", {"-1", "0", "65537"}},
        {"--reference-spp", {"-1", "0", "1048577"}},
    };
    for (const auto& [flag, values] : cases)
        for (const std::string& value : values) {
            const CliRun r = run_compare(dir, flag + " " + value + " --points 1 --spp 1");
            EXPECT_NE(r.exit_code, 0) << flag << " " << value << "\n" << r.out;
            EXPECT_NE(r.out.find(flag + ": Value " + value), std::string::npos) << flag << " " << value << "\n"
                                                                                << r.out;
            EXPECT_EQ(r.out.find("envmis compare:"), std::string::npos) << flag << " " << value << " started a run";
        }
    // The rendered image's size, checked as the flags are parsed, before any study.
    for (const std::string value : {"-4x5", "0x0", "15x16", "8193x16", "16", "abc"}) {
        const CliRun r = run_compare(dir, "--image " + value + " --points 1 --spp 1");
        EXPECT_NE(r.exit_code, 0) << value << "\n" << r.out;
        EXPECT_NE(r.out.find("--image: '" + value + "': expected WxH, each 16 to 8192"), std::string::npos)
            << value << "\n"
            << r.out;
        EXPECT_EQ(r.out.find("envmis compare:"), std::string::npos) << "--image " << value << " started a run";
    }
    // The limits themselves are accepted.
    const CliRun edge =
        run_compare(dir, "--seed 18446744073709551615 --threads 1 --points 1 --spp 1 --techniques bsdf");
    EXPECT_EQ(edge.exit_code, 0) << edge.out;
    EXPECT_NE(edge.out.find("seed 18446744073709551615"), std::string::npos) << edge.out;
    fs::remove_all(dir);
}

// The BSDFs' albedo is shown in the header line and in the JSON inputs, and --bsdf sets
// it; the estimator is linear in a Lambertian's albedo, so halving it halves every mean.
TEST(Compare, BsdfAlbedoIsShownAndSet) {
    const fs::path dir = small_map_folder("envmis_compare_albedo_test");
    const std::string common =
        "--points 3 --spp 64 --threads 2 --seed 7 --techniques env,bsdf,mis-balance,mis-balance-comp";
    const CliRun plain = run_compare(dir, common + " --json default.json");
    ASSERT_EQ(plain.exit_code, 0) << plain.out;
    EXPECT_NE(plain.out.find(", BSDF albedo lambert 0.8, phong:50 0.8, ggx:0.1 0.95/0.64/0.54\n"), std::string::npos)
        << plain.out;
    const nlohmann::json defaults = nlohmann::json::parse(std::ifstream(dir / "default.json"))["inputs"]["albedo"];
    EXPECT_EQ(defaults["lambert"], nlohmann::json({0.8, 0.8, 0.8}));
    EXPECT_EQ(defaults["phong:50"], nlohmann::json({0.8, 0.8, 0.8}));
    EXPECT_EQ(defaults["ggx:0.1"], nlohmann::json({0.95, 0.64, 0.54}));

    const CliRun dark = run_compare(dir, common + " --bsdf lambert:0.4 --json dark.json");
    const CliRun bright = run_compare(dir, common + " --bsdf lambert:0.8 --json bright.json");
    ASSERT_EQ(dark.exit_code, 0) << dark.out;
    ASSERT_EQ(bright.exit_code, 0) << bright.out;
    EXPECT_NE(dark.out.find(", BSDF albedo 0.4\n"), std::string::npos) << dark.out;
    EXPECT_NE(bright.out.find(", BSDF albedo 0.8\n"), std::string::npos) << bright.out;
    const nlohmann::json d = nlohmann::json::parse(std::ifstream(dir / "dark.json"));
    const nlohmann::json b = nlohmann::json::parse(std::ifstream(dir / "bright.json"));
    EXPECT_EQ(d["inputs"]["albedo"]["lambert:0.4"], nlohmann::json({0.4, 0.4, 0.4}));
    EXPECT_EQ(b["inputs"]["albedo"]["lambert"], nlohmann::json({0.8, 0.8, 0.8})) << "the default keeps its name";
    ASSERT_EQ(d["results"].size(), b["results"].size());
    ASSERT_EQ(d["results"].size(), 4u);
    for (size_t i = 0; i < d["results"].size(); ++i) {
        const nlohmann::json &x = d["results"][i], &y = b["results"][i];
        EXPECT_EQ(x["bsdf"], "lambert:0.4");
        EXPECT_EQ(x["technique"], y["technique"]);
        const double half = 0.5 * y["mean"].get<double>();
        EXPECT_NEAR(x["mean"].get<double>(), half, 1e-6 * half) << x["technique"];
        EXPECT_NEAR(x["variance_ratio_vs_mis"].get<double>(), y["variance_ratio_vs_mis"].get<double>(), 1e-6)
            << x["technique"];
    }
    for (const char* bad : {"lambert:-0.1", "lambert:1.5", "phong:50:2", "ggx:0.1:abc"}) {
        const CliRun r = run_compare(dir, std::string("--points 1 --spp 1 --bsdf ") + bad);
        EXPECT_NE(r.exit_code, 0) << bad;
        EXPECT_NE(r.out.find(bad), std::string::npos) << bad << "\n" << r.out;
    }
    fs::remove_all(dir);
}

// --bins takes a square number of normal bins; anything else fails with one line naming
// the flag, before any study.
TEST(Compare, BinsThatAreNotASquareNumberAreRefused) {
    const fs::path dir = small_map_folder("envmis_compare_bins_test");
    for (const std::string value : {"50", "2", "4097"}) {
        const CliRun r = run_compare(dir, "--bins " + value + " --points 1 --spp 1 --techniques mis-balance-bins");
        EXPECT_NE(r.exit_code, 0) << value << "\n" << r.out;
        EXPECT_NE(r.out.find("--bins: " + value + ": expected a square number"), std::string::npos) << r.out;
        EXPECT_EQ(r.out.find("envmis compare:"), std::string::npos) << "--bins " << value << " started a run";
    }
    fs::remove_all(dir);
}

// The -bins techniques run through the table, the JSON and --exact, whose ratio of
// mis-balance over itself is 1 and whose -bins ratio is a positive number, the geometric
// mean of the points' ratios, the worst of which is the worst point's.
TEST(Compare, BinsTechniquesAreReportedWithTheirExactRatios) {
    const fs::path dir = small_map_folder("envmis_compare_bins_run_test");
    const CliRun r = run_compare(dir,
                                 "--bins 16 --points 3 --spp 256 --bsdf lambert,ggx:0.1 --exact --json r.json "
                                 "--techniques mis-balance,mis-balance-bins,mis-power-bins,mis-optimal-bins");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    EXPECT_NE(r.out.find("16 normal bins (49 diffuse; alpha auto per bin)"), std::string::npos) << r.out;
    const nlohmann::json results = nlohmann::json::parse(std::ifstream(dir / "r.json"));
    EXPECT_EQ(results["results"].size(), 8u);
    for (const char* bsdf : {"lambert", "ggx:0.1"}) {
        EXPECT_DOUBLE_EQ(results["exact"][bsdf]["mis-balance"]["ratio"].get<double>(), 1.0);
        const nlohmann::json& bins = results["exact"][bsdf]["mis-balance-bins"];
        EXPECT_GT(bins["ratio"].get<double>(), 0.0);
        const auto points = bins["points"].get<std::vector<double>>();
        ASSERT_EQ(points.size(), 3u);
        double log_sum = 0;
        for (double v : points) log_sum += std::log(v);
        EXPECT_NEAR(std::exp(log_sum / 3), bins["ratio"].get<double>(), 1e-9 * bins["ratio"].get<double>());
        EXPECT_DOUBLE_EQ(*std::max_element(points.begin(), points.end()), bins["worst"].get<double>());
        EXPECT_FALSE(results["exact"][bsdf].contains("mis-optimal-bins")) << "optimal MIS has no exact variance";
    }
    fs::remove_all(dir);
}

// The table's columns tell one story: per-point ratios to mis-balance first (their
// geometric mean, the worst point, the same at equal time), each defined in --help; the
// lines under it compare the normal-aware and the global table against mis-balance.
TEST(Compare, TheHeadlineColumnsArePerPointRatiosToMisBalanceAndHelpDefinesEveryColumn) {
    const fs::path dir = small_map_folder("envmis_compare_columns_test");
    const CliRun r = run_compare(dir,
                                 "--bins 16 --points 5 --spp 256 --bsdf lambert,phong:20 --json r.json "
                                 "--techniques mis-balance,mis-balance-comp,mis-balance-bins");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    const size_t begin = r.out.find("\nbsdf ") + 1;
    const std::string header = r.out.substr(begin, r.out.find('\n', begin) - begin);
    const CliRun help = run_compare(dir, "--help");
    std::istringstream headings(header);
    std::vector<std::string> columns(std::istream_iterator<std::string>(headings), {});
    ASSERT_EQ(columns.size(), 10u) << header;
    EXPECT_EQ(columns[2], "var/mis");
    for (size_t i = 2; i < columns.size(); ++i)
        EXPECT_NE(help.out.find("\n  " + columns[i] + " "), std::string::npos) << columns[i] << " undefined in --help";

    const nlohmann::json results = nlohmann::json::parse(std::ifstream(dir / "r.json"))["results"];
    for (size_t b = 0; b < 2; ++b) {
        const nlohmann::json& mis = results[3 * b];
        ASSERT_EQ(mis["technique"], "mis-balance");
        EXPECT_EQ(mis["variance_ratio_worst"].get<double>(), 1.0);
        EXPECT_EQ(mis["efficiency_ratio_vs_mis"].get<double>(), 1.0);
        for (size_t t = 1; t < 3; ++t) {
            const nlohmann::json& s = results[3 * b + t];
            const auto v = s["point_variances"].get<std::vector<double>>();
            const auto v_mis = mis["point_variances"].get<std::vector<double>>();
            double worst = 0, log_sum = 0;
            for (size_t p = 0; p < v.size(); ++p)
                worst = std::max(worst, v[p] / v_mis[p]), log_sum += std::log(v[p] / v_mis[p]);
            const double ratio = s["variance_ratio_vs_mis"];
            EXPECT_NEAR(ratio, std::exp(log_sum / v.size()), 1e-9 * ratio);
            EXPECT_NEAR(s["variance_ratio_worst"].get<double>(), worst, 1e-9 * worst);
            const double equal_time =
                mis["ns_per_estimate"].get<double>() / (ratio * s["ns_per_estimate"].get<double>());
            EXPECT_NEAR(s["efficiency_ratio_vs_mis"].get<double>(), equal_time, 1e-9 * equal_time);
        }
    }
    EXPECT_NE(r.out.find("lambert: against mis-balance, the normal-aware table (mis-balance-bins) "), std::string::npos)
        << r.out;
    EXPECT_NE(r.out.find("; the global compensated table (mis-balance-comp) "), std::string::npos) << r.out;
    fs::remove_all(dir);
}

// The montage is a grid read through its layout (montage.json): each technique's column
// holds, for every BSDF, the sphere of that technique's own render and, directly under it,
// the sphere of that technique's own error map, pixel for pixel as in their PNGs.
TEST(Compare, TheMontagesErrorMapsLieUnderTheRendersOfTheirOwnTechnique) {
    const fs::path dir = small_map_folder("envmis_compare_montage_test");
    const CliRun r = run_compare(dir,
                                 "--points 1 --spp 4 --bsdf lambert,phong:20 --techniques env,bsdf,mis-balance "
                                 "--images out --image 64x32 --image-spp 2 --reference-spp 8");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    const nlohmann::json layout = nlohmann::json::parse(std::ifstream(dir / "out/montage.json"));
    const RgbImage montage = io::load_image(dir / "out/montage.png").image;
    const auto picture = [&](const std::string& name) { return io::load_image(dir / "out" / name).image; };
    const std::vector<std::string> bsdfs{"lambert", "phong:20"};
    EXPECT_EQ(layout["bsdfs"].get<std::vector<std::string>>(), bsdfs);
    EXPECT_EQ(layout["columns"].size(), 4u);
    // The cell at `rect` shows sphere b (32 pixels wide) of `source` exactly.
    const auto shows = [&](const nlohmann::json& rect, const RgbImage& source, int b) {
        const int x0 = rect[0], y0 = rect[1], w = rect[2], h = rect[3];
        if (w != 32 || h != 32) return false;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                if (const Rgb m = montage.at(x0 + x, y0 + y), p = source.at(32 * b + x, y);
                    m.r != p.r || m.g != p.g || m.b != p.b)
                    return false;
        return true;
    };
    size_t checked = 0;
    for (const nlohmann::json& cell : layout["cells"]) {
        const std::string column = cell["column"];
        const int b = cell["bsdf"] == "lambert" ? 0 : 1;
        if (column.starts_with("reference")) {
            EXPECT_TRUE(shows(cell["render"], picture("reference.png"), b)) << cell;
            continue;
        }
        EXPECT_TRUE(shows(cell["render"], picture(column + ".png"), b)) << cell;
        EXPECT_TRUE(shows(cell["error"], picture(column + "-relmse.png"), b)) << cell;
        EXPECT_EQ(cell["error"][0], cell["render"][0]) << cell;
        EXPECT_GT(cell["error"][1].get<int>(), cell["render"][1].get<int>() + 32) << cell;
        EXPECT_GE(cell["relmse"].get<double>(), 0.0);
        ++checked;
    }
    EXPECT_EQ(checked, 3u * bsdfs.size());
    fs::remove_all(dir);
}

// The README's montage (docs/images/montage.png, made by scripts/readme_pictures.sh) is
// stale when the comparison it shows has other techniques or BSDFs than a default run has
// now, or when the montage's layout has changed: its montage.json, written beside it by
// the same run, is compared with a default run's here.
TEST(Compare, TheReadmesMontageShowsTheDefaultTechniquesInTheCurrentLayout) {
    const fs::path dir = small_map_folder("envmis_compare_readme_montage_test");
    const CliRun r = run_compare(dir, "--points 1 --spp 1 --images out --image 48x16 --image-spp 1 --reference-spp 1");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    const fs::path docs = fs::path(ENVMIS_DATA_DIR) / ".." / "docs" / "images";
    const nlohmann::json now = nlohmann::json::parse(std::ifstream(dir / "out/montage.json"));
    const nlohmann::json shown = nlohmann::json::parse(std::ifstream(docs / "montage.json"), nullptr, false);
    const std::string remedy = "docs/images/montage.png is stale: run bash scripts/readme_pictures.sh";
    ASSERT_FALSE(shown.is_discarded()) << remedy;
    EXPECT_EQ(shown["bsdfs"], now["bsdfs"]) << remedy;
    EXPECT_EQ(shown["columns"].size(), now["columns"].size()) << remedy;
    for (size_t c = 1; c < now["columns"].size() && c < shown["columns"].size(); ++c)
        EXPECT_EQ(shown["columns"][c], now["columns"][c]) << remedy;
    ASSERT_EQ(shown["cells"].size(), now["cells"].size()) << remedy;
    for (size_t i = 0; i < now["cells"].size(); ++i) {
        std::vector<std::string> keys_now, keys_shown;
        for (const auto& [key, value] : now["cells"][i].items()) keys_now.push_back(key);
        for (const auto& [key, value] : shown["cells"][i].items()) keys_shown.push_back(key);
        EXPECT_EQ(keys_shown, keys_now) << remedy;
    }
    const io::ImageSize size = io::read_image_size(docs / "montage.png");
    EXPECT_EQ(shown["size"], nlohmann::json({size.width, size.height})) << "montage.json is not montage.png's";
    fs::remove_all(dir);
}

}  // namespace
}  // namespace envmis
