// bvh-wide traversals compiled for AVX2 (eight lanes in one register), chosen at build time when
// the CPU runs AVX2. Only the code in namespace `avx2` below is compiled for that target; what it
// calls from the library's headers (the primitives' intersection) stays baseline code, so the
// hits are the same bit for bit as every other traversal's.
#include <algorithm>
#include <utility>

#include "../common/lanes_base.hpp"
#include "wide.hpp"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>

namespace rtcost::wide {

#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx2"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx2")
#endif

namespace avx2 {

// Four lanes: a 4-wide node's boxes, and triangle packs of four (every leaf's with tri_lanes=4,
// else a leaf's of at most four triangles, which would fill a pack of eight poorly and read
// twice its bytes). The baseline's SSE lanes: inlined here, they are compiled for this target.
using P4 = lanes::F4;

struct P8 {
    __m256 v;
    static P8 load(const float* p) { return {_mm256_load_ps(p)}; }
    static P8 splat(float x) { return {_mm256_set1_ps(x)}; }
    static P8 sub(P8 a, P8 b) { return {_mm256_sub_ps(a.v, b.v)}; }
    static P8 mul(P8 a, P8 b) { return {_mm256_mul_ps(a.v, b.v)}; }
    static P8 add(P8 a, P8 b) { return {_mm256_add_ps(a.v, b.v)}; }
    static P8 div(P8 a, P8 b) { return {_mm256_div_ps(a.v, b.v)}; }
    static P8 abs(P8 a) { return {_mm256_andnot_ps(_mm256_set1_ps(-0.0f), a.v)}; }
    static __m256 lt(P8 a, P8 b) { return _mm256_cmp_ps(a.v, b.v, _CMP_LT_OQ); }
    static __m256 gt(P8 a, P8 b) { return _mm256_cmp_ps(a.v, b.v, _CMP_GT_OQ); }
    static __m256 eq(P8 a, P8 b) { return _mm256_cmp_ps(a.v, b.v, _CMP_EQ_OQ); }
    static __m256 neq(P8 a, P8 b) { return _mm256_cmp_ps(a.v, b.v, _CMP_NEQ_UQ); }  // true when unordered
    static __m256 mand(__m256 a, __m256 b) { return _mm256_and_ps(a, b); }
    static __m256 mor(__m256 a, __m256 b) { return _mm256_or_ps(a, b); }
    static unsigned bits(__m256 m) { return static_cast<unsigned>(_mm256_movemask_ps(m)); }
    static P8 max(P8 a, P8 b) { return {_mm256_max_ps(a.v, b.v)}; }  // a > b ? a : b
    static P8 min(P8 a, P8 b) { return {_mm256_min_ps(a.v, b.v)}; }  // a < b ? a : b
    static unsigned le(P8 a, P8 b) {
        return static_cast<unsigned>(_mm256_movemask_ps(_mm256_cmp_ps(a.v, b.v, _CMP_LE_OQ)));
    }
    void store(float* p) const { _mm256_store_ps(p, v); }
};

#include "walk.inc"

Walks make(int width, int tri_lanes) {
    if (tri_lanes == 4) return width == 8 ? make_walks<P8, 8, P4, 4, P4>() : make_walks<P4, 4, P4, 4, P4>();
    return width == 8 ? make_walks<P8, 8, P8, 8, P4>() : make_walks<P4, 4, P8, 8, P4>();
}

}  // namespace avx2

#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif

Walks walks_avx2(int width, int tri_lanes) { return avx2::make(width, tri_lanes); }

}  // namespace rtcost::wide

#else

namespace rtcost::wide {
Walks walks_avx2(int width, int) { return walks_baseline(width); }
}  // namespace rtcost::wide

#endif
