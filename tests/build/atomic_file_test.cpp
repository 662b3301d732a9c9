// Specification of atomic file writing (atomic_file.h): what a write leaves behind when
// it succeeds, when it fails, and what it refuses to replace; stale temporaries.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "cli_run.h"
#include "envmis/build/atomic_file.h"

namespace envmis {
namespace {

namespace fs = std::filesystem;
using test::dead_pid;
using test::read_file;
using test::write_text;

// The message of what `f` throws; "" if it does not throw.
template <class F>
std::string thrown(F&& f) {
    try {
        f();
    } catch (const std::runtime_error& e) {
        return e.what();
    }
    return "";
}

class AtomicFileTest : public test::TempFolder {
public:
    AtomicFileTest() : TempFolder("envmis_atomic_file_test_") {}

    std::set<std::string> listing() const {
        std::set<std::string> names;
        for (const auto& e : fs::directory_iterator(dir_)) names.insert(e.path().filename().string());
        return names;
    }
    void write(const fs::path& path, const std::string& text) const {
        write_file_atomically(path, [&](std::ostream& out) { out << text; });
    }
};

TEST_F(AtomicFileTest, ACommittedWriteReplacesTheDestinationAndLeavesNoTemporary) {
    write_text(file("out.csv"), "old");
    write(file("out.csv"), "new contents");
    EXPECT_EQ(read_file(file("out.csv")), "new contents");
    EXPECT_EQ(listing(), std::set<std::string>{"out.csv"});
}

TEST_F(AtomicFileTest, TheTemporaryIsHiddenBesideTheDestinationAndNamesThisProcess) {
    AtomicFile f(file("table.envmis"));
    const std::string name = f.temporary().filename().string(),
                      prefix = ".table.tmp" + std::to_string(::getpid()) + "-";
    EXPECT_EQ(f.temporary().parent_path(), dir_);
    EXPECT_EQ(name.rfind(prefix, 0), 0u) << name;
    EXPECT_TRUE(name.ends_with(".envmis")) << name;
    EXPECT_TRUE(fs::is_regular_file(f.temporary()));
}

TEST_F(AtomicFileTest, AWriterThatThrowsLeavesTheDestinationAndNoTemporary) {
    write_text(file("out.csv"), "old");
    EXPECT_THROW(write_file_atomically(file("out.csv"),
                                       [](std::ostream& out) {
                                           out << "partial";
                                           throw std::runtime_error("interrupted");
                                       }),
                 std::runtime_error);
    EXPECT_EQ(read_file(file("out.csv")), "old");
    EXPECT_EQ(listing(), std::set<std::string>{"out.csv"});
}

// A full disk, made with RLIMIT_FSIZE (the write fails with EFBIG once SIGXFSZ is ignored).
TEST_F(AtomicFileTest, AFailedWriteThrowsNamingTheFileAndLeavesNothing) {
    rlimit saved{};
    ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &saved), 0);
    rlimit small = saved;
    small.rlim_cur = 64 * 1024;
    const auto previous = std::signal(SIGXFSZ, SIG_IGN);
    ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &small), 0);
    const std::string error = thrown([&] { write(file("big.csv"), std::string(1 << 20, 'x')); });
    ::setrlimit(RLIMIT_FSIZE, &saved);
    std::signal(SIGXFSZ, previous);
    EXPECT_NE(error.find(file("big.csv").string() + ": cannot write: File too large"), std::string::npos) << error;
    EXPECT_TRUE(listing().empty());
}

TEST_F(AtomicFileTest, ARewriteKeepsTheDestinationsPermissionsExactly) {
    for (const fs::perms mode : {fs::perms::owner_read | fs::perms::owner_write, fs::perms::all}) {
        write_text(file("t.envmis"), "old");
        fs::permissions(file("t.envmis"), mode);
        write(file("t.envmis"), "new");
        EXPECT_EQ(fs::status(file("t.envmis")).permissions(), mode);
    }
}

TEST_F(AtomicFileTest, ANewFileGetsTheUsualPermissionsUnderTheUmask) {
    const mode_t mask = ::umask(022);
    write(file("new.csv"), "x");
    ::umask(mask);
    EXPECT_EQ(fs::status(file("new.csv")).permissions(), fs::perms(0644));
}

// Each special destination is refused before anything is created, and stays what it was.
TEST_F(AtomicFileTest, AFifoIsRefusedAndStaysAFifo) {
    ASSERT_EQ(::mkfifo(file("fifo").c_str(), 0644), 0);
    const std::string error = thrown([&] { write(file("fifo"), "x"); });
    EXPECT_NE(error.find(file("fifo").string() + ": is a FIFO"), std::string::npos) << error;
    EXPECT_TRUE(fs::is_fifo(fs::symlink_status(file("fifo"))));
    EXPECT_EQ(listing(), std::set<std::string>{"fifo"});
}

