// The cells a design sample reaches (sample_reach.hpp).
#include "sample_reach.hpp"

#include <algorithm>
#include <cmath>

namespace rtcost::designing {

SampleReach::SampleReach(const RaySample& sample, const Box3& root) : sample_(sample) {
    const std::size_t n = sample.size();
    inv_.reserve(n);
    ends_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        const Ray& r = sample.rays.rays[i];
        inv_.emplace_back(r);
        // As reached_model_tree's ReachCollector, with the subdivisions' culling traversal.
        float end = r.tmax;
        if (sample.queries[i] == Query::Closest && sample.t_end[i] < r.tmax)
            end = std::min(r.tmax, sample.t_end[i] + 1e-4f * std::fabs(sample.t_end[i]) + 1e-6f);
        ends_[i] = end;
    }
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
        return box_entry(grown, inv_[r], sample_.rays.rays[r].tmin, ends_[r]) != kInf;
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
