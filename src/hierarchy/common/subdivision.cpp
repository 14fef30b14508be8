// Reference assignment shared by `bsp` and `octree`.
#include "subdivision.hpp"

namespace rtcost::subdiv {

Assigner::Assigner(const Scene& s, spatial::Assign how) : s_(s), how_(how), bounds_(s.size()) {
    for (std::uint32_t i = 0; i < s.size(); ++i) bounds_[i] = s.prim_bounds(i);
}

std::vector<std::uint32_t> Assigner::all() const {
    std::vector<std::uint32_t> r;
    r.reserve(bounds_.size());
    for (std::uint32_t i = 0; i < bounds_.size(); ++i)
        if (!bounds_[i].empty()) r.push_back(i);
    return r;
}

void Assigner::masks(const std::vector<std::uint32_t>& refs, const Box3* cells, int n, std::vector<std::uint8_t>& mask,
                     std::array<std::size_t, 8>& counts) const {
    mask.assign(refs.size(), 0);
    counts.fill(0);
    for (std::size_t i = 0; i < refs.size(); ++i) {
        const std::uint32_t id = refs[i];
        const Box3& pb = bounds_[id];
        std::uint8_t m = 0, box_m = 0;
        for (int k = 0; k < n; ++k) {
            if (!pb.overlaps(cells[k])) continue;
            box_m |= static_cast<std::uint8_t>(1u << k);
            if (how_ == spatial::Assign::Bounds || spatial::overlaps(s_, id, pb, cells[k], how_))
                m |= static_cast<std::uint8_t>(1u << k);
        }
        if (m == 0) m = box_m;  // rounding in the exact test: stay conservative
        mask[i] = m;
        for (int k = 0; k < n; ++k) counts[k] += m >> k & 1;
    }
}

std::vector<std::uint32_t> Assigner::select(const std::vector<std::uint32_t>& refs,
                                            const std::vector<std::uint8_t>& mask, int k, std::size_t count) {
    std::vector<std::uint32_t> out;
    out.reserve(count);
    for (std::size_t i = 0; i < refs.size(); ++i)
        if (mask[i] >> k & 1) out.push_back(refs[i]);
    return out;
}

std::vector<ParamSpec> param_specs(int default_depth, int max_depth, int default_prims) {
    return {ParamSpec::integer("max_depth", std::to_string(default_depth), 0, max_depth, "deepest leaf (root at 0)"),
            ParamSpec::integer("max_prims", std::to_string(default_prims), 1, 1 << 20,
                               "a node with at most this many references is a leaf"),
            kTraversalParam,
            spatial::kAssignParam,
            kGrowthParam,
            spatial::kMailboxParam};
}

}  // namespace rtcost::subdiv
