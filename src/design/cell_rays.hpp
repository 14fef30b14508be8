#pragma once
// The model's termination test for the space subdivisions designed from a ray sample (kd-design,
// octree-design, bsp-design): which sample segments reach each cell, and whether splitting a
// cell into given children pays by the cost model.

#include <array>
#include <cstdint>
#include <map>
#include <vector>

#include "rtcost/design.hpp"

namespace rtcost::designing {

class CellRays {
public:
    /// `trust`: sample segments at a cell at which the sample's share and the surface-area ratio
    /// weigh alike. `k_trav`: cost of one visit of an interior node, in the costs' units.
    CellRays(const Scene& s, const DesignInput& in, double trust, double k_trav);

    /// Whether splitting `cell` (with `n` references) into `k` children holding `counts`
    /// references pays: k_trav + k_isect * sum_i p_i n_i < k_isect n, with p_i the blended
    /// probability that a segment reaching `cell` (clipped where its search ends) meets child i.
    /// When it pays, each child's segments are kept for its own test.
    bool split_pays(const Box3& cell, std::size_t n, const Box3* children, const std::size_t* counts, int k);

private:
    using Key = std::array<std::uint32_t, 6>;
    static Key key_of(const Box3& b);
    bool meets(std::uint32_t r, const Box3& b) const;
    std::vector<std::uint32_t> reaching(const Box3& cell);

    const DesignInput& in_;
    double trust_, k_trav_, k_isect_ = 1;
    std::vector<RayInv> inv_;
    std::map<Key, std::vector<std::uint32_t>> kept_;
};

}  // namespace rtcost::designing
