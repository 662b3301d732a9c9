#include "envmis/build/remap.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "envmis/sampling/distribution.h"

namespace envmis {
namespace {

void check_size(const char* what, Mapping m, uint32_t w, uint32_t h) {
    if (w == 0 || h == 0 || w > kMaxCells1D || h > kMaxCells1D)
        throw std::invalid_argument(std::string("remap: ") + what + " size " + std::to_string(w) + "x" +
                                    std::to_string(h) + " is empty or above 65536 on a side");
    if (m == Mapping::equal_area && w != h)
        throw std::invalid_argument(std::string("remap: ") + what + " equal-area size " + std::to_string(w) + "x" +
                                    std::to_string(h) + " is not square");
}

// The texel that pixel coordinates (x, y), possibly one step outside the image, name
// across the mapping's seams.
size_t wrap(Mapping m, int64_t x, int64_t y, uint32_t w, uint32_t h) noexcept {
    const auto W = static_cast<int64_t>(w), H = static_cast<int64_t>(h);
    if (m == Mapping::equal_area) {
        // Each edge of the octahedral square is glued to itself, mirrored about its middle.
        if (x < 0 || x >= W) {
            x = x < 0 ? -x - 1 : 2 * W - 1 - x;
            y = H - 1 - y;
        }
        if (y < 0 || y >= H) {
            y = y < 0 ? -y - 1 : 2 * H - 1 - y;
            x = W - 1 - x;
        }
    } else if (y < 0 || y >= H) {  // over a pole: the same latitude, half a turn round
        y = y < 0 ? -y - 1 : 2 * H - 1 - y;
        x += W / 2;
    }
    x = ((x % W) + W) % W;
    y = std::clamp<int64_t>(y, 0, H - 1);
    return static_cast<size_t>(y) * w + static_cast<size_t>(x);
}

}  // namespace

double texel_solid_angle(Mapping m, uint32_t y, uint32_t w, uint32_t h) noexcept {
    if (m == Mapping::equal_area) return 4 * kPi / (static_cast<double>(w) * h);
    return 2 * kPi / w * (std::cos(kPi * y / h) - std::cos(kPi * (y + 1.0) / h));
}

std::array<double, 3> total_power(const RgbImage& image, Mapping m) {
    std::array<double, 3> power{};
    for (uint32_t y = 0; y < image.height; ++y) {
        const double a = texel_solid_angle(m, y, image.width, image.height);
        for (uint32_t x = 0; x < image.width; ++x) {
            Rgb p = image.at(x, y);
            BadPixels ignored;
            sanitize_pixel(p, ignored);
            power[0] += a * p.r, power[1] += a * p.g, power[2] += a * p.b;
        }
    }
    return power;
}

RemapResult remap(const RgbImage& in, Mapping from, Mapping to, uint32_t width, uint32_t height, uint32_t supersampling,
                  StopFlag stop) {
    check_size("input", from, in.width, in.height);
    if (in.pixels.size() != size_t{in.width} * in.height)
        throw std::invalid_argument("remap: " + std::to_string(in.pixels.size()) + " pixels do not make a " +
                                    std::to_string(in.width) + "x" + std::to_string(in.height) + " image");
    check_size("output", to, width, height);
    RemapResult result;
    if (supersampling == 0) {
        // At least 16 sub-samples per output texel of average size, where the input
        // texels are largest (the bilinear splat covers the small ones at the poles).
        double largest_in = 0;
        for (uint32_t y = 0; y < in.height; ++y)
            largest_in = std::max(largest_in, texel_solid_angle(from, y, in.width, in.height));
        const double mean_out = 4 * kPi / (static_cast<double>(width) * height);
        supersampling = static_cast<uint32_t>(std::clamp(std::ceil(4 * std::sqrt(largest_in / mean_out)), 2.0, 16.0));
    }
    const uint32_t s = supersampling;
    result.supersampling = s;

    // Per output texel: power received (R, G, B) and solid angle received. Zeroed a block
    // of rows at a time, checking `stop` between blocks: at 16384 x 16384 this buffer is
    // 8.6 GB, whose zero fill alone takes tens of seconds.
    const size_t texels = size_t{width} * height;
    const std::unique_ptr<double[]> power(new double[texels * 4]);
    for (size_t at = 0, block = size_t{width} * 4 * 64; at < texels * 4; at += block) {
        throw_if_stopped(stop);
        std::fill_n(&power[at], std::min(block, texels * 4 - at), 0.0);
    }
    const double share = 1.0 / (static_cast<double>(s) * s);
    // Equirect sub-samples are even in (phi, cos theta), so even in solid angle.
    std::vector<float> cos_phi(size_t{in.width} * s), sin_phi(cos_phi.size());
    for (size_t i = 0; i < cos_phi.size(); ++i) {
        const double phi = 2 * kPi * (i + 0.5) / static_cast<double>(cos_phi.size());
        cos_phi[i] = static_cast<float>(std::cos(phi)), sin_phi[i] = static_cast<float>(std::sin(phi));
    }
    std::vector<float> sub_z(s), sub_r(s);
    for (uint32_t y = 0; y < in.height; ++y) {
        throw_if_stopped(stop);
        const double solid_angle = texel_solid_angle(from, y, in.width, in.height);
        const double z_top = std::cos(kPi * y / in.height), z_bottom = std::cos(kPi * (y + 1.0) / in.height);
        for (uint32_t b = 0; b < s; ++b) {
            const double z = z_top + (z_bottom - z_top) * (b + 0.5) / s;
            sub_z[b] = static_cast<float>(z), sub_r[b] = static_cast<float>(std::sqrt(std::max(0.0, 1 - z * z)));
        }
        for (uint32_t x = 0; x < in.width; ++x) {
            Rgb l = in.at(x, y);
            sanitize_pixel(l, result.bad_pixels);
            const double area = solid_angle * share, pr = l.r * area, pg = l.g * area, pb = l.b * area;
            for (uint32_t b = 0; b < s; ++b)
                for (uint32_t a = 0; a < s; ++a) {
                    const size_t i = size_t{x} * s + a;
                    const Vec3 d = from == Mapping::equal_area
                                       ? equal_area_direction({static_cast<float>((x + (a + 0.5) / s) / in.width),
                                                               static_cast<float>((y + (b + 0.5) / s) / in.height)})
                                       : Vec3{sub_r[b] * cos_phi[i], sub_r[b] * sin_phi[i], sub_z[b]};
                    const Vec2 uv = image_uv(to, d);
                    const double px = uv.x * static_cast<double>(width) - 0.5,
                                 py = uv.y * static_cast<double>(height) - 0.5;
                    const double fx = std::floor(px), fy = std::floor(py), tx = px - fx, ty = py - fy;
                    const auto ix = static_cast<int64_t>(fx), iy = static_cast<int64_t>(fy);
                    const double weights[4] = {(1 - tx) * (1 - ty), tx * (1 - ty), (1 - tx) * ty, tx * ty};
                    const bool inside = ix >= 0 && iy >= 0 && ix + 1 < width && iy + 1 < height;
                    for (int k = 0; k < 4; ++k) {
                        const size_t texel =
                            inside ? static_cast<size_t>(iy + (k >> 1)) * width + static_cast<size_t>(ix + (k & 1))
                                   : wrap(to, ix + (k & 1), iy + (k >> 1), width, height);
                        double* p = &power[4 * texel];
                        p[0] += weights[k] * pr, p[1] += weights[k] * pg, p[2] += weights[k] * pb,
                            p[3] += weights[k] * area;
                    }
                }
        }
    }
    // Radiance is power over the solid angle the same filter brought, so the filter's
    // uneven cover (near the poles, in the sub-sample pattern) cancels and a constant map
    // stays constant; one scale per channel then restores the input's total power
    // exactly (it differs from 1 by the cover's small mismatch with the exact texel
    // solid angles).
    // Texels too small for any sub-sample to reach (at an equirect output's poles) take
    // the input's radiance at their centre.
    std::array<double, 3> received{};
    for (uint32_t y = 0; y < height; ++y) {
        throw_if_stopped(stop);
        const double texel = texel_solid_angle(to, y, width, height);
        for (uint32_t x = 0; x < width; ++x) {
            double* p = &power[4 * (size_t{y} * width + x)];
            if (p[3] > 0) {
                for (int c = 0; c < 3; ++c) p[c] /= p[3];
            } else {
                const Vec2 uv = image_uv(from, image_direction(to, {(x + 0.5f) / width, (y + 0.5f) / height}));
                Rgb l = in.at(detail::cell_of(uv.x, in.width), detail::cell_of(uv.y, in.height));
                BadPixels counted_above;
                sanitize_pixel(l, counted_above);
                p[0] = l.r, p[1] = l.g, p[2] = l.b;
            }
            for (int c = 0; c < 3; ++c) received[c] += p[c] * texel;
        }
    }
    const std::array<double, 3> sent = total_power(in, from);
    result.image = {width, height, RgbPixels(size_t{width} * height)};
    for (size_t i = 0; i < result.image.pixels.size(); ++i) {
        const double* p = &power[4 * i];
        const auto scaled = [&](int c) {
            return static_cast<float>(received[c] > 0 ? p[c] * sent[c] / received[c] : 0.0);
        };
        result.image.pixels[i] = {scaled(0), scaled(1), scaled(2)};
    }
    return result;
}

}  // namespace envmis
