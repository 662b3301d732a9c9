#include "maps_build.h"

#include <stdexcept>
#include <utility>

namespace envmis::python {
namespace {

Built built_from(BuiltMap map, const BuildRequest& request) {
    Built built;
    built.map = std::move(map.map);
    built.binned = std::move(map.binned);
    built.source = std::move(map.source);
    built.request = request;
    built.notices = std::move(map.notices);
    return built;
}

}  // namespace

Built load_table(const std::filesystem::path& path, bool mapped) {
    Table table = read_table(path, mapped ? TableLoading::map : TableLoading::copy);
    Built built;
    built.from_table = true;
    // Its header again (at most 64 KiB): Table does not say how its payload was encoded.
    built.compact = read_table_header(path).compact;
    built.source = table.source;
    built.mapped = table.mapped;
    if (table.bins)
        built.binned.emplace(binned_map(std::move(table)));
    else
        built.map = std::move(table.map);
    return built;
}

Built load(const std::filesystem::path& path, const BuildRequest& request) {
    check(request);
    if (looks_like_table(path)) {
        if (request.bins != 0) throw std::invalid_argument(path.string() + ": is already a table; give an image");
        return load_table(path, true);
    }
    return built_from(build_map(path, request), request);
}

Built from_pixels(RgbImage image, const BuildRequest& request) {
    return built_from(build_map(std::move(image), request), request);
}

}  // namespace envmis::python