TEST_F(AtomicFileTest, ASymlinkToARegularFileIsRefusedAndItsTargetIsUntouched) {
    write_text(file("target.csv"), "target");
    fs::create_symlink("target.csv", file("link.csv"));
    const std::string error = thrown([&] { write(file("link.csv"), "x"); });
    EXPECT_NE(error.find("link.csv: is a symbolic link"), std::string::npos) << error;
    EXPECT_TRUE(fs::is_symlink(file("link.csv")));
    EXPECT_EQ(read_file(file("target.csv")), "target");
    EXPECT_EQ(listing(), (std::set<std::string>{"link.csv", "target.csv"}));
}

TEST_F(AtomicFileTest, ASymlinkToAFolderAndAFolderAreRefused) {
    fs::create_directory(file("folder"));
    fs::create_directory_symlink("folder", file("link"));
    EXPECT_NE(thrown([&] { write(file("link"), "x"); }).find("link: is a symbolic link"), std::string::npos);
    EXPECT_NE(thrown([&] { write(file("folder"), "x"); }).find("folder: is a directory"), std::string::npos);
    EXPECT_TRUE(fs::is_symlink(file("link")) && fs::is_empty(file("folder")));
    EXPECT_EQ(listing(), (std::set<std::string>{"folder", "link"}));
}

// A device made here, like /dev/null (1, 3); mknod needs root (CI runs as root).
TEST_F(AtomicFileTest, ACharacterDeviceIsRefusedAndStaysADevice) {
    if (::mknod(file("null").c_str(), S_IFCHR | 0666, ::makedev(1, 3)) != 0)
        GTEST_SKIP() << "mknod needs root: " << std::strerror(errno);
    const std::string error = thrown([&] { write(file("null"), "x"); });
    EXPECT_NE(error.find("null: is a character device"), std::string::npos) << error;
    EXPECT_TRUE(fs::is_character_file(file("null")));
    EXPECT_EQ(listing(), std::set<std::string>{"null"});
}

TEST_F(AtomicFileTest, TheSystemsNullDeviceIsRefusedByTheCheckAlone) {
    EXPECT_NE(thrown([] { check_destination("/dev/null"); }).find("/dev/null: is a character device"),
              std::string::npos);
}

// Stale temporaries: a dead writer's (this version's names) and one from before this
// run (older names, without a process id) are removed; a live writer's, other
// destinations' and other files are left.
TEST_F(AtomicFileTest, TheNextWriteRemovesOnlyTheStaleTemporariesOfItsDestination) {
    const std::string dead = std::to_string(dead_pid()), live = std::to_string(::getpid());
    const std::set<std::string> stale = {".out.tmp" + dead + "-12345.csv", ".out.tmp3141592653.csv"};
    const std::set<std::string> kept = {".out.tmp" + live + "-12345.csv",  // this process: alive
                                        ".other.tmp" + dead + "-1.csv",    // another destination
                                        ".out.tmp" + dead + "-1.png",      // another extension
                                        ".out.tmpx.csv",                   // not envmis's pattern
                                        ".out.tmp2718.csv",                // older names, but from this run
                                        "out.tmp" + dead + "-1.csv"};      // not hidden
    for (const std::string& name : stale) write_text(file(name), "stale");
    for (const std::string& name : kept) write_text(file(name), "kept");
    const auto before_this_run = fs::file_time_type::clock::now() - std::chrono::hours(1);
    fs::last_write_time(file(".out.tmp3141592653.csv"), before_this_run);

    const std::vector<fs::path> removed = remove_stale_temporaries(file("out.csv"));
    EXPECT_EQ(std::set<fs::path>(removed.begin(), removed.end()),
              (std::set<fs::path>{file(*stale.begin()), file(*stale.rbegin())}));
    write(file("out.csv"), "new");
    std::set<std::string> expected = kept;
    expected.insert("out.csv");
    EXPECT_EQ(listing(), expected);
}

TEST_F(AtomicFileTest, AWriteRemovesStaleTemporariesByItself) {
    const std::string stale = ".out.tmp" + std::to_string(dead_pid()) + "-7.csv";
    write_text(file(stale), "stale");
    write(file("out.csv"), "new");
    EXPECT_EQ(listing(), std::set<std::string>{"out.csv"});
}

}  // namespace
}  // namespace envmis
