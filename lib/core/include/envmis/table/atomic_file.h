// Writing a file so that readers see either the old file or the complete new one.
//
// An AtomicFile names a temporary file beside the destination (same folder, so the
// final rename cannot cross file systems); the caller writes it by any means, then
// commit() renames it over the destination. If commit() is never reached (an error, an
// exception, an interrupted run) the destructor removes the temporary file.
#pragma once

#include <filesystem>
#include <functional>
#include <ostream>

namespace envmis {

class AtomicFile {
public:
    // The temporary name ends in the destination's extension, for writers that choose
    // the format from it. Throws std::runtime_error if the destination's folder is missing.
    explicit AtomicFile(std::filesystem::path destination);
    AtomicFile(const AtomicFile&) = delete;
    AtomicFile& operator=(const AtomicFile&) = delete;
    ~AtomicFile();

    const std::filesystem::path& temporary() const noexcept { return temporary_; }
    const std::filesystem::path& destination() const noexcept { return destination_; }
    // Renames the temporary file over the destination. Throws std::runtime_error naming
    // the destination if that fails.
    void commit();

private:
    std::filesystem::path destination_, temporary_;
    bool committed_ = false;
};

// Writes a file atomically through a binary std::ostream. Throws std::runtime_error
// naming the file if it cannot be created or written.
void write_file_atomically(const std::filesystem::path& destination, const std::function<void(std::ostream&)>& write);

}  // namespace envmis
