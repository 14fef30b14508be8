#pragma once
// `octree`: Glassner's octree ("Space subdivision for fast ray tracing", 1984): each cell cut
// into eight octants at its centre.
//
// Build: a node is a leaf when it holds at most `max_prims` references (default 1, Glassner's)
// or lies at `max_depth` (root at 0), or when the growth guard says subdividing would hardly
// separate its references: its octants would hold at least `growth` (default 6) times as many
// (see common/subdivision.hpp). Beyond that, subdiv::kMaxRefs / kMaxNodes stop the build (never
// reached with sane parameters).
//
// Traversal (the loops are common/cell_tree.hpp's; common/subdivision.hpp says how cells are
// found by the ray parameter t):
//  - locate (default, Glassner's): from the root clip's entry t, descend from the root to the
//    leaf holding the ray just after t (at each node the octant by three compares with the
//    centre), test it, and descend again at its exit until the closest hit lies at or before the
//    exit of the current cell.
//  - recursive: the parametric traversal of Revelles, Urena and Lastra (2000): in a node whose
//    stretch of the ray is [t0, t1], the three mid-plane parameters give the first child (the
//    octant holding the ray just after t0) and the sequence of children, one axis bit flipped at
//    each mid-plane crossed inside (t0, t1), with no point location; children are visited front
//    to back with an explicit stack. A leaf ends the search when the closest hit lies at
//    t <= its t1 (except beside a plane the ray lies in, until the other side too was searched).
//
// Counters per ray: one `box` for the root clip. Per interior node visit (every node of every
// descent in `locate`, each node once in `recursive`) one traversal step `interior(depth)`, with
// the octree depth, and three `plane` (its three compares with the centre or mid-plane
// parameters). Per leaf visit `leaf(depth, n)`, one `prim` per primitive test (mailbox=1: only
// a primitive's first test in this ray).

#include <cstdint>
#include <vector>

#include "../common/cell_tree.hpp"

namespace rtcost::octree {

/// Deepest leaf allowed (root at 0): 2^20 cells per axis is far beyond any use.
inline constexpr int kMaxDepth = 20;

/// 20 bytes. Interior: eight children from `index`, child k = octant k (bit 0 high x, bit 1
/// high y, bit 2 high z). Leaf: `count` references from Octree::refs()[index].
struct Node {
    Vec3 center;
    std::uint32_t index = 0;
    std::uint32_t count : 31 = 0;
    std::uint32_t is_leaf : 1 = 1;
    bool leaf() const { return is_leaf; }
    void make_leaf(std::uint32_t first, std::uint32_t n) {
        is_leaf = 1;
        index = first;
        count = n;
    }
};
static_assert(sizeof(Node) == 20);

using Options = subdiv::CellOptions;

class Octree final : public subdiv::CellTree<Octree, Node> {
public:
    static constexpr const char* kFamily = "octree";
    static constexpr unsigned kArity = 8;
    static constexpr ModelFamily kModelFamily = ModelFamily::Octree;
    static constexpr int kLocateStack = 8 * (kMaxDepth + 2);
    static constexpr int kRecursiveStack = 8 * (kMaxDepth + 2);  // at most seven waiting children per level

    Octree(const Scene& s, const Options& o) : CellTree(s, o) { build_tree(); }

    /// The eight octants at the centre; none where the growth guard keeps the cell a leaf.
    int split(const Box3& cell, int depth, const std::vector<std::uint32_t>& refs, const subdiv::Assigner& as,
              Box3* kids, std::vector<std::uint8_t>& mask, std::array<std::size_t, 8>& counts) const;
    void make_interior(Node& n, const Box3& cell, int depth, std::uint32_t first) const;

