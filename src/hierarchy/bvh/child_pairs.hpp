#pragma once
// The traversal's copy of a binary BVH: an interior node is one 64-byte, cache-line-aligned
// record holding both children's boxes (lanes of 4-float vectors) and what a visit of each child
// needs. A visit then reads one cache line instead of two 32-byte nodes that straddle two lines
// (siblings start at odd indices of BvhData::nodes), and tests both boxes with one vector
// computation whose lanes repeat box_entry's float operations in the same order, so that the
// entry distances, and with them the visits and the counts, are exactly the scalar test's.

#include <cstdint>
#include <vector>

#include "rtcost/math.hpp"

#if defined(__SSE2__)
#include <immintrin.h>
#endif

namespace rtcost::bvh {

/// A child as the traversal enters it: an interior child's record, or a leaf's primitives.
/// Trivial, so that a traversal's stack of them costs nothing to declare.
struct ChildRef {
    std::uint32_t index;       ///< interior: its ChildPair; leaf: its first LeafPrim
    std::uint32_t count : 31;  ///< leaf: its primitives; interior: 2
    std::uint32_t leaf : 1;
};

/// Both children of a binary interior node. Per axis, lanes {lo of child 0, lo of child 1, hi of
/// child 0, hi of child 1}.
struct alignas(64) ChildPair {
    float x[4], y[4], z[4];
    ChildRef child[2];
};
static_assert(sizeof(ChildPair) == 64);

/// The ray's part of the pair test: origin, reciprocal and, per axis, which half of the lanes
/// holds the entry faces.
struct PairRay {
    using f4 = float __attribute__((vector_size(16)));
    using i4 = std::int32_t __attribute__((vector_size(16)));
    f4 o[3], inv[3];
    i4 neg[3];  ///< all ones where the direction is negative (hi faces entered first)
    explicit PairRay(const RayInv& r) {
        for (int a = 0; a < 3; ++a) {
            o[a] = f4{} + r.o[a];
            inv[a] = f4{} + r.inv[a];
            neg[a] = i4{} + (r.neg[a] ? -1 : 0);
        }
    }
};

/// box_entry of both children of `p` over (tmin, tmax): entry distances, +inf for a miss.
inline void pair_entry(const ChildPair& p, const PairRay& r, float tmin, float tmax, float& t0a, float& t0b) {
    using f4 = PairRay::f4;
    using i4 = PairRay::i4;
    const float* axis[3] = {p.x, p.y, p.z};
    f4 t0 = f4{} + tmin, t1 = f4{} + tmax;
    for (int a = 0; a < 3; ++a) {
        f4 v;
        __builtin_memcpy(&v, axis[a], sizeof v);
        const f4 d = (v - r.o[a]) * r.inv[a];             // {lo0, lo1, hi0, hi1} as distances
        const f4 s = __builtin_shufflevector(d, d, 2, 3, 0, 1);  // halves swapped
        const i4 m = r.neg[a];
        const f4 near = reinterpret_cast<f4>((reinterpret_cast<i4>(s) & m) | (reinterpret_cast<i4>(d) & ~m));
        const f4 far = reinterpret_cast<f4>((reinterpret_cast<i4>(d) & m) | (reinterpret_cast<i4>(s) & ~m)) * 1.0000004f;
        // box_entry's `t0 = n > t0 ? n : t0` and `t1 = f < t1 ? f : t1`, NaN (a ray in a face's
        // plane) ignored because every compare with it fails.
#if defined(__SSE2__)
        t0 = reinterpret_cast<f4>(_mm_max_ps(reinterpret_cast<__m128>(near), reinterpret_cast<__m128>(t0)));
        t1 = reinterpret_cast<f4>(_mm_min_ps(reinterpret_cast<__m128>(far), reinterpret_cast<__m128>(t1)));
#else
        t0 = near > t0 ? near : t0;
        t1 = far < t1 ? far : t1;
#endif
    }
    t0a = t0[0] <= t1[0] ? t0[0] : kInf;
    t0b = t0[1] <= t1[1] ? t0[1] : kInf;
}

}  // namespace rtcost::bvh
