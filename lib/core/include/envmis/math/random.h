// A small, fast, deterministic random number generator (PCG32, O'Neill 2014) for the
// estimators: 8 bytes of state, no allocation, usable on the device. Separate streams
// (one per thread or per shading point) come from distinct `stream` values.
#pragma once

#include <cstdint>

#include "envmis/math/math.h"

namespace envmis {

class Pcg32 {
public:
    ENVMIS_HD explicit Pcg32(uint64_t seed = 0x853c49e6748fea9bull, uint64_t stream = 0xda3e39cb94b95bdbull) noexcept
        : increment_((stream << 1u) | 1u) {
        next();
        state_ += seed;
        next();
    }
    ENVMIS_HD uint32_t next() noexcept {
        const uint64_t old = state_;
        state_ = old * 6364136223846793005ull + increment_;
        const auto xorshifted = static_cast<uint32_t>(((old >> 18u) ^ old) >> 27u);
        const auto rot = static_cast<uint32_t>(old >> 59u);
        return (xorshifted >> rot) | (xorshifted << ((~rot + 1u) & 31));
    }
    // Uniform in [0,1) on the 2^-24 grid.
    ENVMIS_HD float uniform() noexcept { return static_cast<float>(next() >> 8) * 0x1p-24f; }
    ENVMIS_HD Vec2 uniform2() noexcept {
        const float a = uniform();
        return {a, uniform()};
    }

private:
    uint64_t state_ = 0, increment_;
};

}  // namespace envmis
