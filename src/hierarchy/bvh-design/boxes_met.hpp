#pragma once
// Which of a few boxes each sample segment meets: bvh-design weighs 8 candidate splits at every
// node, two boxes each, against every sample segment reaching the node (with the binning of the
// candidates, a third of its design time). Four boxes per ray at once with SSE here, decided exactly as
// box_entry decides one (the same operations in the same order; max/min keep the second operand
// on NaN as box_entry's compares do), so the design is the same tree.
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
        const float* near[3];
        const float* far[3];
        for (int a = 0; a < 3; ++a) {
            near[a] = ri.neg[a] ? hi_[a].data() : lo_[a].data();
            far[a] = ri.neg[a] ? lo_[a].data() : hi_[a].data();
        }
#if defined(__SSE2__)
        const __m128 widen = _mm_set1_ps(1.0000004f), inf = _mm_set1_ps(kInf);
        const __m128 o[3] = {_mm_set1_ps(ri.o.x), _mm_set1_ps(ri.o.y), _mm_set1_ps(ri.o.z)};
        const __m128 inv[3] = {_mm_set1_ps(ri.inv.x), _mm_set1_ps(ri.inv.y), _mm_set1_ps(ri.inv.z)};
        for (std::size_t j = 0; j < padded_; j += 4) {
            __m128 t0 = _mm_set1_ps(tmin), t1 = _mm_set1_ps(tmax);
            for (int a = 0; a < 3; ++a) {
                const __m128 tn = _mm_mul_ps(_mm_sub_ps(_mm_loadu_ps(near[a] + j), o[a]), inv[a]);
                const __m128 tf = _mm_mul_ps(_mm_mul_ps(_mm_sub_ps(_mm_loadu_ps(far[a] + j), o[a]), inv[a]), widen);
                t0 = _mm_max_ps(tn, t0);  // tn > t0 ? tn : t0
                t1 = _mm_min_ps(tf, t1);  // tf < t1 ? tf : t1
            }
            // box_entry returns t0 when t0 <= t1 (else +inf), and a box is met when that is finite.
            int mask = _mm_movemask_ps(_mm_and_ps(_mm_cmple_ps(t0, t1), _mm_cmplt_ps(t0, inf)));
            for (; mask; mask &= mask - 1) {
                const std::size_t k = j + static_cast<std::size_t>(__builtin_ctz(static_cast<unsigned>(mask)));
                if (k < n_) met(k);
            }
        }
#else
        for (std::size_t j = 0; j < n_; ++j) {
            float t0 = tmin, t1 = tmax;
            for (int a = 0; a < 3; ++a) {
                const float tn = (near[a][j] - ri.o[a]) * ri.inv[a];
                const float tf = (far[a][j] - ri.o[a]) * ri.inv[a] * 1.0000004f;
                t0 = tn > t0 ? tn : t0;
                t1 = tf < t1 ? tf : t1;
            }
            if (t0 <= t1 && t0 != kInf) met(j);
        }
#endif
    }

private:
    std::size_t n_ = 0, padded_ = 0;
    std::vector<float> lo_[3], hi_[3];
};

}  // namespace rtcost::bvh
