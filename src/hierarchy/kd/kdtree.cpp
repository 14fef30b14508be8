// kd-trees: the build driver shared by both plane choosers, structure statistics, the model
// tree and the registrations of `kd-median` and `kd-sah`.
#include "kdtree.hpp"
#include "../common/tree_stats.hpp"

#include <algorithm>
#include <cmath>

namespace rtcost::kd {

int default_max_depth(std::size_t n) {
    const double d = 8.0 + 1.3 * std::log2(static_cast<double>(std::max<std::size_t>(n, 1)));
    return std::clamp(static_cast<int>(std::lround(d)), 0, kMaxDepth);
}

namespace {

struct Builder {
    const Scene& s;
    const BuildOptions& o;
    const Chooser& choose;
    std::vector<Box3> bounds;  // full primitive bounds, for spatial::overlaps
    KdData d;

    void leaf(std::uint32_t node, const std::vector<BuildRef>& refs) {
        Node& n = d.nodes[node];
        n.axis = 3;
        n.index = static_cast<std::uint32_t>(d.refs.size());
        n.count = static_cast<std::uint32_t>(refs.size());
        for (const BuildRef& r : refs) d.refs.push_back(r.id);
    }

    // Recursion depth is at most kMaxDepth.
    void build(std::uint32_t node, std::vector<BuildRef>& refs, const Box3& cell, int depth) {
        if (o.boxes) {
            Box3 b;
            for (const BuildRef& r : refs) b.extend(r.box);
            d.boxes[node] = b;
        }
        if (depth >= o.max_depth || refs.size() <= static_cast<std::size_t>(o.max_prims)) return leaf(node, refs);
        const Split sp = choose(refs, cell, depth);
        if (sp.axis < 0) return leaf(node, refs);
        const int a = sp.axis;
        const float x = sp.pos;
        const Box3 lcell = spatial::half(cell, a, x, 0), rcell = spatial::half(cell, a, x, 1);
        std::vector<BuildRef> left, right;
        left.reserve(refs.size());
        right.reserve(refs.size());
        for (const BuildRef& r : refs) {
            // Closed intervals: a box touching the plane belongs to both sides.
            bool l = r.box.lo[a] <= x, rr = r.box.hi[a] >= x;
            if (l && rr && o.assign == spatial::Assign::Exact) {
                // Only a box reaching both sides can miss one; a box on one side meets that
                // child exactly as it met the parent.
                l = spatial::overlaps(s, r.id, bounds[r.id], lcell, o.assign);
                rr = spatial::overlaps(s, r.id, bounds[r.id], rcell, o.assign);
                if (!l && !rr) l = rr = true;  // rounding in the clipper: stay conservative
            }
            if (l) {
                BuildRef c = r;
                c.box.hi[a] = std::min(c.box.hi[a], x);
                left.push_back(c);
            }
            if (rr) {
                BuildRef c = r;
                c.box.lo[a] = std::max(c.box.lo[a], x);
                right.push_back(c);
            }
        }
        std::vector<BuildRef>().swap(refs);  // free the parent's list before descending
        const std::uint32_t first = static_cast<std::uint32_t>(d.nodes.size());
        d.nodes.resize(d.nodes.size() + 2);
        if (o.boxes) d.boxes.resize(d.nodes.size());
        Node& n = d.nodes[node];
        n.axis = static_cast<std::uint32_t>(a);
        n.split = x;
        n.index = first;
        n.count = 2;
        build(first, left, lcell, depth + 1);
        build(first + 1, right, rcell, depth + 1);
    }
};

}  // namespace

KdData build_tree(const Scene& s, const BuildOptions& o, const Chooser& choose) {
    Builder b{s, o, choose, {}, {}};
    b.d.root = s.bounds();
    b.d.nodes.resize(1);
    if (o.boxes) b.d.boxes.resize(1);
    std::vector<BuildRef> refs;
    if (!s.empty() && !s.bounds().empty()) {
        b.bounds.resize(s.size());
        refs.reserve(s.size());
        for (std::uint32_t id = 0; id < s.size(); ++id) {
            const Box3 pb = s.prim_bounds(id);
            b.bounds[id] = pb;
            if (pb.empty()) continue;  // degenerate: no surface to reference
            refs.push_back({id, pb});
        }
    }
    b.build(0, refs, b.d.root, 0);
    b.d.nodes.shrink_to_fit();
    b.d.refs.shrink_to_fit();
    return std::move(b.d);
}

StructureStats KdTree::compute_structure() const {
    StructureStats s = tree_structure(d_.nodes, [](const Node& n) { return n.leaf(); }, [](const Node&) { return 2u; });
    s.bytes = d_.nodes.size() * sizeof(Node) + d_.refs.size() * sizeof(std::uint32_t) + d_.boxes.size() * sizeof(Box3);
    return s;
}

// Node for node the traversal: an interior visit is one step costing one plane compare, and with
// node boxes one box test first (the model's gate: the plane is paid only when the box is met).
// Leaves have no box. The root clip is per_ray_box.
bool KdTree::emit_model(ModelSink& sink) const {
    ModelFlags f(ModelFamily::Kd, {.interior_box = 1, .interior_plane = 1});  // the paper's kd node
    f.per_ray_box = 1;
    f.cull_widened = true;  // a leaf ends the search only when cull_bound(hit) is inside it
    if (!sink.begin(f) || d_.nodes.empty()) return true;
    auto emit = [&](auto&& self, std::uint32_t i, const Box3& region) -> void {
        const Node& n = d_.nodes[i];
        ModelNode m;
        m.region = region;
        m.step = true;
        if (n.leaf()) {
            m.count = n.count;
            sink.node(m, std::span<const std::uint32_t>(d_.refs).subspan(n.index, n.count));
            return;
        }
        m.leaf = false;
        m.count = 2;
        m.axis = static_cast<std::int8_t>(n.axis);
        m.split = n.split;
        m.plane = 1;
        if (boxes_) {
            m.has_bv = true;
            m.bv = d_.boxes[i];
            m.box = 1;
        }
        sink.node(m, {});
        if (sink.skip_children()) return;
        for (int side = 0; side < 2; ++side)
            self(self, n.index + side, spatial::half(region, static_cast<int>(n.axis), n.split, side));
    };
    emit(emit, 0, d_.root);
    return true;
}

namespace {

int max_depth(const Params& p, const Scene& s) {
    if (p.is("max_depth", "auto")) return default_max_depth(s.size());
    return static_cast<int>(p.integer("max_depth"));
}

BuildOptions common(const Params& p, const Scene& s) {
    BuildOptions o;
    o.max_depth = max_depth(p, s);
    o.max_prims = static_cast<int>(p.integer("max_prims"));
    o.assign = spatial::parse_assign(p);
    return o;
}

const Registration median_reg{
    {"kd-median",
     "Fussell and Subramanian's median-cut kd-tree: count-balancing planes with few straddlers, free axis, "
     "a box per node tested before its plane",
     {ParamSpec::integer("max_prims", "1", 1, 1 << 20, "a node with at most this many references is a leaf"),
      kMaxDepthParam,
      spatial::kAssignParam,
      spatial::kMailboxParam},
     [](const Scene& s, const Params& p) {
         MedianOptions o;
         o.build = common(p, s);
         o.build.boxes = true;
         return std::make_unique<KdTree>(s, "kd-median", build_median(s, o), p.flag("mailbox"));
     },
     kLargeScene},  // O(N log^2 N) build: 7 s for a million triangles
    {{{}, kTestHits | kTestSampled | kTestSpdModel}}};

const Registration sah_reg{
    {"kd-sah",
     "SAH kd-tree (MacDonald and Booth's cost, Wald and Havran's termination and empty-space bonus)",
     {ParamSpec::integer("max_prims", "1", 1, 1 << 20, "a node with at most this many references is a leaf"),
      kMaxDepthParam,
      ParamSpec::real("c_trav", "15", 0, 1e6, "SAH cost of a traversal step (Wald and Havran's K_T)"),
      ParamSpec::real("c_isect", "20", 1e-6, 1e6, "SAH cost of a primitive test (K_I)"),
      ParamSpec::real("empty_bonus", "0.2", 0, 1, "a split with an empty side costs (1 - empty_bonus) x its SAH cost"),
      spatial::kAssignParam,
      spatial::kMailboxParam},
     [](const Scene& s, const Params& p) {
         SahOptions o;
         o.build = common(p, s);
         o.c_trav = static_cast<float>(p.real("c_trav"));
         o.c_isect = static_cast<float>(p.real("c_isect"));
         o.empty_bonus = static_cast<float>(p.real("empty_bonus"));
         return std::make_unique<KdTree>(s, "kd-sah", build_sah(s, o), p.flag("mailbox"));
     },
     kLargeScene},  // O(N log^2 N) build: 17 s for a million triangles
    {{{}, kTestHits | kTestSampled | kTestSpdModel},
     {{"assign=exact", "mailbox=1"}, kTestHits}}};

}  // namespace
}  // namespace rtcost::kd
