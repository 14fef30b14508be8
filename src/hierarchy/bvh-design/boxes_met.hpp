#pragma once
// Which of a few boxes each sample segment meets: bvh-design weighs its candidate splits at every
// node, two boxes each, against every sample segment reaching the node (a third of its design
// time). Four or eight boxes per segment at once (SSE, or AVX2 where the CPU has it), decided
// exactly as box_entry decides one (the same operations in the same order; max/min keep the
// second operand on NaN as box_entry's compares do), so the design is the same tree on any CPU.
#include <cstdint>
#include <span>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "rtcost/math.hpp"

namespace rtcost::bvh {

/// A sample segment as the box tests read it: RayInv's origin, reciprocal and direction signs,
/// and the part of the ray searched (from tmin to where its search ends).
struct Segment {
    float o[3], inv[3];
    float t0, t1;
    int neg[3];
    Segment(const RayInv& ri, float tmin, float tmax)
        : o{ri.o.x, ri.o.y, ri.o.z}, inv{ri.inv.x, ri.inv.y, ri.inv.z}, t0(tmin), t1(tmax),
          neg{ri.neg[0], ri.neg[1], ri.neg[2]} {}
};

/// The boxes in columns: lo and hi per axis, padded to a multiple of eight with empty boxes,
/// which no segment meets.
class BoxColumns {
public:
    /// Holds `boxes` (replacing any), reusing its storage: one per design, refilled per node.
    void assign(std::span<const Box3> boxes);

    /// Calls `met(j)` for every box j that box_entry(box j, s's ray, s.t0, s.t1) finds.
    template <class Met>
    void each_met(const Segment& s, Met&& met) const {
        const Lanes lanes(*this, s);
        for (std::size_t j = 0; j < padded_; j += 4)
            for (unsigned mask = lanes.met_bits(j); mask; mask &= mask - 1)
                met(j + static_cast<std::size_t>(__builtin_ctz(mask)));
    }

    /// Adds to `counts[j]` how many of the segments `segments[r]`, r in `which`, each_met reports
    /// box j for; `counts` holds padded() entries (the padding's stay 0).
    void count_met(std::span<const std::uint32_t> which, const Segment* segments, std::uint32_t* counts) const;
    /// count_met on the baseline instruction set alone (what a CPU without AVX2 runs).
    void count_met_baseline(std::span<const std::uint32_t> which, const Segment* segments, std::uint32_t* counts) const;

    /// The boxes' count rounded up to a multiple of eight.
    std::size_t padded() const { return padded_; }
    /// Axis `a`'s lower (or upper, `hi`) faces of the padded boxes.
    const float* faces(int a, bool hi) const { return hi ? hi_[a].data() : lo_[a].data(); }

private:
    // One segment against the boxes four at a time, its values broadcast once for all of them.
    struct Lanes {
        const float* near[3];
        const float* far[3];
#if defined(__SSE2__)
        __m128 o[3], inv[3], t0, t1;
        Lanes(const BoxColumns& c, const Segment& s) : t0(_mm_set1_ps(s.t0)), t1(_mm_set1_ps(s.t1)) {
            for (int a = 0; a < 3; ++a) {
                near[a] = c.faces(a, s.neg[a]), far[a] = c.faces(a, !s.neg[a]);
                o[a] = _mm_set1_ps(s.o[a]), inv[a] = _mm_set1_ps(s.inv[a]);
            }
        }
        // Boxes j to j + 3: all ones in the lanes of the boxes met.
        __m128 met(std::size_t j) const {
            const __m128 widen = _mm_set1_ps(1.0000004f);
            __m128 enter = t0, exit = t1;
            for (int a = 0; a < 3; ++a) {
                const __m128 tn = _mm_mul_ps(_mm_sub_ps(_mm_loadu_ps(near[a] + j), o[a]), inv[a]);
                const __m128 tf = _mm_mul_ps(_mm_mul_ps(_mm_sub_ps(_mm_loadu_ps(far[a] + j), o[a]), inv[a]), widen);
                enter = _mm_max_ps(tn, enter);  // tn > enter ? tn : enter
                exit = _mm_min_ps(tf, exit);    // tf < exit ? tf : exit
            }
            // box_entry returns the entry when it is <= the exit (else +inf): met when finite.
            return _mm_and_ps(_mm_cmple_ps(enter, exit), _mm_cmplt_ps(enter, _mm_set1_ps(kInf)));
        }
        unsigned met_bits(std::size_t j) const { return static_cast<unsigned>(_mm_movemask_ps(met(j))); }
#else
        const Segment& s;
        Lanes(const BoxColumns& c, const Segment& seg) : s(seg) {
            for (int a = 0; a < 3; ++a) near[a] = c.faces(a, s.neg[a]), far[a] = c.faces(a, !s.neg[a]);
        }
        // Bit k set when box j + k is met.
        unsigned met_bits(std::size_t j) const {
            unsigned mask = 0;
            for (std::size_t k = 0; k < 4; ++k) {
                float enter = s.t0, exit = s.t1;
                for (int a = 0; a < 3; ++a) {
                    const float tn = (near[a][j + k] - s.o[a]) * s.inv[a];
                    const float tf = (far[a][j + k] - s.o[a]) * s.inv[a] * 1.0000004f;
                    enter = tn > enter ? tn : enter;
                    exit = tf < exit ? tf : exit;
                }
                if (enter <= exit && enter != kInf) mask |= 1u << k;
            }
            return mask;
        }
#endif
    };

    std::size_t n_ = 0, padded_ = 0;
    std::vector<float> lo_[3], hi_[3];
};

}  // namespace rtcost::bvh
