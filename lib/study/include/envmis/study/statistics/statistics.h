// Running statistics of estimates, in double (Welford 1962; Chan et al. 1979 to merge
// partial results, so that parallel runs combine in a fixed order).
#pragma once

#include <cmath>
#include <cstdint>

namespace envmis {

class RunningStats {
public:
    void add(double x) noexcept {
        ++n_;
        const double delta = x - mean_;
        mean_ += delta / static_cast<double>(n_);
        m2_ += delta * (x - mean_);
    }
    void merge(const RunningStats& o) noexcept {
        if (o.n_ == 0) return;
        const double n = static_cast<double>(n_ + o.n_), delta = o.mean_ - mean_;
        m2_ += o.m2_ + delta * delta * static_cast<double>(n_) * static_cast<double>(o.n_) / n;
        mean_ += delta * static_cast<double>(o.n_) / n;
        n_ += o.n_;
    }
    uint64_t count() const noexcept { return n_; }
    double mean() const noexcept { return mean_; }
    // Unbiased sample variance of one value.
    double variance() const noexcept { return n_ > 1 ? m2_ / static_cast<double>(n_ - 1) : 0.0; }
    // Standard error of mean().
    double standard_error() const noexcept { return n_ > 0 ? std::sqrt(variance() / static_cast<double>(n_)) : 0.0; }

private:
    uint64_t n_ = 0;
    double mean_ = 0, m2_ = 0;
};

}  // namespace envmis
