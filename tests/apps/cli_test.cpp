// Specification of the `envmis` command as a user sees it: exit codes, what it prints,
// the files it writes and leaves behind. Every test runs the real binary (ENVMIS_CLI)
// in a temporary folder of its own; input files are made here, with OpenImageIO or by
// hand.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "cli_run.h"
#include "envmis/cpu.h"

extern char** environ;

namespace {

namespace fs = std::filesystem;
using envmis::test::contains;
using envmis::test::expect_one_line_error;
using envmis::test::read_file;
using envmis::test::Result;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

const fs::path kBundled = fs::path(ENVMIS_DATA_DIR) / "envmaps";

// ---------------------------------------------------------------------------------
// Helpers: running the command, reading what it wrote, making input files.

void write_file(const fs::path& path, const std::string& bytes) {
    std::ofstream out(path, std::ios::binary);
    out << bytes;
    if (!out) throw std::runtime_error("test setup: cannot write " + path.string());
}

// The rows of a CSV file after its header.
std::vector<std::vector<double>> csv_rows(const std::string& text, std::string* header) {
    std::istringstream in(text);
    std::string line;
    std::getline(in, *header);
    std::vector<std::vector<double>> rows;
    while (std::getline(in, line)) {
        std::vector<double> row;
        std::istringstream fields(line);
        for (std::string field; std::getline(fields, field, ',');) row.push_back(std::strtod(field.c_str(), nullptr));
        rows.push_back(row);
    }
    return rows;
}

// Float RGB pixels, row-major from the top; written as a 32-bit float EXR.
struct Pixels {
    int w = 0, h = 0;
    std::vector<float> rgb;
};

Pixels constant(int w, int h, float r, float g, float b) {
    Pixels p{w, h, {}};
    for (int i = 0; i < w * h; ++i) p.rgb.insert(p.rgb.end(), {r, g, b});
    return p;
}

void write_exr(const fs::path& path, const Pixels& p) {
    OIIO::ImageSpec spec(p.w, p.h, 3, OIIO::TypeDesc::FLOAT);
    auto out = OIIO::ImageOutput::create("openexr");
    if (!out || !out->open(path.string(), spec) || !out->write_image(OIIO::TypeDesc::FLOAT, p.rgb.data()) ||
        !out->close())
        throw std::runtime_error("test setup: cannot write " + path.string());
}

// Each test works in a folder of its own, removed afterwards.
class Cli : public envmis::test::TempFolder {
public:
    Cli() : TempFolder("envmis_cli_test_") {}

    // Runs envmis with `args` (each passed as one argument) in the test's folder.
    Result envmis(const std::vector<std::string>& args) const {
        return envmis::test::run_envmis(dir_, args, dir_ / "..stdout", dir_ / "..stderr");
    }

    // The names in the test's folder (hidden ones included).
    std::set<std::string> listing() const {
        std::set<std::string> names;
        for (const auto& e : fs::directory_iterator(dir_)) names.insert(e.path().filename().string());
        return names;
    }

    // A small table, quick to write and read, for the tests that damage one.
    fs::path small_table(const std::string& name) const {
        write_exr(file("small.exr"), gradient(16, 8));
        const Result r = envmis({"precompute", "small.exr", "-o", name});
        if (r.exit_code != 0) throw std::runtime_error("test setup: precompute failed");
        fs::remove(file("small.exr"));
        return file(name);
    }

    // A valid small table, changed by `damage`, written to `path`.
    void damaged_table(const fs::path& path, const std::function<void(std::string&)>& damage) const {
        std::string bytes = read_file(small_table("good.envmis"));
        fs::remove(file("good.envmis"));
        damage(bytes);
        write_file(path, bytes);
    }

