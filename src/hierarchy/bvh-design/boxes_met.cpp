// BoxColumns' counts: every segment reaching a node against every candidate box, the inner loop
// of bvh-design. A segment's broadcasts are made once for all its boxes; eight boxes at a time
// with AVX2 where the CPU has it (the same operations lane by lane, so the same counts).
#include "boxes_met.hpp"

#include "util/cpu.hpp"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define RTCOST_BOXES_MET_AVX2 1
#endif

namespace rtcost::bvh {

void BoxColumns::assign(std::span<const Box3> boxes) {
    n_ = boxes.size();
    padded_ = (n_ + 7) / 8 * 8;
    // Empty boxes (lo above hi, at infinity): a segment enters at +inf, which box_entry rejects.
    for (int a = 0; a < 3; ++a) {
        lo_[a].assign(padded_, kInf);
        hi_[a].assign(padded_, -kInf);
    }
    for (std::size_t j = 0; j < n_; ++j)
        for (int a = 0; a < 3; ++a) {
            lo_[a][j] = boxes[j].lo[a];
            hi_[a][j] = boxes[j].hi[a];
        }
}

void BoxColumns::count_met_baseline(std::span<const std::uint32_t> which, const Segment* segments,
                                    std::uint32_t* counts) const {
#if defined(__SSE2__)
    for (std::uint32_t r : which) {
        const Lanes lanes(*this, segments[r]);
        // A met lane is all ones, -1 as an integer: four counts at once.
        for (std::size_t j = 0; j < padded_; j += 4) {
            __m128i* at = reinterpret_cast<__m128i*>(counts + j);
            _mm_storeu_si128(at, _mm_sub_epi32(_mm_loadu_si128(at), _mm_castps_si128(lanes.met(j))));
        }
    }
#else
    for (std::uint32_t r : which)
        each_met(segments[r], [&](std::size_t j) { ++counts[j]; });
#endif
}

#if RTCOST_BOXES_MET_AVX2
#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx2"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx2")
#endif
namespace {

void count_met_avx2(std::size_t padded, const float* const lo[3], const float* const hi[3],
                    std::span<const std::uint32_t> which, const Segment* segments, std::uint32_t* counts) {
    const __m256 widen = _mm256_set1_ps(1.0000004f), inf = _mm256_set1_ps(kInf);
    for (std::uint32_t r : which) {
        const Segment& s = segments[r];
        __m256 o[3], inv[3];
        const float* near[3];
        const float* far[3];
        for (int a = 0; a < 3; ++a) {
            o[a] = _mm256_set1_ps(s.o[a]);
            inv[a] = _mm256_set1_ps(s.inv[a]);
            near[a] = s.neg[a] ? hi[a] : lo[a];
            far[a] = s.neg[a] ? lo[a] : hi[a];
        }
        const __m256 start = _mm256_set1_ps(s.t0), end = _mm256_set1_ps(s.t1);
        for (std::size_t j = 0; j < padded; j += 8) {
            __m256 t0 = start, t1 = end;
            for (int a = 0; a < 3; ++a) {
                const __m256 tn = _mm256_mul_ps(_mm256_sub_ps(_mm256_loadu_ps(near[a] + j), o[a]), inv[a]);
                const __m256 tf =
                    _mm256_mul_ps(_mm256_mul_ps(_mm256_sub_ps(_mm256_loadu_ps(far[a] + j), o[a]), inv[a]), widen);
                t0 = _mm256_max_ps(tn, t0);  // tn > t0 ? tn : t0, as maxps
                t1 = _mm256_min_ps(tf, t1);
            }
            const __m256 met =
                _mm256_and_ps(_mm256_cmp_ps(t0, t1, _CMP_LE_OQ), _mm256_cmp_ps(t0, inf, _CMP_LT_OQ));
            __m256i* at = reinterpret_cast<__m256i*>(counts + j);
            _mm256_storeu_si256(at, _mm256_sub_epi32(_mm256_loadu_si256(at), _mm256_castps_si256(met)));
        }
    }
}

}  // namespace
#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif

#endif

void BoxColumns::count_met(std::span<const std::uint32_t> which, const Segment* segments, std::uint32_t* counts) const {
#if RTCOST_BOXES_MET_AVX2
    static const bool avx2 = cpu_has_avx2();
    if (avx2) {
        const float* lo[3] = {lo_[0].data(), lo_[1].data(), lo_[2].data()};
        const float* hi[3] = {hi_[0].data(), hi_[1].data(), hi_[2].data()};
        count_met_avx2(padded_, lo, hi, which, segments, counts);
        return;
    }
#endif
    count_met_baseline(which, segments, counts);
}

}  // namespace rtcost::bvh
