// Specification of the count, size and seed flags of `envmis` precompute, info, sample,
// visualize, bench and convert: a negative or out-of-range value is refused before any
// work starts, with exit status 2 (a usage error), nothing on stdout, one line on stderr
// that names the flag, and no output file; a mistyped command is named with the nearest
// one; a failure of the work itself exits 1. Every test runs the real binary (ENVMIS_CLI) in a temporary
// folder of its own.
#include <gtest/gtest.h>

#include <filesystem>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "cli_run.h"

namespace {

namespace fs = std::filesystem;
using envmis::test::Result;

const std::string kStudio = (fs::path(ENVMIS_DATA_DIR) / "envmaps" / "studio.exr").string();

// One refused value: the arguments after `envmis`, and the flag the message must name.
struct BadFlag {
    std::string name;
    std::vector<std::string> args;
    std::string flag;
};

std::ostream& operator<<(std::ostream& os, const BadFlag& c) { return os << c.name; }

// Each test works in a folder of its own, removed afterwards.
class Folder : public envmis::test::TempFolder {
public:
    Folder() : TempFolder("envmis_flags_test_") {}

    // Runs envmis with `args` in the test's folder; its output goes beside the folder.
    Result envmis(const std::vector<std::string>& args) const {
        return envmis::test::run_envmis(dir_, args, dir_.string() + ".stdout", dir_.string() + ".stderr");
    }

