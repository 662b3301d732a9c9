// Small value types and constants shared by every envmis module.
//
// Everything here is header-only, allocation-free and usable from device code:
// ENVMIS_HD expands to `__host__ __device__` under a CUDA compiler and to nothing
// in plain C++, so the same sampling code runs in renderers on either side.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

// ENVMIS_INLINE marks the sampling path's steps, which must be inlined into the
// caller's loop: GCC's own estimate left EnvMapView::sample out of line in `envmis
// bench` once it had grown by its prefetches, and the call (its sample returned through
// memory) made the sample much slower (measured: docs/performance-log.md,
// 'ENVMIS_INLINE').
#if defined(__CUDACC__)
#define ENVMIS_HD __host__ __device__
#define ENVMIS_NOINLINE __noinline__
#define ENVMIS_INLINE __forceinline__
#elif defined(__GNUC__)
#define ENVMIS_HD
#define ENVMIS_NOINLINE __attribute__((noinline))
#define ENVMIS_INLINE inline __attribute__((always_inline))
#else
#define ENVMIS_HD
#define ENVMIS_NOINLINE
#define ENVMIS_INLINE inline
#endif

// A hint to start loading the cache line at address p; nothing where unsupported
// (device code, other compilers).
#define ENVMIS_PREFETCH(p) ::envmis::prefetch(p)

namespace envmis {

// ENVMIS_PREFETCH. The empty volatile asm gives the hint an effect the optimiser must
// keep: GCC counts __builtin_prefetch as none, so a function whose only effects are
// prefetches is found `const` and its calls are deleted, prefetches and all (GCC 12 at
// -O2 and -O3: EnvMapView::prefetch_uv and the binned sampler's row prefetch compiled to
// nothing; tests/core/math/prefetch_kept.cpp checks the generated code).
ENVMIS_HD inline void prefetch(const void* p) noexcept {
#if defined(__GNUC__) && !defined(__CUDA_ARCH__)
    __builtin_prefetch(p);
    __asm__ __volatile__("");
#else
    (void)p;
#endif
}

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr float kPiF = 3.14159265358979323846f;
// Largest float below 1: samplers clamp to it so that points stay in [0,1).
inline constexpr float kOneMinusEpsilon = 0x1.fffffep-1f;

struct Vec2 {
    float x = 0, y = 0;
};

struct Vec3 {
    float x = 0, y = 0, z = 0;

    ENVMIS_HD float operator[](int i) const noexcept { return i == 0 ? x : (i == 1 ? y : z); }
    ENVMIS_HD friend Vec3 operator+(Vec3 a, Vec3 b) noexcept { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
    ENVMIS_HD friend Vec3 operator-(Vec3 a, Vec3 b) noexcept { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
    ENVMIS_HD friend Vec3 operator*(Vec3 a, float s) noexcept { return {a.x * s, a.y * s, a.z * s}; }
    ENVMIS_HD friend Vec3 operator*(float s, Vec3 a) noexcept { return a * s; }
};

ENVMIS_HD inline float dot(Vec3 a, Vec3 b) noexcept { return a.x * b.x + a.y * b.y + a.z * b.z; }
ENVMIS_HD inline float length(Vec3 a) noexcept { return std::sqrt(dot(a, a)); }
ENVMIS_HD inline Vec3 normalize(Vec3 a) noexcept { return a * (1.0f / length(a)); }
ENVMIS_HD inline Vec3 cross(Vec3 a, Vec3 b) noexcept {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

// Linear RGB radiance in the table's working colour space (units of the source image).
struct Rgb {
    float r = 0, g = 0, b = 0;
};

// Luminance as a weighted sum of linear RGB; the weights are the Y row of the
// working space's RGB->XYZ matrix (Rec.709 by default).
struct LumaCoefficients {
    float r = 0.2126f, g = 0.7152f, b = 0.0722f;
};

ENVMIS_HD inline float luminance(Rgb c, LumaCoefficients k) noexcept { return k.r * c.r + k.g * c.g + k.b * c.b; }

// std::bit_cast for device code too (memcpy is the portable, optimised-away form).
template <class To, class From>
ENVMIS_HD inline To bit_cast(const From& from) noexcept {
    static_assert(sizeof(To) == sizeof(From));
    To to;
    std::memcpy(&to, &from, sizeof(To));
    return to;
}

// std::min and std::max are host functions to a CUDA compiler: the sampling path
// uses these (same semantics).
template <class T>
ENVMIS_HD constexpr T min(T a, T b) noexcept {
    return b < a ? b : a;
}
template <class T>
ENVMIS_HD constexpr T max(T a, T b) noexcept {
    return a < b ? b : a;
}

template <class T>
ENVMIS_HD constexpr T clamp(T v, T lo, T hi) noexcept {
    return v < lo ? lo : (hi < v ? hi : v);
}

// Lane types. The sampling functions that a batch call runs eight at a time are
// templates on a lane type F: float here, or eight floats in AVX2 (simd::F8,
// lib/common/detail/simd.h), written once for both. Lanes<F> names the integer and
// vector types of F, and the functions below are float's forms of the operations F8
// has: a comparison gives a bool (an M8), select(c, a, b) is c ? a : b with both
// evaluated, and a lane integer is a uint32_t (wrapping, >> logical; to_float reads it
// as signed, truncate as a signed conversion).
struct SinCos;
template <class F>
struct Lanes;
template <>
struct Lanes<float> {
    using Int = uint32_t;
    using Vec2 = envmis::Vec2;
    using Vec3 = envmis::Vec3;
    using SinCos = envmis::SinCos;
};
template <class F>
using IntOf = typename Lanes<F>::Int;
template <class F>
using Vec2Of = typename Lanes<F>::Vec2;
template <class F>
using Vec3Of = typename Lanes<F>::Vec3;
template <class F>
using SinCosOf = typename Lanes<F>::SinCos;
// The lane type of a vector type: float for Vec2 and Vec3.
template <class V>
using LaneOf = decltype(V::x);

ENVMIS_HD inline float select(bool c, float a, float b) noexcept { return c ? a : b; }
ENVMIS_HD inline uint32_t select(bool c, uint32_t a, uint32_t b) noexcept { return c ? a : b; }
ENVMIS_HD inline float abs_of(float v) noexcept { return std::abs(v); }
ENVMIS_HD inline float sqrt_of(float v) noexcept { return std::sqrt(v); }
ENVMIS_HD inline float copysign_of(float magnitude, float sign) noexcept { return std::copysign(magnitude, sign); }
ENVMIS_HD inline float to_float(uint32_t v) noexcept { return static_cast<float>(static_cast<int32_t>(v)); }
ENVMIS_HD inline uint32_t truncate(float v) noexcept { return static_cast<uint32_t>(static_cast<int32_t>(v)); }
ENVMIS_HD inline uint32_t to_bits(float v) noexcept { return bit_cast<uint32_t>(v); }
ENVMIS_HD inline float from_bits(uint32_t v) noexcept { return bit_cast<float>(v); }

// c ? a : b by a bit mask, never a jump: for selects on data a branch would mispredict.
// Without SSE4.1, GCC compiles a float ?: (and min, max, clamp) to a jump.
ENVMIS_HD inline float select_bits(bool c, float a, float b) noexcept {
    const uint32_t m = 0u - static_cast<uint32_t>(c);
    return from_bits((to_bits(a) & m) | (to_bits(b) & ~m));
}

}  // namespace envmis
