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

// The optional grey albedo after a BSDF's parameters: "" keeps `fallback`.
Rgb parse_albedo(std::string_view text, std::string_view value, Rgb fallback) {
    if (value.empty() && text.ends_with(':'))
        throw std::invalid_argument("BSDF '" + std::string(text) + "': empty albedo");
    if (value.empty()) return fallback;
    const float a = parse_parameter(text, value);
    if (!(a >= 0 && a <= 1))
        throw std::invalid_argument("BSDF '" + std::string(text) + "': albedo " + std::string(value) +
                                    " is not in [0, 1]");
    return {a, a, a};
}

bool same(Rgb a, Rgb b) { return a.r == b.r && a.g == b.g && a.b == b.b; }

}  // namespace

Rgb Bsdf::default_reflectance(BsdfKind kind) {
    return kind == BsdfKind::ggx ? ggx(0.1f).reflectance : lambert().reflectance;
}

Bsdf Bsdf::parse(std::string_view text) {
    const size_t colon = text.find(':');
    const std::string_view kind = text.substr(0, colon);
    const std::string_view rest = colon == std::string_view::npos ? std::string_view{} : text.substr(colon + 1);
    const size_t second = rest.find(':');
    const std::string_view value = rest.substr(0, second);
    const std::string_view albedo = second == std::string_view::npos ? std::string_view{} : rest.substr(second + 1);
    const bool has_value = colon != std::string_view::npos;
    if (kind == "lambert") {
        if (!has_value) return lambert();
        if (second == std::string_view::npos && !value.empty())
            return lambert(parse_albedo(text, value, default_reflectance(BsdfKind::lambert)));
    }
    if (kind == "phong" && has_value) {
        const float n = parse_parameter(text, value);
        if (n >= 0 && n <= 1e5f) return phong(n, parse_albedo(text, albedo, default_reflectance(BsdfKind::phong)));
    }
    if (kind == "ggx" && has_value) {
        const float a = parse_parameter(text, value);
        if (a >= 1e-3f && a <= 1) return ggx(a, parse_albedo(text, albedo, default_reflectance(BsdfKind::ggx)));
    }
    throw std::invalid_argument("BSDF '" + std::string(text) +
                                "': expected lambert[:ALBEDO], phong:N[:ALBEDO] (0 <= N <= 1e5) or ggx:A[:F0] "
                                "(0.001 <= A <= 1), ALBEDO and F0 grey in [0, 1]");
}

std::string Bsdf::name() const {
    char buffer[32];
    // ":" + albedo_text() unless the reflectance is the kind's default.
    const std::string albedo =
        same(reflectance, default_reflectance(kind)) ? std::string() : std::string(":").append(albedo_text());
    switch (kind) {
        case BsdfKind::lambert: return "lambert" + albedo;
        case BsdfKind::phong: std::snprintf(buffer, sizeof buffer, "phong:%g", exponent); return buffer + albedo;
        case BsdfKind::ggx: std::snprintf(buffer, sizeof buffer, "ggx:%g", alpha); return buffer + albedo;
    }
    return "unknown";
}

std::string Bsdf::albedo_text() const {
    char buffer[64];
    if (reflectance.r == reflectance.g && reflectance.g == reflectance.b)
        std::snprintf(buffer, sizeof buffer, "%g", reflectance.r);
    else
        std::snprintf(buffer, sizeof buffer, "%g/%g/%g", reflectance.r, reflectance.g, reflectance.b);
    return buffer;
}

}  // namespace envmis
