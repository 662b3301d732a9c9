// Specification of the `envmis` command on inputs that are valid files but odd or
// absurd: EXR windows, sizes beyond the documented limits or free memory, maps whose
// power overflows float, and names with terminal escape sequences. Every test runs the
// real binary (ENVMIS_CLI) in a temporary folder of its own.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <regex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "cli_run.h"
#include "envmis/cpu.h"

namespace {

namespace fs = std::filesystem;

// AddressSanitizer reserves terabytes of address space for its shadow memory at start-up,
// so a build with it (GCC's __SANITIZE_ADDRESS__; the test and the command are built
// alike) cannot run under `ulimit -v`.
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kAddressSanitizer = true;
#else
constexpr bool kAddressSanitizer = false;
#endif
using envmis::test::contains;
using envmis::test::expect_one_line_error;
using envmis::test::quoted;
using envmis::test::Result;

// Float RGB pixels, row-major from the top, written as a 32-bit float EXR; with a data
// window (x, y, w, h) inside a display window of `display_w` x `display_h` when given.
struct Pixels {
    int w = 0, h = 0;
    std::vector<float> rgb;
};

Pixels constant(int w, int h, float value) { return {w, h, std::vector<float>(size_t(w) * h * 3, value)}; }

void write_exr(const fs::path& path, const Pixels& p, int x = 0, int y = 0, int display_w = 0, int display_h = 0) {
    OIIO::ImageSpec spec(p.w, p.h, 3, OIIO::TypeDesc::FLOAT);
    spec.x = x;
    spec.y = y;
    if (display_w > 0) {
        spec.full_x = spec.full_y = 0;
        spec.full_width = display_w;
        spec.full_height = display_h;
    }
    auto out = OIIO::ImageOutput::create("openexr");
    if (!out || !out->open(path.string(), spec) || !out->write_image(OIIO::TypeDesc::FLOAT, p.rgb.data()) ||
        !out->close())
        throw std::runtime_error("test setup: cannot write " + path.string());
}

class InputFaults : public envmis::test::TempFolder {
public:
    InputFaults() : TempFolder("envmis_input_faults_") {}

    Result envmis(const std::vector<std::string>& args) const {
        return envmis::test::run_envmis(dir_, args, dir_ / "..stdout", dir_ / "..stderr");
    }

