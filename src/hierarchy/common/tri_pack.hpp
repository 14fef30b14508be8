#pragma once
// Triangles stored side by side for a SIMD test of several at once (bvh-wide's leaves, the binary
// BVH's leaves of triangles). The test itself is tri_pack_test.inc, compiled per instruction set.

#include <cstdint>

#include "rtcost/primitive.hpp"

namespace rtcost {

/// `K` triangles of a leaf side by side, one lane each (every lane a PrimKind::Triangle):
/// `v[3 i + a]` is vertex i's coordinate on axis a. Lanes past the leaf's count are unused.
/// 160 bytes for K = 4 and 320 for K = 8: five half lines, ten.
template <int K>
struct alignas(32) TriPack {
    float v[9][K];
    std::uint32_t id[K];
};
static_assert(sizeof(TriPack<4>) == 160 && sizeof(TriPack<8>) == 320);

}  // namespace rtcost
