// Specification of the `envmis` command's outputs under faults: a full disk (a file size
// limit, RLIMIT_FSIZE), standard output that cannot be written (/dev/full), outputs that
// are special files, and the temporaries that killed runs leave. Whatever fails, the
// command says so in one line naming the file, exits non-zero, and leaves nothing at the
// destination and no temporary file. Every test runs the real binary (ENVMIS_CLI).
#include <OpenImageIO/imageio.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "cli_run.h"

namespace {

namespace fs = std::filesystem;
using envmis::test::contains;
using envmis::test::dead_pid;
using envmis::test::expect_one_line_error;
using envmis::test::read_file;
using envmis::test::Result;
using envmis::test::write_text;

const std::string kStudio = (fs::path(ENVMIS_DATA_DIR) / "envmaps" / "studio.exr").string();

class OutputFaults : public envmis::test::TempFolder {
public:
    OutputFaults() : TempFolder("envmis_output_faults_test_") {}

    // Runs envmis with `args` in the test's folder, its standard output written to
    // `stdout_path` (the run's `out` is what that file then holds, if it is one of the
    // folder's), every file it writes limited to `file_size_limit` bytes.
    Result envmis(const std::vector<std::string>& args, const fs::path& stdout_path = {},
                  rlim_t file_size_limit = RLIM_INFINITY) const {
        const fs::path out = stdout_path.empty() ? dir_.parent_path() / (dir_.filename().string() + ".stdout")
                                                 : stdout_path,
                       err = dir_.parent_path() / (dir_.filename().string() + ".stderr");
        std::vector<std::string> argv_text = {ENVMIS_CLI};
        argv_text.insert(argv_text.end(), args.begin(), args.end());
        std::vector<char*> argv;
        for (std::string& a : argv_text) argv.push_back(a.data());
        argv.push_back(nullptr);
        const pid_t pid = ::fork();
        if (pid == 0) {
            const rlimit limit{file_size_limit, RLIM_INFINITY};
            const int out_fd = ::open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644),
                      err_fd = ::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
            if (::chdir(dir_.c_str()) != 0 || out_fd < 0 || err_fd < 0 || ::dup2(out_fd, 1) < 0 ||
                ::dup2(err_fd, 2) < 0 || ::setrlimit(RLIMIT_FSIZE, &limit) != 0)
                ::_exit(126);
            ::execv(argv[0], argv.data());
            ::_exit(127);
        }
        int status = 0;
        ::waitpid(pid, &status, 0);
        Result r;
        for (const std::string& a : args) r.command += " " + a;
        r.command = "envmis" + r.command + (stdout_path.empty() ? "" : " > " + stdout_path.string());
        r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        if (stdout_path.empty()) {
            r.out = read_file(out);
            fs::remove(out);
        }
        r.err = read_file(err);
        fs::remove(err);
        return r;
    }

    // A small map, map.exr (16 x 8), for the tests that let the command do all its work.
    std::string small_map() const {
        std::vector<float> rgb;
        for (int i = 0; i < 16 * 8; ++i) rgb.insert(rgb.end(), {0.1f + i % 7, 0.2f + i % 5, 0.3f + i % 3});
        const OIIO::ImageSpec spec(16, 8, 3, OIIO::TypeDesc::FLOAT);
        auto out = OIIO::ImageOutput::create("openexr");
        const std::string path = file("map.exr").string();
        if (!out || !out->open(path, spec) || !out->write_image(OIIO::TypeDesc::FLOAT, rgb.data()) || !out->close())
            throw std::runtime_error("test setup: cannot write " + path);
        return path;
    }

    // Every name below the test's folder (hidden ones included), relative to it.
    std::set<std::string> listing() const {
        std::set<std::string> names;
        for (const auto& e : fs::recursive_directory_iterator(dir_))
            names.insert(fs::relative(e.path(), dir_).string());
        return names;
    }

    // The names below the test's folder that look like temporaries (".NAME.tmp...").
    std::vector<std::string> temporaries() const {
        std::vector<std::string> found;
        for (const std::string& name : listing())
            if (contains(fs::path(name).filename().string(), R"(^\..*\.tmp)")) found.push_back(name);
        return found;
    }
};

// ---------------------------------------------------------------------------------
// A full disk: every writer's file larger than the limit fails cleanly.