    static Pixels gradient(int w, int h) {
        Pixels p{w, h, {}};
        for (int i = 0; i < w * h; ++i) p.rgb.insert(p.rgb.end(), {0.1f + i % 7, 0.2f + i % 5, 0.3f + i % 3});
        return p;
    }
};

// ---------------------------------------------------------------------------------
// Help.

struct HelpCase {
    std::string subcommand;
    std::vector<std::string> options;
};

// Parameters print as their names (in test listings and CTest names).
void PrintTo(const HelpCase& c, std::ostream* os) { *os << c.subcommand; }

class CliHelp : public Cli, public testing::WithParamInterface<HelpCase> {};

TEST_P(CliHelp, PrintsUsageAndEveryOptionAndExitsZero) {
    const HelpCase& c = GetParam();
    const Result r = envmis({c.subcommand, "--help"});
    EXPECT_EQ(r.exit_code, 0) << r;
    EXPECT_TRUE(contains(r.out, "usage:.*" + c.subcommand)) << r;
    for (const std::string& option : c.options) EXPECT_NE(r.out.find(option), std::string::npos) << option << r;
}

const std::vector<std::string> kMapFlags = {"--no-compensate", "--alpha", "--colorspace", "--working-space", "--axes"};

std::vector<std::string> with_map_flags(std::vector<std::string> options) {
    options.insert(options.end(), kMapFlags.begin(), kMapFlags.end());
    return options;
}

INSTANTIATE_TEST_SUITE_P(
    Subcommands, CliHelp,
    testing::Values(
        HelpCase{"precompute", with_map_flags({"input", "-o,--output", "--bins", "--cell-columns", "--bin-cost"})},
        HelpCase{"info", with_map_flags({"input"})},
        HelpCase{"sample",
                 with_map_flags({"input", "-n,--count", "--seed", "-o,--output", "--normal", "--view", "--lobe"})},
        HelpCase{"visualize",
                 with_map_flags({"input", "-o,--output", "--panel-width", "--normal", "--bins", "--lobe"})},
        HelpCase{"bench", {"input", "--size", "--repeats", "--samples", "--no-compensate", "--bins", "--json"}}),
    [](const testing::TestParamInfo<HelpCase>& info) { return info.param.subcommand; });

TEST_F(Cli, TopLevelHelpListsEverySubcommand) {
    const Result r = envmis({"--help"});
    EXPECT_EQ(r.exit_code, 0) << r;
    for (const char* s : {"precompute", "info", "sample", "visualize", "bench"})
        EXPECT_TRUE(contains(r.out, s)) << s << r;
}

TEST_F(Cli, UsageErrorsExitNonZeroWithAMessage) {
    for (const Result& r :
         {envmis({}), envmis({"frobnicate"}), envmis({"sample"}), envmis({"sample", "x.exr", "-n", "many"})}) {
        EXPECT_NE(r.exit_code, 0) << r;
        EXPECT_FALSE(r.err.empty()) << r;
    }
}

// ---------------------------------------------------------------------------------
// Success paths, on a bundled map (studio.exr: 1024 x 512, 3 negative channel values).

// The summary that precompute and info print, for studio.exr.
void expect_studio_summary(const Result& r) {
    for (const char* line :
         {R"(size +1024 x 512\n)", R"(dynamic range [0-9.e+]+ \([0-9.]+ decades\))",
          R"(mean \(Lbar\) +[0-9.e+-]+ \(solid-angle weighted\))",
          R"(compensation +alpha 1, threshold [0-9.e+-]+, zeroed [0-9]+ texels .*\([0-9.]+%\))",
          R"(bad pixels +0 NaN, 0 Inf, 3 negative)", R"(fallback +none)", R"(time +load [0-9.]+ ms.*build [0-9.]+ ms)"})
        EXPECT_TRUE(contains(r.out, line)) << "missing /" << line << "/" << r;
}

TEST_F(Cli, PrecomputeWritesATableAndPrintsTheSummary) {
    const Result r = envmis({"precompute", (kBundled / "studio.exr").string(), "-o", "studio.envmis"});
    ASSERT_EQ(r.exit_code, 0) << r;
    EXPECT_EQ(r.err, "") << r;
    expect_studio_summary(r);
    EXPECT_TRUE(contains(r.out, R"(write [0-9.]+ ms)")) << r;
    EXPECT_EQ(read_file(file("studio.envmis")).substr(1, 7), "ENVMIS\x1a");
}

// convert makes a square equal-area map with the same power; precompute samples it as
// such when told, and says so; converting back gives the latitude-longitude size.
TEST_F(Cli, ConvertToEqualAreaAndBack) {
    const Result to = envmis(
        {"convert", (kBundled / "studio.exr").string(), "-o", "square.exr", "--to", "equal-area", "--size", "128"});
    ASSERT_EQ(to.exit_code, 0) << to;
    EXPECT_TRUE(contains(to.out, R"(\(1024x512 equirect\) -> square.exr \(128x128 equal-area\))")) << to;
    const Result table = envmis({"precompute", "square.exr", "-o", "square.envmis", "--mapping", "equal-area"});
    ASSERT_EQ(table.exit_code, 0) << table;
    EXPECT_TRUE(contains(table.out, R"(mapping +equal-area)")) << table;
    const Result info = envmis({"info", "square.envmis"});
    EXPECT_TRUE(contains(info.out, R"(mapping +equal-area)")) << info;
    const Result square_as_equirect = envmis({"info", "square.exr"});
    EXPECT_TRUE(contains(square_as_equirect.err, "is square; it is read as equirect")) << square_as_equirect;
    const Result back =
        envmis({"convert", "square.exr", "-o", "back.exr", "--from", "equal-area", "--to", "equirect", "--size", "64"});
    ASSERT_EQ(back.exit_code, 0) << back;
    EXPECT_TRUE(contains(back.out, R"(-> back.exr \(128x64 equirect\))")) << back;
    expect_one_line_error(envmis({"convert", "missing.exr", "-o", "x.exr"}), "missing.exr", "");
    expect_one_line_error(
        envmis({"precompute", (kBundled / "studio.exr").string(), "-o", "x.envmis", "--mapping", "equal-area"}),
        "studio.exr", "must be square");
}

TEST_F(Cli, InfoDescribesATableAndTheImageItCameFrom) {
    ASSERT_EQ(envmis({"precompute", (kBundled / "studio.exr").string(), "-o", "studio.envmis"}).exit_code, 0);
    const Result table = envmis({"info", "studio.envmis"});
    ASSERT_EQ(table.exit_code, 0) << table;
    EXPECT_TRUE(contains(table.out, "studio.envmis: envmis table, format version 7")) << table;
    expect_studio_summary(table);

    const Result image = envmis({"info", (kBundled / "studio.exr").string()});
    ASSERT_EQ(image.exit_code, 0) << image;
    EXPECT_TRUE(contains(image.out, "studio.exr: image, 3 channels")) << image;
    expect_studio_summary(image);
    // The table records what the build found: the same statistics line by line.
    for (const char* line : {"luminance", "mean \\(Lbar\\)", "compensation", "bad pixels"}) {
        std::smatch a, b;
        const std::regex whole(std::string("  ") + line + ".*");
        ASSERT_TRUE(std::regex_search(table.out, a, whole) && std::regex_search(image.out, b, whole)) << line;
        EXPECT_EQ(a.str(), b.str());
    }
}

TEST_F(Cli, SampleWritesTheHeaderAndOneRowPerSampleToStdoutOrAFile) {
    const Result r = envmis({"sample", (kBundled / "studio.exr").string(), "-n", "17", "--seed", "3"});
    ASSERT_EQ(r.exit_code, 0) << r;
    std::string header;
    const auto rows = csv_rows(r.out, &header);
    EXPECT_EQ(header, "u,v,x,y,z,pdf");
    EXPECT_EQ(rows.size(), 17u);
    for (const auto& row : rows) EXPECT_EQ(row.size(), 6u);

    // The same seed gives the same samples, whether to stdout or to a file.
    const Result to_file =
        envmis({"sample", (kBundled / "studio.exr").string(), "-n", "17", "--seed", "3", "-o", "s.csv"});
    ASSERT_EQ(to_file.exit_code, 0) << to_file;
    EXPECT_EQ(to_file.out, "");
    EXPECT_EQ(read_file(file("s.csv")), r.out);
}

TEST_F(Cli, SampleOnABinnedTableNeedsTheShadingPointAndDrawsFromItsBins) {
    write_exr(file("map.exr"), gradient(64, 32));
    ASSERT_EQ(envmis({"precompute", "map.exr", "-o", "binned.envmis", "--bins", "9"}).exit_code, 0);
    const Result none = envmis({"sample", "binned.envmis", "-n", "5"});
    EXPECT_NE(none.exit_code, 0);
    EXPECT_TRUE(contains(none.err, "binned.envmis: a binned table samples per shading point: give --normal X,Y,Z"))
        << none;
    EXPECT_EQ(none.out, "");
    const Result plain = envmis({"sample", "map.exr", "-n", "5", "--normal", "0,0,1"});
    EXPECT_NE(plain.exit_code, 0);
    EXPECT_TRUE(contains(plain.err, "map.exr: --normal samples a binned table's bins, and this is an image")) << plain;
    EXPECT_NE(envmis({"sample", "binned.envmis", "--normal", "0,0,0"}).exit_code, 0);
    EXPECT_NE(envmis({"sample", "binned.envmis", "--lobe", "phong:20"}).exit_code, 0);  // --lobe needs --normal
    for (const std::vector<std::string>& point : {std::vector<std::string>{"--normal", "0,0,1"},
                                                  {"--normal", "0.3,0.2,1", "--view", "1,0,1", "--lobe", "ggx:0.1"}}) {
        std::vector<std::string> args = {"sample", "binned.envmis", "-n", "200", "--seed", "4"};
        args.insert(args.end(), point.begin(), point.end());
        const Result r = envmis(args);
        ASSERT_EQ(r.exit_code, 0) << r;
        std::string header;
        const auto rows = csv_rows(r.out, &header);
        EXPECT_EQ(header, "u,v,x,y,z,pdf");
        ASSERT_EQ(rows.size(), 200u);
        for (const auto& row : rows) EXPECT_GT(row[5], 0.0) << r;
    }
}

TEST_F(Cli, VisualizeWritesAPngThatOpenImageIOReads) {
    const Result r = envmis({"visualize", (kBundled / "studio.exr").string(), "-o", "studio.png"});
    ASSERT_EQ(r.exit_code, 0) << r;
    EXPECT_TRUE(contains(r.out, "studio.png")) << r;
    auto in = OIIO::ImageInput::open(file("studio.png").string());
    ASSERT_TRUE(in) << OIIO::geterror();
    EXPECT_STREQ(in->format_name(), "png");
    EXPECT_GE(in->spec().width, 512);
    EXPECT_GT(in->spec().height, 0);
    EXPECT_EQ(in->spec().nchannels, 3);
    std::vector<uint8_t> pixels(size_t(in->spec().width) * in->spec().height * 3);
    EXPECT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, pixels.data())) << in->geterror();
}

