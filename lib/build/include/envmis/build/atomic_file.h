// Writing a file so that readers see either the old file or the complete new one, and
// so that no failure (a full disk, an exception, an interrupted or killed run) leaves a
// partial file at the destination.
//
// An AtomicFile creates a temporary file beside the destination (same folder, so the
// final rename cannot cross file systems), exclusively (O_EXCL: never an existing file or
// a link planted there) and with the destination's permission bits when it exists; the
// caller writes it through write(), every write checked; commit() flushes it to disk,
// renames it over the destination and flushes the folder, so that after a power loss the
// destination holds the old file or the new one. If commit() is never reached, the
// destructor removes the temporary. POSIX only.
//
// A killed run (SIGKILL, power loss) cannot remove its temporary; its name records the
// writer's process id, so that the next write of the same destination can tell that it
// is stale and remove it. The names, for a destination FOLDER/STEM.EXT:
//   FOLDER/.STEM.tmpPID-RANDOM.EXT   this version (PID: the writer's process id)
//   FOLDER/.STEM.tmpRANDOM.EXT       envmis before it (no process id)
// RANDOM is decimal digits; the names end in the destination's extension, for tools
// that choose the format from it.
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <ostream>
#include <span>
#include <vector>

#include "envmis/build_export.h"

namespace envmis {

// Throws std::runtime_error naming `destination` where it cannot be written as a regular
// file: its folder is missing, or it exists and is not a regular file ("PATH: is a FIFO,
// not a regular file: refusing to replace it"): a symbolic link (not followed, whatever
// it points to), a directory, a character or block device, a FIFO or a socket. Does
// nothing where it is a regular file or does not exist.
ENVMIS_BUILD_API void check_destination(const std::filesystem::path& destination);

// Removes the stale temporaries of `destination` (names of either pattern above, for this
// destination only): those whose process id names no running process, and those without
// one last modified over a second before this process started. A running process's
// temporary and every other file are left alone; a process id reused since the kill keeps
// its stale file until that process ends. Process ids are this machine's: on a folder
// shared between machines, another machine's live writer can look dead. Returns the
// paths removed; a file that cannot be removed is skipped. Never throws.
ENVMIS_BUILD_API std::vector<std::filesystem::path> remove_stale_temporaries(
    const std::filesystem::path& destination) noexcept;

class ENVMIS_BUILD_API AtomicFile {
public:
    // Checks the destination (check_destination), removes its stale temporaries
    // (remove_stale_temporaries) and creates the temporary. Throws std::runtime_error
    // naming the destination if the check fails or the temporary cannot be created.
    explicit AtomicFile(std::filesystem::path destination);
    AtomicFile(const AtomicFile&) = delete;
    AtomicFile& operator=(const AtomicFile&) = delete;
    ~AtomicFile();

    const std::filesystem::path& temporary() const noexcept { return temporary_; }
    const std::filesystem::path& destination() const noexcept { return destination_; }
    // Appends `bytes` to the temporary. Throws std::runtime_error "DESTINATION: cannot
    // write: REASON" (e.g. "No space left on device", "File too large") on failure.
    void write(std::span<const std::byte> bytes);
    // Flushes the temporary to disk, closes it, renames it over the destination and
    // flushes the folder. Throws std::runtime_error naming the destination if any step
    // fails; the destination is untouched unless the rename was done (only flushing the
    // folder failed).
    void commit();

private:
    std::filesystem::path destination_, temporary_;
    int fd_ = -1;
    bool committed_ = false;
};

// Writes a file atomically through a binary std::ostream (an AtomicFile's). The first
// failed write ends `write` with an exception (the stream's badbit is an exception), so
// that a full disk does not cost the rest of the work. Throws std::runtime_error naming
// the file if it cannot be created or written.
ENVMIS_BUILD_API void write_file_atomically(const std::filesystem::path& destination,
                                            const std::function<void(std::ostream&)>& write);

}  // namespace envmis
