// libFuzzer target for `envmis report`'s reader and writer (report/markdown.h): any input
// must either be refused by parse_results (std::runtime_error naming the field) or give a
// report; a writer's exception (a field the reader let through unchecked), a sanitizer
// report or a crash is a finding.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string_view>

#include "envmis/report/markdown.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    std::optional<nlohmann::json> run;
    try {
        run = envmis::parse_results(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz");
    } catch (const std::runtime_error&) {
        return 0;
    }
    if (!run) return 0;
    // Two runs of one map: the cases, their means and the plots' links across runs.
    std::ostringstream out;
    envmis::MarkdownOptions options;
    options.plots = "plots";
    envmis::write_markdown(out, {*run, *run}, options);
    options.no_timing = true;
    envmis::write_markdown(out, {*run}, options);
    return 0;
}
