#pragma once
// A box as two 4-lane float vectors (x, y, z and a spare lane), for the builders' passes over
// many primitive boxes: one min and one max instruction per extend instead of six. Extending
// keeps Box3::extend's exact results (the same comparison picks each lane, so even the sign of
// a zero agrees), so that a builder may use either and make the same tree.

#include <cstdint>
#include <cstring>

#include "rtcost/math.hpp"

#if defined(__SSE2__)
#include <immintrin.h>
#endif

namespace rtcost::bvh {

using f4 = float __attribute__((vector_size(16)));

/// std::min(a, b) lane by lane: b where b < a, else a.
inline f4 min4(f4 a, f4 b) {
#if defined(__SSE2__)
    return reinterpret_cast<f4>(_mm_min_ps(reinterpret_cast<__m128>(b), reinterpret_cast<__m128>(a)));
#else
    return b < a ? b : a;
#endif
}

/// std::max(a, b) lane by lane: b where a < b, else a.
inline f4 max4(f4 a, f4 b) {
#if defined(__SSE2__)
    return reinterpret_cast<f4>(_mm_max_ps(reinterpret_cast<__m128>(b), reinterpret_cast<__m128>(a)));
#else
    return a < b ? b : a;
#endif
}

inline f4 to_f4(Vec3 v, float w = 0) { return f4{v.x, v.y, v.z, w}; }
inline Vec3 to_vec3(f4 v) { return {v[0], v[1], v[2]}; }

struct Box4 {
    f4 lo{kInf, kInf, kInf, kInf};
    f4 hi{-kInf, -kInf, -kInf, -kInf};
    void extend(f4 p) { lo = min4(lo, p), hi = max4(hi, p); }
    void extend(f4 l, f4 h) { lo = min4(lo, l), hi = max4(hi, h); }
    Box3 box3() const { return {to_vec3(lo), to_vec3(hi)}; }
};

/// A primitive's box with its id in the spare lane of `lo` (its bits, not a value: read it with
/// id(), and use centroid(), which clears that lane, for arithmetic).
struct alignas(16) BoxRef {
    f4 lo, hi;
    BoxRef() = default;
    BoxRef(const Box3& b, std::uint32_t id) : lo(to_f4(b.lo)), hi(to_f4(b.hi)) {
        float bits;
        std::memcpy(&bits, &id, sizeof bits);
        lo[3] = bits;
    }
    std::uint32_t id() const {
        const float bits = lo[3];
        std::uint32_t v;
        std::memcpy(&v, &bits, sizeof v);
        return v;
    }
    /// Box3::center() of the box, lane by lane; 0 in the spare lane.
    f4 centroid() const {
        f4 l = lo;
        l[3] = 0;
        return (l + f4{hi[0], hi[1], hi[2], 0}) * 0.5f;
    }
};
static_assert(sizeof(BoxRef) == 32);

}  // namespace rtcost::bvh
