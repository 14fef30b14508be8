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
        blocks(ri, tmin, tmax, [&](std::size_t j, unsigned mask) {
            for (; mask; mask &= mask - 1) {
                const std::size_t k = j + static_cast<std::size_t>(__builtin_ctz(mask));
                met(k);
            }
        });
    }

    /// Adds one to `counts[j]` for every box j that each_met would report; `counts` holds
    /// padded() entries (the padding's stay 0).
    void count_met(const RayInv& ri, float tmin, float tmax, std::uint32_t* counts) const {
        blocks(ri, tmin, tmax, [&](std::size_t j, unsigned mask) {
            for (int k = 0; k < 4; ++k) counts[j + k] += (mask >> k) & 1u;
        });
    }

    /// The boxes' count rounded up to a multiple of four.
    std::size_t padded() const { return padded_; }

private:
    // Calls block(j, mask) for each four boxes from j, bit k set when box j + k is met. The padding
    // boxes (a point at the origin, which a ray can meet) have their bits cleared.
    template <class Block>
    void blocks(const RayInv& ri, float tmin, float tmax, Block&& block) const {
        const float* near[3];
        const float* far[3];
        for (int a = 0; a < 3; ++a) {
            near[a] = ri.neg[a] ? hi_[a].data() : lo_[a].data();
            far[a] = ri.neg[a] ? lo_[a].data() : hi_[a].data();
        }
        for (std::size_t j = 0; j < padded_; j += 4) {
            unsigned mask = 0;
#if defined(__SSE2__)
            const __m128 widen = _mm_set1_ps(1.0000004f), inf = _mm_set1_ps(kInf);
            __m128 t0 = _mm_set1_ps(tmin), t1 = _mm_set1_ps(tmax);
            for (int a = 0; a < 3; ++a) {
                const __m128 o = _mm_set1_ps(ri.o[a]), inv = _mm_set1_ps(ri.inv[a]);
                const __m128 tn = _mm_mul_ps(_mm_sub_ps(_mm_loadu_ps(near[a] + j), o), inv);
                const __m128 tf = _mm_mul_ps(_mm_mul_ps(_mm_sub_ps(_mm_loadu_ps(far[a] + j), o), inv), widen);
                t0 = _mm_max_ps(tn, t0);  // tn > t0 ? tn : t0
                t1 = _mm_min_ps(tf, t1);  // tf < t1 ? tf : t1
            }
            // box_entry returns t0 when t0 <= t1 (else +inf), and a box is met when that is finite.
            mask = static_cast<unsigned>(_mm_movemask_ps(_mm_and_ps(_mm_cmple_ps(t0, t1), _mm_cmplt_ps(t0, inf))));
#else
            for (std::size_t k = 0; k < 4; ++k) {
                float t0 = tmin, t1 = tmax;
                for (int a = 0; a < 3; ++a) {
                    const float tn = (near[a][j + k] - ri.o[a]) * ri.inv[a];
                    const float tf = (far[a][j + k] - ri.o[a]) * ri.inv[a] * 1.0000004f;
                    t0 = tn > t0 ? tn : t0;
                    t1 = tf < t1 ? tf : t1;
                }
                if (t0 <= t1 && t0 != kInf) mask |= 1u << k;
            }
#endif
            if (j + 4 > n_) mask &= (1u << (n_ - j)) - 1;
            block(j, mask);
        }
    }

    std::size_t n_ = 0, padded_ = 0;
    std::vector<float> lo_[3], hi_[3];
};

}  // namespace rtcost::bvh
