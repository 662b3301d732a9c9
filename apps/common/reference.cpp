#include "reference.h"

#include <cmath>
#include <vector>

namespace envmis::reference {
namespace {

std::vector<float> textbook_density(const RgbImage& image, const EnvMapOptions& options) {
    const uint32_t w = image.width, h = image.height;
    std::vector<float> density(size_t{w} * h);
    for (size_t i = 0; i < density.size(); ++i) density[i] = luminance(image.pixels[i], options.luma);
    const float threshold =
        options.compensation.enabled
            ? compensation_threshold(solid_angle_mean(density, w, h, options.mapping), options.compensation.alpha)
            : 0.0f;
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            float& d = density[size_t{y} * w + x];
            d = compensate(d, threshold) * row_weight(options.mapping, y, h);
        }
    return density;
}

// The clouds' brightness factor in direction d, 0.3 to 2: products of sines of the
// direction's coordinates, a few periods across the sphere.
double cloud_factor(Vec3 d) {
    const double c = std::sin(7.0 * d.x + 3 * std::sin(5.0 * d.y)) * std::sin(6.0 * d.y + 2.0 * d.z) *
                     std::cos(9.0 * d.z + 4.0 * d.x);
    return 0.3 + 1.7 * (0.5 + 0.5 * c);
}

}  // namespace

TextbookEnvMap::TextbookEnvMap(const RgbImage& image, const EnvMapOptions& options)
    : image_(&image),
      axes_(options.axes),
      mapping_(options.mapping),
      distribution_(textbook_density(image, options), image.width, image.height) {}

// Equal-area texels all cover 4 pi / (w h): the image density over 4 pi is the
// solid-angle density; equirect ones shrink with sin(theta).
EnvSample TextbookEnvMap::sample(Vec2 u) const noexcept {
    const auto s = distribution_.sample(u);
    const Rgb radiance = image_->pixels[size_t{s.y} * image_->width + s.x];
    if (mapping_ == Mapping::equal_area)
        return {to_world(axes_, equal_area_direction(s.p)), s.pdf / kFourPi, radiance, s.p};
    float sin_theta = 0;
    const Vec3 canonical = equirect_direction(s.p, &sin_theta);
    return {to_world(axes_, canonical), EnvMapView::solid_angle_pdf(s.pdf, sin_theta), radiance, s.p};
}

float TextbookEnvMap::pdf(Vec3 direction) const noexcept {
    const Vec2 uv = image_uv(mapping_, to_canonical(axes_, direction));
    if (mapping_ == Mapping::equal_area) return distribution_.pdf(uv) / kFourPi;
    return EnvMapView::solid_angle_pdf(distribution_.pdf(uv), std::sin(kPiF * uv.y));
}

RgbImage synthetic_sky(uint32_t w, uint32_t h, Mapping mapping, SkyDetail detail) {
    RgbImage sky{w, h, RgbPixels(size_t{w} * h)};
    const double sun_theta = kPi / 4, sun_phi = kPi / 3, sun_radius = 0.25 * kPi / 180;
    const Vec3 sun{static_cast<float>(std::sin(sun_theta) * std::cos(sun_phi)),
                   static_cast<float>(std::sin(sun_theta) * std::sin(sun_phi)),
                   static_cast<float>(std::cos(sun_theta))};
    const float cos_radius = static_cast<float>(std::cos(sun_radius));
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            const Vec3 d = image_direction(mapping, {(x + 0.5f) / w, (y + 0.5f) / h});
            const float up = std::max(d.z, 0.0f);
            float sky_level = d.z >= 0 ? 0.3f + 0.7f * up : 0.05f;
            if (detail == SkyDetail::clouds) sky_level *= static_cast<float>(cloud_factor(d));
            Rgb& p = sky.pixels[size_t{y} * w + x];
            p = {0.5f * sky_level, 0.7f * sky_level, 1.0f * sky_level};
            if (dot(d, sun) >= cos_radius) p = {1e5f, 0.95e5f, 0.9e5f};
        }
    // On small maps no texel centre may fall inside the sun: keep at least its own texel.
    const Vec2 uv = image_uv(mapping, sun);
    sky.pixels[size_t{detail::cell_of(uv.y, h)} * w + detail::cell_of(uv.x, w)] = {1e5f, 0.95e5f, 0.9e5f};
    return sky;
}

}  // namespace envmis::reference
