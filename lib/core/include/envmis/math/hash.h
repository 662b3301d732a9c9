// A fast 64-bit content hash for table checksums and source-file fingerprints.
//
// Not cryptographic: it detects corruption and identifies a source file, nothing more.
// Every 8-byte word goes through an invertible step (xor, then multiply by an odd
// constant), so changing any single word of the input always changes the hash; four
// independent lanes keep it near memory speed (measured: docs/performance-log.md,
// 'Hasher').
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>

namespace envmis {

class Hasher {
public:
    void update(std::span<const std::byte> bytes) noexcept {
        const std::byte* p = bytes.data();
        size_t n = bytes.size();
        total_ += n;
        while (n && pending_size_) {  // finish a partial word from the previous update
            pending_[pending_size_++] = *p++, --n;
            if (pending_size_ == sizeof pending_) flush_pending();
        }
        for (; n >= 32; p += 32, n -= 32)
            for (int lane = 0; lane < 4; ++lane) mix(lane, load(p + 8 * lane));
        for (; n; --n) {
            pending_[pending_size_++] = *p++;
            if (pending_size_ == sizeof pending_) flush_pending();
        }
    }

    uint64_t digest() const noexcept {
        Hasher h = *this;
        const size_t tail = h.pending_size_;
        std::memset(h.pending_ + tail, 0, sizeof h.pending_ - tail);
        for (int lane = 0; lane < 4; ++lane) h.mix(lane, load(h.pending_ + 8 * lane));
        uint64_t out = h.total_;
        for (uint64_t lane : h.lanes_) out = avalanche(out ^ avalanche(lane));
        return out;
    }

private:
    static constexpr uint64_t kPrime = 0x100000001b3ull * 0x9e3779b97f4a7c15ull | 1;

    static uint64_t load(const std::byte* p) noexcept {
        uint64_t v;
        std::memcpy(&v, p, 8);
        return v;
    }
    static uint64_t avalanche(uint64_t x) noexcept {
        x ^= x >> 33, x *= 0xff51afd7ed558ccdull;
        x ^= x >> 33, x *= 0xc4ceb9fe1a85ec53ull;
        return x ^ (x >> 33);
    }
    void mix(int lane, uint64_t word) noexcept { lanes_[lane] = (lanes_[lane] ^ word) * kPrime; }
    void flush_pending() noexcept {
        for (int lane = 0; lane < 4; ++lane) mix(lane, load(pending_ + 8 * lane));
        pending_size_ = 0;
    }

    uint64_t lanes_[4] = {0xcbf29ce484222325ull, 0x84222325cbf29ce4ull, 0x9e3779b97f4a7c15ull, 0x7f4a7c159e3779b9ull};
    std::byte pending_[32] = {};
    size_t pending_size_ = 0;
    uint64_t total_ = 0;
};

inline uint64_t hash64(std::span<const std::byte> bytes) noexcept {
    Hasher h;
    h.update(bytes);
    return h.digest();
}

}  // namespace envmis
