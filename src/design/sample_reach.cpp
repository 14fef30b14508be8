// The cells a design sample reaches (sample_reach.hpp).
#include "sample_reach.hpp"

#include <algorithm>

namespace rtcost::designing {

SampleReach::SampleReach(const RaySample& sample, const Box3& root)
    : sample_(sample), seg_(sample, true) {  // the subdivisions' traversals cull
    const Vec3 e = root.extent();
    grow_ = 1e-5f * std::max({e.x, e.y, e.z, 1e-30f});
}

bool SampleReach::operator()(const Box3& cell, int depth) {
    if (depth < 0) return true;
    if (static_cast<std::size_t>(depth) >= by_depth_.size()) by_depth_.resize(static_cast<std::size_t>(depth) + 1);
    std::vector<std::uint32_t>& out = by_depth_[static_cast<std::size_t>(depth)];
    out.clear();
    Box3 grown = cell;
    for (int a = 0; a < 3; ++a) grown.lo[a] -= grow_, grown.hi[a] += grow_;
    auto meets = [&](std::uint32_t r) {
        return box_entry(grown, seg_.inv[r], sample_.rays.rays[r].tmin, seg_.ends[r]) != kInf;
    };
    if (depth == 0) {
        for (std::uint32_t r = 0; r < sample_.size(); ++r)
            if (meets(r)) out.push_back(r);
    } else {
        // The parent asked at depth - 1 just before its children (depth first), so its list is
        // the last one there.
        for (std::uint32_t r : by_depth_[static_cast<std::size_t>(depth) - 1])
            if (meets(r)) out.push_back(r);
    }
    return !out.empty();
}

}  // namespace rtcost::designing
