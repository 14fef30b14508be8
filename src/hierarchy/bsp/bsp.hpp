#pragma once
// `bsp`: Kaplan's BSP tree ("Space-tracing: a constant time ray-tracer", 1985): binary, each
// cell cut at its spatial mid-plane, axes X, Y, Z in turn (a node at depth d splits axis d % 3).
//
// Build: a node is a leaf when it holds at most `max_prims` references or lies at `max_depth`
// (root at 0), or, at the top of a block of three levels (depth 0, 3, 6, ...; the block ends in
// the cell's eight octants, the octree's cells), when the growth guard says that the block would
// hardly separate its references: the octants would hold at least `growth` (default 6) times as
// many (common/subdivision.hpp). Beyond that, subdiv::kMaxRefs / kMaxNodes stop the build (never
// reached with sane parameters).
//
// Traversal (the loops are common/cell_tree.hpp's; common/subdivision.hpp says how cells are
// found by the ray parameter t):
//  - locate (default, Kaplan's): from the root clip's entry t, descend from the root to the leaf
//    holding the ray just after t; test its primitives; the cell's exit is the smallest crossing
//    bounding it from above (or the root exit); stop when the closest hit so far lies at or before
//    that exit, otherwise descend again from the root at the exit.
//  - recursive: front-to-back recursion with an explicit stack over the stretch [t0, t1] of the
//    ray in each node: the near child gets [t0, ts], the far one [ts, t1], a child whose stretch
//    is empty in the half-open partition is skipped. A leaf ends the search when the closest hit
//    lies at t <= its t1 (except on the low side of a plane the ray lies in, until the high side
//    too has been searched).
//
// Counters per ray: one `box` for the root clip (a ray that misses costs just that). Per interior
// node visited -- every node of every descent in `locate`, each node once in `recursive` --
// `interior(depth)` and one `plane` (the compare with its mid-plane). Per leaf visit
// `leaf(depth, n)` and one `prim` per primitive test (mailbox=1: only a primitive's first test in
// this ray).

#include <cstdint>
#include <vector>

#include "../common/cell_tree.hpp"

namespace rtcost::bsp {

/// Deepest leaf allowed (root at 0); bounds the traversal stacks.
inline constexpr int kMaxDepth = 60;

/// 12 bytes. Interior (axis 0..2): children at `index` (low half) and `index + 1`. Leaf
/// (axis 3): `count` references from Bsp::refs()[index].
struct Node {
    float split = 0;
    std::uint32_t index = 0;
    std::uint32_t count : 30 = 0;
    std::uint32_t axis : 2 = 3;
    bool leaf() const { return axis == 3; }
    void make_leaf(std::uint32_t first, std::uint32_t n) {
        axis = 3;
        index = first;
        count = n;
    }
};
static_assert(sizeof(Node) == 12);

using Options = subdiv::CellOptions;

class Bsp final : public subdiv::CellTree<Bsp, Node> {
public:
    static constexpr const char* kFamily = "bsp";
    static constexpr unsigned kArity = 2;
    static constexpr ModelFamily kModelFamily = ModelFamily::Bsp;
    static constexpr int kLocateStack = kMaxDepth + 8;  // one extra per axis the ray lies in
    static constexpr int kRecursiveStack = kMaxDepth + 2;  // one waiting child per level

    Bsp(const Scene& s, const Options& o) : CellTree(s, o) { build_tree(); }

    /// The two halves at the mid-plane of axis depth % 3; none where the growth guard, at the
    /// top of a block of three levels, keeps the cell a leaf.
    int split(const Box3& cell, int depth, const std::vector<std::uint32_t>& refs, const subdiv::Assigner& as,
              Box3* kids, std::vector<std::uint8_t>& mask, std::array<std::size_t, 8>& counts) const;
    void make_interior(Node& n, const Box3& cell, int depth, std::uint32_t first) const;

    template <class C, class Push>
    void locate_children(const Node& n, const subdiv::CellRay& r, float t, float up, C& counting, Push push) const {
        counting.plane();
        const int a = static_cast<int>(n.axis);
        if (r.moving[a]) {
            const float ts = r.cross(a, n.split);
            const bool high = r.high_after(a, ts, t);
            push(n.index + (high ? 1u : 0u), r.leaves(a, high) && ts < up ? ts : up);
        } else if (r.ri.o[a] != n.split) {
            push(n.index + (r.ri.o[a] > n.split ? 1u : 0u), up);
        } else {
            push(n.index + 1, up);
            push(n.index, up);
        }
    }

    template <class C>
    int recursive_children(const Node& n, const subdiv::CellRay& r, const subdiv::CellEntry& e, C& counting,
                           subdiv::CellEntry* out) const {
        counting.plane();
        const int a = static_cast<int>(n.axis);
        const int depth = e.depth + 1;
        if (r.moving[a]) {
            const float ts = r.cross(a, n.split);
            const std::uint32_t near = n.index + (r.ri.neg[a] ? 1u : 0u);
            const std::uint32_t far = n.index + (r.ri.neg[a] ? 0u : 1u);
            // The half-open partition: the near side holds [t0, ts), the far one [ts, t1].
            const bool want_near = e.t0 < ts;
            const bool want_far = ts < e.t1 || !want_near;
            if (want_near && want_far) {
                out[0] = {near, e.t0, ts, depth, e.may_end};
                out[1] = {far, ts, e.t1, depth, e.may_end};
                return 2;
            }
            out[0] = {want_near ? near : far, e.t0, e.t1, depth, e.may_end};
            return 1;
        }
        if (r.ri.o[a] != n.split) {
            out[0] = {n.index + (r.ri.o[a] > n.split ? 1u : 0u), e.t0, e.t1, depth, e.may_end};
            return 1;
        }
        // In the plane: both sides cover the same stretch, the low one may not end it.
        out[0] = {n.index, e.t0, e.t1, depth, false};
        out[1] = {n.index + 1, e.t0, e.t1, depth, e.may_end};
        return 2;
    }

    /// One model node per BSP node: a visit costs one plane compare and is one step.
    template <class Child>
    void emit_interior(ModelSink& sink, const Node& n, const Box3& region, Child child) const {
        const int a = static_cast<int>(n.axis);
        ModelNode m;
        m.region = region;
        m.step = true;
        m.leaf = false;
        m.count = 2;
        m.axis = static_cast<std::int8_t>(a);
        m.split = n.split;
        m.plane = 1;
        sink.node(m, {});
        if (sink.skip_children()) return;
        for (int side = 0; side < 2; ++side) child(n.index + side, subdiv::half(region, a, n.split, side));
    }
};

}  // namespace rtcost::bsp