struct FullDiskCase {
    std::string name;
    std::vector<std::string> args;
    std::string output;  // the file that cannot be written, relative to the test's folder
    rlim_t limit;        // bytes per file: far below the output's size, above the error message's
};

void PrintTo(const FullDiskCase& c, std::ostream* os) { *os << c.name; }

class FullDisk : public OutputFaults, public testing::WithParamInterface<FullDiskCase> {};

TEST_P(FullDisk, FailsWithOneLineNamingTheFileAndLeavesNeitherItNorATemporary) {
    const FullDiskCase& c = GetParam();
    fs::create_directory(file("out"));
    const Result r = envmis(c.args, "/dev/null", c.limit);
    expect_one_line_error(r, c.output, "file too large");
    EXPECT_FALSE(fs::exists(file(c.output))) << r;
    EXPECT_EQ(temporaries(), std::vector<std::string>{}) << r;
}

// studio.exr is 1024 x 512: its table, remapped EXR, panels and samples are all far
// larger than 32 KiB; compare's files (of one shading point) than 1 KiB.
constexpr rlim_t kKiB = 1024;
const std::vector<std::string> kComparePoint = {"compare", kStudio, "--normal", "0,0,1", "--spp", "16"};

std::vector<std::string> compare_args(const std::vector<std::string>& more) {
    std::vector<std::string> args = kComparePoint;
    args.insert(args.end(), more.begin(), more.end());
    return args;
}

INSTANTIATE_TEST_SUITE_P(
    Writers, FullDisk,
    testing::Values(
        FullDiskCase{
            "VisualizePng", {"visualize", kStudio, "-o", "out/x.png", "--panel-width", "1024"}, "out/x.png", 32 * kKiB},
        FullDiskCase{"PrecomputeTable", {"precompute", kStudio, "-o", "out/x.envmis"}, "out/x.envmis", 32 * kKiB},
        FullDiskCase{"ConvertExr",
                     {"convert", kStudio, "-o", "out/x.exr", "--to", "equal-area", "--size", "256"},
                     "out/x.exr",
                     32 * kKiB},
        FullDiskCase{"SampleCsv", {"sample", kStudio, "-n", "100000", "-o", "out/x.csv"}, "out/x.csv", 32 * kKiB},
        FullDiskCase{"CompareJson", compare_args({"--json", "out/x.json"}), "out/x.json", kKiB},
        FullDiskCase{"CompareCsv", compare_args({"--csv", "out/x.csv"}), "out/x.csv", kKiB},
        FullDiskCase{"ComparePlotsPng", compare_args({"--plots", "out"}), "out/variance_vs_balance.png", kKiB},
        FullDiskCase{"CompareImagesExr",
                     compare_args({"--images", "out", "--image", "64x16", "--image-spp", "1", "--reference-spp", "1"}),
                     "out/reference.exr", kKiB}),
    [](const testing::TestParamInfo<FullDiskCase>& info) { return info.param.name; });

// ---------------------------------------------------------------------------------
// Standard output that cannot be written is an error, not a lost report.

class FullStandardOutput : public OutputFaults, public testing::WithParamInterface<std::vector<std::string>> {};

TEST_P(FullStandardOutput, ExitsNonZeroSayingSo) {
    const Result r = envmis(GetParam(), "/dev/full");
    expect_one_line_error(r, "standard output", "no space left on device");
}

INSTANTIATE_TEST_SUITE_P(Commands, FullStandardOutput,
                         testing::Values(std::vector<std::string>{"info", kStudio},
                                         std::vector<std::string>{"precompute", kStudio, "-o", "x.envmis"},
                                         kComparePoint, std::vector<std::string>{"--help"},
                                         std::vector<std::string>{"--version"},
                                         std::vector<std::string>{"sample", "--help"}),
                         [](const testing::TestParamInfo<std::vector<std::string>>& info) {
                             std::string name;
                             for (const std::string& a : info.param)
                                 if (a[0] != '/') name += a;
                             std::erase_if(name, [](char c) { return !std::isalnum(static_cast<unsigned char>(c)); });
                             return name;
                         });

// ---------------------------------------------------------------------------------
// Outputs that are not regular files are refused, before any work, and left as they are.

struct Writer {
    std::string subcommand, output;
};
const Writer kWriters[] = {{"sample", "out.csv"}, {"precompute", "out.envmis"}, {"visualize", "out.png"}};