TEST_F(Cli, BenchPrintsOneLinePerSamplerWithTheDocumentedFields) {
    const Result r = envmis({"bench", "--size", "256x128", "--repeats", "1", "--samples", "10000"});
    ASSERT_EQ(r.exit_code, 0) << r;
    EXPECT_TRUE(contains(
        r.out, R"((^|\n)map=synthetic-sky size=256x128 mapping=equirect compensated=1 repeats=1 samples=10000)"))
        << r;
    const std::string number = "[0-9]+(\\.[0-9]+)?";
    for (const char* sampler : {"guided", "guided-batch", "textbook", "pbrt-v4-style"})
        EXPECT_TRUE(contains(r.out, std::string("(^|\\n)sampler=") + sampler + " build_ms=" + number +
                                        " ns_per_sample=" + number + " ns_per_pdf=" + number +
                                        " bytes_per_texel=" + number + "\\n"))
            << sampler << r;
    for (const char* reference : {"textbook", "pbrt"})
        EXPECT_TRUE(contains(r.out, std::string("\\nspeedup_vs_") + reference + " build=" + number +
                                        "x sample=" + number + "x pdf=" + number + "x batch_sample=" + number +
                                        "x batch_pdf=" + number + "x\\n"))
            << reference << r;
    EXPECT_TRUE(contains(r.out, "pbrt-v4-style on an equal-area 181x181 square")) << r;
    EXPECT_TRUE(contains(r.out, "\\nbatch_over_single sample=" + number + "x lookup_over_pdf=" + number +
                                    "x lookup_over_lookup=" + number + "x "))
        << r;
}

