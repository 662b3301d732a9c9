// A reference sampler that follows pbrt-v4's image environment light (ImageInfiniteLight
// over PiecewiseConstant2D), written here from the published algorithm: what a pbrt
// user's renderer does today, for envmis's figures to be measured against in the same run.
//
// As pbrt-v4 has it: the image is an equal-area octahedral square; each texel's sampling
// value is the average of its three channels (not luminance); the compensated
// distribution subtracts the values' plain mean times alpha and clamps at 0 (all zero:
// a constant 1). Each row is a PiecewiseConstant1D (float function, float CDF of n + 1
// entries, its integral), the rows' integrals the marginal; a sample searches the
// marginal's CDF and then its row's by binary search (pbrt's FindInterval), and its pdf
// is the product of the two 1D pdfs. Sample_Li turns the point into a direction
// (square to sphere with std::sin and std::cos) and a 3x3 rotation into the world; the
// radiance is the nearest texel. PDF_Li rotates back, maps the direction to the square
// (the arc tangent as a polynomial, as pbrt does) and divides its row's function value by
// the marginal's integral, reached through the row's own vector. Solid-angle pdf: the
// square's density over 4 pi.
//
// Not for rendering (envmis's EnvMap is); for timing like with like, it returns
// EnvMap's EnvSample.
#pragma once

#include <cstddef>
#include <vector>

#include "envmis/sampling/envmap.h"

namespace envmis::reference {

// pbrt-v4's PiecewiseConstant1D over [0, 1]: a function of n values and its CDF.
class PbrtPiecewise1D {
public:
    explicit PbrtPiecewise1D(std::vector<float> function);
    // A point in [0, 1) with its density; `offset` receives the value's index.
    float sample(float u, float* pdf, size_t* offset) const noexcept;
    float integral() const noexcept { return integral_; }
    const std::vector<float>& function() const noexcept { return function_; }
    size_t bytes() const noexcept { return (function_.size() + cdf_.size()) * sizeof(float); }

private:
    std::vector<float> function_, cdf_;
    float integral_ = 0;
};

// pbrt-v4's PiecewiseConstant2D over [0, 1]^2: one PiecewiseConstant1D a row, and the
// marginal of the rows' integrals.
class PbrtPiecewise2D {
public:
    PbrtPiecewise2D(const std::vector<float>& function, uint32_t w, uint32_t h);
    Vec2 sample(Vec2 u, float* pdf) const noexcept;
    float pdf(Vec2 p) const noexcept;
    size_t bytes() const noexcept;

private:
    std::vector<PbrtPiecewise1D> rows_;
    PbrtPiecewise1D marginal_;
};

class PbrtStyleEnvMap {
public:
    // `image` must be square (equal-area, options.mapping), clean and outlive the map.
    // Throws std::invalid_argument otherwise.
    PbrtStyleEnvMap(const RgbImage& image, const EnvMapOptions& options);

    // Sample_Li: a direction by the (compensated, per the options) distribution.
    EnvSample sample(Vec2 u) const noexcept;
    // PDF_Li: the solid-angle density of a world direction.
    float pdf(Vec3 direction) const noexcept;
    size_t distribution_bytes() const noexcept { return distribution_.bytes(); }

private:
    const RgbImage* image_;
    float to_world_[3][3];  // rows: world = M canonical; canonical = M^T world
    PbrtPiecewise2D distribution_;
};

// pbrt-v4's mappings between the equal-area square and the sphere, written here: square
// to sphere with std::sin and std::cos, sphere to square with a polynomial arc tangent
// (within 3e-7 of a quarter turn).
Vec3 pbrt_square_to_sphere(Vec2 p) noexcept;
Vec2 pbrt_sphere_to_square(Vec3 d) noexcept;

}  // namespace envmis::reference