std::vector<std::string> writer_args(const Writer& w, const std::string& output, const std::string& input = kStudio) {
    return {w.subcommand, input, "-o", output};
}

// Every writer, and compare's and report's outputs, named as the input itself, through a
// symbolic link to it and through a hard link: refused, the input's bytes kept.
TEST_F(OutputFaults, AnOutputThatIsTheInputIsRefusedAndTheInputKept) {
    fs::copy_file(kStudio, file("map.exr"));
    fs::create_symlink("map.exr", file("link.exr"));
    fs::create_hard_link(file("map.exr"), file("hard.exr"));
    const std::string original = read_file(file("map.exr"));
    for (const std::string name : {"map.exr", "link.exr", "hard.exr"}) {
        std::vector<std::vector<std::string>> runs;
        for (const Writer& w : kWriters)
            if (w.subcommand != std::string("visualize")) runs.push_back(writer_args(w, name, "map.exr"));
        runs.push_back({"convert", "map.exr", "-o", name});
        runs.push_back({"compare", "map.exr", "--points", "1", "--spp", "4", "--json", name});
        runs.push_back({"compare", "map.exr", "--points", "1", "--spp", "4", "--csv", name});
        runs.push_back({"report", "map.exr", "-o", name});
        for (const auto& args : runs) {
            expect_one_line_error(envmis(args), name, "is the input map.exr; refusing to overwrite an input");
            ASSERT_EQ(read_file(file("map.exr")), original) << args[0] << " " << name;
        }
    }
    EXPECT_TRUE(fs::is_symlink(file("link.exr")));
    EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 3);
    // visualize writes PNG only: a PNG input named as its output, itself or linked.
    ASSERT_EQ(envmis({"visualize", "map.exr", "-o", "map.png", "--panel-width", "64"}).exit_code, 0);
    fs::create_symlink("map.png", file("link.png"));
    fs::create_hard_link(file("map.png"), file("hard.png"));
    const std::string picture = read_file(file("map.png"));
    for (const std::string name : {"map.png", "link.png", "hard.png"}) {
        expect_one_line_error(envmis({"visualize", "map.png", "-o", name}), name,
                              "is the input map.png; refusing to overwrite an input");
        ASSERT_EQ(read_file(file("map.png")), picture) << name;
    }
}

TEST_F(OutputFaults, TwoOutputsOfOneRunThatAreOneFileAreRefused) {
    expect_one_line_error(
        envmis({"compare", kStudio, "--points", "1", "--spp", "4", "--json", "r.txt", "--csv", "./r.txt"}), "r.txt",
        "is also --json's file");
    EXPECT_TRUE(fs::is_empty(dir_));
}

// Library mode: the summary is an output like the maps' (a map named summary.exr would
// write summary.json over it) and is never one of the inputs.
TEST_F(OutputFaults, LibraryModeRefusesASummaryThatIsAnInputOrAMapsOutput) {
    fs::create_directory(file("maps"));
    fs::copy_file(kStudio, file("maps/summary.exr"));
    const Result compare =
        envmis({"compare", "maps", "--out-dir", "out", "--points", "1", "--spp", "4", "--bsdf", "lambert"});
    expect_one_line_error(compare, "summary.json", "is also --summary's file");
    expect_one_line_error(envmis({"precompute", "maps", "-o", "tables", "--summary", "maps/summary.exr"}),
                          "maps/summary.exr", "refusing to overwrite an input");
    EXPECT_EQ(read_file(file("maps/summary.exr")), read_file(kStudio));
    EXPECT_FALSE(fs::exists(file("out/summary.json")));
}

TEST_F(OutputFaults, AFifoAsOutputIsRefusedAndStaysAFifo) {
    for (const Writer& w : kWriters) {
        ASSERT_EQ(::mkfifo(file(w.output).c_str(), 0644), 0);
        expect_one_line_error(envmis(writer_args(w, w.output)), w.output, "is a FIFO, not a regular file");
        EXPECT_TRUE(fs::is_fifo(fs::symlink_status(file(w.output)))) << w.subcommand;
        fs::remove(file(w.output));
        EXPECT_TRUE(fs::is_empty(dir_)) << w.subcommand;
    }
}

