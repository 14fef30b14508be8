#pragma once
// What Kaplan's BSP tree (`bsp`) and Glassner's octree (`octree`) are made of alike: a tree of
// regular cells over the scene box stored as one array, each leaf a run of references; the
// build's termination (leaf size, depth, the memory bound, the growth guard's and a designed
// variant's split test); both traversals' outer loops (`locate` and `recursive`, see
// subdivision.hpp for how cells are found by the ray parameter t); structure statistics; and the
// model tree's leaves. A family says only how one of its nodes cuts a cell and a ray:
//
//   struct Node { bool leaf() const; std::uint32_t index, count; void make_leaf(index, count); };
//   static constexpr const char* kFamily;          // for messages
//   static constexpr unsigned kArity;              // children per interior node
//   static constexpr int kMaxDepth, kLocateStack, kRecursiveStack;
//   static constexpr ModelFamily kModelFamily;
//   // The children of `cell` at `depth` (their boxes, and each reference's mask among them);
//   // 0 when the family's own guard keeps the cell a leaf.
//   int split(const Box3& cell, int depth, const std::vector<std::uint32_t>& refs,
//             const Assigner& as, Box3* kids, std::vector<std::uint8_t>& mask,
//             std::array<std::size_t, 8>& counts) const;
//   void make_interior(Node& n, const Box3& cell, int depth, std::uint32_t first) const;
//   // locate: the children holding the ray just after t, each with the cell's exit so far
//   template <class C, class Push> void locate_children(const Node&, const CellRay&, float t,
//                                                       float up, C&, Push push) const;
//   // recursive: the children in order along [e.t0, e.t1]; returns how many
//   template <class C> int recursive_children(const Node&, const CellRay&, const CellEntry& e,
//                                             C&, CellEntry* out) const;
//   // the model tree below an interior node (its own node included), `child(i, region)` for each
//   template <class Child> void emit_interior(ModelSink&, const Node&, const Box3& region,
//                                             Child child) const;

#include <fmt/format.h>

#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "subdivision.hpp"
#include "tree_stats.hpp"

namespace rtcost::subdiv {

/// The options both families take; each registration gives its own defaults (param_specs).
struct CellOptions {
    int max_depth = 8;
    int max_prims = 1;
    spatial::Assign assign = spatial::Assign::Bounds;
    bool locate = true;
    bool mailbox = false;
    double growth = 6;  ///< see kGrowthParam
    SplitTest split_pays;  ///< when set, a cell is split only where this says it pays
    /// When set, a cell above the leaf size and depth is left unbuilt where this says no ray of a sample
    /// reaches it (`reached(cell, depth)`, asked depth first): an empty leaf that the model tree
    /// marks pruned (ModelNode::pruned). Such a tree predicts the sample as the whole tree does,
    /// for a fraction of its build, and must not be traced (partial()).
    std::function<bool(const Box3&, int)> reached;
    std::string name;  ///< the registered name (a designed variant's)
};

/// Reads param_specs' parameters (the name is the caller's).
inline CellOptions read_options(const Params& p) {
    CellOptions o;
    o.max_depth = static_cast<int>(p.integer("max_depth"));
    o.max_prims = static_cast<int>(p.integer("max_prims"));
    o.locate = p.is("traversal", "locate");
    o.assign = spatial::parse_assign(p);
    o.mailbox = p.flag("mailbox");
    o.growth = p.real("growth");
    return o;
}

/// A node's stretch [t0, t1] of the ray in the recursive traversal.
struct CellEntry {
    std::uint32_t node;
    float t0, t1;
    int depth;
    bool may_end;  ///< false beside a plane the ray lies in, until the other side is searched
};

template <class Derived, class NodeT>
class CellTree : public HierarchyImpl<Derived> {
public:
    using Node = NodeT;

    std::string_view name() const override { return o_.name; }
    bool emit_model(ModelSink& sink) const override;

    const Box3& root() const { return root_; }
    /// Some cells were left unbuilt (CellOptions::reached): a tree for the model only.
    bool partial() const { return !unbuilt_.empty(); }
    const std::vector<Node>& nodes() const { return nodes_; }
    const std::vector<std::uint32_t>& refs() const { return refs_; }

    template <class C, Query Q>
    bool trace(const Ray& ray, Hit& hit, C& counting) const {
        return trace_with<C, Q>(ray, hit, counting, RealPrimTest{*this->scene_});
    }

    /// Whether Hierarchy::replay is the model tree's prediction: not with mailboxes, which the
    /// model does not know.
    bool replay_is_model() const { return !o_.mailbox; }

    /// The traversal with the primitive test supplied by the caller (design/replay.hpp).
    template <class C, Query Q, class PrimTest>
    bool trace_with(const Ray& ray, Hit& hit, C& counting, PrimTest test) const {
        if (o_.locate)
            return o_.mailbox ? locate<C, Q, true>(ray, hit, counting, test) : locate<C, Q, false>(ray, hit, counting, test);
        return o_.mailbox ? recursive<C, Q, true>(ray, hit, counting, test)
                          : recursive<C, Q, false>(ray, hit, counting, test);
    }

protected:
    CellTree(const Scene& s, const CellOptions& o) : HierarchyImpl<Derived>(s), o_(o), root_(s.bounds()) {}

