// The textbook 2D sampler: float marginal and conditional CDFs, each inverted by binary
// search (std::upper_bound), as in most renderers and textbooks. It is the reference
// that `envmis bench` and the benchmarks measure Distribution2D against, and it obeys
// the same interface and tests.
//
// Cost (n = w h cells): 8 bytes per cell (float func, float CDF); build O(n), serial;
// sample O(log w + log h); pdf O(1); invertible. Its float CDFs lose cells whose mass is
// below float resolution of the running sum, which Distribution2D's double CDFs keep.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "envmis/math/math.h"
#include "envmis/sampling/distribution.h"

namespace envmis {

class TextbookDistribution2D {
public:
    using Sample = Distribution2DView::Sample;

    TextbookDistribution2D() = default;
    // Same contract as Distribution2D's constructor.
    TextbookDistribution2D(std::span<const float> func, uint32_t w, uint32_t h);

    Sample sample(Vec2 u) const noexcept;
    float pdf(Vec2 p) const noexcept;
    Vec2 invert(Vec2 p) const noexcept;

    uint32_t width() const noexcept { return w_; }
    uint32_t height() const noexcept { return h_; }
    double integral() const noexcept { return integral_; }
    bool uniform_fallback() const noexcept { return uniform_; }
    size_t bytes() const noexcept { return (func_.size() + cdf_.size() + marginal_cdf_.size()) * sizeof(float); }

private:
    std::vector<float> func_;          // w h
    std::vector<float> cdf_;           // h rows of w + 1 entries, each from 0 to 1
    std::vector<float> marginal_cdf_;  // h + 1 entries
    uint32_t w_ = 0, h_ = 0;
    double integral_ = 0;
    float inv_integral_ = 0;
    bool uniform_ = false;
};

}  // namespace envmis
