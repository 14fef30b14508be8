// `octree`: the build, structure statistics, the model tree and the registration.
#include <fmt/format.h>

#include "octree.hpp"
#include "../common/tree_stats.hpp"

#include <algorithm>

namespace rtcost::octree {

Octree::Octree(const Scene& s, const Options& o) : HierarchyImpl(s), o_(o), root_(s.bounds()) {
    const bool empty = s.empty() || root_.empty();
    if (empty) root_ = Box3{{0, 0, 0}, {0, 0, 0}};
    const subdiv::Assigner as(s, o.assign);
    std::vector<std::uint32_t> refs = empty ? std::vector<std::uint32_t>{} : as.all();
    nodes_.emplace_back();
    build(0, root_, 0, refs, as);
    nodes_.shrink_to_fit();
    refs_.shrink_to_fit();
}

void Octree::make_leaf(std::uint32_t node, const std::vector<std::uint32_t>& refs) {
    Node& n = nodes_[node];
    n.is_leaf = 1;
    n.index = static_cast<std::uint32_t>(refs_.size());
    n.count = static_cast<std::uint32_t>(refs.size());
    refs_.insert(refs_.end(), refs.begin(), refs.end());
}

// Recursion depth is at most max_depth <= kMaxDepth.
void Octree::build(std::uint32_t node, const Box3& cell, int depth, std::vector<std::uint32_t>& refs,
                   const subdiv::Assigner& as) {
    if (refs.size() <= static_cast<std::size_t>(o_.max_prims) || depth >= o_.max_depth) return make_leaf(node, refs);
    if (refs_.size() >= subdiv::kMaxRefs || nodes_.size() >= subdiv::kMaxNodes) {
        capped_ = true;
        return make_leaf(node, refs);
    }
    const Vec3 c = subdiv::centre(cell);
    Box3 oct[8];
    for (int k = 0; k < 8; ++k) oct[k] = subdiv::octant(cell, c, k);
    std::vector<std::uint8_t> mask;
    std::array<std::size_t, 8> counts;
    as.masks(refs, oct, 8, mask, counts);
    if (subdiv::hardly_separates(counts, refs.size(), o_.growth)) return make_leaf(node, refs);
    if (o_.split_pays && !o_.split_pays(cell, refs.size(), oct, counts.data(), 8)) return make_leaf(node, refs);
    std::vector<std::uint32_t> child[8];
    for (int k = 0; k < 8; ++k) child[k] = subdiv::Assigner::select(refs, mask, k, counts[k]);
    std::vector<std::uint32_t>().swap(refs);  // free the parent's list before descending
    const std::uint32_t first = static_cast<std::uint32_t>(nodes_.size());
    nodes_.resize(nodes_.size() + 8);
    Node& n = nodes_[node];
    n.is_leaf = 0;
    n.center = c;
    n.index = first;
    n.count = 0;
    for (int k = 0; k < 8; ++k) build(first + k, oct[k], depth + 1, child[k], as);
}

StructureStats Octree::compute_structure() const {
    if (capped_) {
        StructureStats s = compute_tree();
        s.limits.push_back(fmt::format("octree: subdivision stopped at {} references or {} nodes (the memory bound); "
                                       "leaves below it hold more primitives than max_prims",
                                       subdiv::kMaxRefs, subdiv::kMaxNodes));
        return s;
    }
    return compute_tree();
}

StructureStats Octree::compute_tree() const {
    StructureStats s = tree_structure(nodes_, [](const Node& n) { return n.leaf(); }, [](const Node&) { return 8u; });
    s.bytes = nodes_.size() * sizeof(Node) + refs_.size() * sizeof(std::uint32_t);
    return s;
}

// The model's binary tree: an octree node is three binary levels at its centre, X, then Y, then
// Z. The X level carries the visit (one step, three plane compares); the Y and Z levels only
// carry regions and planes for the probabilities (no step, no operations). A Z-level node's
// children are the octants (x, y, 0) and (x, y, 1).
bool Octree::emit_model(ModelSink& sink) const {
    ModelFlags f(ModelFamily::Octree);
    f.locate = o_.locate;
    f.per_ray_box = 1;
    if (!sink.begin(f) || nodes_.empty()) return true;
    auto emit = [&](auto&& self, std::uint32_t i, const Box3& region) -> void {
        const Node& n = nodes_[i];
        ModelNode m;
        m.region = region;
        m.step = true;
        if (n.leaf()) {
            m.count = n.count;
            sink.node(m, std::span<const std::uint32_t>(refs_).subspan(n.index, n.count));
            return;
        }
        m.leaf = false;
        m.count = 2;
        m.axis = 0;
        m.split = n.center.x;
        m.plane = 3;
        sink.node(m, {});
        for (int xi = 0; xi < 2; ++xi) {
            ModelNode y;
            y.region = subdiv::half(region, 0, n.center.x, xi);
            y.leaf = false;
            y.axis = 1;
            y.split = n.center.y;
            y.count = 2;
            y.step = false;
            sink.node(y, {});
            for (int yi = 0; yi < 2; ++yi) {
                ModelNode z;
                z.region = subdiv::half(y.region, 1, n.center.y, yi);
                z.leaf = false;
                z.axis = 2;
                z.split = n.center.z;
                z.count = 2;
                z.step = false;
                sink.node(z, {});
                for (int zi = 0; zi < 2; ++zi)
                    self(self, n.index + static_cast<std::uint32_t>(xi | yi << 1 | zi << 2),
                         subdiv::half(z.region, 2, n.center.z, zi));
            }
        }
    };
    emit(emit, 0, root_);
    return true;
}

namespace {

const Registration reg{
    {"octree",
     "Glassner's octree: eight children at the centre",
     subdiv::param_specs(8, kMaxDepth, 1),
     [](const Scene& s, const Params& p) {
         return std::make_unique<Octree>(s, subdiv::read_options<Options>(p));
     }},
    {{{}, kTestHits | kTestSampled | kTestSpdModel | kTestSubdivision},
     {{"traversal=recursive", "max_prims=4"}, kTestHits},
     {{"traversal=recursive", "max_prims=2"}, kTestSampled},
     {{"traversal=recursive"}, kTestSubdivision},
     {{"assign=exact", "mailbox=1"}, kTestSubdivision},
     {{"traversal=recursive", "max_prims=4", "mailbox=1"}, kTestSubdivision},
     {{"max_depth=0"}, kTestSubdivision},
     {{"max_depth=0", "traversal=recursive"}, kTestSubdivision},
     {{"max_depth=10", "max_prims=2"}, kTestSubdivision}}};

}  // namespace
}  // namespace rtcost::octree
