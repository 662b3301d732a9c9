// Specification of how `envmis` stops when interrupted: SIGINT or SIGTERM, sent while a
// long command is in the middle of its work, ends it within about a second with exit
// status 128 + the signal (130, 143) and one line on stderr, leaving no temporary file
// and no result that does not say it is partial.
//
// Each test starts the real binary (ENVMIS_CLI) with ENVMIS_PROGRESS=1, which makes it
// print a line on stderr as each phase starts ("building bins   0%"), waits for the line
// of the phase under test, lets the phase run a little longer, and signals it.
#include <OpenImageIO/imageio.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <chrono>
#include <filesystem>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "cli_run.h"

extern char** environ;

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

// How long a run may take to stop once signalled: about a second, with room for a
// loaded machine.
constexpr auto kStopWithin = 2s;
// How long a run may take to reach the phase under test.
constexpr auto kReachWithin = 10s;
// How long the phase runs before the signal: well inside its work.
constexpr auto kIntoThePhase = 300ms;

// A 32-bit float RGB EXR of w x h texels, uneven so that every build has work to do.
void write_exr(const fs::path& path, int w, int h) {
    std::vector<float> rgb;
    for (int i = 0; i < w * h; ++i) rgb.insert(rgb.end(), {0.1f + i % 7, 0.2f + i % 5, 0.3f + i % 3});
    OIIO::ImageSpec spec(w, h, 3, OIIO::TypeDesc::FLOAT);
    auto out = OIIO::ImageOutput::create("openexr");
    if (!out || !out->open(path.string(), spec) || !out->write_image(OIIO::TypeDesc::FLOAT, rgb.data()) ||
        !out->close())
        throw std::runtime_error("test setup: cannot write " + path.string());
}

// What an interrupted run did: its exit status (-1 if a signal ended it, or if it had to
// be killed), how long it took to stop once signalled, and its output.
struct Stopped {
    int exit_code = -1;
    bool reached = false;  // the phase's line appeared
    Clock::duration stop_time{};
    std::string out, err;
};

std::ostream& operator<<(std::ostream& os, const Stopped& s) {
    return os << "\nexit code " << s.exit_code << ", phase reached " << s.reached << ", stopped after "
              << std::chrono::duration<double>(s.stop_time).count() << " s\n--- stdout:\n"
              << s.out.substr(0, 2000) << "--- stderr:\n"
              << s.err.substr(0, 2000);
}

class Interrupt : public envmis::test::TempFolder {
public:
    Interrupt() : TempFolder("envmis_interrupt_test_") {}

