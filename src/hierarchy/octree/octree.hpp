#pragma once
// `octree`: Glassner's octree ("Space subdivision for fast ray tracing", 1984): each cell cut
// into eight octants at its centre.
//
// Build: a node is a leaf when it holds at most `max_prims` references (default 1, Glassner's)
// or lies at `max_depth` (root at 0), or when the growth guard says subdividing would hardly
// separate its references: its octants would hold at least `growth` (default 6) times as many
// (see bsp/subdivision.hpp). Beyond that, subdiv::kMaxRefs / kMaxNodes stop the build (never
// reached with sane parameters).
//
// Traversal (see bsp/subdivision.hpp for how cells are found by the ray parameter t):
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
#include <string_view>
#include <vector>

#include "../bsp/subdivision.hpp"

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
};
static_assert(sizeof(Node) == 20);

struct Options {
    int max_depth = 8;
    int max_prims = 1;
    spatial::Assign assign = spatial::Assign::Bounds;
    bool locate = true;
    bool mailbox = false;
    double growth = 6;  ///< see subdiv::kGrowthParam
    subdiv::SplitTest split_pays;  ///< when set, a cell is split only where this says it pays
    std::string name = "octree";  ///< the registered name (a designed variant's)
};

class Octree final : public HierarchyImpl<Octree> {
public:
    Octree(const Scene& s, const Options& o);

    std::string_view name() const override { return o_.name; }
    bool emit_model(ModelSink& sink) const override;

    const Box3& root() const { return root_; }
    const std::vector<Node>& nodes() const { return nodes_; }
    const std::vector<std::uint32_t>& refs() const { return refs_; }

    template <class C, Query Q>
    bool trace(const Ray& ray, Hit& hit, C& counting) const {
        if (o_.locate) return o_.mailbox ? locate<C, Q, true>(ray, hit, counting) : locate<C, Q, false>(ray, hit, counting);
        return o_.mailbox ? recursive<C, Q, true>(ray, hit, counting) : recursive<C, Q, false>(ray, hit, counting);
    }

protected:
    StructureStats compute_structure() const override;
    StructureStats compute_tree() const;
    bool capped_ = false;  ///< the references or nodes bound stopped the build somewhere

private:
    void build(std::uint32_t node, const Box3& cell, int depth, std::vector<std::uint32_t>& refs,
               const subdiv::Assigner& as);
    void make_leaf(std::uint32_t node, const std::vector<std::uint32_t>& refs);

    // A leaf's references through subdiv::test_leaf; true when an any-hit query may stop.
    template <class C, Query Q, bool kMailbox>
    bool test_leaf(const Node& n, int depth, const Ray& ray, Hit& hit, C& counting, spatial::Mailbox* mb,
                   bool& found) const {
        return subdiv::test_leaf<C, Q, kMailbox>(*scene_, refs_.data() + n.index, n.count, depth, ray, hit, counting,
                                                 mb, found);
    }

    template <class C, Query Q, bool kMailbox>
    bool locate(const Ray& ray, Hit& hit, C& counting) const {
        counting.box();
        const subdiv::CellRay r(ray);
        float t, t_end;
        if (!subdiv::clip_root(root_, r.ri, ray.tmin, ray.tmax, t, t_end)) return false;
        spatial::Mailbox* mb = nullptr;
        if constexpr (kMailbox) mb = &spatial::Mailbox::begin_ray(this, scene_->size());
        const Node* nodes = nodes_.data();
        bool found = false;
        struct Item {
            std::uint32_t node;
            int depth;
            float up;  // smallest crossing above t on the path so far: the cell's exit
        };
        // A descent branches only at planes the ray lies in (at most once per axis on a path).
        Item stack[8 * (kMaxDepth + 2)];
        for (;;) {
            float exit = t_end;
            int sp = 0;
            stack[sp++] = {0, 0, t_end};
            while (sp > 0) {
                const Item it = stack[--sp];
                const Node& n = nodes[it.node];
                if (n.leaf()) {
                    if (test_leaf<C, Q, kMailbox>(n, it.depth, ray, hit, counting, mb, found)) return true;
                    exit = it.up < exit ? it.up : exit;
                    continue;
                }
                counting.interior(it.depth);
                unsigned bits = 0, both = 0;
                float up = it.up;
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
                    stack[sp++] = {n.index + (bits | sub), it.depth + 1, up};
                    if (sub == 0) break;
                }
            }
            // A hit up to and including the exit lies in these cells: nothing later is nearer.
            if constexpr (Q != Query::All) {
                if (hit.t <= exit) return found;
            }
            if (exit >= t_end) return found;
            t = exit;  // strictly greater than before: every exit bounds its cell from above
        }
    }

    template <class C, Query Q, bool kMailbox>
    bool recursive(const Ray& ray, Hit& hit, C& counting) const {
        counting.box();
        const subdiv::CellRay r(ray);
        struct Entry {
            std::uint32_t node;
            float t0, t1;
            int depth;
            bool may_end;  // false beside a plane the ray lies in, until the other side is done
        };
        Entry e{0, 0, 0, 0, true};
        if (!subdiv::clip_root(root_, r.ri, ray.tmin, ray.tmax, e.t0, e.t1)) return false;
        spatial::Mailbox* mb = nullptr;
        if constexpr (kMailbox) mb = &spatial::Mailbox::begin_ray(this, scene_->size());
        const Node* nodes = nodes_.data();
        bool found = false;
        Entry stack[8 * (kMaxDepth + 2)];  // at most seven waiting children per level
        int sp = 0;
        for (;;) {
            const Node& n = nodes[e.node];
            if (n.leaf()) {
                if (test_leaf<C, Q, kMailbox>(n, e.depth, ray, hit, counting, mb, found)) return true;
                if constexpr (Q != Query::All) {
                    if (e.may_end && hit.t <= e.t1) return found;
                }
                if (sp == 0) return found;
                e = stack[--sp];
                continue;
            }
            counting.interior(e.depth);
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
            Entry list[8];
            int nl = 0;
            const int depth = e.depth + 1;
            float lo = e.t0;
            for (int k = 0;;) {
                const float hi = k < nx ? xt[k] : e.t1;
                for (unsigned sub = both;; sub = (sub - 1) & both) {
                    list[nl++] = {n.index + (bits | sub), lo, hi, depth, sub == 0 ? e.may_end : false};
                    if (sub == 0) break;
                }
                if (k >= nx) break;
                const float x = xt[k];
                for (; k < nx && xt[k] == x; ++k) bits ^= xbit[k];
                lo = x;
            }
            for (int k = nl - 1; k > 0; --k) stack[sp++] = list[k];
            e = list[0];
        }
    }

    Options o_;
    Box3 root_;
    std::vector<Node> nodes_;
    std::vector<std::uint32_t> refs_;
};

}  // namespace rtcost::octree
