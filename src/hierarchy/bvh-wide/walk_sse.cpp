// bvh-wide traversals for the baseline instruction set: SSE2 on x86-64 (four lanes in one
// register, eight in two), plain per-lane loops elsewhere.
#include <algorithm>
#include <cmath>
#include <utility>

#include "wide.hpp"

#if defined(__x86_64__) || defined(_M_X64)
#include <immintrin.h>
#define RTCOST_WIDE_SSE 1
#endif

namespace rtcost::wide {
namespace base {

#if RTCOST_WIDE_SSE
struct P4 {
    __m128 v;
    static P4 load(const float* p) { return {_mm_load_ps(p)}; }
    static P4 splat(float x) { return {_mm_set1_ps(x)}; }
    static P4 sub(P4 a, P4 b) { return {_mm_sub_ps(a.v, b.v)}; }
    static P4 mul(P4 a, P4 b) { return {_mm_mul_ps(a.v, b.v)}; }
    static P4 add(P4 a, P4 b) { return {_mm_add_ps(a.v, b.v)}; }
    static P4 div(P4 a, P4 b) { return {_mm_div_ps(a.v, b.v)}; }
    static P4 abs(P4 a) { return {_mm_andnot_ps(_mm_set1_ps(-0.0f), a.v)}; }  // the sign bit cleared
    static __m128 lt(P4 a, P4 b) { return _mm_cmplt_ps(a.v, b.v); }
    static __m128 gt(P4 a, P4 b) { return _mm_cmpgt_ps(a.v, b.v); }
    static __m128 eq(P4 a, P4 b) { return _mm_cmpeq_ps(a.v, b.v); }
    static __m128 neq(P4 a, P4 b) { return _mm_cmpneq_ps(a.v, b.v); }  // true when unordered
    static __m128 mand(__m128 a, __m128 b) { return _mm_and_ps(a, b); }
    static __m128 mor(__m128 a, __m128 b) { return _mm_or_ps(a, b); }
    static unsigned bits(__m128 m) { return static_cast<unsigned>(_mm_movemask_ps(m)); }
    static P4 max(P4 a, P4 b) { return {_mm_max_ps(a.v, b.v)}; }  // a > b ? a : b
    static P4 min(P4 a, P4 b) { return {_mm_min_ps(a.v, b.v)}; }  // a < b ? a : b
    static unsigned le(P4 a, P4 b) { return static_cast<unsigned>(_mm_movemask_ps(_mm_cmple_ps(a.v, b.v))); }
    void store(float* p) const { _mm_store_ps(p, v); }
};
#else
struct P4 {
    float v[4];
    static P4 load(const float* p) { return {{p[0], p[1], p[2], p[3]}}; }
    static P4 splat(float x) { return {{x, x, x, x}}; }
    static P4 sub(P4 a, P4 b) { return {{a.v[0] - b.v[0], a.v[1] - b.v[1], a.v[2] - b.v[2], a.v[3] - b.v[3]}}; }
    static P4 mul(P4 a, P4 b) { return {{a.v[0] * b.v[0], a.v[1] * b.v[1], a.v[2] * b.v[2], a.v[3] * b.v[3]}}; }
    static P4 add(P4 a, P4 b) { return {{a.v[0] + b.v[0], a.v[1] + b.v[1], a.v[2] + b.v[2], a.v[3] + b.v[3]}}; }
    static P4 div(P4 a, P4 b) { return {{a.v[0] / b.v[0], a.v[1] / b.v[1], a.v[2] / b.v[2], a.v[3] / b.v[3]}}; }
    static P4 abs(P4 a) { return {{std::fabs(a.v[0]), std::fabs(a.v[1]), std::fabs(a.v[2]), std::fabs(a.v[3])}}; }
    template <class F>
    static unsigned mask(P4 a, P4 b, F f) {
        unsigned m = 0;
        for (int i = 0; i < 4; ++i) m |= unsigned(f(a.v[i], b.v[i])) << i;
        return m;
    }
    static unsigned lt(P4 a, P4 b) { return mask(a, b, [](float x, float y) { return x < y; }); }
    static unsigned gt(P4 a, P4 b) { return mask(a, b, [](float x, float y) { return x > y; }); }
    static unsigned eq(P4 a, P4 b) { return mask(a, b, [](float x, float y) { return x == y; }); }
    static unsigned neq(P4 a, P4 b) { return mask(a, b, [](float x, float y) { return !(x == y); }); }
    static unsigned mand(unsigned a, unsigned b) { return a & b; }
    static unsigned mor(unsigned a, unsigned b) { return a | b; }
    static unsigned bits(unsigned m) { return m; }
    static P4 max(P4 a, P4 b) {
        P4 r;
        for (int i = 0; i < 4; ++i) r.v[i] = a.v[i] > b.v[i] ? a.v[i] : b.v[i];
        return r;
    }
    static P4 min(P4 a, P4 b) {
        P4 r;
        for (int i = 0; i < 4; ++i) r.v[i] = a.v[i] < b.v[i] ? a.v[i] : b.v[i];
        return r;
    }
    static unsigned le(P4 a, P4 b) {
        unsigned m = 0;
        for (int i = 0; i < 4; ++i) m |= unsigned(a.v[i] <= b.v[i]) << i;
        return m;
    }
    void store(float* p) const { std::copy(v, v + 4, p); }
};
#endif

/// Eight lanes as two halves.
struct P8 {
    P4 a, b;
    static P8 load(const float* p) { return {P4::load(p), P4::load(p + 4)}; }
    static P8 splat(float x) { return {P4::splat(x), P4::splat(x)}; }
    static P8 sub(P8 x, P8 y) { return {P4::sub(x.a, y.a), P4::sub(x.b, y.b)}; }
    static P8 mul(P8 x, P8 y) { return {P4::mul(x.a, y.a), P4::mul(x.b, y.b)}; }
    static P8 max(P8 x, P8 y) { return {P4::max(x.a, y.a), P4::max(x.b, y.b)}; }
    static P8 min(P8 x, P8 y) { return {P4::min(x.a, y.a), P4::min(x.b, y.b)}; }
    static unsigned le(P8 x, P8 y) { return P4::le(x.a, y.a) | (P4::le(x.b, y.b) << 4); }
    void store(float* p) const {
        a.store(p);
        b.store(p + 4);
    }
};

#include "walk.inc"

}  // namespace base

Walks walks_baseline(int width) {
    return width == 8 ? base::make_walks<base::P8, 8, base::P4, 4, base::P4>()
                      : base::make_walks<base::P4, 4, base::P4, 4, base::P4>();
}

}  // namespace rtcost::wide