    // envmis with its address space limited to `mib` MiB, so that a run that tries to
    // allocate too much fails at once instead of taking the machine's memory (not under
    // AddressSanitizer: the cases using this are refused before any large allocation).
    Result envmis_within(uint64_t mib, const std::vector<std::string>& args) const {
        const std::string limit = kAddressSanitizer ? "" : "ulimit -v " + std::to_string(mib * 1024) + " && ";
        std::string command = "cd " + quoted(dir_.string()) + " && " + limit + quoted(ENVMIS_CLI);
        for (const std::string& a : args)
            command.append(" ").append(quoted(a));  // not " " + ...: GCC 12 warns falsely (-Wrestrict)
        Result r = envmis::test::run_shell(command, dir_ / "..stdout", dir_ / "..stderr");
        fs::remove(dir_ / "..stdout");
        fs::remove(dir_ / "..stderr");
        return r;
    }
};

// ---------------------------------------------------------------------------------
// EXR data and display windows.

TEST_F(InputFaults, ACroppedExrIsReadAsItsDisplayWindowWithANoteNamingIt) {
    write_exr(file("crop.exr"), constant(4, 2, 1.0f), 2, 1, 16, 8);
    const Result r = envmis({"info", "crop.exr"});
    ASSERT_EQ(r.exit_code, 0) << r;
    EXPECT_TRUE(contains(r.out, R"(size +16 x 8\n)")) << r;
    EXPECT_TRUE(contains(r.err, R"(^note: crop\.exr: data window 4x2 at \(2, 1\) differs from the display window)"))
        << r;
}

TEST_F(InputFaults, AnOverscanExrIsCroppedToItsDisplayWindowWithANote) {
    write_exr(file("overscan.exr"), constant(20, 10, 1.0f), -2, -1, 16, 8);
    const Result r = envmis({"convert", "overscan.exr", "-o", "out.exr", "--to", "equirect", "--size", "16x8"});
    ASSERT_EQ(r.exit_code, 0) << r;
    EXPECT_TRUE(contains(r.out, R"(overscan\.exr \(16x8 equirect\))")) << r;
    EXPECT_TRUE(contains(r.err, R"(^note: overscan\.exr: .*data outside it cropped)")) << r;
}

// The display window's black border beside the data's lit texels: the bins' densities
// stay finite there (a black cell beside a lit one), and so does every estimate.
TEST_F(InputFaults, ACroppedExrGivesFiniteBinnedEstimates) {
    write_exr(file("crop.exr"), constant(4, 2, 1.0f), 2, 1, 16, 8);
    const Result r = envmis({"compare", "crop.exr", "--bins", "16", "--points", "8", "--spp", "64", "--bsdf",
                             "lambert,ggx:0.1", "--techniques", "mis-balance,mis-balance-bins"});
    ASSERT_EQ(r.exit_code, 0) << r;
    EXPECT_FALSE(contains(r.out, "(nan|inf)")) << r;
}

// An input that is not a regular file would block (a FIFO without a writer) or never end
// (/dev/zero): refused before any read, naming it.
TEST_F(InputFaults, AnInputThatIsAFifoOrADeviceIsRefusedNamingIt) {
    ASSERT_EQ(::mkfifo(file("pipe.exr").c_str(), 0644), 0);
    for (const std::string& input : {file("pipe.exr").string(), std::string("/dev/zero")})
        for (const std::vector<std::string>& args : {std::vector<std::string>{"info", input},
                                                     {"precompute", input, "-o", "t.envmis"},
                                                     {"sample", input, "-n", "1"},
                                                     {"compare", input, "--points", "1", "--spp", "1"}}) {
            expect_one_line_error(envmis(args), input, "not a regular file");
            EXPECT_FALSE(fs::exists(file("t.envmis")));
        }
}

// A file this process may not read says why, not just that the reader failed (root
// reads everything: skipped there).
TEST_F(InputFaults, AnUnreadableInputSaysPermissionDenied) {
    if (::geteuid() == 0) GTEST_SKIP() << "root may read a file of mode 000";
    write_exr(file("locked.exr"), constant(16, 8, 1.0f));
    fs::permissions(file("locked.exr"), fs::perms::none);
    for (const std::vector<std::string>& args :
         {std::vector<std::string>{"info", "locked.exr"}, {"precompute", "locked.exr", "-o", "t.envmis"}})
        expect_one_line_error(envmis(args), "locked.exr", R"(cannot read \(Permission denied\))");
}

// ---------------------------------------------------------------------------------
// Sizes: each checked against its documented limit and free memory before allocating.

// A header can declare any size: the map it would make is checked against the memory
// available from the header alone, before a pixel is read, naming the file and its size.
class HugeHeader : public InputFaults, public testing::WithParamInterface<std::string> {};

TEST_P(HugeHeader, IsRefusedFromItsHeaderNamingTheFileAndItsSize) {
    if (kAddressSanitizer) GTEST_SKIP() << "needs ulimit -v, which AddressSanitizer cannot run under";
    // A Radiance header of 30000 x 30000 (no pixels follow), and an EXR whose display
    // window is 32768 x 32768 around one stored texel.
    envmis::test::write_text(file("huge.hdr"), "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 30000 +X 30000\n");
    write_exr(file("window.exr"), constant(1, 1, 1.0f), 0, 0, 32768, 32768);
    for (const auto& [name, size] : {std::pair{"huge.hdr", "30000x30000"}, {"window.exr", "32768x32768"}}) {
        std::vector<std::string> args = {GetParam(), name};
        if (GetParam() == "precompute") args.insert(args.end(), {"-o", "out"});
        if (GetParam() == "convert") args.insert(args.end(), {"-o", "out.exr"});
        if (GetParam() == "compare") args.insert(args.end(), {"--points", "1", "--spp", "1"});
        const Result r = envmis_within(4096, args);
        expect_one_line_error(r, std::string(name) + " (" + size + ")",
                              R"(needs \d+ MB of memory, more than the \d+ MB available)");
        EXPECT_FALSE(fs::exists(file("out")));
        EXPECT_FALSE(fs::exists(file("out.exr")));
    }
}

INSTANTIATE_TEST_SUITE_P(Commands, HugeHeader, testing::Values("info", "precompute", "compare", "sample", "convert"));

// The panels keep the map's aspect, at most 4096 pixels high: a map too tall for that is refused.
TEST_F(InputFaults, VisualizeRefusesAMapFarTallerThanWideNamingItAndTheLimit) {
    write_exr(file("tall.exr"), constant(1, 8192, 1.0f));
    const Result r = envmis_within(4096, {"visualize", "tall.exr", "-o", "tall.png"});
    expect_one_line_error(r, "tall.exr", R"(1x8192 map is too tall to draw: at most 64 times taller than wide)");
    EXPECT_FALSE(fs::exists(file("tall.png")));
}

TEST_F(InputFaults, ConvertRefusesAnOutputAboveTheTexelLimitNamingTheFlag) {
    write_exr(file("map.exr"), constant(16, 8, 1.0f));
    const Result r = envmis_within(4096, {"convert", "map.exr", "-o", "out.exr", "--size", "65536"});
    expect_one_line_error(r, "--size 65536", R"(65536x65536 is 4294967296 texels, above the limit of 2147483648)");
    EXPECT_FALSE(fs::exists(file("out.exr")));
}

// Memory is the address space ulimit leaves (or MemAvailable, whichever is smaller).
TEST_F(InputFaults, ConvertRefusesAnOutputAboveFreeMemoryNamingTheFlag) {
    if (kAddressSanitizer) GTEST_SKIP() << "needs ulimit -v, which AddressSanitizer cannot run under";
    write_exr(file("map.exr"), constant(16, 8, 1.0f));
    const Result r = envmis_within(1024, {"convert", "map.exr", "-o", "out.exr", "--size", "20000"});
    expect_one_line_error(r, "--size 20000", R"(needs 21363 MB of memory, more than the \d+ MB available)");
    EXPECT_FALSE(fs::exists(file("out.exr")));
}

TEST_F(InputFaults, BenchRefusesASkyAboveTheTexelLimitNamingTheFlag) {
    const Result r = envmis_within(4096, {"bench", "--size", "65536x65536"});
    expect_one_line_error(r, "--size 65536x65536", "above the limit of 2147483648");
}

// A process bound to one CPU (taskset, a batch system's binding) runs one worker by
// default, and its JSON says so.
TEST_F(InputFaults, CompareBoundToOneCpuRecordsOneThread) {
    if (std::system("command -v taskset > /dev/null 2>&1") != 0) GTEST_SKIP() << "no taskset";
    write_exr(file("map.exr"), constant(16, 8, 1.0f));
    const std::string command = "cd " + quoted(dir_.string()) + " && taskset -c 0 " + quoted(ENVMIS_CLI) +
                                " compare map.exr --points 1 --spp 4 --bsdf lambert --json out.json";
    const Result r = envmis::test::run_shell(command, dir_ / "..stdout", dir_ / "..stderr");
    ASSERT_EQ(r.exit_code, 0) << r;
    EXPECT_TRUE(std::regex_search(envmis::test::read_file(file("out.json")), std::regex("\"threads\": 1[,\n ]")))
        << envmis::test::read_file(file("out.json"));
}

TEST_F(InputFaults, CompareUsesAtMostFourThreadsPerUsableCoreWithANote) {
    const unsigned cores = envmis::usable_cores();
    if (4 * cores >= 1024) GTEST_SKIP() << cores << " hardware threads: --threads 1024 is within the limit";
    write_exr(file("map.exr"), constant(16, 8, 1.0f));
    const Result r = envmis({"compare", "map.exr", "--points", "1", "--spp", "4", "--bsdf", "lambert", "--threads",
                             "1024", "--json", "out.json"});
    ASSERT_EQ(r.exit_code, 0) << r;
    EXPECT_TRUE(contains(r.err, "note: --threads 1024: more than 4 per usable core \\(" + std::to_string(cores) +
                                    "\\); using " + std::to_string(4 * cores) + "\n"))
        << r;
}

// ---------------------------------------------------------------------------------
// Overflow: finite pixels whose power does not fit a float.

class OverflowingMap : public InputFaults, public testing::WithParamInterface<std::vector<std::string>> {};

TEST_P(OverflowingMap, IsAnErrorNamingTheMapAndTheFix) {
    write_exr(file("bright.exr"), constant(32, 16, 3e38f));
    const Result r = envmis(GetParam());
    expect_one_line_error(r, "bright.exr", R"(luminance overflows.*scale the map down \(e\.g\. multiply it by 1e-3\))");
    EXPECT_FALSE(fs::exists(file("out")));
}

INSTANTIATE_TEST_SUITE_P(Commands, OverflowingMap,
                         testing::Values(std::vector<std::string>{"precompute", "bright.exr", "-o", "out"},
                                         std::vector<std::string>{"info", "bright.exr"},
                                         std::vector<std::string>{"compare", "bright.exr", "--points", "2", "--spp",
                                                                  "8", "--json", "out"}),
                         [](const testing::TestParamInfo<std::vector<std::string>>& info) { return info.param[0]; });

// A sun near float's maximum can overflow its row's float sums though the map's power
// fits: the map must work, with finite statistics.
TEST_F(InputFaults, ASunNearFloatsMaximumStillGivesFiniteStatistics) {
    Pixels p = constant(128, 64, 1.0f);
    for (int x = 40; x < 72; ++x)
        for (int c = 0; c < 3; ++c) p.rgb[(32 * 128 + x) * 3 + c] = 3e38f;
    write_exr(file("sun.exr"), p);
    const Result r = envmis({"precompute", "sun.exr", "-o", "sun.envmis"});
    ASSERT_EQ(r.exit_code, 0) << r;
    EXPECT_TRUE(contains(r.out, "fallback +none")) << r;
    EXPECT_FALSE(contains(r.out, R"(  (luminance|mean \(Lbar\)|compensation) .*(nan|inf))")) << r;
}

// ---------------------------------------------------------------------------------
// Names read from files are printed with their control characters escaped.

TEST_F(InputFaults, InfoEscapesControlCharactersInTheSourceName) {
    const std::string name = "evil\x1b]0;owned\x07\x1b[2J.exr";
    write_exr(file(name), constant(16, 8, 1.0f));
    ASSERT_EQ(envmis({"precompute", name, "-o", "t.envmis"}).exit_code, 0);
    const Result r = envmis({"info", "t.envmis"});
    ASSERT_EQ(r.exit_code, 0) << r;
    EXPECT_EQ(r.out.find('\x1b'), std::string::npos) << r;
    EXPECT_EQ(r.out.find('\x07'), std::string::npos) << r;
    EXPECT_NE(r.out.find(R"(source        evil\x1b]0;owned\x07\x1b[2J.exr (envmis table)"), std::string::npos) << r;
}

// Error messages name files as given; their control characters (which can retitle or
// clear a terminal) are escaped like those of names read from tables.
TEST_F(InputFaults, AnErrorNamingAFileEscapesItsControlCharacters) {
    const std::string name = "evil\x1b]0;owned\x07.exr";
    for (const std::vector<std::string>& args :
         {std::vector<std::string>{"info", name}, {"precompute", name, "-o", "t.envmis"}}) {
        const Result r = envmis(args);
        EXPECT_NE(r.exit_code, 0) << r;
        EXPECT_EQ(r.err.find('\x1b'), std::string::npos) << r;
        EXPECT_EQ(r.err.find('\x07'), std::string::npos) << r;
        EXPECT_NE(r.err.find(R"(evil\x1b]0;owned\x07.exr)"), std::string::npos) << r;
    }
}

}  // namespace
