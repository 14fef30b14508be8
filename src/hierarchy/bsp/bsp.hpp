#pragma once
// `bsp`: Kaplan's BSP tree ("Space-tracing: a constant time ray-tracer", 1985): binary, each
// cell cut at its spatial mid-plane, axes X, Y, Z in turn (a node at depth d splits axis d % 3).
//
// Build: a node is a leaf when it holds at most `max_prims` references or lies at `max_depth`
// (root at 0), or, at the top of a block of three levels (depth 0, 3, 6, ...; the block ends in
// the cell's eight octants, the octree's cells), when the growth guard says that the block would
// hardly separate its references: the octants would hold at least `growth` (default 6) times as
// many (subdivision.hpp). Beyond that,
// subdiv::kMaxRefs / kMaxNodes stop the build (never reached with sane parameters).
//
// Traversal (see subdivision.hpp for how cells are found by the ray parameter t):
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
#include <string_view>
#include <vector>

#include "subdivision.hpp"

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
};
static_assert(sizeof(Node) == 12);

struct Options {
    int max_depth = 20;
    int max_prims = 2;
    spatial::Assign assign = spatial::Assign::Bounds;
    bool locate = true;
    bool mailbox = false;
    double growth = 6;  ///< see subdiv::kGrowthParam
    subdiv::SplitTest split_pays;  ///< when set, a cell is split only where this says it pays
    std::string name = "bsp";  ///< the registered name (a designed variant's)
};

class Bsp final : public HierarchyImpl<Bsp> {
public:
    Bsp(const Scene& s, const Options& o);

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
        // A descent branches only at a plane the ray lies in, at most once per axis on a path.
        Item stack[kMaxDepth + 8];
        for (;;) {
            // Descend to every leaf holding the ray just after t (one, unless the ray lies in a
            // split plane); the stretch they share ends at the smallest of their exits.
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
                counting.plane();
                const int a = static_cast<int>(n.axis);
                if (r.moving[a]) {
                    const float ts = r.cross(a, n.split);
                    const bool high = r.high_after(a, ts, t);
                    const float up = r.leaves(a, high) && ts < it.up ? ts : it.up;
                    stack[sp++] = {n.index + (high ? 1u : 0u), it.depth + 1, up};
                } else if (r.ri.o[a] != n.split) {
                    stack[sp++] = {n.index + (r.ri.o[a] > n.split ? 1u : 0u), it.depth + 1, it.up};
                } else {
                    stack[sp++] = {n.index + 1, it.depth + 1, it.up};
                    stack[sp++] = {n.index, it.depth + 1, it.up};
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
            bool may_end;  // false on the low side of a plane the ray lies in
        };
        Entry e{0, 0, 0, 0, true};
        if (!subdiv::clip_root(root_, r.ri, ray.tmin, ray.tmax, e.t0, e.t1)) return false;
        spatial::Mailbox* mb = nullptr;
        if constexpr (kMailbox) mb = &spatial::Mailbox::begin_ray(this, scene_->size());
        const Node* nodes = nodes_.data();
        bool found = false;
        Entry stack[kMaxDepth + 2];  // at most one waiting child per level
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
                    stack[sp++] = {far, ts, e.t1, depth, e.may_end};
                    e = {near, e.t0, ts, depth, e.may_end};
                } else {
                    e = {want_near ? near : far, e.t0, e.t1, depth, e.may_end};
                }
            } else if (r.ri.o[a] != n.split) {
                e = {n.index + (r.ri.o[a] > n.split ? 1u : 0u), e.t0, e.t1, depth, e.may_end};
            } else {
                // In the plane: both sides cover the same stretch, the low one may not end it.
                stack[sp++] = {n.index + 1, e.t0, e.t1, depth, e.may_end};
                e = {n.index, e.t0, e.t1, depth, false};
            }
        }
    }

    Options o_;
    Box3 root_;
    std::vector<Node> nodes_;
    std::vector<std::uint32_t> refs_;
};

}  // namespace rtcost::bsp
