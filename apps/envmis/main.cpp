// envmis: precompute, inspect, sample, visualise and benchmark environment-map samplers.
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <exception>
#include <iostream>
#include <new>
#include <string>
#include <vector>

#include "cli.h"

int main(int argc, char** argv) {
    using namespace envmis::cli;
    // First of all: a signal from here on is seen by the command's first check.
    install_interrupt_handler();
    // Past RLIMIT_FSIZE a write fails with EFBIG, which the writers report and clean up
    // after, instead of the signal killing the process and leaving its temporary file.
    std::signal(SIGXFSZ, SIG_IGN);
    CLI::App app{"envmis: importance sampling of HDR environment maps, with and without MIS compensation"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "envmis 0.1.0");
    // A usage error is one line, naming the flag: "envmis: -n: Value -5 not in range 1 to ...".
    app.failure_message(
        [](const CLI::App*, const CLI::Error& e) { return "envmis: " + printable(e.what()) + " (see --help)\n"; });
    const std::vector<Subcommand> subcommands = {add_compare(app), add_report(app), add_precompute(app),
                                                 add_info(app),    add_sample(app), add_visualize(app),
                                                 add_bench(app),   add_convert(app)};
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        const int status = app.exit(e);
        // --help and --version print to standard output: one that cannot take it (full,
        // closed) makes the run a failure, as it does for every command's output.
        if (status == 0 && (std::fflush(stdout) != 0 || std::ferror(stdout) || !std::cout)) {
            std::cerr << "envmis: standard output: " << std::strerror(errno) << "\n";
            return 1;
        }
        return status;
    }
    try {
        StandardOutput standard_output;
        for (const Subcommand& s : subcommands)
            if (s.app->parsed()) s.run();
        standard_output.finish();
    } catch (const envmis::Interrupted& e) {
        return exit_interrupted(e.what());
    } catch (const std::bad_alloc&) {
        // The last resort: sizes are checked against free memory before large allocations.
        std::cerr << "envmis: out of memory (try a smaller size, or free memory)\n";
        return 1;
    } catch (const std::exception& e) {
        // A failure caused by the interruption (a library's read stopped half-way) is the
        // interruption's.
        if (interrupted()) return exit_interrupted(e.what());
        std::cerr << "envmis: " << printable(e.what()) << "\n";
        return 1;
    }
    // A signal during the last of the work, after its last check, still says so: the
    // outputs are complete, but the exit status must not tell a script the run was whole.
    if (interrupted()) return exit_interrupted("");
    return 0;
}
