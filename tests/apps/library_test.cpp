// Specification of library mode: `envmis precompute` and `envmis compare` over several
// maps or a folder, in parallel (--jobs), with up-to-date outputs skipped and one summary.
// The maps are the three bundled ones made 32x16 (envmis convert), once per ctest run.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "cli_run.h"

namespace {

namespace fs = std::filesystem;
using envmis::test::expect_one_line_error;
using envmis::test::read_file;
using envmis::test::Result;
using envmis::test::write_text;
using json = nlohmann::json;

const fs::path kBundled = fs::path(ENVMIS_DATA_DIR) / "envmaps";
const std::vector<std::string> kStems = {"city", "rooitou_park_1k", "studio"};

class Library : public envmis::test::TempFolder {
public:
    Library() : TempFolder("envmis_library_test_") {}

    // The small maps: under ctest, made once per run by the fixture library_test.maps
    // (tests/apps/library_maps.cmake; each test runs in a process of its own); otherwise
    // made here, once for all the tests of this process.
    static void SetUpTestSuite() {
#ifdef ENVMIS_LIBRARY_MAPS
        const fs::path shared = ENVMIS_LIBRARY_MAPS;
        if (std::all_of(kStems.begin(), kStems.end(),
                        [&](const std::string& stem) { return fs::is_regular_file(shared / (stem + ".exr")); })) {
            small_ = shared;
            return;
        }
#endif
        owned_ = true;
        small_ = fs::temp_directory_path() / ("envmis_library_maps_" + std::to_string(::getpid()));
        fs::create_directories(small_);
        for (const char* name : {"city.exr", "rooitou_park_1k.hdr", "studio.exr"}) {
            const fs::path out = small_ / (fs::path(name).stem().string() + ".exr");
            const Result r = envmis::test::run_envmis(
                small_,
                {"convert", (kBundled / name).string(), "-o", out.string(), "--to", "equirect", "--size", "32x16"},
                small_ / "..stdout", small_ / "..stderr");
            ASSERT_EQ(r.exit_code, 0) << r;
        }
    }
    static void TearDownTestSuite() {
        std::error_code ignored;
        if (owned_) fs::remove_all(small_, ignored);
    }

    Result envmis(const std::vector<std::string>& args) const {
        return envmis::test::run_envmis(dir_, args, dir_ / "..stdout", dir_ / "..stderr");
    }

    // maps/ with the three small maps (and, with `corrupt`, maps/broken.hdr: not an image).
    void make_maps(bool corrupt) const {
        fs::create_directories(file("maps"));
        for (const std::string& stem : kStems) fs::copy_file(small_ / (stem + ".exr"), file("maps/" + stem + ".exr"));
        if (corrupt) write_text(file("maps/broken.hdr"), "#?RADIANCE\nnot an image\n");
    }

    json summary(const std::string& path) const { return json::parse(read_file(file(path))); }

    // Each map's status in a summary, by input path.
    std::map<std::string, std::string> statuses(const std::string& path) const {
        const json s = summary(path);
        std::map<std::string, std::string> result;
        for (const json& entry : s["results"]) result[entry["input"]] = entry["status"];
        return result;
    }

    // Expects every one of the three maps to have `status` in the summary at `path`.
    void expect_all(const std::string& path, const std::string& status) const {
        std::map<std::string, std::string> expected;
        for (const std::string& stem : kStems) expected["maps/" + stem + ".exr"] = status;
        EXPECT_EQ(statuses(path), expected);
    }

