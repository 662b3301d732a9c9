// Allocator for the large buffers: sampling tables and the radiance they index (hundreds
// of MB for 8k and 16k maps).
//
// Two things make such buffers slow, and this allocator removes both: zero-filling
// memory that is overwritten anyway (it default-initialises, so a new
// std::vector<uint32_t> is left unwritten; a type with member initialisers, such as
// Rgb, is still initialised), and 4 KiB pages (on Linux, blocks of 4 MiB or more are
// 2 MiB-aligned and advised to use transparent huge pages before anything touches them,
// so they fault in as huge pages where the system allows it). Lookups read an 8k map's
// radiance and tables at random texels; on 4 KiB pages nearly every such read also
// misses the TLB.
// The table builders then touch the memory first from all cores, in parallel.
#pragma once

#include <cstddef>
#include <cstdlib>
#include <new>
#include <utility>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace envmis {

template <class T>
struct LargeAllocator {
    using value_type = T;

    LargeAllocator() = default;
    template <class U>
    LargeAllocator(const LargeAllocator<U>&) noexcept {}

    static constexpr size_t kHuge = size_t{2} << 20;
    static constexpr size_t kLarge = 2 * kHuge;

    T* allocate(size_t n) {
        const size_t bytes = n * sizeof(T);
        if (bytes < kLarge) return static_cast<T*>(::operator new(bytes));
        void* p = std::aligned_alloc(kHuge, (bytes + kHuge - 1) / kHuge * kHuge);
        if (!p) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
        ::madvise(p, bytes, MADV_HUGEPAGE);
#endif
        return static_cast<T*>(p);
    }
    void deallocate(T* p, size_t n) noexcept {
        if (n * sizeof(T) < kLarge)
            ::operator delete(p);
        else
            std::free(p);
    }
    // Default-initialisation: no zero fill for trivial types.
    template <class U>
    void construct(U* p) noexcept {
        ::new (static_cast<void*>(p)) U;
    }
    template <class U, class... Args>
    void construct(U* p, Args&&... args) {
        ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }
    template <class U>
    friend bool operator==(const LargeAllocator&, const LargeAllocator<U>&) noexcept {
        return true;
    }
};

template <class T>
using LargeVector = std::vector<T, LargeAllocator<T>>;

}  // namespace envmis