TEST_F(Cli, VisualizeWithANormalAddsTheBinnedPanelToTheSamePicture) {
    const std::string map = (kBundled / "studio.exr").string();
    const auto width = [&](const std::string& png) {
        auto in = OIIO::ImageInput::open(file(png).string());
        return in ? in->spec().width : 0;
    };
    const Result plain = envmis({"visualize", map, "-o", "plain.png", "--panel-width", "512"});
    ASSERT_EQ(plain.exit_code, 0) << plain;
    const Result r = envmis({"visualize", map, "-o", "binned.png", "--panel-width", "512", "--normal", "0,0,2",
                             "--bins", "16", "--lobe", "ggx:0.2"});
    ASSERT_EQ(r.exit_code, 0) << r;
    EXPECT_TRUE(contains(r.out, "binned.png")) << r;
    EXPECT_GE(width("binned.png"), width("plain.png") + 512) << r;  // one more panel
}

TEST_F(Cli, BenchWithBinsAddsTheBinnedSamplerAgainstTodaysMaps) {
    const Result r = envmis({"bench", "--size", "256x128", "--repeats", "1", "--samples", "10000", "--bins", "16"});
    ASSERT_EQ(r.exit_code, 0) << r;
    const std::string number = "[0-9]+(\\.[0-9]+)?";
    EXPECT_TRUE(contains(r.out, "\\nbinned bins=16 cells=8x4 lobe_class=0 ")) << r;
    for (const char* sampler : {"plain", "compensated", "binned"})
        EXPECT_TRUE(contains(
            r.out, std::string("\\nsampler=") + sampler + " build_ms=" + number + " ns_per_sample=" + number +
                       " ns_per_pdf=" + number + " ns_per_lookup=" + number + " ns_per_batch_sample=" + number +
                       " ns_per_batch_lookup=" + number + " bytes=[0-9]+ batch_over_single sample=" + number +
                       "x lookup_over_pdf=" + number + "x lookup_over_lookup=" + number + "x\\n"))
            << sampler << r;
    EXPECT_TRUE(contains(r.out, "\\nbinned_over_compensated sample=" + number + "x pdf=" + number +
                                    "x batch_sample=" + number + "x batch_lookup=" + number + "x build=" + number +
                                    "x memory=" + number + "%\\n"))
        << r;
    EXPECT_TRUE(contains(r.out, "\\nbinned_pdf_in_picked_bin ns=" + number + " over_plain_pdf=" + number + "x\\n"))
        << r;
    EXPECT_TRUE(contains(r.out, "\\nbinned_sample_over_global_same_density median=" + number + "x least=" + number +
                                    "x most=" + number + "x bins=[1-7]\\n"))
        << r;
    const Result j =
        envmis({"bench", "--size", "256x128", "--repeats", "1", "--samples", "1000", "--bins", "4", "--json"});
    ASSERT_EQ(j.exit_code, 0) << j;
    const nlohmann::json binned = nlohmann::json::parse(j.out).at("binned");
    EXPECT_EQ(binned.at("bins"), 4);
    ASSERT_EQ(binned.at("samplers").size(), 3u);
    for (const char* field : {"sample", "pdf", "batch_sample", "batch_lookup", "build", "memory"})
        EXPECT_GT(binned.at("binned_over_compensated").at(field).get<double>(), 0) << field << j;
    for (const char* field : {"ns", "over_plain_pdf"})
        EXPECT_GT(binned.at("pdf_in_picked_bin").at(field).get<double>(), 0) << field << j;
    const nlohmann::json& same = binned.at("sample_over_global_same_density");
    EXPECT_GE(same.at("bins").get<int>(), 1) << j;
    EXPECT_LE(same.at("least").get<double>(), same.at("median").get<double>()) << j;
    EXPECT_LE(same.at("median").get<double>(), same.at("most").get<double>()) << j;
    EXPECT_GT(same.at("least").get<double>(), 0) << j;
    for (const auto& s : binned.at("samplers")) {
        EXPECT_GT(s.at("ns_per_lookup").get<double>(), 0) << j;
        for (const char* field : {"sample", "lookup_over_pdf", "lookup_over_lookup"})
            EXPECT_GT(s.at("batch_over_single").at(field).get<double>(), 0) << field << j;
    }
}