    static inline fs::path small_;
    static inline bool owned_ = false;  // small_ was made here (and is removed here)
};

const std::vector<std::string> kStudy = {"--spp",  "16",      "--points",     "2",
                                         "--bsdf", "lambert", "--techniques", "mis-balance,mis-balance-comp"};

std::vector<std::string> with(std::vector<std::string> args, const std::vector<std::string>& more) {
    args.insert(args.end(), more.begin(), more.end());
    return args;
}

TEST_F(Library, AFolderWithACorruptMapPrecomputesTheOthersAndReportsIt) {
    make_maps(true);
    const Result r = envmis({"precompute", "maps", "-o", "tables", "--jobs", "2"});
    EXPECT_EQ(r.exit_code, 1) << r;
    EXPECT_NE(r.err.find("envmis: maps/broken.hdr: "), std::string::npos) << r;
    EXPECT_NE(r.err.find("1 of 4 maps failed"), std::string::npos) << r;
    const json s = summary("tables/summary.json");
    EXPECT_EQ(s["maps"], 4);
    for (const json& entry : s["results"]) {
        const std::string input = entry["input"];
        if (input == "maps/broken.hdr") {
            EXPECT_EQ(entry["status"], "failed");
            EXPECT_NE(entry["error"].get<std::string>().find("maps/broken.hdr"), std::string::npos);
            EXPECT_FALSE(fs::exists(file("tables/broken.envmis")));
            continue;
        }
        EXPECT_EQ(entry["status"], "written") << input;
        EXPECT_EQ(entry["source_hash"].get<std::string>().size(), 16u);
        EXPECT_EQ(entry["details"]["width"], 32);
        const Result info = envmis({"info", entry["output"]});
        EXPECT_EQ(info.exit_code, 0) << info;
        EXPECT_NE(info.out.find(entry["source_hash"].get<std::string>()), std::string::npos) << info;
    }
    // One block of output per map, whole.
    for (const std::string& stem : kStems)
        EXPECT_NE(r.out.find("envmis precompute: maps/" + stem + ".exr -> tables/" + stem + ".envmis\n  source"),
                  std::string::npos)
            << r;
}

TEST_F(Library, ASecondRunSkipsEveryUpToDateTableAndLeavesItUntouched) {
    make_maps(false);
    ASSERT_EQ(envmis({"precompute", "maps", "-o", "tables", "--alpha", "auto"}).exit_code, 0);
    std::map<std::string, fs::file_time_type> written;
    for (const std::string& stem : kStems) written[stem] = fs::last_write_time(file("tables/" + stem + ".envmis"));
    const Result again = envmis({"precompute", "maps", "-o", "tables", "--alpha", "auto"});
    EXPECT_EQ(again.exit_code, 0) << again;
    expect_all("tables/summary.json", "up-to-date");
    for (const std::string& stem : kStems)
        EXPECT_EQ(fs::last_write_time(file("tables/" + stem + ".envmis")), written[stem]) << stem;
    const Result forced = envmis({"precompute", "maps", "-o", "tables", "--alpha", "auto", "--force"});
    expect_all("tables/summary.json", "written");
}

TEST_F(Library, ChangingAnOptionOrASourcesBytesRebuildsWhatChangedOnly) {
    make_maps(false);
    ASSERT_EQ(envmis({"precompute", "maps", "-o", "tables"}).exit_code, 0);
    // --alpha 1 is the default: the same table.
    envmis({"precompute", "maps", "-o", "tables", "--alpha", "1"});
    expect_all("tables/summary.json", "up-to-date");
    envmis({"precompute", "maps", "-o", "tables", "--alpha", "0.5"});
    expect_all("tables/summary.json", "written");
    envmis({"precompute", "maps", "-o", "tables", "--alpha", "auto"});
    expect_all("tables/summary.json", "written");
    fs::copy_file(file("maps/city.exr"), file("maps/studio.exr"), fs::copy_options::overwrite_existing);
    const Result r = envmis({"precompute", "maps", "-o", "tables", "--alpha", "auto"});
    EXPECT_EQ(r.exit_code, 0) << r;
    const std::map<std::string, std::string> expected = {
        {"maps/city.exr", "up-to-date"}, {"maps/rooitou_park_1k.exr", "up-to-date"}, {"maps/studio.exr", "written"}};
    EXPECT_EQ(statuses("tables/summary.json"), expected);
}

// A map that had a table and now fails (here: its bytes are no longer an image) leaves no
// table that looks valid beside the failure: the old one is removed, and the run says so.
TEST_F(Library, AMapThatNowFailsLosesItsEarlierTableAndTheRunSaysSo) {
    make_maps(false);
    ASSERT_EQ(envmis({"precompute", "maps", "-o", "tables"}).exit_code, 0);
    ASSERT_TRUE(fs::exists(file("tables/studio.envmis")));
    write_text(file("maps/studio.exr"), "not an image any more");
    const Result r = envmis({"precompute", "maps", "-o", "tables"});
    EXPECT_EQ(r.exit_code, 1) << r;
    EXPECT_NE(r.err.find("its earlier output tables/studio.envmis was removed"), std::string::npos) << r;
    EXPECT_FALSE(fs::exists(file("tables/studio.envmis")));
    EXPECT_TRUE(fs::exists(file("tables/city.envmis")));
    const json after = summary("tables/summary.json");
    for (const json& entry : after["results"])
        EXPECT_EQ(entry.value("removed_output", false), entry["input"] == "maps/studio.exr") << entry;
}

// A run that fails for a reason of its own (here a full disk while rewriting with --force)
// keeps the earlier tables, which still match their inputs.
TEST_F(Library, AFailureThatIsNotTheInputsKeepsTheTablesThatStillMatch) {
    make_maps(false);
    ASSERT_EQ(envmis({"precompute", "maps", "-o", "tables"}).exit_code, 0);
    const Result r =
        envmis::test::run_shell("cd " + envmis::test::quoted(dir_.string()) + " && ulimit -f 8 && " +
                                    envmis::test::quoted(ENVMIS_CLI) + " precompute maps -o tables --force --jobs 1",
                                dir_ / "..stdout", dir_ / "..stderr");
    EXPECT_NE(r.exit_code, 0) << r;
    EXPECT_EQ(r.err.find("was removed"), std::string::npos) << r;
    for (const std::string& stem : kStems) EXPECT_TRUE(fs::exists(file("tables/" + stem + ".envmis"))) << stem << r;
}

TEST_F(Library, TwoInputsWithTheSameStemAreRefusedBeforeAnyWork) {
    make_maps(false);
    fs::create_directories(file("other"));
    fs::copy_file(file("maps/city.exr"), file("other/city.exr"));
    const Result r = envmis({"precompute", "maps", "other/city.exr", "-o", "tables"});
    expect_one_line_error(r, "other/city.exr", "maps/city.exr and other/city.exr: both would write tables/city");
    EXPECT_FALSE(fs::exists(file("tables")));
}

TEST_F(Library, JobsOutsideOneTo1024AreRefused) {
    make_maps(false);
    for (const char* jobs : {"0", "1025", "-1", "many"}) {
        const Result r = envmis({"precompute", "maps", "-o", "tables", "--jobs", jobs});
        expect_one_line_error(r, "--jobs", "not in range 1 to 1024");
        EXPECT_FALSE(fs::exists(file("tables"))) << jobs;
    }
}

// "input_bytes" is the input file's size; the options name the bins built, 121 where a
// -bins technique runs without --bins.
TEST_F(Library, TheSummaryGivesEachInputsSizeAndTheOptionsTheBinsBuilt) {
    make_maps(false);
    const Result r = envmis({"compare", "maps", "--out-dir", "out", "--spp", "16", "--points", "2", "--bsdf", "lambert",
                             "--techniques", "mis-balance,mis-balance-bins"});
    ASSERT_EQ(r.exit_code, 0) << r;
    for (const json& entry : summary("out/summary.json")["results"])
        EXPECT_EQ(entry["input_bytes"].get<uintmax_t>(), fs::file_size(file(entry["input"].get<std::string>())));
    for (const std::string& stem : kStems) {
        const std::string options = json::parse(read_file(file("out/" + stem + ".json")))["inputs"]["options"];
        EXPECT_NE(options.find(" bins=121 "), std::string::npos) << options;
    }
}

TEST_F(Library, CompareWritesEachMapsJsonAndASummaryAndSkipsThemOnTheSecondRun) {
    make_maps(false);
    const Result r = envmis(with({"compare", "maps", "--out-dir", "out", "--jobs", "2"}, kStudy));
    ASSERT_EQ(r.exit_code, 0) << r;
    for (const std::string& stem : kStems) {
        const json run = json::parse(read_file(file("out/" + stem + ".json")));
        EXPECT_EQ(run["inputs"]["map"], stem + ".exr");
        EXPECT_EQ(run["inputs"]["source_hash"].get<std::string>().size(), 16u);
        EXPECT_NE(run["inputs"]["options"].get<std::string>().find("spp=16"), std::string::npos);
        EXPECT_FALSE(run["results"].empty());
    }
    expect_all("out/summary.json", "written");
    // The tables print whole, one map after the other (in the order they finish): each
    // header line is followed by its own table's.
    for (const std::string& stem : kStems)
        EXPECT_TRUE(envmis::test::contains(r.out, "(^|\n)envmis compare: " + stem + "\\.exr [^\n]*\nbsdf +technique"))
            << stem << r;
    const Result again = envmis(with({"compare", "maps", "--out-dir", "out"}, kStudy));
    EXPECT_EQ(again.exit_code, 0) << again;
    expect_all("out/summary.json", "up-to-date");
    envmis(with({"compare", "maps", "--out-dir", "out", "--seed", "2"}, kStudy));
    expect_all("out/summary.json", "written");
    // The bins' options are the results' too.
    envmis(with({"compare", "maps", "--out-dir", "out", "--seed", "2", "--cell-columns", "2"}, kStudy));
    expect_all("out/summary.json", "written");
    envmis(
        with({"compare", "maps", "--out-dir", "out", "--seed", "2", "--cell-columns", "2", "--bin-cost", "2"}, kStudy));
    expect_all("out/summary.json", "written");
    // report takes out/*.json: the summary is skipped with a note.
    const Result report = envmis({"report", "out/city.json", "out/studio.json", "out/summary.json", "-o", "r.md"});
    EXPECT_EQ(report.exit_code, 0) << report;
    EXPECT_NE(report.err.find("out/summary.json: the summary of a library run"), std::string::npos) << report;
    EXPECT_NE(report.out.find("(2 runs)"), std::string::npos) << report;
}

TEST_F(Library, CompareOverTablesKeysEachResultOnItsTableSoASecondRunSkipsThemAndARebuildRunsAgain) {
    make_maps(false);
    ASSERT_EQ(envmis({"precompute", "maps", "-o", "tables"}).exit_code, 0);
    const auto expect_tables = [&](const std::string& status) {
        std::map<std::string, std::string> expected;
        for (const std::string& stem : kStems) expected["tables/" + stem + ".envmis"] = status;
        EXPECT_EQ(statuses("out/summary.json"), expected);
    };
    const Result r = envmis(with({"compare", "tables", "--out-dir", "out", "--jobs", "2"}, kStudy));
    ASSERT_EQ(r.exit_code, 0) << r;
    expect_tables("written");
    // The per-map JSON and the summary name the same hash: the table file's, not its image's.
    const json written = summary("out/summary.json");
    ASSERT_EQ(written["results"].size(), kStems.size());
    for (const json& entry : written["results"]) {
        const json run = json::parse(read_file(file(entry["output"])));
        EXPECT_EQ(run["inputs"]["source_hash"], entry["source_hash"]) << entry;
    }
    envmis(with({"compare", "tables", "--out-dir", "out"}, kStudy));
    expect_tables("up-to-date");
    // The same images built with another alpha: other tables, studied again.
    ASSERT_EQ(envmis({"precompute", "maps", "-o", "tables", "--alpha", "0.5"}).exit_code, 0);
    envmis(with({"compare", "tables", "--out-dir", "out"}, kStudy));
    expect_tables("written");
}

TEST_F(Library, ACsvFolderThatCannotBeMadeStopsTheRunBeforeAnyMap) {
    make_maps(false);
    write_text(file("csv"), "a file where the folder should be\n");
    expect_one_line_error(envmis(with({"compare", "maps", "--out-dir", "out", "--csv", "csv"}, kStudy)), "--csv csv",
                          "cannot make the folder");
    EXPECT_FALSE(fs::exists(file("out/summary.json")));
    for (const std::string& stem : kStems) EXPECT_FALSE(fs::exists(file("out/" + stem + ".json"))) << stem;
}

TEST_F(Library, SeveralInputsWithoutAnOutputFolderAreRefused) {
    make_maps(false);
    expect_one_line_error(envmis(with({"compare", "maps/city.exr", "maps/studio.exr"}, kStudy)), "--out-dir",
                          "required with several inputs");
}

}  // namespace