    bool folder_is_empty() const { return fs::is_empty(dir_); }
};

class Flags : public Folder, public testing::WithParamInterface<BadFlag> {};
class FlagBounds : public Folder {};

TEST_P(Flags, AnOutOfRangeValueIsRefusedInOneLineNamingTheFlagBeforeAnyWork) {
    const BadFlag& c = GetParam();
    const Result r = envmis(c.args);
    EXPECT_EQ(r.exit_code, 2) << r;
    EXPECT_EQ(r.out, "") << r;
    EXPECT_TRUE(!r.err.empty() && r.err.back() == '\n' && r.err.find('\n') == r.err.size() - 1)
        << "expected exactly one line on stderr" << r;
    EXPECT_NE(r.err.find(c.flag), std::string::npos) << "stderr does not name " << c.flag << r;
    EXPECT_TRUE(folder_is_empty()) << "an output file was written" << r;
}

std::vector<std::string> sample(std::vector<std::string> flags) {
    flags.insert(flags.begin(), {"sample", kStudio, "-o", "out.csv"});
    return flags;
}

std::vector<std::string> convert(std::vector<std::string> flags) {
    flags.insert(flags.begin(), {"convert", kStudio, "-o", "out.exr"});
    return flags;
}

std::vector<std::string> bench(std::vector<std::string> flags) {
    flags.insert(flags.begin(), {"bench", "--repeats", "1", "--samples", "16", "--size", "16x8"});
    return flags;
}

std::vector<std::string> visualize(std::vector<std::string> flags) {
    flags.insert(flags.begin(), {"visualize", kStudio, "-o", "out.png"});
    return flags;
}

INSTANTIATE_TEST_SUITE_P(
    Subcommands, Flags,
    testing::Values(
        // sample: -n (--count, the name the message gives) 1 to 2^40, --seed 0 to 2^64 - 1.
        BadFlag{"SampleNegativeCount", sample({"-n", "-5"}), "--count"},
        BadFlag{"SampleNegativeCountLongName", sample({"--count", "-1"}), "--count"},
        BadFlag{"SampleZeroCount", sample({"-n", "0"}), "--count"},
        BadFlag{"SampleCountAbove2To40", sample({"-n", "1099511627777"}), "--count"},
        BadFlag{"SampleNegativeSeed", sample({"--seed", "-5"}), "--seed"},
        BadFlag{"SampleSeedAbove64Bits", sample({"--seed", "18446744073709551616"}), "--seed"},
        BadFlag{"SampleToStandardOutputNegativeCount", {"sample", kStudio, "-n", "-5"}, "--count"},
        // convert: --size N or WxH, each side 1 to 65536 (equirect N to 32768); --supersampling 0 to 64.
        BadFlag{"ConvertNegativeSize", convert({"--size", "-4"}), "--size"},
        BadFlag{"ConvertNegativeWidth", convert({"--size", "-4x4"}), "--size"},
        BadFlag{"ConvertNegativeHeight", convert({"--size", "4x-4"}), "--size"},
        BadFlag{"ConvertZeroSize", convert({"--size", "0"}), "--size"},
        BadFlag{"ConvertSizeAbove65536", convert({"--size", "65537", "--to", "equal-area"}), "--size"},
        BadFlag{"ConvertWidthAbove65536", convert({"--size", "70000x16"}), "--size"},
        BadFlag{"ConvertEquirectSizeWhoseWidthIsAbove65536", convert({"--size", "40000", "--to", "equirect"}),
                "--size"},
        BadFlag{"ConvertNegativeSupersampling", convert({"--supersampling", "-1"}), "--supersampling"},
        BadFlag{"ConvertSupersamplingAbove64", convert({"--supersampling", "65"}), "--supersampling"},
        // bench: --repeats 1 to 1000, --samples 1 to 2^26, --size WxH each 1 to 65536.
        BadFlag{"BenchNegativeRepeats", bench({"--repeats", "-1"}), "--repeats"},
        // --bins: a square number of bins, 1 to 4096 (64 x 64).
        BadFlag{"BenchBinsNotSquare", bench({"--bins", "10"}), "--bins"},
        BadFlag{"BenchZeroBins", bench({"--bins", "0"}), "--bins"},
        BadFlag{"BenchBinsAbove4096", bench({"--bins", "4225"}), "--bins"},
        BadFlag{"VisualizeBinsNotSquare", visualize({"--normal", "0,0,1", "--bins", "-4"}), "--bins"},
        // visualize --normal X,Y,Z: three finite numbers, not all zero; --lobe a BSDF.
        BadFlag{"VisualizeZeroNormal", visualize({"--normal", "0,0,0"}), "--normal"},
        BadFlag{"VisualizeNanNormal", visualize({"--normal", "0,nan,1"}), "--normal"},
        BadFlag{"VisualizeInfiniteNormal", visualize({"--normal", "inf,0,1"}), "--normal"},
        BadFlag{"VisualizeNormalWithTwoComponents", visualize({"--normal", "0,1"}), "--normal"},
        BadFlag{"VisualizeNormalWithFourComponents", visualize({"--normal", "0,1,0,1"}), "--normal"},
        BadFlag{"VisualizeUnknownLobe", visualize({"--normal", "0,0,1", "--lobe", "velvet"}), "--lobe"},
        BadFlag{"BenchZeroRepeats", bench({"--repeats", "0"}), "--repeats"},
        BadFlag{"BenchRepeatsAbove1000", bench({"--repeats", "1001"}), "--repeats"},
        BadFlag{"BenchNegativeSamples", bench({"--samples", "-1"}), "--samples"},
        BadFlag{"BenchZeroSamples", bench({"--samples", "0"}), "--samples"},
        BadFlag{"BenchSamplesAbove2To26", bench({"--samples", "67108865"}), "--samples"},
        BadFlag{"BenchNegativeWidth", bench({"--size", "-4x4"}), "--size"},
        BadFlag{"BenchNegativeHeight", bench({"--size", "8x-4"}), "--size"},
        BadFlag{"BenchZeroWidth", bench({"--size", "0x8"}), "--size"},
        BadFlag{"BenchWidthAbove65536", bench({"--size", "65537x8"}), "--size"},
        BadFlag{"BenchSizeWithoutHeight", bench({"--size", "16"}), "--size"},
        // visualize: --panel-width 64 to 4096.
        BadFlag{"VisualizeNegativePanelWidth", visualize({"--panel-width", "-1"}), "--panel-width"},
        BadFlag{"VisualizePanelWidthBelow64", visualize({"--panel-width", "63"}), "--panel-width"},
        BadFlag{"VisualizePanelWidthAbove4096", visualize({"--panel-width", "4097"}), "--panel-width"},
        // The map flags: --alpha a finite number >= 0 (or auto).
        BadFlag{"SampleNegativeAlpha", sample({"--alpha", "-1"}), "--alpha"},
        BadFlag{"SampleInfiniteAlpha", sample({"--alpha", "inf"}), "--alpha"},
        BadFlag{"PrecomputeNegativeAlpha", {"precompute", kStudio, "-o", "out.envmis", "--alpha", "-0.5"}, "--alpha"},
        BadFlag{"PrecomputeNanAlpha", {"precompute", kStudio, "-o", "out.envmis", "--alpha", "nan"}, "--alpha"},
        // precompute: --bins a square number 1 to 4096, --cell-columns 0 to 4096.
        BadFlag{"PrecomputeBinsNotASquare", {"precompute", kStudio, "-o", "out.envmis", "--bins", "50"}, "--bins"},
        BadFlag{"PrecomputeNegativeBins", {"precompute", kStudio, "-o", "out.envmis", "--bins", "-1"}, "--bins"},
        BadFlag{"PrecomputeBinsAbove4096", {"precompute", kStudio, "-o", "out.envmis", "--bins", "99999999"}, "--bins"},
        BadFlag{"PrecomputeCellColumnsAbove4096",
                {"precompute", kStudio, "-o", "out.envmis", "--bins", "64", "--cell-columns", "4097"},
                "--cell-columns"},
        BadFlag{"CompareCellColumnsAbove4096", {"compare", kStudio, "--cell-columns", "4097"}, "--cell-columns"},
        // --bin-cost 1 to 100, with --bins only.
        BadFlag{"PrecomputeBinCostBelow1",
                {"precompute", kStudio, "-o", "out.envmis", "--bins", "64", "--bin-cost", "0.5"},
                "--bin-cost"},
        BadFlag{"PrecomputeBinCostWithoutBins",
                {"precompute", kStudio, "-o", "out.envmis", "--bin-cost", "2"},
                "--bin-cost"},
        BadFlag{"CompareNanBinCost", {"compare", kStudio, "--bin-cost", "nan"}, "--bin-cost"},
        // Empty outputs, directions that are not finite, absent lists, conflicting flags.
        BadFlag{"SampleEmptyOutput", {"sample", kStudio, "-o", ""}, "--output"},
        BadFlag{"CompareEmptyJson", {"compare", kStudio, "--json", ""}, "--json"},
        BadFlag{"CompareEmptyCsv", {"compare", kStudio, "--csv", ""}, "--csv"},
        BadFlag{"CompareInfiniteNormal", {"compare", kStudio, "--normal", "inf,0,0"}, "--normal"},
        BadFlag{"CompareNormalBeyondFloat", {"compare", kStudio, "--normal", "1e39,0,0"}, "--normal"},
        BadFlag{"CompareInfiniteView", {"compare", kStudio, "--normal", "0,0,1", "--view", "inf,0,0"}, "--view"},
        BadFlag{"CompareViewWithoutNormal", {"compare", kStudio, "--view", "0,0,1"}, "--view"},
        BadFlag{"CompareNormalWithPoints", {"compare", kStudio, "--normal", "0,0,1", "--points", "4"}, "--points"},
        BadFlag{"CompareEmptyBsdf", {"compare", kStudio, "--bsdf", ""}, "--bsdf"},
        BadFlag{"CompareZeroBins", {"compare", kStudio, "--bins", "0"}, "--bins"},
        BadFlag{"SampleAlphaWithoutCompensation", sample({"--no-compensate", "--alpha", "0.5"}), "--alpha"},
        BadFlag{"InfoNegativeAlpha", {"info", kStudio, "--alpha", "-1"}, "--alpha"},
        BadFlag{"VisualizeNegativeAlpha", visualize({"--alpha", "-1"}), "--alpha"}),
    [](const testing::TestParamInfo<BadFlag>& info) { return info.param.name; });

TEST_F(FlagBounds, AMistypedCommandIsAUsageErrorThatNamesTheNearestCommand) {
    for (const auto& [typed, meant] : {std::pair<std::string, std::string>{"compre", "compare"},
                                       {"comprae", "compare"},
                                       {"prec", "precompute"},
                                       {"infp", "info"},
                                       {"vizualize", "visualize"}}) {
        const Result r = envmis({typed, kStudio});
        EXPECT_EQ(r.exit_code, 2) << r;
        EXPECT_EQ(r.out, "") << r;
        EXPECT_EQ(r.err, "envmis: unknown command '" + typed + "'; did you mean '" + meant + "'? (see --help)\n") << r;
    }
    const Result far = envmis({"bogus"});
    EXPECT_EQ(far.exit_code, 2) << far;
    EXPECT_EQ(far.err, "envmis: unknown command 'bogus' (see --help)\n") << far;
    EXPECT_TRUE(folder_is_empty());
}

TEST_F(FlagBounds, AnOutputNamedForAnotherFormatThanTheOneWrittenIsRefused) {
    for (const auto& [args, format] :
         {std::pair<std::vector<std::string>, std::string>{{"visualize", kStudio, "-o", "vis.jpg"}, "PNG"},
          {{"convert", kStudio, "-o", "square.png"}, "OpenEXR"}}) {
        const Result r = envmis(args);
        EXPECT_EQ(r.exit_code, 2) << r;
        EXPECT_NE(r.err.find("writes " + format), std::string::npos) << r;
        EXPECT_TRUE(folder_is_empty()) << r;
    }
    EXPECT_EQ(envmis({"visualize", kStudio, "-o", "vis.PNG", "--panel-width", "64"}).exit_code, 0);
}

TEST_F(FlagBounds, AFailureOfTheWorkExitsOneAndHelpNamesTheStatuses) {
    const Result missing = envmis({"info", "no-such-map.exr"});
    EXPECT_EQ(missing.exit_code, 1) << missing;
    const Result help = envmis({"--help"});
    EXPECT_EQ(help.exit_code, 0) << help;
    EXPECT_NE(help.out.find("Exit status: 0 success, 1 failure, 2 usage error"), std::string::npos) << help;
}

// The limits themselves are accepted.
TEST_F(FlagBounds, TheLimitsThemselvesAreAccepted) {
    const Result s = envmis({"sample", kStudio, "-n", "1", "--seed", "18446744073709551615"});
    EXPECT_EQ(s.exit_code, 0) << s;
    EXPECT_EQ(s.out.substr(0, s.out.find('\n')), "u,v,x,y,z,pdf") << s;
    const Result b = envmis({"bench", "--size", "1x1", "--repeats", "1", "--samples", "1"});
    EXPECT_EQ(b.exit_code, 0) << b;
    const Result z = envmis({"sample", kStudio, "-n", "1", "--seed", "0", "--alpha", "0"});
    EXPECT_EQ(z.exit_code, 0) << z;
}

}  // namespace
