// kd-design's bottom-up pruning (src/hierarchy/kd-design/prune.hpp): no primitive lost, a tree
// whose traversal the model prices above any test collapses to one leaf, and the split test and
// the pruning price each reference by its own test, polygon edges included.
#include <algorithm>

#include "../src/design/cell_rays.hpp"
#include "../src/hierarchy/kd-design/prune.hpp"
#include "rtcost/design.hpp"
#include "test_support.hpp"

namespace rtcost::test {
namespace {

struct Fixture {
    Scene s = builtin_scene("balls", 2);
    DesignInput in = draw_design_input(s, Params(design_param_specs(), {"rays=spd", "size=32x32", "sample=256"}));
    kd::KdData tree() const {
        kd::SahOptions deep;
        deep.c_trav = 2;  // deeper than any model would keep
        deep.build.max_prims = 0;
        deep.build.max_depth = kd::default_max_depth(s.size());
        return kd::build_tree(s, deep.build, [&](const std::vector<kd::BuildRef>& refs, const Box3& cell, int) {
            return kd::sah_plane(refs, cell, deep, false);
        });
    }
};

std::vector<std::uint32_t> referenced(const kd::KdData& t) {
    std::vector<std::uint32_t> ids;
    for (const kd::Node& n : t.nodes)
        if (n.leaf()) ids.insert(ids.end(), t.refs.begin() + n.index, t.refs.begin() + n.index + n.count);
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    return ids;
}

TEST(KdPrune, KeepsEveryPrimitiveAndOnlyRemovesNodes) {
    Fixture f;
    const kd::KdData base = f.tree();
    ASSERT_GT(base.nodes.size(), 100u);
    const designing::CellRays cells(f.s, f.in, 32, f.in.costs.plane, f.in.costs.step);
    const kd::KdData pruned = kd::prune(base, cells);
    EXPECT_EQ(referenced(pruned), referenced(base));
    EXPECT_LT(pruned.nodes.size(), base.nodes.size());  // a tree split at a quarter of a test's price
    EXPECT_GT(pruned.nodes.size(), 1u);
    // Every interior node keeps its plane and its two children.
    for (const kd::Node& n : pruned.nodes)
        if (!n.leaf()) {
            EXPECT_LT(n.index + 1, pruned.nodes.size());
        }
}

TEST(KdPrune, ATraversalDearerThanEveryTestLeavesOneLeaf) {
    Fixture f;
    const designing::CellRays cells(f.s, f.in, 32, 1e12, 0);
    const kd::KdData pruned = kd::prune(f.tree(), cells);
    ASSERT_EQ(pruned.nodes.size(), 1u);
    ASSERT_TRUE(pruned.nodes[0].leaf());
    // Each primitive once, in id order.
    std::vector<std::uint32_t> all(f.s.size());
    for (std::uint32_t i = 0; i < f.s.size(); ++i) all[i] = i;
    EXPECT_EQ(pruned.refs, all);
}

TEST(KdPrune, EachReferencePricedByItsOwnTestWithItsEdges) {
    // A hexagon and a triangle: the hexagon's test walks six edges.
    Scene s;
    const Vec3 hex[6] = {{1, 0, 0}, {0.5f, 0.87f, 0}, {-0.5f, 0.87f, 0}, {-1, 0, 0}, {-0.5f, -0.87f, 0}, {0.5f, -0.87f, 0}};
    s.add_polygon(hex, 0);
    const Vec3 tri[3] = {{3, 0, 1}, {4, 0, 1}, {3, 1, 1}};
    s.add_polygon(tri, 0);
    s.finalize();
    DesignInput in = draw_design_input(s, Params(design_param_specs(), {"rays=random", "size=8x8", "sample=16"}));
    in.costs = UnitCosts{};
    in.costs.polygon_edge = 2;
    const designing::CellRays cells(s, in, 32, 1, 0);
    std::uint32_t hexagon = ~0u, triangle = ~0u;
    for (std::uint32_t id = 0; id < s.size(); ++id) (s.edges_walked(id) == 6 ? hexagon : triangle) = id;
    ASSERT_NE(hexagon, ~0u);
    ASSERT_NE(triangle, ~0u);
    EXPECT_DOUBLE_EQ(cells.test_cost(hexagon), in.costs.prim[static_cast<int>(s.kind(hexagon))] + 12);
    EXPECT_DOUBLE_EQ(cells.test_cost(triangle), in.costs.prim[static_cast<int>(s.kind(triangle))]);
}

}  // namespace
}  // namespace rtcost::test