TEST_F(Cli, BenchTimesAnEqualAreaSkyOnASquareSizeOnly) {
    const Result r = envmis(
        {"bench", "--mapping", "equal-area", "--size", "64x64", "--repeats", "1", "--samples", "1000", "--json"});
    ASSERT_EQ(r.exit_code, 0) << r;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j.at("mapping"), "equal-area");
    EXPECT_GT(j.at("speedup_vs_textbook").at("sample").get<double>(), 0) << r;
    const Result oblong = envmis({"bench", "--mapping", "equal-area", "--size", "128x64", "--repeats", "1"});
    EXPECT_NE(oblong.exit_code, 0) << oblong;
    EXPECT_TRUE(contains(oblong.err, "--size 128x64: an equal-area sky is square")) << oblong;
}

TEST_F(Cli, BenchJsonIsOneObjectWithTheSameFields) {
    const Result r = envmis({"bench", "--size", "256x128", "--repeats", "1", "--samples", "10000", "--json"});
    ASSERT_EQ(r.exit_code, 0) << r;
    nlohmann::json j;
    ASSERT_NO_THROW(j = nlohmann::json::parse(r.out)) << r;
    EXPECT_EQ(j.at("width"), 256);
    EXPECT_EQ(j.at("height"), 128);
    EXPECT_EQ(j.at("samples"), 10000);
    EXPECT_EQ(j.at("repeats"), 1);
    EXPECT_EQ(j.at("compensated"), true);
    ASSERT_EQ(j.at("samplers").size(), 4u);
    EXPECT_EQ(j["samplers"][0].at("sampler"), "guided");
    EXPECT_EQ(j["samplers"][1].at("sampler"), "guided-batch");
    EXPECT_EQ(j["samplers"][2].at("sampler"), "textbook");
    EXPECT_EQ(j["samplers"][3].at("sampler"), "pbrt-v4-style");
    EXPECT_EQ(j.at("pbrt_square"), nlohmann::json::array({181, 181}));  // the square of about as many texels
    for (const auto& s : j["samplers"])
        for (const char* field : {"build_ms", "ns_per_sample", "ns_per_pdf", "bytes_per_texel"})
            EXPECT_TRUE(s.at(field).is_number() && s[field].get<double>() > 0) << field << r;
    for (const char* field : {"build", "sample", "pdf", "batch_sample", "batch_pdf"})
        for (const char* reference : {"speedup_vs_textbook", "speedup_vs_pbrt"})
            EXPECT_GT(j.at(reference).at(field).get<double>(), 0) << reference << " " << field;
    for (const char* field : {"sample", "lookup_over_pdf", "lookup_over_lookup"})
        EXPECT_GT(j.at("batch_over_single").at(field).get<double>(), 0) << field << r;
}

// ---------------------------------------------------------------------------------
// Bad inputs: the subcommands that read a map fail the same way and leave nothing
// behind in the folder (visualize reads maps with the same code as sample; each run of
// the command costs about 0.4 s of dynamic linking, so it is left out here).

struct BadInput {
    std::string name;     // for the test name
    std::string file;     // as given on the command line
    std::string problem;  // regex the message must match
    void (*make)(Cli&, const fs::path&);
};

void PrintTo(const BadInput& c, std::ostream* os) { *os << c.name; }

class CliBadInput : public Cli, public testing::WithParamInterface<BadInput> {};

TEST_P(CliBadInput, EverySubcommandFailsWithOneLineNamingTheFileAndLeavesNoFiles) {
    const BadInput& c = GetParam();
    c.make(*this, file(c.file));
    const std::set<std::string> before = listing();
    for (const Result& r : {envmis({"info", c.file}), envmis({"sample", c.file, "-o", "out.csv"}),
                            envmis({"precompute", c.file, "-o", "out.envmis"})}) {
        expect_one_line_error(r, c.file, c.problem);
        EXPECT_EQ(listing(), before) << "files were added or removed" << r;
    }
}

INSTANTIATE_TEST_SUITE_P(
    Files, CliBadInput,
    testing::Values(BadInput{"MissingFile", "missing.exr", "no such file", [](Cli&, const fs::path&) {}},
                    BadInput{"TextFileNamedExr", "x.exr", "not (a|an) .*(image|openexr)",
                             [](Cli&, const fs::path& p) { write_file(p, "this is not an image\n"); }},
                    BadInput{"TruncatedExr", "half.exr", "truncated|corrupt",
                             [](Cli&, const fs::path& p) {
                                 const std::string bytes = read_file(kBundled / "city.exr");
                                 write_file(p, bytes.substr(0, bytes.size() / 2));
                             }},
                    BadInput{"CorruptedTable", "corrupt.envmis", "corrupt",
                             [](Cli& t, const fs::path& p) {
                                 // A byte of the radiance, before the final checksum.
                                 t.damaged_table(p, [](std::string& bytes) { bytes[bytes.size() - 100] ^= 0x5a; });
                             }},
                    BadInput{"TruncatedTable", "half.envmis", "truncated",
                             [](Cli& t, const fs::path& p) {
                                 t.damaged_table(p, [](std::string& bytes) { bytes.resize(bytes.size() / 2); });
                             }},
                    BadInput{"RandomBytesNamedEnvmis", "random.envmis", "not (a|an) ",
                             [](Cli&, const fs::path& p) {
                                 std::string bytes(5000, '\0');
                                 uint32_t x = 12345;
                                 for (char& b : bytes) b = static_cast<char>((x = x * 1664525u + 1013904223u) >> 24);
                                 write_file(p, bytes);
                             }},
                    BadInput{"TableOfANewerVersion", "newer.envmis", "version 8.*newer",
                             [](Cli& t, const fs::path& p) {
                                 // The format version: uint32, little-endian, at byte 8.
                                 t.damaged_table(
                                     p, [](std::string& bytes) { bytes.replace(8, 4, std::string("\x08\0\0\0", 4)); });
                             }},
                    BadInput{"Folder", "folder.exr", "directory",
                             [](Cli&, const fs::path& p) { fs::create_directory(p); }}),
    [](const testing::TestParamInfo<BadInput>& info) { return info.param.name; });