    // Runs envmis `args` in the test's folder, sends `signal` once stderr shows `phase`
    // and kIntoThePhase more have passed, and waits for the run to end (killing it if it
    // has not after kStopWithin and as long again).
    Stopped interrupt(const std::vector<std::string>& args, const std::string& phase, int signal,
                      Clock::duration reach_within = kReachWithin) const {
        const std::string cli = ENVMIS_CLI, out = (dir_ / "..stdout").string(), err = (dir_ / "..stderr").string();
        std::vector<const char*> argv = {cli.c_str()};
        for (const std::string& a : args) argv.push_back(a.c_str());
        argv.push_back(nullptr);
        std::vector<std::string> environment = {"ENVMIS_PROGRESS=1"};
        for (char** e = environ; *e; ++e)
            if (std::string(*e).rfind("ENVMIS_PROGRESS=", 0) != 0) environment.push_back(*e);
        std::vector<const char*> envp;
        for (const std::string& e : environment) envp.push_back(e.c_str());
        envp.push_back(nullptr);

        posix_spawn_file_actions_t files;
        posix_spawn_file_actions_init(&files);
        posix_spawn_file_actions_addopen(&files, STDOUT_FILENO, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        posix_spawn_file_actions_addopen(&files, STDERR_FILENO, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        // posix_spawn has no portable chdir: the tests give absolute paths.
        pid_t pid = 0;
        const int spawned = posix_spawn(&pid, cli.c_str(), &files, nullptr, const_cast<char* const*>(argv.data()),
                                        const_cast<char* const*>(envp.data()));
        posix_spawn_file_actions_destroy(&files);
        if (spawned != 0) throw std::runtime_error("test setup: cannot start " + cli);

        Stopped s;
        int status = 0;
        bool ended = false;
        for (const auto deadline = Clock::now() + reach_within; Clock::now() < deadline;) {
            if (::waitpid(pid, &status, WNOHANG) == pid) {
                ended = true;
                break;
            }
            if (envmis::test::read_file(err).find(phase) != std::string::npos) {
                s.reached = true;
                break;
            }
            std::this_thread::sleep_for(10ms);
        }
        if (!ended) {
            std::this_thread::sleep_for(kIntoThePhase);
            ::kill(pid, signal);
            const auto signalled = Clock::now();
            while (!(ended = ::waitpid(pid, &status, WNOHANG) == pid) && Clock::now() < signalled + 2 * kStopWithin)
                std::this_thread::sleep_for(10ms);
            s.stop_time = Clock::now() - signalled;
            if (!ended) {
                ::kill(pid, SIGKILL);
                ::waitpid(pid, &status, 0);
            }
        }
        s.exit_code = ended && WIFEXITED(status) ? WEXITSTATUS(status) : -1;
        s.out = envmis::test::read_file(out);
        s.err = envmis::test::read_file(err);
        fs::remove(out);
        fs::remove(err);
        return s;
    }

    // The names in the test's folder, or in `sub` inside it (hidden ones included).
    std::set<std::string> listing(const std::string& sub = "") const {
        std::set<std::string> names;
        for (const auto& e : fs::directory_iterator(dir_ / sub)) names.insert(e.path().filename().string());
        return names;
    }

    std::string path(const std::string& name) const { return file(name).string(); }
};

// The run stopped on its own, quickly, as the signal asks, saying so in one line.
void expect_stopped_by(const Stopped& s, int signal) {
    EXPECT_TRUE(s.reached) << "the run never reached the phase under test" << s;
    EXPECT_EQ(s.exit_code, 128 + signal) << s;
    EXPECT_LT(s.stop_time, kStopWithin) << s;
    const std::string line = std::string("envmis: interrupted by ") + (signal == SIGTERM ? "SIGTERM" : "SIGINT");
    EXPECT_NE(s.err.find(line), std::string::npos) << s;
}

TEST_F(Interrupt, APrecomputeSignalledWhileBuildingBinsExits130AndLeavesNoTable) {
    write_exr(file("map.exr"), 512, 256);
    const Stopped s =
        interrupt({"precompute", path("map.exr"), "-o", path("map.envmis"), "--bins", "4096"}, "building bins", SIGINT);
    expect_stopped_by(s, SIGINT);
    EXPECT_EQ(listing(), std::set<std::string>{"map.exr"});
}

TEST_F(Interrupt, AConvertSignalledWhileRemappingExits143AndLeavesNoImage) {
    write_exr(file("map.exr"), 256, 128);
    const Stopped s = interrupt({"convert", path("map.exr"), "-o", path("out.exr"), "--to", "equal-area", "--size",
                                 "1024", "--supersampling", "64"},
                                "remapping", SIGTERM);
    expect_stopped_by(s, SIGTERM);
    EXPECT_EQ(listing(), std::set<std::string>{"map.exr"});
}

TEST_F(Interrupt, AVisualizeSignalledWhileBuildingItsBinsExits130AndLeavesNoPicture) {
    write_exr(file("map.exr"), 512, 256);
    const Stopped s =
        interrupt({"visualize", path("map.exr"), "-o", path("map.png"), "--normal", "0,0,1", "--bins", "4096"},
                  "building bins", SIGINT);
    expect_stopped_by(s, SIGINT);
    EXPECT_EQ(listing(), std::set<std::string>{"map.exr"});
}

// One shading point of a billion estimates: the signal arrives inside the point's
// estimate loop, long before the first point is done.
std::vector<std::string> endless_compare(const Interrupt& t) {
    return {"compare", t.path("map.exr"), "--spp",        "1000000000",      "--points",  "3",
            "--bsdf",  "lambert",         "--techniques", "mis-balance,env", "--threads", "2",
            "--json",  t.path("r.json"),  "--csv",        t.path("r.csv"),   "--plots",   t.path("plots")};
}

TEST_F(Interrupt, ACompareSignalledInsideAPointExits130AndWritesNoResults) {
    write_exr(file("map.exr"), 32, 16);
    const Stopped s = interrupt(endless_compare(*this), "compare   0%", SIGINT);
    expect_stopped_by(s, SIGINT);
    EXPECT_NE(s.err.find("0 of 3 points"), std::string::npos) << s;
    EXPECT_NE(s.out.find("interrupted"), std::string::npos) << "stdout must say its table is partial" << s;
    // --plots made its folder before the study; nothing was written into it.
    EXPECT_EQ(listing(), (std::set<std::string>{"map.exr", "plots"}));
    EXPECT_TRUE(fs::is_empty(file("plots")));
}

TEST_F(Interrupt, ACompareSignalledWithSigtermExits143AndWritesNoResults) {
    write_exr(file("map.exr"), 32, 16);
    const Stopped s = interrupt(endless_compare(*this), "compare   0%", SIGTERM);
    expect_stopped_by(s, SIGTERM);
    EXPECT_EQ(listing(), (std::set<std::string>{"map.exr", "plots"}));
    EXPECT_TRUE(fs::is_empty(file("plots")));
}

// The exact variances' quadratures (--exact) run over every texel at every point: on a
// 2048x1024 map and 128 points, about 3 s per technique, stopped within a row. The study
// before them takes about 9 s (its references are quadratures too).
TEST_F(Interrupt, ACompareSignalledInItsExactVariancesExits130) {
    write_exr(file("map.exr"), 2048, 1024);
    const Stopped s = interrupt({"compare", path("map.exr"), "--exact", "--spp", "16", "--points", "128", "--bsdf",
                                 "lambert", "--techniques", "mis-balance,mis-balance-comp", "--json", path("r.json")},
                                "exact variances", SIGINT, 60s);
    expect_stopped_by(s, SIGINT);
    EXPECT_EQ(listing(), std::set<std::string>{"map.exr"});
}

// ---------------------------------------------------------------------------------
// Library mode: one job (--jobs 1) over maps/ in name order, a.hdr (not an image: it
// fails at once), b.exr, c.exr; signalled once the bar says a third of the maps is done,
// inside b's work. The run still writes its summary, saying what became of each map.

// Each map's status in the summary at `path`, by input file name.
std::map<std::string, std::string> summary_statuses(const fs::path& path) {
    const nlohmann::json summary = nlohmann::json::parse(envmis::test::read_file(path));
    std::map<std::string, std::string> statuses;
    for (const nlohmann::json& entry : summary.at("results"))
        statuses[fs::path(entry.at("input").get<std::string>()).filename().string()] = entry.at("status");
    return statuses;
}

const std::map<std::string, std::string> kStoppedInB = {
    {"a.hdr", "failed"}, {"b.exr", "interrupted"}, {"c.exr", "not started"}};

void make_library(const Interrupt& t, int w, int h) {
    fs::create_directories(t.file("maps"));
    envmis::test::write_text(t.file("maps/a.hdr"), "#?RADIANCE\nnot an image\n");
    write_exr(t.file("maps/b.exr"), w, h);
    write_exr(t.file("maps/c.exr"), w, h);
}

TEST_F(Interrupt, ALibraryPrecomputeSignalledInsideAMapExits130AndSummarisesEveryMap) {
    make_library(*this, 512, 256);
    // Bins over a fine cell grid: b's build takes many seconds.
    const Stopped s = interrupt(
        {"precompute", path("maps"), "-o", path("out"), "--jobs", "1", "--bins", "4096", "--cell-columns", "256"},
        "3 maps  33%", SIGINT);
    expect_stopped_by(s, SIGINT);
    EXPECT_NE(s.err.find("1 of 3 maps done, listed in " + path("out/summary.json")), std::string::npos) << s;
    ASSERT_TRUE(fs::exists(file("out/summary.json"))) << s;
    EXPECT_EQ(summary_statuses(file("out/summary.json")), kStoppedInB);
    // No table, whole or half-written, and no temporary: only the summary.
    EXPECT_EQ(listing("out"), std::set<std::string>{"summary.json"});
}

TEST_F(Interrupt, ALibraryCompareSignalledInsideAMapExits130AndSummarisesEveryMap) {
    make_library(*this, 32, 16);
    const Stopped s =
        interrupt({"compare", path("maps"), "--out-dir", path("out"), "--jobs", "1", "--spp", "1000000000", "--points",
                   "3", "--bsdf", "lambert", "--techniques", "mis-balance,env", "--csv", path("out/csv")},
                  "3 maps  33%", SIGTERM);
    expect_stopped_by(s, SIGTERM);
    EXPECT_NE(s.err.find("1 of 3 maps done, listed in " + path("out/summary.json")), std::string::npos) << s;
    ASSERT_TRUE(fs::exists(file("out/summary.json"))) << s;
    EXPECT_EQ(summary_statuses(file("out/summary.json")), kStoppedInB);
    // No JSON or CSV of b's partial study, and no temporary.
    EXPECT_EQ(listing("out"), (std::set<std::string>{"csv", "summary.json"}));
    EXPECT_TRUE(fs::is_empty(file("out/csv")));
}

}  // namespace
