#include "envmis/image/mapping.h"

#include <stdexcept>

namespace envmis {

bool Axes::valid() const noexcept {
    int seen = 0;
    for (int8_t c : code) {
        const int a = c < 0 ? -c : c;
        if (a < 1 || a > 3) return false;
        seen |= 1 << a;
    }
    return seen == 0b1110;
}

std::string_view Axes::preset() const noexcept {
    for (const std::string_view name : {"z-up", "y-up", "mitsuba3", "blender"})
        if (parse(name) == *this) return name;
    return {};
}

Axes Axes::parse(std::string_view text) {
    if (text == "z-up" || text == "pbrt-v4") return Axes{{1, 2, 3}};
    if (text == "y-up") return Axes{{1, 3, -2}};
    if (text == "mitsuba3") return Axes{{2, 3, -1}};
    if (text == "blender") return Axes{{-1, 2, 3}};
    Axes axes;
    int i = 0;
    size_t pos = 0;
    bool ok = true;
    while (ok && pos <= text.size()) {
        const size_t comma = std::min(text.find(',', pos), text.size());
        std::string_view item = text.substr(pos, comma - pos);
        const bool negative = !item.empty() && item.front() == '-';
        if (negative || (!item.empty() && item.front() == '+')) item.remove_prefix(1);
        ok = i < 3 && item.size() == 1 && item[0] >= 'x' && item[0] <= 'z';
        if (ok) axes.code[i++] = static_cast<int8_t>((item[0] - 'x' + 1) * (negative ? -1 : 1));
        pos = comma + 1;
    }
    if (!ok || i != 3 || !axes.valid())
        throw std::invalid_argument(
            "axes '" + std::string(text) +
            "': expected z-up, y-up, pbrt-v4, mitsuba3, blender or a signed permutation such as x,z,-y");
    return axes;
}

std::string_view to_string(Mapping m) noexcept { return m == Mapping::equal_area ? "equal-area" : "equirect"; }

Mapping parse_mapping(std::string_view text) {
    if (text == "equirect") return Mapping::equirect;
    if (text == "equal-area") return Mapping::equal_area;
    throw std::invalid_argument("mapping '" + std::string(text) + "': expected equirect or equal-area");
}

std::string Axes::to_string() const {
    std::string s;
    for (int i = 0; i < 3; ++i) {
        if (i) s += ',';
        if (code[i] < 0) s += '-';
        s += static_cast<char>('x' + (code[i] < 0 ? -code[i] : code[i]) - 1);
    }
    return s;
}

}  // namespace envmis
