#include "envmis/study/shading/bsdf.h"

#include <charconv>
#include <cstdio>
#include <stdexcept>

namespace envmis {
namespace {

float parse_parameter(std::string_view text, std::string_view value) {
    float v = 0;
    const auto [end, error] = std::from_chars(value.data(), value.data() + value.size(), v);
    if (error != std::errc() || end != value.data() + value.size() || !std::isfinite(v))
        throw std::invalid_argument("BSDF '" + std::string(text) + "': '" + std::string(value) + "' is not a number");
    return v;
}

}  // namespace

Bsdf Bsdf::parse(std::string_view text) {
    const size_t colon = text.find(':');
    const std::string_view kind = text.substr(0, colon);
    const bool has_value = colon != std::string_view::npos;
    if (kind == "lambert" && !has_value) return lambert();
    if (kind == "phong" && has_value) {
        const float n = parse_parameter(text, text.substr(colon + 1));
        if (n >= 0 && n <= 1e5f) return phong(n);
    }
    if (kind == "ggx" && has_value) {
        const float a = parse_parameter(text, text.substr(colon + 1));
        if (a >= 1e-3f && a <= 1) return ggx(a);
    }
    throw std::invalid_argument("BSDF '" + std::string(text) +
                                "': expected lambert, phong:N (0 <= N <= 1e5) or ggx:A (0.001 <= A <= 1)");
}

std::string Bsdf::name() const {
    char buffer[32];
    switch (kind) {
        case BsdfKind::lambert: return "lambert";
        case BsdfKind::phong: std::snprintf(buffer, sizeof buffer, "phong:%g", exponent); return buffer;
        case BsdfKind::ggx: std::snprintf(buffer, sizeof buffer, "ggx:%g", alpha); return buffer;
    }
    return "unknown";
}

}  // namespace envmis
