#pragma once
// Four float lanes for the baseline instruction set: SSE2 on x86-64, plain per-lane loops
// elsewhere. bvh-wide's baseline traversal and the binary BVH's triangle packs compute in them;
// the AVX2 traversal has its own (walk_avx2.cpp).

#include <algorithm>
#include <cmath>

#if defined(__x86_64__) || defined(_M_X64)
#include <immintrin.h>
#define RTCOST_LANES_SSE 1
#endif

namespace rtcost::lanes {

#if RTCOST_LANES_SSE
struct F4 {
    __m128 v;
    static F4 load(const float* p) { return {_mm_load_ps(p)}; }
    static F4 splat(float x) { return {_mm_set1_ps(x)}; }
    static F4 sub(F4 a, F4 b) { return {_mm_sub_ps(a.v, b.v)}; }
    static F4 mul(F4 a, F4 b) { return {_mm_mul_ps(a.v, b.v)}; }
    static F4 add(F4 a, F4 b) { return {_mm_add_ps(a.v, b.v)}; }
    static F4 div(F4 a, F4 b) { return {_mm_div_ps(a.v, b.v)}; }
    static F4 abs(F4 a) { return {_mm_andnot_ps(_mm_set1_ps(-0.0f), a.v)}; }  // the sign bit cleared
    static __m128 lt(F4 a, F4 b) { return _mm_cmplt_ps(a.v, b.v); }
    static __m128 gt(F4 a, F4 b) { return _mm_cmpgt_ps(a.v, b.v); }
    static __m128 eq(F4 a, F4 b) { return _mm_cmpeq_ps(a.v, b.v); }
    static __m128 neq(F4 a, F4 b) { return _mm_cmpneq_ps(a.v, b.v); }  // true when unordered
    static __m128 mand(__m128 a, __m128 b) { return _mm_and_ps(a, b); }
    static __m128 mor(__m128 a, __m128 b) { return _mm_or_ps(a, b); }
    static unsigned bits(__m128 m) { return static_cast<unsigned>(_mm_movemask_ps(m)); }
    static F4 max(F4 a, F4 b) { return {_mm_max_ps(a.v, b.v)}; }  // a > b ? a : b
    static F4 min(F4 a, F4 b) { return {_mm_min_ps(a.v, b.v)}; }  // a < b ? a : b
    static unsigned le(F4 a, F4 b) { return static_cast<unsigned>(_mm_movemask_ps(_mm_cmple_ps(a.v, b.v))); }
    void store(float* p) const { _mm_store_ps(p, v); }
};
#else
struct F4 {
    float v[4];
    static F4 load(const float* p) { return {{p[0], p[1], p[2], p[3]}}; }
    static F4 splat(float x) { return {{x, x, x, x}}; }
    static F4 sub(F4 a, F4 b) { return {{a.v[0] - b.v[0], a.v[1] - b.v[1], a.v[2] - b.v[2], a.v[3] - b.v[3]}}; }
    static F4 mul(F4 a, F4 b) { return {{a.v[0] * b.v[0], a.v[1] * b.v[1], a.v[2] * b.v[2], a.v[3] * b.v[3]}}; }
    static F4 add(F4 a, F4 b) { return {{a.v[0] + b.v[0], a.v[1] + b.v[1], a.v[2] + b.v[2], a.v[3] + b.v[3]}}; }
    static F4 div(F4 a, F4 b) { return {{a.v[0] / b.v[0], a.v[1] / b.v[1], a.v[2] / b.v[2], a.v[3] / b.v[3]}}; }
    static F4 abs(F4 a) { return {{std::fabs(a.v[0]), std::fabs(a.v[1]), std::fabs(a.v[2]), std::fabs(a.v[3])}}; }
    template <class F>
    static unsigned mask(F4 a, F4 b, F f) {
        unsigned m = 0;
        for (int i = 0; i < 4; ++i) m |= unsigned(f(a.v[i], b.v[i])) << i;
        return m;
    }
    static unsigned lt(F4 a, F4 b) { return mask(a, b, [](float x, float y) { return x < y; }); }
    static unsigned gt(F4 a, F4 b) { return mask(a, b, [](float x, float y) { return x > y; }); }
    static unsigned eq(F4 a, F4 b) { return mask(a, b, [](float x, float y) { return x == y; }); }
    static unsigned neq(F4 a, F4 b) { return mask(a, b, [](float x, float y) { return !(x == y); }); }
    static unsigned mand(unsigned a, unsigned b) { return a & b; }
    static unsigned mor(unsigned a, unsigned b) { return a | b; }
    static unsigned bits(unsigned m) { return m; }
    static F4 max(F4 a, F4 b) {
        F4 r;
        for (int i = 0; i < 4; ++i) r.v[i] = a.v[i] > b.v[i] ? a.v[i] : b.v[i];
        return r;
    }
    static F4 min(F4 a, F4 b) {
        F4 r;
        for (int i = 0; i < 4; ++i) r.v[i] = a.v[i] < b.v[i] ? a.v[i] : b.v[i];
        return r;
    }
    static unsigned le(F4 a, F4 b) {
        unsigned m = 0;
        for (int i = 0; i < 4; ++i) m |= unsigned(a.v[i] <= b.v[i]) << i;
        return m;
    }
    void store(float* p) const { std::copy(v, v + 4, p); }
};
#endif

}  // namespace rtcost::lanes
