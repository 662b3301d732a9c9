#include "envmis/compensation/compensation.h"

#include <stdexcept>
#include <string>
#include <vector>

#include "envmis/image/mapping.h"

namespace envmis {

double solid_angle_mean(std::span<const float> luminance, uint32_t w, uint32_t h, Mapping mapping) {
    if (w == 0 || h == 0 || luminance.size() != size_t{w} * h)
        throw std::invalid_argument("solid_angle_mean: " + std::to_string(luminance.size()) + " values do not make a " +
                                    std::to_string(w) + "x" + std::to_string(h) + " image");
    std::vector<double> rows(h, 0.0);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) rows[y] += luminance[size_t{y} * w + x];
    return solid_angle_mean_of_rows(rows, w, mapping);
}

double solid_angle_mean_of_rows(std::span<const double> row_sums, uint32_t w, Mapping mapping) noexcept {
    const auto h = static_cast<uint32_t>(row_sums.size());
    double weighted = 0, weights = 0;
    for (uint32_t y = 0; y < h; ++y) {
        const double s = row_weight(mapping, y, h);
        weighted += s * row_sums[y];
        weights += s * w;
    }
    return weights > 0 ? weighted / weights : 0.0;
}

}  // namespace envmis