    /// Builds the whole tree (the empty scene: one empty leaf in a point box). Called by the
    /// family's constructor, not by this one: the build asks the family how to split, and a
    /// base's constructor runs before the family object exists.
    void build_tree() {
        const Scene& s = *this->scene_;
        const bool empty = s.empty() || root_.empty();
        if (empty) root_ = Box3{{0, 0, 0}, {0, 0, 0}};
        const Assigner as(s, o_.assign);
        std::vector<std::uint32_t> refs = empty ? std::vector<std::uint32_t>{} : as.all();
        nodes_.emplace_back();
        build(0, root_, 0, refs, as);
        nodes_.shrink_to_fit();
        refs_.shrink_to_fit();
    }

    StructureStats compute_structure() const override;

    const CellOptions& options() const { return o_; }

private:
    const Derived& self() const { return static_cast<const Derived&>(*this); }
    void make_leaf(std::uint32_t node, const std::vector<std::uint32_t>& refs);
    void build(std::uint32_t node, const Box3& cell, int depth, std::vector<std::uint32_t>& refs, const Assigner& as);

    template <class C, Query Q, bool kMailbox, class PrimTest>
    bool test_leaf(const Node& n, int depth, const Ray& ray, Hit& hit, C& counting, spatial::Mailbox* mb, bool& found,
                   PrimTest& test) const {
        // A replay's test is told when it enters a cell left unbuilt (a real trace never runs
        // on a partial tree, and its test has no such member: no code here).
        if constexpr (requires { test.unbuilt(); }) {
            const auto i = static_cast<std::size_t>(&n - nodes_.data());
            if (i < unbuilt_.size() && unbuilt_[i]) test.unbuilt();
        }
        return subdiv::test_leaf<C, Q, kMailbox>(refs_.data() + n.index, n.count, depth, ray, hit, counting, mb, found,
                                                 test);
    }

    // From the root clip's entry t, descend to every leaf holding the ray just after t (one,
    // unless the ray lies in a split plane); test them; stop when the closest hit lies at or
    // before the smallest of their exits, otherwise descend again from the root at that exit.
    template <class C, Query Q, bool kMailbox, class PrimTest>
    bool locate(const Ray& ray, Hit& hit, C& counting, PrimTest& test) const {
        counting.box();
        const CellRay r(ray);
        float t, t_end;
        if (!clip_root(root_, r.ri, ray.tmin, ray.tmax, t, t_end)) return false;
        spatial::Mailbox* mb = nullptr;
        if constexpr (kMailbox) mb = &spatial::Mailbox::begin_ray(this, this->scene_->size());
        const Node* nodes = nodes_.data();
        bool found = false;
        struct Item {
            std::uint32_t node;
            int depth;
            float up;  // smallest crossing above t on the path so far: the cell's exit
        };
        // A descent branches only at planes the ray lies in, at most once per axis on a path.
        Item stack[Derived::kLocateStack];
        for (;;) {
            float exit = t_end;
            int sp = 0;
            stack[sp++] = {0, 0, t_end};
            while (sp > 0) {
                const Item it = stack[--sp];
                const Node& n = nodes[it.node];
                if (n.leaf()) {
                    if (test_leaf<C, Q, kMailbox>(n, it.depth, ray, hit, counting, mb, found, test)) return true;
                    exit = it.up < exit ? it.up : exit;
                    continue;
                }
                counting.interior(it.depth);
                self().locate_children(n, r, t, it.up, counting, [&](std::uint32_t child, float up) {
                    stack[sp++] = {child, it.depth + 1, up};
                });
            }
            // A hit up to and including the exit lies in these cells: nothing later is nearer.
            if constexpr (Q != Query::All) {
                if (hit.t <= exit) return found;
            }
            if (exit >= t_end) return found;
            t = exit;  // strictly greater than before: every exit bounds its cell from above
        }
    }

    // Front to back with an explicit stack over each node's stretch of the ray. A leaf ends the
    // search when the closest hit lies at t <= its t1 (unless beside a plane the ray lies in).
    template <class C, Query Q, bool kMailbox, class PrimTest>
    bool recursive(const Ray& ray, Hit& hit, C& counting, PrimTest& test) const {
        counting.box();
        const CellRay r(ray);
        CellEntry e{0, 0, 0, 0, true};
        if (!clip_root(root_, r.ri, ray.tmin, ray.tmax, e.t0, e.t1)) return false;
        spatial::Mailbox* mb = nullptr;
        if constexpr (kMailbox) mb = &spatial::Mailbox::begin_ray(this, this->scene_->size());
        const Node* nodes = nodes_.data();
        bool found = false;
        CellEntry stack[Derived::kRecursiveStack];  // at most arity - 1 waiting children per level
        int sp = 0;
        for (;;) {
            const Node& n = nodes[e.node];
            if (n.leaf()) {
                if (test_leaf<C, Q, kMailbox>(n, e.depth, ray, hit, counting, mb, found, test)) return true;
                if constexpr (Q != Query::All) {
                    if (e.may_end && hit.t <= e.t1) return found;
                }
                if (sp == 0) return found;
                e = stack[--sp];
                continue;
            }
            counting.interior(e.depth);
            CellEntry list[Derived::kArity];
            const int nl = self().recursive_children(n, r, e, counting, list);
            for (int k = nl - 1; k > 0; --k) stack[sp++] = list[k];
            e = list[0];
        }
    }

