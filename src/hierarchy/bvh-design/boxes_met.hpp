#pragma once
// Which of a few boxes each sample segment meets: bvh-design weighs 10 candidate splits at every
// node, two boxes each, against every sample segment reaching the node (with the binning of the
// candidates, a third of its design time). Four boxes per ray at once with SSE here, decided
// exactly as box_entry decides one (the same operations in the same order; max/min keep the
// second operand on NaN as box_entry's compares do), so the design is the same tree.
#include <cstdint>
#include <span>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "rtcost/math.hpp"

namespace rtcost::bvh {

/// The boxes in four-wide columns: lo and hi per axis, padded to a multiple of four.
class BoxColumns {
public:
    /// Holds `boxes` (replacing any), reusing its storage: one per design, refilled per node.
    void assign(std::span<const Box3> boxes) {
        n_ = boxes.size();
        padded_ = (n_ + 3) / 4 * 4;
        for (int a = 0; a < 3; ++a) {
            lo_[a].assign(padded_, 0.0f);
            hi_[a].assign(padded_, 0.0f);
        }
        for (std::size_t j = 0; j < n_; ++j)
            for (int a = 0; a < 3; ++a) {
                lo_[a][j] = boxes[j].lo[a];
                hi_[a][j] = boxes[j].hi[a];
            }
    }

    /// Calls `met(j)` for every box j that box_entry(box j, ri, tmin, tmax) finds on the segment.
    template <class Met>
    void each_met(const RayInv& ri, float tmin, float tmax, Met&& met) const {
        const Rows rows(*this, ri);
        for (std::size_t j = 0; j < padded_; j += 4)
            for (unsigned mask = met_bits(rows, j, ri, tmin, tmax); mask; mask &= mask - 1)
                met(j + static_cast<std::size_t>(__builtin_ctz(mask)));
    }

    /// Adds one to `counts[j]` for every box j that each_met would report; `counts` holds
    /// padded() entries (the padding's stay 0).
    void count_met(const RayInv& ri, float tmin, float tmax, std::uint32_t* counts) const {
        const Rows rows(*this, ri);
#if defined(__SSE2__)
        // Four counts at once: a met lane is all ones, -1 as an integer (a tenth of the design
        // time went to adding the four bits one by one).
        for (std::size_t j = 0; j < padded_; j += 4) {
            __m128i* at = reinterpret_cast<__m128i*>(counts + j);
            _mm_storeu_si128(at, _mm_sub_epi32(_mm_loadu_si128(at), _mm_castps_si128(met_lanes(rows, j, ri, tmin, tmax))));
        }
#else
        for (std::size_t j = 0; j < padded_; j += 4) {
            const unsigned mask = met_bits(rows, j, ri, tmin, tmax);
            for (int k = 0; k < 4; ++k) counts[j + k] += (mask >> k) & 1u;
        }
#endif
    }

    /// The boxes' count rounded up to a multiple of four.
    std::size_t padded() const { return padded_; }

private:
    // Each axis's near and far planes for the ray's direction signs.
    struct Rows {
        const float* near[3];
        const float* far[3];
        Rows(const BoxColumns& c, const RayInv& ri) {
            for (int a = 0; a < 3; ++a) {
                near[a] = ri.neg[a] ? c.hi_[a].data() : c.lo_[a].data();
                far[a] = ri.neg[a] ? c.lo_[a].data() : c.hi_[a].data();
            }
        }
    };

#if defined(__SSE2__)
    // Boxes j to j + 3: all ones in the lanes of the boxes met, zero in the others and in the
    // padding's (a point at the origin, which a ray can meet).
    __m128 met_lanes(const Rows& rows, std::size_t j, const RayInv& ri, float tmin, float tmax) const {
        const __m128 widen = _mm_set1_ps(1.0000004f), inf = _mm_set1_ps(kInf);
        __m128 t0 = _mm_set1_ps(tmin), t1 = _mm_set1_ps(tmax);
        for (int a = 0; a < 3; ++a) {
            const __m128 o = _mm_set1_ps(ri.o[a]), inv = _mm_set1_ps(ri.inv[a]);
            const __m128 tn = _mm_mul_ps(_mm_sub_ps(_mm_loadu_ps(rows.near[a] + j), o), inv);
            const __m128 tf = _mm_mul_ps(_mm_mul_ps(_mm_sub_ps(_mm_loadu_ps(rows.far[a] + j), o), inv), widen);
            t0 = _mm_max_ps(tn, t0);  // tn > t0 ? tn : t0
            t1 = _mm_min_ps(tf, t1);  // tf < t1 ? tf : t1
        }
        // box_entry returns t0 when t0 <= t1 (else +inf), and a box is met when that is finite.
        __m128 met = _mm_and_ps(_mm_cmple_ps(t0, t1), _mm_cmplt_ps(t0, inf));
        if (j + 4 > n_) {
            alignas(16) static constexpr std::int32_t kKeep[4][4] = {{0, 0, 0, 0}, {-1, 0, 0, 0}, {-1, -1, 0, 0}, {-1, -1, -1, 0}};
            met = _mm_and_ps(met, _mm_load_ps(reinterpret_cast<const float*>(kKeep[n_ - j])));
        }
        return met;
    }
#endif

    // met_lanes as four bits, bit k for box j + k.
    unsigned met_bits(const Rows& rows, std::size_t j, const RayInv& ri, float tmin, float tmax) const {
#if defined(__SSE2__)
        return static_cast<unsigned>(_mm_movemask_ps(met_lanes(rows, j, ri, tmin, tmax)));
#else
        unsigned mask = 0;
        for (std::size_t k = 0; k < 4; ++k) {
            float t0 = tmin, t1 = tmax;
            for (int a = 0; a < 3; ++a) {
                const float tn = (rows.near[a][j + k] - ri.o[a]) * ri.inv[a];
                const float tf = (rows.far[a][j + k] - ri.o[a]) * ri.inv[a] * 1.0000004f;
                t0 = tn > t0 ? tn : t0;
                t1 = tf < t1 ? tf : t1;
            }
            if (t0 <= t1 && t0 != kInf) mask |= 1u << k;
        }
        if (j + 4 > n_) mask &= (1u << (n_ - j)) - 1;
        return mask;
#endif
    }

    std::size_t n_ = 0, padded_ = 0;
    std::vector<float> lo_[3], hi_[3];
};

}  // namespace rtcost::bvh
