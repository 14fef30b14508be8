// `kd-median`: the median-cut kd-tree of Subramanian and Fussell's section 3.3 ("the hierarchy is
// balanced on the number of objects ... the number of objects straddling the plane is also
// minimized ... three dimensions to choose from").
//
// Criterion, per node of N references with boxes clipped to the cell: on each axis, every
// plane strictly between two consecutive distinct box edges (at the gap's midpoint, so that no
// box merely touches it), N_L = boxes reaching below it, N_R = boxes reaching above it,
// N_S = N_L + N_R - N straddlers. The plane minimises
//     max(N_L, N_R) = (N + N_S + |N_L - N_R|) / 2,
// i.e. count imbalance and straddlers weighted alike: the most balanced cut when nothing
// straddles, and a straddler costs as much as one object of imbalance. Ties: fewer straddlers,
// then the plane nearest the cell's centre (relative to the cell's extent on its axis). Planes
// that more than half the objects straddle (N_S > N/2) are not candidates -- "straddling
// minimised" as a bound, without which heavily overlapping objects (the shells scene: 3.7M
// references for 5761 spheres) multiply references at every level -- and a node is split only
// when max(N_L, N_R) < N, so every split makes progress on both sides. Each axis sorts its
// edges: O(N log N) per node, O(N log^2 N) for the tree.
#include <algorithm>
#include <cmath>

#include "kdtree.hpp"

namespace rtcost::kd {
namespace {

struct Best {
    std::size_t worst;     // max(N_L, N_R)
    std::size_t straddle;  // N_S
    float off_centre;      // |pos - centre| / extent
    Split split;
    bool better(const Best& o) const {
        if (worst != o.worst) return worst < o.worst;
        if (straddle != o.straddle) return straddle < o.straddle;
        return off_centre < o.off_centre;
    }
};

Split choose_median(const std::vector<BuildRef>& refs, const Box3& cell) {
    const std::size_t n = refs.size();
    Best best{n, n, kInf, {}};
    std::vector<float> lo(n), hi(n);
    for (int a = 0; a < 3; ++a) {
        const float ext = cell.hi[a] - cell.lo[a];
        if (!(ext > 0)) continue;
        for (std::size_t i = 0; i < n; ++i) {
            lo[i] = refs[i].box.lo[a];
            hi[i] = refs[i].box.hi[a];
        }
        std::sort(lo.begin(), lo.end());
        std::sort(hi.begin(), hi.end());
        const float centre = 0.5f * (cell.lo[a] + cell.hi[a]);
        // Sweep the distinct edge values v in increasing order; after consuming v, i boxes have
        // lo <= v and j boxes have hi <= v. A plane in (v, next) has N_L = i, N_R = n - j.
        std::size_t i = 0, j = 0;
        while (i < n || j < n) {
            const float v = std::min(i < n ? lo[i] : kInf, j < n ? hi[j] : kInf);
            while (i < n && lo[i] == v) ++i;
            while (j < n && hi[j] == v) ++j;
            const float next = std::min(i < n ? lo[i] : kInf, j < n ? hi[j] : kInf);
            if (next == kInf) break;
            const float pos = v + 0.5f * (next - v);
            if (!(pos > v && pos < next && pos > cell.lo[a] && pos < cell.hi[a])) continue;
            const std::size_t nl = i, nr = n - j;
            if (2 * (nl + nr - n) > n) continue;  // more than half the objects straddle
            Best c{std::max(nl, nr), nl + nr - n, std::fabs(pos - centre) / ext, {a, pos}};
            if (c.better(best)) best = c;
        }
    }
    if (best.split.axis < 0 || best.worst >= n) return {};
    return best.split;
}

}  // namespace

KdData build_median(const Scene& s, const MedianOptions& o) {
    return build_tree(s, o.build, [](const std::vector<BuildRef>& refs, const Box3& cell, int) {
        return choose_median(refs, cell);
    });
}

}  // namespace rtcost::kd
