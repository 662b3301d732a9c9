// envmis: precompute, inspect, sample, visualise and benchmark environment-map samplers.
#include <algorithm>
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
    app.set_version_flag("--version", "envmis " ENVMIS_VERSION);
    // A usage error is one line, naming the flag: "envmis: -n: Value -5 not in range 1 to ...".
    app.failure_message(
        [](const CLI::App*, const CLI::Error& e) { return "envmis: " + printable(e.what()) + " (see --help)\n"; });
    const std::vector<Subcommand> subcommands = {add_compare(app), add_report(app), add_precompute(app),
                                                 add_info(app),    add_sample(app), add_visualize(app),
                                                 add_bench(app),   add_convert(app)};
    app.footer("Exit status: 0 success, 1 failure, 2 usage error (nothing started), 128 + N on signal N.");
    if (argc > 1 && argv[1][0] != '-') {
        std::vector<std::string> names;
        for (const Subcommand& s : subcommands) names.push_back(s.app->get_name());
        if (std::find(names.begin(), names.end(), argv[1]) == names.end()) {
            const std::string near = nearest_name(argv[1], names);
            std::cerr << "envmis: unknown command '" << printable(argv[1]) << "'"
                      << (near.empty() ? "" : "; did you mean '" + near + "'?") << " (see --help)\n";
            return kExitUsage;
        }
    }
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        const int status = app.exit(e) == 0 ? 0 : kExitUsage;
        // --help and --version print to standard output: one that cannot take it (full,
        // closed) makes the run a failure, as it does for every command's output.
        if (status == 0 && (std::fflush(stdout) != 0 || std::ferror(stdout) || !std::cout)) {
            std::cerr << "envmis: standard output: " << std::strerror(errno) << "\n";
            return kExitFailure;
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
    } catch (const UsageError& e) {
        std::cerr << "envmis: " << printable(e.what()) << "\n";
        return kExitUsage;
    } catch (const std::bad_alloc&) {
        // The last resort: sizes are checked against free memory before large allocations.
        std::cerr << "envmis: out of memory (try a smaller size, or free memory)\n";
        return kExitFailure;
    } catch (const std::exception& e) {
        // A failure caused by the interruption (a library's read stopped half-way) is the
        // interruption's.
        if (interrupted()) return exit_interrupted(e.what());
        std::cerr << "envmis: " << printable(e.what()) << "\n";
        return kExitFailure;
    }
    // A signal during the last of the work, after its last check, still says so: the
    // outputs are complete, but the exit status must not tell a script the run was whole.
    if (interrupted()) return exit_interrupted("");
    return 0;
}
