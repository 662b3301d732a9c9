#include "library.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <iostream>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <thread>

#include <OpenImageIO/imageio.h>

#include "cli.h"
#include "envmis/build/atomic_file.h"
#include "envmis/cpu.h"
#include "envmis/io/image_io.h"
#include "envmis/table/table.h"

namespace envmis::cli {
namespace fs = std::filesystem;

namespace {

std::string lower(std::string text) {
    std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return std::tolower(c); });
    return text;
}

// The extensions OpenImageIO's readers claim ("openexr:exr,sxr;hdr:hdr,rgbe;..."), with the dot.
std::set<std::string> image_extensions() {
    std::set<std::string> extensions;
    const std::string list = OIIO::get_string_attribute("extension_list");
    std::stringstream formats(list);
    for (std::string format; std::getline(formats, format, ';');) {
        std::stringstream names(format.substr(format.find(':') + 1));
        for (std::string name; std::getline(names, name, ',');)
            if (!name.empty()) extensions.insert("." + lower(name));
    }
    return extensions;
}

std::vector<fs::path> folder_files(const fs::path& folder, bool recursive, const std::set<std::string>& extensions) {
    std::vector<fs::path> files;
    std::error_code ec;
    const auto keep = [&](const fs::directory_entry& entry) {
        std::error_code type_ec;
        if (entry.is_regular_file(type_ec) && extensions.count(lower(entry.path().extension().string())))
            files.push_back(entry.path());
    };
    if (recursive) {
        for (fs::recursive_directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) keep(*it);
    } else {
        for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) keep(*it);
    }
    if (ec) throw std::runtime_error(folder.string() + ": cannot read the folder: " + ec.message());
    if (files.empty())
        throw std::runtime_error(folder.string() +
                                 ": a directory without image files (a folder input gives every file in it that "
                                 "OpenImageIO reads)");
    std::sort(files.begin(), files.end());
    return files;
}

}  // namespace

std::vector<fs::path> expand_inputs(const std::vector<std::string>& inputs, bool recursive, bool tables) {
    std::set<std::string> extensions = image_extensions();
    if (tables) extensions.insert(".envmis");
    std::vector<fs::path> files;
    for (const std::string& input : inputs) {
        std::error_code ec;
        if (!fs::is_directory(input, ec)) {
            files.emplace_back(input);
            continue;
        }
        const std::vector<fs::path> found = folder_files(input, recursive, extensions);
        files.insert(files.end(), found.begin(), found.end());
    }
    return files;
}

std::vector<LibraryItem> plan_outputs(const std::vector<fs::path>& inputs, const fs::path& dir,
                                      const std::string& extension) {
    std::vector<LibraryItem> items;
    std::map<fs::path, fs::path> writer;  // output -> its input
    for (const fs::path& input : inputs) {
        const fs::path output = dir / (input.stem().string() + extension);
        const auto [it, added] = writer.emplace(output, input);
        if (!added)
            throw std::runtime_error(it->second.string() + " and " + input.string() + ": both would write " +
                                     output.string() + " (rename one, or run them separately)");
        items.push_back({input, output});
    }
    return items;
}

CLI::Option* add_jobs_flag(CLI::App& app, uint32_t& jobs) {
    jobs = usable_cores();
    return app
        .add_option("--jobs", jobs,
                    "With several inputs or a folder: maps run at once, 1 to 1024 (default: the core count)")
        ->check(in_range(uint32_t{1}, kMaxJobs))
        ->capture_default_str();
}

std::string hash_text(uint64_t hash) {
    char text[17];
    std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(hash));
    return text;
}

namespace {

// A failure's message, naming the file where the error itself does not.
std::string naming(const fs::path& input, const std::string& message) {
    return message.find(input.string()) == std::string::npos ? input.string() + ": " + message : message;
}

// Admits maps to run while their estimated needs fit together in the memory that was
// available when no map ran; a map that does not fit waits for running ones to finish.
// Nothing running, a map is checked alone against the memory available then, as
// check_memory does, and so never waits for ever.
class MemoryGate {
public:
    // True once `need` bytes are admitted (release them after); false if a signal arrived
    // while waiting. Throws check_memory's error for a map that does not fit alone.
    bool admit(const fs::path& input, uint64_t need) {
        std::unique_lock guard(lock_);
        while (running_ > 0 && budget_ && held_ + need > *budget_) {
            if (interrupted()) return false;
            // A signal does not notify: look again at least every 100 ms.
            changed_.wait_for(guard, std::chrono::milliseconds(100));
        }
        if (running_ == 0) {
            budget_ = available_memory();
            check_memory(input.string(), need);
        }
        ++running_, held_ += need;
        return true;
    }
    // Releases what admit took, on every way out of the map's job.
    struct Admitted {
        MemoryGate& gate;
        uint64_t need;
        ~Admitted() { gate.release(need); }
    };

private:
    void release(uint64_t need) {
        {
            const std::lock_guard guard(lock_);
            --running_, held_ -= need;
        }
        changed_.notify_all();
    }