TEST_F(OutputFaults, ASymlinkToAFileAsOutputIsRefusedAndItsTargetUntouched) {
    write_text(file("target"), "previous contents");
    for (const Writer& w : kWriters) {
        fs::create_symlink("target", file(w.output));
        expect_one_line_error(envmis(writer_args(w, w.output)), w.output, "is a symbolic link");
        EXPECT_TRUE(fs::is_symlink(file(w.output))) << w.subcommand;
        EXPECT_EQ(read_file(file("target")), "previous contents") << w.subcommand;
        fs::remove(file(w.output));
        EXPECT_EQ(listing(), std::set<std::string>{"target"}) << w.subcommand;
    }
}

TEST_F(OutputFaults, ASymlinkToAFolderAsOutputIsRefused) {
    fs::create_directory(file("folder"));
    for (const Writer& w : kWriters) {
        fs::create_directory_symlink("folder", file(w.output));
        expect_one_line_error(envmis(writer_args(w, w.output)), w.output, "is a symbolic link");
        EXPECT_TRUE(fs::is_symlink(file(w.output))) << w.subcommand;
        fs::remove(file(w.output));
        EXPECT_EQ(listing(), std::set<std::string>{"folder"}) << w.subcommand;
    }
}

// A device like /dev/null (1, 3), made here: mknod needs root (CI runs as root).
TEST_F(OutputFaults, ACharacterDeviceAsOutputIsRefusedAndStaysADevice) {
    for (const Writer& w : kWriters) {
        if (::mknod(file(w.output).c_str(), S_IFCHR | 0666, ::makedev(1, 3)) != 0)
            GTEST_SKIP() << "mknod needs root: " << std::strerror(errno);
        expect_one_line_error(envmis(writer_args(w, w.output)), w.output, "is a character device");
        EXPECT_TRUE(fs::is_character_file(file(w.output))) << w.subcommand;
        fs::remove(file(w.output));
        EXPECT_TRUE(fs::is_empty(dir_)) << w.subcommand;
    }
}

// The output is checked before the input is even read.
TEST_F(OutputFaults, ARefusedOutputIsReportedBeforeAMissingInput) {
    ASSERT_EQ(::mkfifo(file("out.envmis").c_str(), 0644), 0);
    expect_one_line_error(envmis({"precompute", "missing.exr", "-o", "out.envmis"}), "out.envmis", "is a FIFO");
}

TEST_F(OutputFaults, RewritingAPrivateTableKeepsItPrivate) {
    const std::string map = small_map();
    ASSERT_EQ(envmis({"precompute", map, "-o", "t.envmis"}).exit_code, 0);
    fs::permissions(file("t.envmis"), fs::perms::owner_read | fs::perms::owner_write);
    const Result r = envmis({"precompute", map, "-o", "t.envmis"});
    EXPECT_EQ(r.exit_code, 0) << r;
    EXPECT_EQ(fs::status(file("t.envmis")).permissions(), fs::perms::owner_read | fs::perms::owner_write);
}

// ---------------------------------------------------------------------------------
// Killed runs: their temporaries are removed by the next write of the same output.

TEST_F(OutputFaults, TheNextWriteOfAnOutputRemovesTheTemporariesOfKilledRunsAndSaysSo) {
    const std::string dead = std::to_string(dead_pid()), live = std::to_string(::getpid()), map = small_map();
    for (const Writer& w : kWriters) {
        const fs::path out(w.output);
        const std::string hidden = std::string(".").append(out.stem().string()).append(".tmp");
        // Of an envmis that recorded no process id (killed an hour ago), of a dead process, of a live one.
        const std::string old_stale = hidden + "123456789" + out.extension().string(),
                          stale = hidden + dead + "-42" + out.extension().string(),
                          live_one = hidden + live + "-42" + out.extension().string();
        for (const std::string& name : {old_stale, stale, live_one}) write_text(file(name), "partial");
        fs::last_write_time(file(old_stale), fs::file_time_type::clock::now() - std::chrono::hours(1));

        const Result r = envmis(writer_args(w, w.output, map));
        EXPECT_EQ(r.exit_code, 0) << r;
        EXPECT_EQ(listing(), (std::set<std::string>{"map.exr", live_one, w.output})) << r;
        for (const std::string& name : {old_stale, stale})
            EXPECT_TRUE(contains(r.err, "removed .*" + std::regex_replace(name, std::regex(R"(\.)"), R"(\.)")))
                << name << r;
        fs::remove(file(live_one));
        fs::remove(file(w.output));
    }
}

}  // namespace