// --bins K: the texels keep the plain density and each of K bins of normals its own
// compensation; precompute and info describe the bins and what they cost.
TEST_F(Cli, PrecomputeWithBinsWritesABinnedTableThatInfoDescribes) {
    write_exr(file("map.exr"), gradient(64, 32));
    const Result r = envmis({"precompute", "map.exr", "-o", "binned.envmis", "--bins", "64", "--alpha", "auto"});
    ASSERT_EQ(r.exit_code, 0) << r;
    EXPECT_EQ(r.err, "") << r;
    for (const char* line :
         {R"(compensation +per bin)",
          R"(bins +64 \(8 x 8 octahedral grid of normals; the diffuse class 225, 15 x 15\), cells 2 x 1)",
          R"(bin alphas +diffuse: +[0-9]+ )", R"(bin alphas +Phong 200: +[0-9]+ )",
          R"(bins build +[0-9.]+ ms \(choosing alphas [0-9.]+ ms\), [0-9]+ bytes over the plain )"
          R"(map \(\+[0-9.]+%\))"})
        EXPECT_TRUE(contains(r.out, line)) << "missing /" << line << "/" << r;
    const Result info = envmis({"info", "binned.envmis"});
    ASSERT_EQ(info.exit_code, 0) << info;
    for (const char* line :
         {"binned.envmis: envmis table, format version 7", R"(bins +64 \(8 x 8)", R"(bin alphas +Phong 20: )",
          R"(complete pdf +(yes|no.*) \(the plain map's; the bins': 'bins complete' below\))",
          R"(alpha a: max\(L - a E_b / pi, 0\) times the bin's cosine factor; plain: the map's own density)",
          R"(bins complete +diffuse (yes|no), Phong 20)",
          R"(bins build +[0-9.]+ ms \(rebuilt from the stored layout\), [0-9]+ bytes over the plain map)"})
        EXPECT_TRUE(contains(info.out, line)) << "missing /" << line << "/" << info;
    const Result fixed = envmis(
        {"precompute", "map.exr", "-o", "fixed.envmis", "--bins", "1", "--no-compensate", "--cell-columns", "4"});
    ASSERT_EQ(fixed.exit_code, 0) << fixed;
    EXPECT_TRUE(
        contains(fixed.out, R"(bins +1 \(1 x 1 octahedral grid of normals; the diffuse class 1, 1 x 1\), cells 4 x 2)"))
        << fixed;
    EXPECT_TRUE(contains(fixed.out, R"(bin alphas +diffuse: +1 alpha 0\n)")) << fixed;
}

// --threads caps the build's loops (as ENVMIS_THREADS does), and precompute says how many
// it ran on; the default is every usable core, and a bad count is a usage error.
TEST_F(Cli, ThreadsCapsTheBuildsLoopsAndPrecomputeSaysSo) {
    write_exr(file("map.exr"), gradient(64, 32));
    const Result one = envmis({"precompute", "map.exr", "-o", "map.envmis", "--threads", "1", "--bins", "4"});
    ASSERT_EQ(one.exit_code, 0) << one;
    EXPECT_TRUE(contains(one.out, R"(write [0-9.]+ ms \(at most 1 thread\))")) << one;
    const Result every = envmis({"precompute", "map.exr", "-o", "map.envmis"});
    EXPECT_TRUE(
        contains(every.out, R"(write [0-9.]+ ms \(at most )" + std::to_string(envmis::usable_cores()) + " thread"))
        << every;
    for (const char* command : {"convert", "visualize", "sample", "info", "bench"}) {
        const Result bad = envmis({command, "map.exr", "--threads", "0"});
        EXPECT_EQ(bad.exit_code, 2) << bad;
        EXPECT_NE(bad.err.find("--threads"), std::string::npos) << bad;
    }
}

// With ENVMIS_PROGRESS=1, precompute reports each stage as it starts and ends, in order:
// an 8k map's build with bins is seconds long in each.
TEST_F(Cli, PrecomputeReportsEveryStageAsItStartsAndEnds) {
    write_exr(file("map.exr"), gradient(64, 32));
    for (const auto& [flags, stages] : {std::pair<std::string, std::vector<std::string>>{
                                            "--bins 4", {"reading", "building", "building bins", "writing"}},
                                        {"--alpha auto", {"reading", "choosing alpha", "building", "writing"}}}) {
        const Result r =
            envmis::test::run_shell("cd " + envmis::test::quoted(dir_.string()) + " && ENVMIS_PROGRESS=1 " +
                                        envmis::test::quoted(ENVMIS_CLI) + " precompute map.exr -o map.envmis " + flags,
                                    dir_ / "..stdout", dir_ / "..stderr");
        ASSERT_EQ(r.exit_code, 0) << r;
        std::string expected;
        for (const std::string& stage : stages) expected += stage + "   0%\n" + stage + " 100%\n";
        EXPECT_EQ(r.err, expected) << flags;
    }
}

