#pragma once
// A design's price of a built candidate on its sample, by the candidate's own traversal: each
// sample ray traced with a primitive test that answers from the ray's known crossings (what the
// segments estimator's probe does through a model tree), the operations counted and priced.
// Without mailboxes this is the model's prediction (sample_cost) -- the model tree's replay
// visits what the traversal visits -- at the cost of the nodes the rays reach, with no model
// tree materialised (a grid's holds two nodes per cell; a designed octree's, 10^5 nodes, was
// most of its design time). With mailboxes it counts only a primitive's first test per ray, as
// the traversal does (the model tree does not know mailboxes).
#include <cstdint>
#include <span>
#include <vector>

#include "../hierarchy/common/impl.hpp"
#include "../model/model_internal.hpp"
#include "rtcost/design.hpp"
#include "rtcost/hierarchy.hpp"
#include "rtcost/stats.hpp"

namespace rtcost::designing {

/// The sample's cost per ray through any hierarchy `H` with
///   template <class C, Query Q, class PrimTest> bool trace_with(const Ray&, Hit&, C&, PrimTest) const;
/// One per design: it holds the scene's primitive kinds, one byte each. On a cell tree built
/// only where the sample reaches, throws model::PrunedNodeReached if a ray enters a cell left
/// unbuilt.
class SampleReplay {
public:
    SampleReplay(const Scene& s, const RaySample& sample, const UnitCosts& costs)
        : scene_(s), sample_(sample), costs_(costs), kinds_(s.size()) {
        // The scene's records are far larger, and a replay looks up a kind for every reference
        // of every leaf it visits.
        for (std::uint32_t id = 0; id < s.size(); ++id) kinds_[id] = static_cast<std::uint8_t>(s.kind(id));
    }

    /// The model's prediction of the sample's operations through `h`, priced (sample_cost's).
    template <class H>
    double cost(const H& h) const {
        return costs_.scalar(counted(h));
    }

    /// The same with the time model's terms of the structure: the cache misses of its size and
    /// its box tests made several at once (a costs file's cache, box_simd and box_pair; built-in
    /// typical costs have the first two).
    /// What a design compares built candidates by.
    template <class H>
    double time(const H& h) const {
        return time(h, counters(h, Rays::All));
    }

    /// Which of the sample's rays a replay takes: all, its occlusion (any-hit) rays, or the others.
    enum class Rays { All, Occlusion, Others };

    /// The operations of the sample's `which` rays through `h`. Two orders of one tree for
    /// occlusion rays count the other rays alike: counted once, they are added to each order's.
    template <class H>
    RayCounters counters(const H& h, Rays which) const {
        RayCounters counters;
        Count counting{counters};
        for (std::size_t i = 0; i < sample_.size(); ++i) {
            const Query q = sample_.queries[i];
            if (which != Rays::All && (q == Query::Any) != (which == Rays::Occlusion)) continue;
            const KnownTest test{model::KnownCrossings(sample_.crossings_of(i)), kinds_.data(), scene_};
            const Ray& ray = sample_.rays.rays[i];
            Hit hit;
            switch (q) {
                case Query::Closest: h.template trace_with<Count, Query::Closest>(ray, hit, counting, test); break;
                case Query::Any: h.template trace_with<Count, Query::Any>(ray, hit, counting, test); break;
                case Query::All: h.template trace_with<Count, Query::All>(ray, hit, counting, test); break;
            }
        }
        return counters;
    }

    /// time(h) of `whole`: counters of every sample ray through `h` (e.g. its other rays' and
    /// its occlusion rays' added up).
    template <class H>
    double time(const H& h, RayCounters whole) const {
        const bool sized = costs_.cache > 0 || costs_.box_simd >= 0 || costs_.box_pair >= 0;
        whole.rays = sample_.size();
        return costs_.scalar(measured_cost(whole), sized ? h.structure() : StructureStats{});
    }

private:
    template <class H>
    CostVector counted(const H& h) const {
        RayCounters whole = counters(h, Rays::All);
        whole.rays = sample_.size();
        return measured_cost(whole);
    }

    const Scene& scene_;
    const RaySample& sample_;
    UnitCosts costs_;
    std::vector<std::uint8_t> kinds_;
};

}  // namespace rtcost::designing
