// envmis report RESULTS.json... -o OUT.md: one Markdown report from the JSON files of
// `envmis compare` runs (envmis/report/markdown.h reads and writes them).
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <memory>
#include <optional>
#include <sstream>

#include "cli.h"
#include "envmis/build/atomic_file.h"
#include "envmis/report/markdown.h"

namespace envmis::cli {
namespace {

using nlohmann::json;

// The flags of `envmis report`, as CLI11 fills them.
struct ReportArgs {
    std::vector<std::string> inputs;
    std::string output;
    MarkdownOptions markdown;
};

// The results of one compare run in the file at `path`; empty for a library run's summary.
std::optional<json> read_results(const std::string& path) {
    std::error_code ec;
    if (std::filesystem::exists(path, ec) && !std::filesystem::is_regular_file(path, ec))
        throw std::runtime_error(path + ": not a regular file");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error(path + ": cannot open");
    std::ostringstream text;
    text << in.rdbuf();
    if (in.bad()) throw std::runtime_error(path + ": read error");
    return parse_results(text.str(), path);
}

void run_report(const ReportArgs& args) {
    check_outputs({args.inputs.begin(), args.inputs.end()}, {{"-o", args.output}});
    prepare_output(args.output);
    std::vector<json> runs;
    for (const std::string& path : args.inputs) {
        if (std::optional<json> run = read_results(path))
            runs.push_back(std::move(*run));
        else
            std::cerr << "note: " << printable(path)
                      << ": the summary of a library run, not a map's results; skipped\n";
    }
    if (runs.empty()) throw std::runtime_error(args.inputs.front() + ": no results of envmis compare among the inputs");
    write_file_atomically(args.output, [&](std::ostream& out) { write_markdown(out, runs, args.markdown); });
    std::cout << "report: " << args.output << " (" << runs.size() << " runs)\n";
}

}  // namespace

Subcommand add_report(CLI::App& app) {
    auto args = std::make_shared<ReportArgs>();
    CLI::App* sub = app.add_subcommand("report", "Markdown report from the JSON of envmis compare runs (one per map)");
    sub->add_option("results", args->inputs, "JSON files written by envmis compare --json")->required();
    sub->add_option("-o,--output", args->output, "Markdown file to write")->required()->check(non_empty());
    sub->add_option("--title", args->markdown.title, "Title of the report")->capture_default_str();
    sub->add_option("--command", args->markdown.command, "The command that made the results, quoted in the report");
    sub->add_flag("--no-timing", args->markdown.no_timing,
                  "Leave out what measured time decides (ns/estimate, efficiency, the allocation section): the "
                  "report then depends only on the inputs and seeds, e.g. to compare a sharded run with one process");
    sub->add_option("--plots", args->markdown.plots,
                    "Folder, relative to the report, holding each map's plots (MAP/variance_vs_balance.png, ...)");
    return {sub, [args] { run_report(*args); }};
}

}  // namespace envmis::cli
