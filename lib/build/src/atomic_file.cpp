#include "envmis/build/atomic_file.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cstring>
#include <ios>
#include <random>
#include <stdexcept>
#include <streambuf>
#include <string>
#include <string_view>

namespace envmis {
namespace {

namespace fs = std::filesystem;

// A temporary without a process id last modified before this process started cannot be
// this run's. Taken before main, less a second: file times come from a coarser clock
// (a file made just after this instant can be stamped a few milliseconds before it).
const fs::file_time_type kBeforeThisRun = fs::file_time_type::clock::now() - std::chrono::seconds(1);

[[noreturn]] void fail(const fs::path& destination, const std::string& problem) {
    throw std::runtime_error(destination.string() + ": " + problem);
}

[[noreturn]] void fail_errno(const fs::path& destination, const char* action, int error) {
    fail(destination, std::string(action) + ": " + std::strerror(error));
}

const char* type_name(fs::file_type type) {
    switch (type) {
        case fs::file_type::symlink: return "a symbolic link";
        case fs::file_type::directory: return "a directory";
        case fs::file_type::character: return "a character device";
        case fs::file_type::block: return "a block device";
        case fs::file_type::fifo: return "a FIFO";
        case fs::file_type::socket: return "a socket";
        default: return "not a regular file";
    }
}

fs::path folder_of(const fs::path& destination) {
    return destination.has_parent_path() ? destination.parent_path() : fs::path(".");
}

// ".STEM.tmp", how every temporary of `destination` starts. (Appended piece by piece:
// GCC 12 warns falsely, -Wrestrict, of "." + string.)
std::string hidden_prefix(const fs::path& destination) {
    std::string prefix = ".";
    prefix += destination.stem().string();
    prefix += ".tmp";
    return prefix;
}

// The part of a temporary's name between ".STEM.tmp" and ".EXT"; empty if `name` is not
// one of `destination`'s.
std::string_view temporary_id(std::string_view name, const fs::path& destination) {
    const std::string prefix = hidden_prefix(destination), suffix = destination.extension().string();
    if (name.size() <= prefix.size() + suffix.size() || !name.starts_with(prefix) || !name.ends_with(suffix)) return {};
    return name.substr(prefix.size(), name.size() - prefix.size() - suffix.size());
}

bool all_digits(std::string_view s) {
    return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

bool process_exists(pid_t pid) { return ::kill(pid, 0) == 0 || errno == EPERM; }

// Whether the file `entry` (a temporary of the destination with id `id`) is stale.
bool stale(const fs::directory_entry& entry, std::string_view id) {
    const size_t dash = id.find('-');
    if (dash == std::string_view::npos) {
        std::error_code ec;
        const auto modified = entry.last_write_time(ec);
        return all_digits(id) && !ec && modified < kBeforeThisRun;
    }
    const std::string_view pid_text = id.substr(0, dash);
    int pid = 0;
    const auto [end, error] = std::from_chars(pid_text.data(), pid_text.data() + pid_text.size(), pid);
    return all_digits(pid_text) && all_digits(id.substr(dash + 1)) && error == std::errc() &&
           end == pid_text.data() + pid_text.size() && pid > 0 && !process_exists(pid);
}

// The temporary's name for this process, made unique by the random part.
fs::path temporary_name(const fs::path& destination) {
    std::string name = hidden_prefix(destination);
    name += std::to_string(::getpid());
    name += '-';
    name += std::to_string(std::random_device{}());
    name += destination.extension().string();
    return folder_of(destination) / name;
}

void fsync_folder(const fs::path& destination) {
    const int fd = ::open(folder_of(destination).c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0) fail_errno(destination, "written, but cannot open its folder to flush it", errno);
    // Some file systems cannot flush a folder (EINVAL): there the rename is as durable as it gets.
    const int error = ::fsync(fd) == 0 || errno == EINVAL ? 0 : errno;
    ::close(fd);
    if (error) fail_errno(destination, "written, but flushing its folder failed", error);
}

// An ostream's buffer over an AtomicFile that keeps the first error instead of throwing
// through the stream (whose badbit then ends the writer).
class AtomicFileBuffer : public std::streambuf {
public:
    explicit AtomicFileBuffer(AtomicFile& file) : file_(file) { setp(buffer_.data(), buffer_.data() + buffer_.size()); }
    const std::string& error() const noexcept { return error_; }

protected:
    int_type overflow(int_type c) override {
        if (!drain()) return traits_type::eof();
        if (!traits_type::eq_int_type(c, traits_type::eof())) {
            *pptr() = traits_type::to_char_type(c);
            pbump(1);
        }
        return traits_type::not_eof(c);
    }
    int sync() override { return drain() ? 0 : -1; }

private:
    bool drain() {
        if (!error_.empty()) return false;
        try {
            file_.write(std::as_bytes(std::span(pbase(), static_cast<size_t>(pptr() - pbase()))));
        } catch (const std::runtime_error& e) {
            error_ = e.what();
            return false;
        }
        setp(buffer_.data(), buffer_.data() + buffer_.size());
        return true;
    }

    AtomicFile& file_;
    std::array<char, size_t{1} << 16> buffer_;
    std::string error_;
};

}  // namespace

void check_destination(const fs::path& destination) {
    const fs::path folder = folder_of(destination);
    std::error_code ec;
    if (!fs::is_directory(folder, ec))
        fail(destination, "cannot create: folder " + folder.string() + " does not exist");
    const fs::file_status status = fs::symlink_status(destination, ec);
    if (status.type() == fs::file_type::not_found || status.type() == fs::file_type::regular) return;
    if (ec) fail(destination, "cannot check: " + ec.message());
    fail(destination, std::string("is ") + type_name(status.type()) + ", not a regular file: refusing to replace it");
}

std::vector<fs::path> remove_stale_temporaries(const fs::path& destination) noexcept {
    std::vector<fs::path> removed;
    try {
        std::error_code ec;
        for (const fs::directory_entry& entry : fs::directory_iterator(folder_of(destination), ec)) {
            const std::string name = entry.path().filename().string();
            const std::string_view id = temporary_id(name, destination);
            if (id.empty() || entry.symlink_status(ec).type() != fs::file_type::regular || !stale(entry, id)) continue;
            if (fs::remove(entry.path(), ec)) removed.push_back(entry.path());
        }
    } catch (const std::exception&) {
        // Cleaning up is a courtesy: a folder that cannot be listed leaves the write to fail or not on its own.
    }
    return removed;
}

AtomicFile::AtomicFile(fs::path destination) : destination_(std::move(destination)) {
    check_destination(destination_);
    remove_stale_temporaries(destination_);
    // The destination's permission bits exactly, not under the umask (set-id bits are not
    // kept: they have no business on a data file); a new file's are 0666 under the umask.
    struct stat existing {};
    const bool exists = ::stat(destination_.c_str(), &existing) == 0;
    temporary_ = temporary_name(destination_);
    fd_ = ::open(temporary_.c_str(), O_CREAT | O_EXCL | O_WRONLY | O_CLOEXEC, 0666);
    if (fd_ < 0) fail_errno(destination_, "cannot create a temporary file beside it", errno);
    if (exists && ::fchmod(fd_, existing.st_mode & 0777) != 0) {
        const int error = errno;
        ::close(fd_);
        ::unlink(temporary_.c_str());
        fail_errno(destination_, "cannot give the new file the old one's permissions", error);
    }
}

AtomicFile::~AtomicFile() {
    if (fd_ >= 0) ::close(fd_);
    if (!committed_) ::unlink(temporary_.c_str());
}

void AtomicFile::write(std::span<const std::byte> bytes) {
    while (!bytes.empty()) {
        const ssize_t written = ::write(fd_, bytes.data(), bytes.size());
        if (written < 0 && errno == EINTR) continue;
        // A write of 0 bytes is a full device that did not say so.
        if (written <= 0) fail_errno(destination_, "cannot write", written < 0 ? errno : ENOSPC);
        bytes = bytes.subspan(static_cast<size_t>(written));
    }
}

void AtomicFile::commit() {
    if (::fsync(fd_) != 0) fail_errno(destination_, "cannot write", errno);
    const int closed = ::close(fd_);
    fd_ = -1;
    if (closed != 0) fail_errno(destination_, "cannot write", errno);
    if (::rename(temporary_.c_str(), destination_.c_str()) != 0) fail_errno(destination_, "cannot write", errno);
    committed_ = true;
    fsync_folder(destination_);
}

void write_file_atomically(const fs::path& destination, const std::function<void(std::ostream&)>& write) {
    AtomicFile file(destination);
    AtomicFileBuffer buffer(file);
    std::ostream out(&buffer);
    out.exceptions(std::ios::badbit);
    try {
        write(out);
        out.flush();
    } catch (const std::ios_base::failure&) {
        if (buffer.error().empty()) throw;
        throw std::runtime_error(buffer.error());
    }
    file.commit();
}

}  // namespace envmis
