// The table file's layout (docs/table-format.md), shared by the reader (table.h, in
// envmis::core) and the writer (envmis/build/table_writer.h): the preamble's constants,
// the metadata flags, the limits a reader enforces on every size it reads, the bins
// section's size, and the RGBE codec of compact tables. All little-endian.
#pragma once

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>

#include "envmis/math/math.h"

namespace envmis::table_format {

static_assert(std::endian::native == std::endian::little, "table files are little-endian; port the I/O first");

inline constexpr std::byte kMagic[8] = {std::byte{0x89}, std::byte{'E'}, std::byte{'N'}, std::byte{'V'},
                                        std::byte{'M'},  std::byte{'I'}, std::byte{'S'}, std::byte{0x1A}};
inline constexpr uint32_t kByteOrderMark = 0x01020304;
inline constexpr size_t kPreambleSize = 32;
inline constexpr uint32_t kMaxMetadataSize = 64 * 1024;
inline constexpr uint32_t kMaxStringSize = 4096;
inline constexpr uint64_t kMaxTexels = uint64_t{1} << 31;
inline constexpr uint32_t kSamplerCdf = 1;
inline constexpr uint32_t kFlagCompensation = 1;
inline constexpr uint32_t kFlagCompact = 2;  // payload: RGBE radiance only (TableEncoding::compact)
// Version 3 pads the metadata block with zeros to a multiple of this, so that the payload's
// arrays are aligned in the file and a mapping of it can be used in place.
inline constexpr uint32_t kMetadataAlignment = 8;
// The bins section (BinLayout): four u32 (bins per side g of the glossy classes, cell
// columns, cell rows, classes C), from version 6 a fifth (the diffuse class's g_d; before,
// g_d = g), C lobe exponents, then g_d^2 + (C - 1) g^2 choices: (alpha, threshold), from
// version 7 (alpha, threshold, min_view_cos); all 4 bytes.
inline constexpr uint32_t kMaxBinsPerSide = 64, kMaxCellSide = 4096, kMaxLobeClasses = 8;
constexpr uint32_t bins_section_size(uint32_t version, uint32_t gd, uint32_t g, uint32_t classes) {
    return (version >= 6 ? 20 : 16) + 4 * classes + (version >= 7 ? 12 : 8) * (gd * gd + (classes - 1) * g * g);
}
inline constexpr uint32_t kMaxBinsSection = bins_section_size(7, kMaxBinsPerSide, kMaxBinsPerSide, kMaxLobeClasses);
inline constexpr uint32_t kMinBinsSection = bins_section_size(5, 1, 1, 1);

// RGBE (Ward 1991): three 8-bit mantissas sharing the exponent of the largest channel,
// rounded to nearest. Byte 3 is the exponent + 128; 0 means black.
// 2^k as a double, for |k| < 1023, from its bits (no libm call on the per-texel path).
inline double power_of_two(int k) noexcept { return std::bit_cast<double>(static_cast<uint64_t>(k + 1023) << 52); }

inline uint32_t rgbe_encode(Rgb c) noexcept {
    const float m = std::max({c.r, c.g, c.b});
    if (!(m >= 1e-38f)) return 0;
    // m = f 2^e with f in [0.5, 1) (m is a normal float): the largest mantissa is 128..255.
    int e = static_cast<int>((std::bit_cast<uint32_t>(m) >> 23) & 0xff) - 126;
    if (m * power_of_two(8 - e) + 0.5 >= 256) ++e;  // rounds up to 256: one more bit of exponent
    e = std::min(e, 127);                           // above 2^127 (1.7e38) the largest channel saturates at 255 2^119
    const double scale = power_of_two(8 - e);
    const auto byte = [&](float v) { return static_cast<uint32_t>(std::min(v * scale + 0.5, 255.0)); };
    return byte(c.r) | byte(c.g) << 8 | byte(c.b) << 16 | static_cast<uint32_t>(e + 128) << 24;
}

inline Rgb rgbe_decode(uint32_t v) noexcept {
    const int e = static_cast<int>(v >> 24);
    if (e == 0) return {};
    const double scale = power_of_two(e - 128 - 8);
    const auto channel = [&](int shift) {
        return static_cast<float>(static_cast<double>((v >> shift) & 0xff) * scale);
    };
    return {channel(0), channel(8), channel(16)};
}

}  // namespace envmis::table_format
