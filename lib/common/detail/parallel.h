// Internal: splits an index range over the cores this process may use (usable_cores:
// affinity, cgroup quota) with plain std::thread,
// so that envmis::core needs no threading library. Each index is processed by exactly
// one call, so results never depend on the number of threads.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <thread>
#include <utility>
#include <vector>

#include "envmis/cpu.h"
#include "envmis/interrupt.h"

namespace envmis::detail {

// Calls fn(lo, hi) on disjoint chunks of `chunk` indices (the last one shorter)
// covering [0, n). Threads take the next chunk as they finish one, so that ranges whose
// indices cost unevenly (a sky's bright and black rows) still keep every core busy to
// the end. A range of one chunk runs inline.
//
// With a StopFlag (interrupt.h), no chunk starts once it is set, even on one thread, and
// the call throws Interrupted after the chunks under way have finished: fn must not
// throw, as it runs on threads that cannot pass exceptions on.
template <class Fn>
void parallel_for(uint32_t n, uint32_t chunk, StopFlag stop, Fn&& fn) {
    chunk = std::max(1u, chunk);
    const uint32_t chunks = n / chunk + (n % chunk != 0);
    const uint32_t threads = std::min(usable_cores(), chunks);
    if (threads <= 1 && !stop) {
        fn(0u, n);
        return;
    }
    std::atomic<uint32_t> next{0};
    auto work = [&] {
        for (uint32_t c; !stop_requested(stop) && (c = next.fetch_add(1, std::memory_order_relaxed)) < chunks;) {
            const uint32_t lo = c * chunk;
            fn(lo, lo + std::min(chunk, n - lo));
        }
    };
    {
        std::vector<std::jthread> pool;
        pool.reserve(threads > 0 ? threads - 1 : 0);
        for (uint32_t t = 1; t < threads; ++t) pool.emplace_back(work);
        work();
    }
    throw_if_stopped(stop);
}

template <class Fn>
void parallel_for(uint32_t n, uint32_t chunk, Fn&& fn) {
    parallel_for(n, chunk, nullptr, std::forward<Fn>(fn));
}

}  // namespace envmis::detail
