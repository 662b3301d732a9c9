// Running statistics of estimates, in double (Welford 1962; Chan et al. 1979 to merge
// partial results, so that parallel runs combine in a fixed order).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

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

// The median of `values` (the mean of the two middle ones for an even count); 0 for none.
// Robust summaries of timings, where a descheduled run is an outlier.
inline double median(std::vector<double> values) {
    if (values.empty()) return 0;
    std::sort(values.begin(), values.end());
    const size_t half = values.size() / 2;
    return values.size() % 2 ? values[half] : 0.5 * (values[half - 1] + values[half]);
}

}  // namespace envmis