    template <class C, class Push>
    void locate_children(const Node& n, const subdiv::CellRay& r, float t, float up, C& counting, Push push) const {
        unsigned bits = 0, both = 0;
        for (int a = 0; a < 3; ++a) {
            counting.plane();
            const float s = n.center[a];
            if (r.moving[a]) {
                const float ts = r.cross(a, s);
                const bool high = r.high_after(a, ts, t);
                bits |= static_cast<unsigned>(high) << a;
                if (r.leaves(a, high) && ts < up) up = ts;
            } else if (r.ri.o[a] > s) {
                bits |= 1u << a;
            } else if (r.ri.o[a] == s) {
                both |= 1u << a;  // in the plane: both octants on this axis
            }
        }
        for (unsigned sub = both;; sub = (sub - 1) & both) {
            push(n.index + (bits | sub), up);
            if (sub == 0) break;
        }
    }

    template <class C>
    int recursive_children(const Node& n, const subdiv::CellRay& r, const subdiv::CellEntry& e, C& counting,
                           subdiv::CellEntry* out) const {
        // The first child and the mid-plane crossings inside (t0, t1), by parameter only.
        unsigned bits = 0, both = 0;
        float xt[3];
        unsigned xbit[3];
        int nx = 0;
        for (int a = 0; a < 3; ++a) {
            counting.plane();
            const float s = n.center[a];
            if (r.moving[a]) {
                const float ts = r.cross(a, s);
                bits |= static_cast<unsigned>(r.high_after(a, ts, e.t0)) << a;
                if (e.t0 < ts && ts < e.t1) {
                    // Insertion in ascending order (at most three).
                    int j = nx++;
                    for (; j > 0 && xt[j - 1] > ts; --j) {
                        xt[j] = xt[j - 1];
                        xbit[j] = xbit[j - 1];
                    }
                    xt[j] = ts;
                    xbit[j] = 1u << a;
                }
            } else if (r.ri.o[a] > s) {
                bits |= 1u << a;
            } else if (r.ri.o[a] == s) {
                both |= 1u << a;
            }
        }
        // The children in order along the ray: one per stretch between crossings (equal
        // crossings, a corner, flip their bits together), times the octants beside planes the
        // ray lies in, of which only the last may end the search.
        int nl = 0;
        const int depth = e.depth + 1;
        float lo = e.t0;
        for (int k = 0;;) {
            const float hi = k < nx ? xt[k] : e.t1;
            for (unsigned sub = both;; sub = (sub - 1) & both) {
                out[nl++] = {n.index + (bits | sub), lo, hi, depth, sub == 0 ? e.may_end : false};
                if (sub == 0) break;
            }
            if (k >= nx) break;
            const float x = xt[k];
            for (; k < nx && xt[k] == x; ++k) bits ^= xbit[k];
            lo = x;
        }
        return nl;
    }

    /// The model's binary tree: an octree node is three binary levels at its centre, X, then Y,
    /// then Z. The X level carries the visit (one step, three plane compares); the Y and Z
    /// levels only carry regions and planes for the probabilities (no step, no operations). A
    /// Z-level node's children are the octants (x, y, 0) and (x, y, 1).
    template <class Child>
    void emit_interior(ModelSink& sink, const Node& n, const Box3& region, Child child) const {
        ModelNode m;
        m.region = region;
        m.step = true;
        m.leaf = false;
        m.count = 2;
        m.axis = 0;
        m.split = n.center.x;
        m.plane = 3;
        sink.node(m, {});
        if (sink.skip_children()) return;
        for (int xi = 0; xi < 2; ++xi) {
            ModelNode y;
            y.region = subdiv::half(region, 0, n.center.x, xi);
            y.leaf = false;
            y.axis = 1;
            y.split = n.center.y;
            y.count = 2;
            y.step = false;
            sink.node(y, {});
            if (sink.skip_children()) continue;
            for (int yi = 0; yi < 2; ++yi) {
                ModelNode z;
                z.region = subdiv::half(y.region, 1, n.center.y, yi);
                z.leaf = false;
                z.axis = 2;
                z.split = n.center.z;
                z.count = 2;
                z.step = false;
                sink.node(z, {});
                if (sink.skip_children()) continue;
                for (int zi = 0; zi < 2; ++zi)
                    child(n.index + static_cast<std::uint32_t>(xi | yi << 1 | zi << 2),
                          subdiv::half(z.region, 2, n.center.z, zi));
            }
        }
    }
};

}  // namespace rtcost::octree
