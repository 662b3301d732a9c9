// Test support: running the built `envmis` command (ENVMIS_CLI, defined for every test
// target) from a test, and a temporary folder for each test. Header-only.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <cstddef>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <ostream>
#include <regex>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

namespace envmis::test {

// The whole file, byte for byte; "" when it cannot be read.
inline std::string read_file(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Replaces `path` with `text`; throws if that fails (a broken test set-up, not a finding).
inline void write_text(const std::filesystem::path& path, const std::string& text) {
    std::ofstream out(path, std::ios::binary);
    out << text;
    if (!out) throw std::runtime_error("test setup: cannot write " + path.string());
}

// A process id that names no process: a child that has exited and been reaped.
inline pid_t dead_pid() {
    const pid_t pid = ::fork();
    if (pid == 0) ::_exit(0);
    ::waitpid(pid, nullptr, 0);
    return pid;
}

// `s` as one word for the POSIX shell, in single quotes.
inline std::string quoted(const std::string& s) {
    std::string q = "'";
    for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

// One run of a command: what was run (for messages), its exit code, stdout and stderr.
struct Result {
    std::string command;
    int exit_code = -1;
    std::string out, err;
};

// Describes a run for failure messages (the first 2000 characters of stdout).
inline std::ostream& operator<<(std::ostream& os, const Result& r) {
    return os << "\n$ " << r.command << "\nexit code " << r.exit_code << "\n--- stdout:\n"
              << r.out.substr(0, 2000) << "--- stderr:\n"
              << r.err;
}

// A regex search, case-insensitive, across lines.
inline bool contains(const std::string& text, const std::string& pattern) {
    return std::regex_search(text, std::regex(pattern, std::regex::icase | std::regex::ECMAScript));
}

// A failure as the user must see it: exit code != 0, nothing on stdout, and one line on
// stderr that names `what` (the file or the flag) and says what is wrong (`problem`, a regex).
inline void expect_one_line_error(const Result& r, const std::string& what, const std::string& problem) {
    EXPECT_NE(r.exit_code, 0) << r;
    EXPECT_EQ(r.out, "") << r;
    EXPECT_TRUE(!r.err.empty() && r.err.back() == '\n' && r.err.find('\n') == r.err.size() - 1)
        << "expected exactly one line on stderr" << r;
    EXPECT_NE(r.err.find(what), std::string::npos) << "stderr does not name " << what << r;
    EXPECT_TRUE(contains(r.err, problem)) << "stderr does not say /" << problem << "/" << r;
}

// Runs the shell command line `command` with its stdout written to `out` and its stderr
// to `err` (both replaced, and left in place), and returns the run with what they hold;
// a command killed by a signal exits 128 + the signal's number, as the shell reports it.
inline Result run_shell(const std::string& command, const std::filesystem::path& out,
                        const std::filesystem::path& err) {
    const int status = std::system((command + " > " + quoted(out.string()) + " 2> " + quoted(err.string())).c_str());
    Result r;
    r.command = command;
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    r.out = read_file(out);
    r.err = read_file(err);
    return r;
}

// Runs envmis with `args`, each passed as one argument, in the folder `dir`; stdout and
// stderr go through the files `out` and `err`, removed afterwards. The run's command
// reads "envmis ARGS..." (unquoted).
inline Result run_envmis(const std::filesystem::path& dir, const std::vector<std::string>& args,
                         const std::filesystem::path& out, const std::filesystem::path& err) {
    std::string command = "cd " + quoted(dir.string()) + " && " + quoted(ENVMIS_CLI);
    std::string shown = "envmis";
    for (const std::string& a : args) {
        command.append(" ").append(quoted(a));
        shown.append(" ").append(a);
    }
    Result r = run_shell(command, out, err);
    r.command = shown;
    std::filesystem::remove(out);
    std::filesystem::remove(err);
    return r;
}

// A fixture giving each test an empty folder of its own, `dir_`, removed afterwards:
// TEMP/PREFIX + PID + "_" + SUITE + "_" + TEST, every character but letters and digits of
// SUITE_TEST made '_'. A test fixture derives from it, passing its prefix.
class TempFolder : public testing::Test {
public:
    void SetUp() override {
        const auto* info = testing::UnitTest::GetInstance()->current_test_info();
        std::string name = std::string(info->test_suite_name()) + "_" + info->name();
        for (char& c : name)
            if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
        dir_ = std::filesystem::temp_directory_path() / (prefix_ + std::to_string(::getpid()) + "_" + name);
        std::filesystem::remove_all(dir_);
        std::filesystem::create_directories(dir_);
    }
    void TearDown() override {
        std::error_code ignored;
        std::filesystem::remove_all(dir_, ignored);
    }

    std::filesystem::path file(const std::string& name) const { return dir_ / name; }

    std::filesystem::path dir_;

protected:
    explicit TempFolder(std::string prefix) : prefix_(std::move(prefix)) {}

private:
    std::string prefix_;
};

}  // namespace envmis::test