// What the summary prints agrees with the options and the file: the axes by their preset's
// name too, memory as in memory, a compact table said to be one.
TEST_F(Cli, TheSummaryNamesTheAxesPresetMemoryInMemoryAndACompactTable) {
    write_exr(file("map.exr"), gradient(64, 32));
    const Result r = envmis({"precompute", "map.exr", "-o", "y.envmis", "--axes", "y-up", "--compact"});
    ASSERT_EQ(r.exit_code, 0) << r;
    EXPECT_TRUE(contains(r.out, R"(axes x,z,-y \(y-up\))")) << r;
    EXPECT_TRUE(
        contains(r.out, R"(memory +[0-9.]+ bytes/texel \(distribution\) \+ 12 \(float RGB radiance\), in memory)"))
        << r;
    const Result info = envmis({"info", "y.envmis"});
    ASSERT_EQ(info.exit_code, 0) << info;
    EXPECT_TRUE(contains(info.out, R"(format version 7, compact \(RGBE radiance, 4 bytes/texel on disk)")) << info;
    EXPECT_TRUE(contains(info.out, R"(axes x,z,-y \(y-up\))")) << info;
    ASSERT_EQ(envmis({"precompute", "map.exr", "-o", "p.envmis", "--axes", "x,-z,y"}).exit_code, 0);
    const Result other = envmis({"info", "p.envmis"});
    EXPECT_TRUE(contains(other.out, R"(axes x,-z,y\n)")) << other;
    EXPECT_FALSE(contains(other.out, "compact")) << other;
}

TEST_F(Cli, PrecomputeRefusesBinsThatAreNotASquareNumberInOneLineAndWritesNothing) {
    write_exr(file("map.exr"), gradient(16, 8));
    for (const char* bins : {"50", "-1", "99999999", "0", "4225", "8x8"}) {
        const Result r = envmis({"precompute", "map.exr", "-o", "out.envmis", "--bins", bins});
        expect_one_line_error(r, "--bins", std::string(bins) + ": expected a square number of bins");
        EXPECT_EQ(listing(), std::set<std::string>{"map.exr"}) << r;
    }
}

TEST_F(Cli, PrecomputeRefusesATableWithOneLine) {
    small_table("t.envmis");
    const std::set<std::string> before = listing();
    expect_one_line_error(envmis({"precompute", "t.envmis", "-o", "again.envmis"}), "t.envmis", "already a table");
    EXPECT_EQ(listing(), before);
}

// ---------------------------------------------------------------------------------
// Output files: written whole or not at all.

struct Writer {
    std::string subcommand, output;
};
const Writer kWriters[] = {{"sample", "out.csv"}, {"precompute", "out.envmis"}, {"visualize", "out.png"}};

TEST_F(Cli, OutputIntoAMissingFolderFailsWithOneLineAndWritesNothing) {
    write_exr(file("map.exr"), gradient(16, 8));
    for (const Writer& w : kWriters) {
        const std::string output = "no/such/folder/" + w.output;
        expect_one_line_error(envmis({w.subcommand, "map.exr", "-o", output}), output,
                              "no such file or directory|does not exist|missing folder");
        EXPECT_EQ(listing(), std::set<std::string>{"map.exr"});
    }
}

// The rename at the end fails (the destination is a folder): the complete temporary
// file must not stay behind, and the folder is untouched.
TEST_F(Cli, AFailedFinalRenameLeavesNoTemporaryFile) {
    write_exr(file("map.exr"), gradient(16, 8));
    for (const Writer& w : kWriters) {
        fs::create_directory(file(w.output));
        const std::set<std::string> before = listing();
        expect_one_line_error(envmis({w.subcommand, "map.exr", "-o", w.output}), w.output, "cannot write|directory");
        EXPECT_EQ(listing(), before);
        EXPECT_TRUE(fs::is_directory(file(w.output)) && fs::is_empty(file(w.output)));
    }
}

TEST_F(Cli, AFailedRunLeavesAnExistingDestinationUntouched) {
    for (const Writer& w : kWriters) {
        write_file(file(w.output), "previous contents");
        expect_one_line_error(envmis({w.subcommand, "missing.exr", "-o", w.output}), "missing.exr", "no such file");
        EXPECT_EQ(read_file(file(w.output)), "previous contents") << w.subcommand;
    }
}

