// Internal: splits an index range over the machine's cores with plain std::thread,
// so that envmis::core needs no threading library. Each index is processed by exactly
// one call, so results never depend on the number of threads.
#pragma once

#include <algorithm>
#include <cstdint>
#include <thread>
#include <vector>

namespace envmis::detail {

// Calls fn(lo, hi) on disjoint chunks covering [0, n). Small ranges run inline.
template <class Fn>
void parallel_for(uint32_t n, uint32_t min_per_thread, Fn&& fn) {
    const uint32_t cores = std::max(1u, std::thread::hardware_concurrency());
    const uint32_t threads = std::min(cores, std::max(1u, n / std::max(1u, min_per_thread)));
    if (threads <= 1) {
        fn(0u, n);
        return;
    }
    std::vector<std::jthread> pool;
    pool.reserve(threads - 1);
    const uint32_t chunk = (n + threads - 1) / threads;
    for (uint32_t t = 1; t < threads; ++t) {
        const uint32_t lo = std::min(n, t * chunk), hi = std::min(n, lo + chunk);
        pool.emplace_back([&fn, lo, hi] { fn(lo, hi); });
    }
    fn(0u, std::min(n, chunk));
}

}  // namespace envmis::detail
