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
    /// weigh alike. `k_trav`: cost of one visit of an interior node beyond its step, in the
    /// costs' units; `k_step`: cost of any node visit (a traversal step, with the time model's
    /// cache term for the structure's expected size).
    CellRays(const Scene& s, const DesignInput& in, double trust, double k_trav, double k_step = 0);

    /// Whether splitting `cell` (with `n` references) into `k` children holding `counts`
    /// references pays: k_trav + sum_i p_i (k_step + k_isect n_i) < k_isect n, with p_i the
    /// blended probability that a segment reaching `cell` (clipped where its search ends) meets
    /// child i (the cell's own step is paid either way). When it pays, each child's segments
    /// are kept for its own test.
    bool split_pays(const Box3& cell, std::size_t n, const Box3* children, const std::size_t* counts, int k);
    /// The same with each reference priced by its own test (test_cost): `tests` for the cell's,
    /// `child_tests[i]` for child i's references.
    bool split_pays(const Box3& cell, double tests, const Box3* children, const double* child_tests, int k);
    /// A test of primitive `id` in the costs' units: its kind's price and the edges it may walk.
    double test_cost(std::uint32_t id) const;

    /// For a judge of a whole built tree (kd-design's pruning): the sample segments that meet
    /// `b`, of `rays` (all of the sample when null), and the blended probability that a segment
    /// reaching `cell` meets `child` when `met` of the `m` that reach `cell` do.
    std::vector<std::uint32_t> meeting(const std::vector<std::uint32_t>* rays, const Box3& b) const;
    double probability(const Box3& cell, const Box3& child, std::size_t m, std::size_t met) const;
    double k_trav() const { return k_trav_; }
    double k_step() const { return k_step_; }

private:
    using Key = std::array<std::uint32_t, 6>;
    static Key key_of(const Box3& b);
    bool meets(std::uint32_t r, const Box3& b) const;
    std::vector<std::uint32_t> reaching(const Box3& cell);

    const Scene& scene_;
    const DesignInput& in_;
    double trust_, k_trav_, k_step_, k_isect_ = 1;
    std::vector<RayInv> inv_;
    std::map<Key, std::vector<std::uint32_t>> kept_;
};

}  // namespace rtcost::designing
