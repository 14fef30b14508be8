// bvh-median: Kay and Kajiya's construction. Each node is cut at the object median along the
// longest axis of its primitives' centroids, until a leaf holds at most max_prims objects.
#include <algorithm>

#include "topdown.hpp"

namespace rtcost::bvh {

BvhData build_median(const Scene& s, const MedianOptions& o) {
    PrimInfo info(s);
    return build_topdown(s, info, [&](std::vector<std::uint32_t>& ids, std::uint32_t begin, std::uint32_t end,
                                      const Box3&, int depth) -> std::uint32_t {
        if (static_cast<int>(end - begin) <= o.max_prims || depth >= o.max_depth) return begin;
        Box3 cb;
        for (std::uint32_t i = begin; i < end; ++i) cb.extend(info.centroids[ids[i]]);
        int axis = max_axis(cb.extent());
        std::uint32_t mid = begin + (end - begin) / 2;
        // Ties broken by id so that the tree does not depend on the sort's implementation.
        std::nth_element(ids.begin() + begin, ids.begin() + mid, ids.begin() + end, [&](std::uint32_t a, std::uint32_t b) {
            float ca = info.centroids[a][axis], cb2 = info.centroids[b][axis];
            return ca < cb2 || (ca == cb2 && a < b);
        });
        return mid;
    });
}

}  // namespace rtcost::bvh
