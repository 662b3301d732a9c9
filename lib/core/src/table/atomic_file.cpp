#include "envmis/table/atomic_file.h"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>

namespace envmis {

AtomicFile::AtomicFile(std::filesystem::path destination) : destination_(std::move(destination)) {
    const std::filesystem::path folder = destination_.has_parent_path() ? destination_.parent_path() : ".";
    std::error_code ec;
    if (!std::filesystem::is_directory(folder, ec))
        throw std::runtime_error(destination_.string() + ": cannot create: folder " + folder.string() +
                                 " does not exist");
    // Hidden, unique per process and attempt, and ending in the destination's extension.
    temporary_ = folder / ("." + destination_.stem().string() + ".tmp" + std::to_string(std::random_device{}()) +
                           destination_.extension().string());
}

AtomicFile::~AtomicFile() {
    if (!committed_) {
        std::error_code ignored;
        std::filesystem::remove(temporary_, ignored);
    }
}

void AtomicFile::commit() {
    std::error_code ec;
    std::filesystem::rename(temporary_, destination_, ec);
    if (ec) throw std::runtime_error(destination_.string() + ": cannot write: " + ec.message());
    committed_ = true;
}

void write_file_atomically(const std::filesystem::path& destination, const std::function<void(std::ostream&)>& write) {
    AtomicFile file(destination);
    {
        std::ofstream out(file.temporary(), std::ios::binary | std::ios::trunc);
        if (!out) throw std::runtime_error(destination.string() + ": cannot create: " + std::strerror(errno));
        write(out);
        out.close();
        if (!out) throw std::runtime_error(destination.string() + ": cannot write: " + std::strerror(errno));
    }
    file.commit();
}

}  // namespace envmis
