// `octree-design`, `bsp-design`: Glassner's octree and Kaplan's BSP tree built by their own
// builders, a cell split only where the cost model, with visit probabilities from a sample of
// the given rays, says the split pays (design/cell_rays.hpp) -- instead of splitting down to
// max_prims or max_depth -- or, where the model predicts it cheaper on the sample, the tree the
// builder makes with the yardstick's termination.
#include "../bsp/bsp.hpp"
#include "../octree/octree.hpp"
#include "design/cell_rays.hpp"
#include "design/replay.hpp"
#include "design/sample_reach.hpp"
#include "model/model_internal.hpp"

namespace rtcost {
namespace {

std::vector<ParamSpec> specs(int default_depth, int max_depth, int default_prims) {
    std::vector<ParamSpec> p = design_param_specs("ops");
    for (const ParamSpec& q : subdiv::param_specs(default_depth, max_depth, default_prims)) p.push_back(q);
    p.push_back(ParamSpec::real("trust", "32", 0, 1e30, "sample segments at a cell at which sample and surface area weigh alike"));
    return p;
}

// Builds with the model's split test (the test and the sample it reads live only during the
// build) and compares it, on the sample, with the tree the builder makes with the yardstick's
// depth and leaf size (`usual_depth`, `usual_prims`); keeps the one the model predicts cheaper
// (a tie keeps the design, as designing::cheapest_on_sample does). The yardstick's tree is first
// built only where the sample reaches (a yardstick octree can be a hundred times the design's
// size, all of it built only to be compared), and whole only when it is kept.
template <class H>
std::unique_ptr<Hierarchy> build(const Scene& s, const Params& p, double planes, const char* name,
                                 int usual_depth, int usual_prims) {
    const DesignInput in = draw_design_input(s, p);
    designing::CellRays cells(s, in, p.real("trust"), planes * in.costs.plane, in.costs.step);
    subdiv::CellOptions o = subdiv::read_options(p);
    o.name = name;
    subdiv::CellOptions usual = o;
    usual.max_depth = usual_depth;
    usual.max_prims = usual_prims;
    o.split_pays = [&cells](const Box3& cell, std::size_t n, const Box3* children, const std::size_t* counts, int k) {
        return cells.split_pays(cell, n, children, counts, k);
    };
    auto designed = std::make_unique<H>(s, o);
    // Each tree priced by its own traversal of the sample (design/replay.hpp: the model's
    // prediction without materialising its model tree, most of the design's time before).
    const designing::SampleReplay replay(s, in.sample, in.costs);
    const double designed_cost = replay.cost(*designed);
    designing::SampleReach reach(in.sample, s.bounds());
    subdiv::CellOptions reached = usual;
    reached.reached = [&reach](const Box3& cell, int depth) { return reach(cell, depth); };
    std::unique_ptr<H> yardstick = std::make_unique<H>(s, reached);
    double yardstick_cost;
    try {
        yardstick_cost = replay.cost(*yardstick);
    } catch (const model::PrunedNodeReached&) {
        // A ray went where no segment was thought to reach (it cannot, but rounding is
        // rounding): the whole tree.
        yardstick = std::make_unique<H>(s, usual);
        yardstick_cost = replay.cost(*yardstick);
    }
    if (!(yardstick_cost < designed_cost)) return designed;
    if (yardstick->partial()) yardstick = std::make_unique<H>(s, usual);
    return yardstick;
}

// The operations of one interior visit: an octree node's three planes, a BSP node's one.
const Registration octree_reg{
    {"octree-design", "Glassner's octree, a cell split only where the cost model with a sample of the given rays says it pays",
     specs(12, octree::kMaxDepth, 1),
     [](const Scene& s, const Params& p) {
         return build<octree::Octree>(s, p, 3, "octree-design", 8, 1);
     },
     kLargeScene}};  // every candidate split replayed on the sample: 10 s for a million triangles

const Registration bsp_reg{
    {"bsp-design", "Kaplan's BSP tree, a cell split only where the cost model with a sample of the given rays says it pays",
     specs(30, bsp::kMaxDepth, 1),
     [](const Scene& s, const Params& p) {
         return build<bsp::Bsp>(s, p, 1, "bsp-design", 20, 2);
     }}};

}  // namespace
}  // namespace rtcost
