#pragma once
// The slab test of a binary node's two children at once, in SSE lanes (x, y, z and a spare
// lane), for the binary BVH walk: the same entry distances as box_entry on each child, bit for
// bit but for the sign of a zero. The scalar test spent most of the walk's instructions picking
// each axis' near and far face through the ray's sign array; here one mask picks all three.

#include <cstddef>

#include "rtcost/math.hpp"

#if defined(__SSE2__)
#include <immintrin.h>
#endif

namespace rtcost::bvh {

#if defined(__SSE2__)

/// A ray's part of the test, made once per walk. The spare lane's reciprocal is NaN, so that
/// lane (whatever the node holds there) is dropped by the min and max below, as box_entry drops
/// the NaN of a ray in a face's plane.
struct PairRay {
    __m128 o, inv, neg, xyz;
    explicit PairRay(const RayInv& r)
        : o(_mm_setr_ps(r.o.x, r.o.y, r.o.z, 0.0f)),
          inv(_mm_setr_ps(r.inv.x, r.inv.y, r.inv.z, __builtin_nanf(""))),
          neg(_mm_castsi128_ps(_mm_setr_epi32(-r.neg[0], -r.neg[1], -r.neg[2], 0))),
          xyz(_mm_castsi128_ps(_mm_setr_epi32(-1, -1, -1, 0))) {}
};

/// Entry distances of boxes `a` and `b` over (tmin, limit), kInf for a miss: box_entry's. Each
/// box is read with the four bytes after it (a node's box is followed by its index).
[[gnu::always_inline]] inline void pair_entry(const Box3& a, const Box3& b, const PairRay& r, float tmin, float limit,
                                               float& ta, float& tb) {
    static_assert(offsetof(Box3, hi) == 12);
    const __m128 grow = _mm_set1_ps(1.0000004f);  // box_entry's widening of the exit distance
    const __m128 t0 = _mm_set1_ps(tmin), t1 = _mm_set1_ps(limit);
    auto one = [&](const Box3& box, __m128& near, __m128& far) {
        // lo.x lo.y lo.z hi.x and hi.x hi.y hi.z 0: the spare lanes are dropped. The four bytes
        // after the box are cleared, not computed with: a node's index read as a float is
        // subnormal, and arithmetic on a subnormal costs a microcode assist (twice the walk's time).
        const __m128 lo = _mm_loadu_ps(&box.lo.x), hi = _mm_and_ps(_mm_loadu_ps(&box.hi.x), r.xyz);
        const __m128 swap = _mm_and_ps(_mm_xor_ps(lo, hi), r.neg);  // faces exchanged where neg
        const __m128 tn = _mm_mul_ps(_mm_sub_ps(_mm_xor_ps(lo, swap), r.o), r.inv);
        const __m128 tf = _mm_mul_ps(_mm_mul_ps(_mm_sub_ps(_mm_xor_ps(hi, swap), r.o), r.inv), grow);
        // maxps(a, b) is `a > b ? a : b`: a NaN lane yields the bound, as in box_entry.
        near = _mm_max_ps(tn, t0);
        far = _mm_min_ps(tf, t1);
    };
    __m128 na, fa, nb, fb;
    one(a, na, fa);
    one(b, nb, fb);
    // Lanes (a, b) side by side, then the largest entry and smallest exit of each; no NaN is left,
    // so the order of the reduction does not change the values.
    __m128 n = _mm_max_ps(_mm_unpacklo_ps(na, nb), _mm_unpackhi_ps(na, nb));
    __m128 f = _mm_min_ps(_mm_unpacklo_ps(fa, fb), _mm_unpackhi_ps(fa, fb));
    n = _mm_max_ps(n, _mm_movehl_ps(n, n));
    f = _mm_min_ps(f, _mm_movehl_ps(f, f));
    const int met = _mm_movemask_ps(_mm_cmple_ps(n, f));
    ta = met & 1 ? _mm_cvtss_f32(n) : kInf;
    tb = met & 2 ? _mm_cvtss_f32(_mm_shuffle_ps(n, n, 1)) : kInf;
}

#else

struct PairRay {
    const RayInv* r;
    explicit PairRay(const RayInv& ri) : r(&ri) {}
};

inline void pair_entry(const Box3& a, const Box3& b, const PairRay& r, float tmin, float limit, float& ta, float& tb) {
    ta = box_entry(a, *r.r, tmin, limit);
    tb = box_entry(b, *r.r, tmin, limit);
}

#endif

}  // namespace rtcost::bvh