    CellOptions o_;
    Box3 root_;
    std::vector<Node> nodes_;
    std::vector<std::uint32_t> refs_;
    std::vector<std::uint8_t> unbuilt_;  ///< per node (up to the last one unbuilt): left unbuilt
    bool capped_ = false;  ///< the references or nodes bound stopped the build somewhere
};

template <class Derived, class NodeT>
void CellTree<Derived, NodeT>::make_leaf(std::uint32_t node, const std::vector<std::uint32_t>& refs) {
    nodes_[node].make_leaf(static_cast<std::uint32_t>(refs_.size()), static_cast<std::uint32_t>(refs.size()));
    refs_.insert(refs_.end(), refs.begin(), refs.end());
}

// Recursion depth is at most max_depth <= Derived::kMaxDepth.
template <class Derived, class NodeT>
void CellTree<Derived, NodeT>::build(std::uint32_t node, const Box3& cell, int depth, std::vector<std::uint32_t>& refs,
                                     const Assigner& as) {
    if (refs.size() <= static_cast<std::size_t>(o_.max_prims) || depth >= o_.max_depth) return make_leaf(node, refs);
    if (refs_.size() >= kMaxRefs || nodes_.size() >= kMaxNodes) {
        capped_ = true;
        return make_leaf(node, refs);
    }
    Box3 kids[8];
    std::vector<std::uint8_t> mask;
    std::array<std::size_t, 8> counts;
    if (o_.reached && !o_.reached(cell, depth)) {  // before the split's work
        if (unbuilt_.size() < nodes_.size()) unbuilt_.resize(nodes_.size(), 0);
        unbuilt_[node] = 1;
        return make_leaf(node, {});
    }
    const int k = self().split(cell, depth, refs, as, kids, mask, counts);
    if (k == 0) return make_leaf(node, refs);
    if (o_.split_pays && !o_.split_pays(cell, refs.size(), kids, counts.data(), k)) return make_leaf(node, refs);
    std::vector<std::uint32_t> child[8];
    for (int j = 0; j < k; ++j) child[j] = Assigner::select(refs, mask, j, counts[j]);
    std::vector<std::uint32_t>().swap(refs);  // free the parent's list before descending
    const std::uint32_t first = static_cast<std::uint32_t>(nodes_.size());
    nodes_.resize(nodes_.size() + static_cast<std::size_t>(k));
    self().make_interior(nodes_[node], cell, depth, first);
    for (int j = 0; j < k; ++j) build(first + static_cast<std::uint32_t>(j), kids[j], depth + 1, child[j], as);
}

template <class Derived, class NodeT>
StructureStats CellTree<Derived, NodeT>::compute_structure() const {
    StructureStats s = tree_structure(nodes_, [](const Node& n) { return n.leaf(); },
                                      [](const Node&) { return Derived::kArity; });
    s.bytes = nodes_.size() * sizeof(Node) + refs_.size() * sizeof(std::uint32_t);
    if (capped_)
        s.limits.push_back(fmt::format("{}: subdivision stopped at {} references or {} nodes (the memory bound); "
                                       "leaves below it hold more primitives than max_prims",
                                       Derived::kFamily, kMaxRefs, kMaxNodes));
    return s;
}

// One model node per tree node below the family's interior levels; every visit is one step,
// and with `locate` the model charges every leaf visit its whole descent again.
template <class Derived, class NodeT>
bool CellTree<Derived, NodeT>::emit_model(ModelSink& sink) const {
    // The paper's Kaplan/Glassner term: a plane compare and the far region's entry.
    ModelFlags f(Derived::kModelFamily, {.interior_plane = 1, .far_entry = true});
    f.locate = o_.locate;
    f.point_touches = false;  // locate and the recursive children step over an edge or corner at once
    f.per_ray_box = 1;
    if (!sink.begin(f) || nodes_.empty()) return true;
    auto emit = [&](auto&& recurse, std::uint32_t i, const Box3& region) -> void {
        const Node& n = nodes_[i];
        if (!n.leaf()) {
            self().emit_interior(sink, n, region,
                                 [&](std::uint32_t child, const Box3& r) { recurse(recurse, child, r); });
            return;
        }
        ModelNode m;
        m.region = region;
        m.step = true;
        m.count = n.count;
        m.pruned = i < unbuilt_.size() && unbuilt_[i];
        sink.node(m, std::span<const std::uint32_t>(refs_).subspan(n.index, n.count));
    };
    emit(emit, 0, root_);
    return true;
}

}  // namespace rtcost::subdiv
