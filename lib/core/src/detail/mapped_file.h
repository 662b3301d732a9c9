// A whole file mapped read-only into memory, where the platform allows (POSIX mmap);
// the table reader borrows the radiance of a table from it instead of copying.
#pragma once

#include <cstddef>
#include <filesystem>
#include <memory>
#include <span>

namespace envmis::detail {

class MappedFile {
public:
    // The mapping, or null where mapping is unsupported or fails (the caller then reads
    // the file instead). Pages are shared with the page cache and with other processes
    // mapping the same file; they are read from disk as they are first touched.
    static std::shared_ptr<const MappedFile> map(const std::filesystem::path& path) noexcept;

    MappedFile(const MappedFile&) = delete;
    MappedFile& operator=(const MappedFile&) = delete;
    ~MappedFile();

    std::span<const std::byte> bytes() const noexcept { return {data_, size_}; }
    // Tells the system that the whole pages inside `range` (part of bytes()) will not be
    // read again: they leave this process's resident set (the page cache keeps them, so
    // a later read still works, from the cache or the file).
    void release(std::span<const std::byte> range) const noexcept;

private:
    MappedFile(const std::byte* data, size_t size) noexcept : data_(data), size_(size) {}

    const std::byte* data_;
    size_t size_;
};

}  // namespace envmis::detail
