// Specification of the content hash (hash.h).
#include <gtest/gtest.h>

#include <vector>

#include "envmis/math/hash.h"
#include "stats.h"

namespace envmis {
namespace {

std::vector<std::byte> random_bytes(size_t n, uint64_t seed) {
    test::Rng rng(seed);
    std::vector<std::byte> b(n);
    for (auto& x : b) x = static_cast<std::byte>(rng.engine()() & 0xff);
    return b;
}

TEST(Hash, EverySingleBitFlipChangesTheHash) {
    const auto bytes = random_bytes(203, 1);
    const uint64_t h = hash64(bytes);
    for (size_t i = 0; i < bytes.size(); ++i)
        for (int bit = 0; bit < 8; ++bit) {
            auto copy = bytes;
            copy[i] ^= std::byte{static_cast<unsigned char>(1u << bit)};
            ASSERT_NE(hash64(copy), h) << i << ":" << bit;
        }
}

TEST(Hash, LengthMatters) {
    const std::vector<std::byte> a(64, std::byte{0}), b(65, std::byte{0});
    EXPECT_NE(hash64(a), hash64(b));
    EXPECT_NE(hash64({}), hash64(std::span(a).first(1)));
}

TEST(Hash, StreamingEqualsOneShotForAnySplit) {
    const auto bytes = random_bytes(300, 2);
    const uint64_t whole = hash64(bytes);
    for (size_t split : {0, 1, 7, 31, 32, 33, 100, 299, 300}) {
        Hasher h;
        h.update(std::span(bytes).first(split));
        h.update(std::span(bytes).subspan(split));
        EXPECT_EQ(h.digest(), whole) << split;
    }
}

}  // namespace
}  // namespace envmis