    std::mutex lock_;
    std::condition_variable changed_;
    std::optional<uint64_t> budget_;  // empty: unknown (not Linux, no limit), every map admitted
    uint64_t held_ = 0;
    uint32_t running_ = 0;
};

// The output of a map whose job failed, where it is shown not to match its input: the
// input could not be read (no hash), or run.up_to_date says it holds other results.
// Removed, so that the folder never holds an output that looks valid beside a failure.
// True if removed.
bool remove_stale_output(const LibraryRun& run, const fs::path& output, std::optional<uint64_t> hash) {
    std::error_code ec;
    if (!fs::is_regular_file(fs::symlink_status(output, ec))) return false;
    if (hash && run.up_to_date && run.up_to_date(output, *hash)) return false;
    return fs::remove(output, ec);
}

// One map through `job` once the gate admits it, timed, its failure caught: the summary's entry.
nlohmann::json run_one(const LibraryItem& item, const MapJob& job, MemoryGate& gate, const LibraryRun& run,
                       MapOutcome& outcome, std::string& error) {
    nlohmann::json entry = {{"input", item.input.string()}, {"output", item.output.string()}};
    auto start = std::chrono::steady_clock::now();
    std::optional<uint64_t> hash;
    bool unreadable = false;  // the input itself failed to be read
    try {
        const uint64_t need = header_texels(item.input) * run.bytes_per_texel;
        if (!gate.admit(item.input, need)) return entry;
        const MemoryGate::Admitted admitted{gate, need};
        start = std::chrono::steady_clock::now();
        std::error_code ec;
        const uintmax_t bytes = fs::file_size(item.input, ec);
        if (!ec) entry["input_bytes"] = bytes;
        try {
            hash = io::hash_file(item.input, &interrupted());
        } catch (const io::ImageError&) {
            unreadable = true;
            throw;
        }
        entry["source_hash"] = hash_text(*hash);
        outcome = job(item, *hash);
        entry["status"] = outcome.status;
        entry["details"] = std::move(outcome.details);
    } catch (const Interrupted&) {
        entry["status"] = "interrupted";
    } catch (const std::exception& e) {
        entry["status"] = interrupted() ? "interrupted" : "failed";
        if (!interrupted()) {
            error = naming(item.input, e.what());
            if ((hash || unreadable) && remove_stale_output(run, item.output, hash)) {
                error += " (its earlier output " + item.output.string() + " was removed: it no longer matches)";
                entry["removed_output"] = true;
            }
            entry["error"] = error;
        }
    }
    entry["seconds"] = milliseconds_since(start) / 1e3;
    return entry;
}

void write_summary(const LibraryRun& run, const std::vector<nlohmann::json>& entries) {
    std::map<std::string, size_t> counts;
    for (const nlohmann::json& e : entries) ++counts[e.value("status", "not started")];
    nlohmann::json summary = {
        {"envmis_summary", run.command}, {"maps", entries.size()}, {"counts", counts}, {"results", entries}};
    write_file_atomically(run.summary, [&](std::ostream& out) { out << summary.dump(2) << "\n"; });
}

}  // namespace

void run_library(const std::vector<LibraryItem>& items, const LibraryRun& run, const MapJob& job) {
    std::vector<std::filesystem::path> inputs;
    std::vector<NamedOutput> outputs{{"--summary", run.summary}};
    for (const LibraryItem& item : items)
        inputs.push_back(item.input), outputs.push_back({"the output of " + item.input.string(), item.output});
    check_outputs(inputs, outputs);
    prepare_output(run.summary);
    std::vector<nlohmann::json> entries(items.size());
    for (size_t i = 0; i < items.size(); ++i)
        entries[i] = {
            {"input", items[i].input.string()}, {"output", items[i].output.string()}, {"status", "not started"}};
    std::mutex lock;  // guards the progress bar, the entries and the standard streams
    size_t done = 0, failed = 0;
    std::optional<Progress> progress(std::in_place, run.command + " " + std::to_string(items.size()) + " maps",
                                     items.size());
    std::atomic<size_t> next{0};
    MemoryGate gate;
    const auto worker = [&] {
        for (size_t i; !interrupted() && (i = next++) < items.size();) {
            MapOutcome outcome;
            std::string error;
            nlohmann::json entry = run_one(items[i], job, gate, run, outcome, error);
            if (!entry.contains("status")) continue;  // a signal arrived while it waited: not started
            const std::lock_guard guard(lock);
            std::cerr << outcome.notes;
            if (!error.empty()) std::cerr << "envmis: " << printable(error) << "\n", ++failed;
            std::cout << outcome.printed << std::flush;
            // A map stopped by the signal is not done: the message after the run says so.
            if (entry["status"] != "interrupted") progress->update(++done);
            entries[i] = std::move(entry);
        }
    };
    {
        std::vector<std::jthread> pool;
        const size_t threads = std::min<size_t>(run.jobs, items.size());
        for (size_t t = 1; t < threads; ++t) pool.emplace_back(worker);
        worker();
    }
    progress.reset();
    write_summary(run, entries);
    if (interrupted())
        throw Interrupted(std::to_string(done) + " of " + std::to_string(items.size()) + " maps done, listed in " +
                          run.summary.string());
    if (failed)
        throw std::runtime_error(std::to_string(failed) + " of " + std::to_string(items.size()) +
                                 " maps failed, listed in " + run.summary.string());
}

}  // namespace envmis::cli
