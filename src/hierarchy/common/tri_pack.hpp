#pragma once
// Triangles stored side by side for a SIMD test of several at once (bvh-wide's leaves, the binary
// BVH's leaves of triangles). The test itself is tri_pack_test.inc, compiled per instruction set.

#include <cstdint>

#include "rtcost/primitive.hpp"

namespace rtcost {

/// `K` triangles of a leaf side by side, one lane each:
/// `v[3 i + a]` is vertex i's coordinate on axis a. Lanes past the leaf's count are unused.
template <int K>
struct alignas(32) TriPack {
    float v[9][K];
    std::uint32_t id[K];
    PrimKind kind[K];
};

}  // namespace rtcost