// Ctrl-C during a long `sample -o`: the destination must not appear, and the hidden
// temporary file must not stay behind.
TEST_F(Cli, AnInterruptedSampleLeavesNoFiles) {
    write_exr(file("map.exr"), gradient(16, 8));
    const std::string cli = ENVMIS_CLI, out = file("out.csv").string(), map = file("map.exr").string();
    std::vector<const char*> argv = {cli.c_str(),  "sample", map.c_str(), "-n",
                                     "1000000000", "-o",     out.c_str(), nullptr};
    pid_t pid = 0;
    ASSERT_EQ(posix_spawn(&pid, cli.c_str(), nullptr, nullptr, const_cast<char* const*>(argv.data()), environ), 0);
    // Interrupt once it is writing: when its temporary file has appeared (or after 10 s).
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (listing().size() < 2 && std::chrono::steady_clock::now() < deadline)
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    ::kill(pid, SIGINT);
    int status = 0;
    ::waitpid(pid, &status, 0);
    EXPECT_FALSE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "the run was meant to be interrupted";
    EXPECT_EQ(listing(), std::set<std::string>{"map.exr"});
}

// ---------------------------------------------------------------------------------
// Unusual pixels and sizes: each map is precomputed (summary checked), visualised, and
// sampled with and without compensation and from its table, with finite positive pdfs.

struct OddMap {
    std::string name;
    Pixels pixels;
    std::vector<std::string> summary;  // regexes the precompute summary must match
};

Pixels bad_values() {
    Pixels p = constant(8, 4, 0.5f, 0.25f, 2.0f);
    // 2 NaN, 3 Inf, 4 negative channel values; -Inf counts as infinite.
    const float bad[] = {kNaN, kNaN, kInf, kInf, -kInf, -1.0f, -0.5f, -1e-7f, -1e30f};
    for (size_t i = 0; i < std::size(bad); ++i) p.rgb[7 * i + 1] = bad[i];
    return p;
}

Pixels odd_size() {
    Pixels p{7, 3, {}};
    for (int i = 0; i < 21; ++i) p.rgb.insert(p.rgb.end(), {0.1f * i, 0.05f * (i % 4), 1.0f + (i % 3)});
    return p;
}

// Grey texels from 1e-8 to 1e8, a dynamic range of 1e16 (16 decades).
Pixels extreme_range() {
    Pixels p = constant(16, 8, 1.0f, 1.0f, 1.0f);
    for (int i = 0; i < 3; ++i) p.rgb[i] = 1e-8f;
    for (int i = 3; i < 6; ++i) p.rgb[i] = 1e8f;
    return p;
}

void PrintTo(const OddMap& c, std::ostream* os) { *os << c.name; }

class CliOddMap : public Cli, public testing::WithParamInterface<OddMap> {};

TEST_P(CliOddMap, PrecomputeReportsItAndEverySubcommandWorks) {
    const OddMap& c = GetParam();
    write_exr(file("map.exr"), c.pixels);
    const Result pre = envmis({"precompute", "map.exr", "-o", "map.envmis"});
    ASSERT_EQ(pre.exit_code, 0) << pre;
    for (const std::string& line : c.summary) EXPECT_TRUE(contains(pre.out, line)) << "missing /" << line << "/" << pre;
    for (const char* line : {"luminance", "mean \\(Lbar\\)", "compensation"})
        EXPECT_FALSE(contains(pre.out, std::string("  ") + line + ".*(nan|inf)")) << "non-finite statistics" << pre;

    const Result vis = envmis({"visualize", "map.envmis", "-o", "map.png"});
    EXPECT_EQ(vis.exit_code, 0) << vis;

    // A table records its own mode, so the flag only matters for the image.
    for (const std::vector<std::string>& args : {std::vector<std::string>{"sample", "map.exr", "-n", "2000"},
                                                 {"sample", "map.exr", "-n", "2000", "--no-compensate"},
                                                 {"sample", "map.envmis", "-n", "2000"}}) {
        const Result s = envmis(args);
        ASSERT_EQ(s.exit_code, 0) << s;
        std::string header;
        const auto rows = csv_rows(s.out, &header);
        ASSERT_EQ(rows.size(), 2000u) << s.command;
        size_t bad = 0;
        for (const auto& row : rows) bad += !(row.size() == 6 && std::isfinite(row[5]) && row[5] > 0);
        EXPECT_EQ(bad, 0u) << "rows with a pdf that is not finite and positive" << s;
    }
}

INSTANTIATE_TEST_SUITE_P(
    Maps, CliOddMap,
    testing::Values(
        OddMap{"NanInfAndNegativePixels",
               bad_values(),
               {R"(bad pixels +2 NaN, 3 Inf, 4 negative channel values \(replaced by 0\))", "fallback +none"}},
        OddMap{"OneTexel", constant(1, 1, 1.0f, 2.0f, 3.0f), {R"(size +1 x 1\n)", "fallback +uncompensated"}},
        OddMap{"OddSize7x3", odd_size(), {R"(size +7 x 3\n)", "fallback +none"}},
        OddMap{"AllBlack", constant(32, 16, 0, 0, 0), {"fallback +uniform"}},
        OddMap{"Constant", constant(32, 16, 0.7f, 0.7f, 0.7f), {"fallback +uncompensated"}},
        OddMap{"DynamicRange1e16",
               extreme_range(),
               {R"(dynamic range 1(\.0+)?e\+16 \(16(\.0+)? decades\))", "fallback +none"}}),
    [](const testing::TestParamInfo<OddMap>& info) { return info.param.name; });

}  // namespace
