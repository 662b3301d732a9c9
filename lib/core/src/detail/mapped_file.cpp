#include "detail/mapped_file.h"

#include <cstdint>

#if defined(__unix__) || defined(__APPLE__)
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>
#define ENVMIS_HAVE_MMAP 1
#endif

namespace envmis::detail {

#if defined(ENVMIS_HAVE_MMAP)

std::shared_ptr<const MappedFile> MappedFile::map(const std::filesystem::path& path) noexcept {
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return nullptr;
    struct stat st {};
    void* p = MAP_FAILED;
    // An empty file cannot be mapped; the reader's own checks report it.
    if (::fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && st.st_size > 0)
        p = ::mmap(nullptr, static_cast<size_t>(st.st_size), PROT_READ, MAP_SHARED, fd, 0);
    ::close(fd);  // the mapping keeps the file open
    if (p == MAP_FAILED) return nullptr;
    try {
        return std::shared_ptr<const MappedFile>(
            new MappedFile(static_cast<const std::byte*>(p), static_cast<size_t>(st.st_size)));
    } catch (...) {
        ::munmap(p, static_cast<size_t>(st.st_size));
        return nullptr;
    }
}

MappedFile::~MappedFile() { ::munmap(const_cast<std::byte*>(data_), size_); }

void MappedFile::release(std::span<const std::byte> range) const noexcept {
    const auto page = static_cast<uintptr_t>(::sysconf(_SC_PAGESIZE));
    const auto first = (reinterpret_cast<uintptr_t>(range.data()) + page - 1) / page * page;
    const auto last = (reinterpret_cast<uintptr_t>(range.data()) + range.size()) / page * page;
    if (last > first) ::madvise(reinterpret_cast<void*>(first), last - first, MADV_DONTNEED);
}

#else

std::shared_ptr<const MappedFile> MappedFile::map(const std::filesystem::path&) noexcept { return nullptr; }
MappedFile::~MappedFile() = default;
void MappedFile::release(std::span<const std::byte>) const noexcept {}

#endif

}  // namespace envmis::detail
