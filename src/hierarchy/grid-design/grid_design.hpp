#pragma once
#include <utility>
// `grid-design`: the uniform grid whose per-axis resolution minimises the cost model's
// prediction for a sample of the user's rays (design.hpp), traversed as `grid` is.

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "../grid/grid.hpp"
#include "rtcost/design.hpp"

namespace rtcost::grid {

/// One resolution tried and the sample's predicted cost per ray there.
struct Candidate {
    std::array<int, 3> res{1, 1, 1};
    double cost = 0;
};

/// The search: the hetero formula's cell shape from 1 cell per primitive, doubled (up to 64) or
/// else halved (down to 1/8) while the cost falls, then
/// coordinate descent on each axis (factors 3/4 and 4/3) from the cheapest, until no step
/// pays. At most `max_cells` cells per candidate. Returns every candidate, cheapest first, and
/// in `*cheapest` (when given) the first one's grid, as built in the search (or null).
std::vector<Candidate> search_resolution(const Scene& s, const DesignInput& in, spatial::Assign assign, bool mailbox,
                                         std::uint64_t max_cells, std::unique_ptr<Grid>* cheapest = nullptr);

class GridDesign final : public HierarchyImpl<GridDesign> {
public:
    GridDesign(const Scene& s, std::unique_ptr<Grid> g, std::vector<Candidate> tried)
        : HierarchyImpl(s), g_(std::move(g)), tried_(std::move(tried)) {}
    std::string_view name() const override { return "grid-design"; }
    bool emit_model(ModelSink& sink) const override { return g_->emit_model(sink); }
    const Grid& grid() const { return *g_; }
    const std::vector<Candidate>& tried() const { return tried_; }

    template <class C, Query Q>
    bool trace(const Ray& ray, Hit& hit, C& counting) const {
        return g_->template trace<C, Q>(ray, hit, counting);
    }
    /// The grid's traversal with the caller's primitive test, and whether its replay is the
    /// model's (Hierarchy::replay, crossings).
    template <class C, Query Q, class PrimTest>
    bool trace_with(const Ray& ray, Hit& hit, C& counting, PrimTest&& test) const {
        return g_->template trace_with<C, Q>(ray, hit, counting, std::forward<PrimTest>(test));
    }
    bool replay_is_model() const { return g_->replay_is_model(); }

protected:
    StructureStats compute_structure() const override { return g_->structure(); }

private:
    std::unique_ptr<Grid> g_;
    std::vector<Candidate> tried_;
};

}  // namespace rtcost::grid
