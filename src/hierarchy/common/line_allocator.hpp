#pragma once
// An allocator that places an array against 64-byte cache lines, for arrays whose elements a
// traversal reads a line at a time (malloc aligns to 16 bytes, so every other element would
// straddle two lines).
#include <cstddef>
#include <new>

namespace rtcost {

/// Places the array's first element `Lead` elements before a cache line starts: with `Lead` 0,
/// every element of a multiple of 32 bytes starts a line or half a line in, and so spans no more
/// lines than its size rounded up to a line (bvh's leaf packs, 160 bytes: three); with `Lead` 1 and
/// 32-byte elements, each pair from an odd index shares one line (a binary BVH's sibling nodes,
/// laid out as the root, then pairs).
template <class T, std::size_t Lead = 0>
struct LineAllocator {
    static_assert(sizeof(T) % 32 == 0 || 64 % sizeof(T) == 0, "elements tile cache lines or half lines");
    static constexpr std::size_t kLeadBytes = Lead * sizeof(T);
    using value_type = T;
    template <class U>
    struct rebind {
        using other = LineAllocator<U, Lead>;
    };
    LineAllocator() = default;
    template <class U>
    LineAllocator(const LineAllocator<U, Lead>&) {}
    T* allocate(std::size_t n) {
        auto* line = static_cast<std::byte*>(::operator new(n * sizeof(T) + kLeadBytes, std::align_val_t{64}));
        return reinterpret_cast<T*>(line + kLeadBytes);
    }
    void deallocate(T* p, std::size_t) {
        ::operator delete(reinterpret_cast<std::byte*>(p) - kLeadBytes, std::align_val_t{64});
    }
    friend bool operator==(const LineAllocator&, const LineAllocator&) { return true; }
};

}  // namespace rtcost
