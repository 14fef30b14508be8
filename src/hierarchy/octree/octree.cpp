// `octree`: the build, structure statistics, the model tree and the registration.
#include "octree.hpp"

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
    if (refs.size() <= static_cast<std::size_t>(o_.max_prims) || depth >= o_.max_depth ||
        refs_.size() >= subdiv::kMaxRefs || nodes_.size() >= subdiv::kMaxNodes)
        return make_leaf(node, refs);
    const Vec3 c = subdiv::centre(cell);
    Box3 oct[8];
    for (int k = 0; k < 8; ++k) oct[k] = subdiv::octant(cell, c, k);
    std::vector<std::uint8_t> mask;
    std::array<std::size_t, 8> counts;
    as.masks(refs, oct, 8, mask, counts);
    if (subdiv::hardly_separates(counts, refs.size(), o_.growth)) return make_leaf(node, refs);
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
    StructureStats s;
    std::vector<int> depth(nodes_.size(), 0);  // children always follow their parent
    for (std::size_t i = 0; i < nodes_.size(); ++i) {
        const Node& n = nodes_[i];
        if (n.leaf()) {
            ++s.leaves;
            s.empty_leaves += n.count == 0;
            s.references += n.count;
            s.depth = std::max(s.depth, depth[i]);
        } else {
            ++s.interior;
            for (int k = 0; k < 8; ++k) depth[n.index + k] = depth[i] + 1;
        }
    }
    s.bytes = nodes_.size() * sizeof(Node) + refs_.size() * sizeof(std::uint32_t);
    return s;
}

// The model's binary tree: an octree node is three binary levels at its centre, X, then Y, then
// Z. The X level carries the visit (one step, three plane compares); the Y and Z levels only
// carry regions and planes for the probabilities (no step, no operations). A Z-level node's
// children are the octants (x, y, 0) and (x, y, 1).
ModelTree Octree::model_tree() const {
    ModelTree t;
    t.family = "octree";
    t.locate = o_.locate;
    t.per_ray_box = 1;
    t.prims = refs_;
    struct Work {
        std::uint32_t octree, model;
    };
    std::vector<Work> work{{0, 0}};
    // Fourteen model nodes per interior node: reserved, so that millions are not copied as the tree grows.
    std::size_t interior = 0;
    for (const Node& n : nodes_) interior += !n.leaf();
    t.nodes.reserve(1 + 14 * interior);
    t.nodes.emplace_back();
    t.nodes[0].region = root_;
    // Depth first; every node's children are allocated before any of them is expanded, so a
    // child's index is always greater than its parent's.
    while (!work.empty()) {
        const Work w = work.back();
        work.pop_back();
        const Node& n = nodes_[w.octree];
        if (n.leaf()) {
            ModelNode& m = t.nodes[w.model];
            m.leaf = true;
            m.step = true;
            m.first = n.index;
            m.count = n.count;
            continue;
        }
        const std::uint32_t ys = static_cast<std::uint32_t>(t.nodes.size());
        const std::uint32_t zs = ys + 2, os = ys + 6;
        t.nodes.resize(t.nodes.size() + 14);
        ModelNode& x = t.nodes[w.model];
        x.leaf = false;
        x.axis = 0;
        x.split = n.center.x;
        x.first = ys;
        x.count = 2;
        x.step = true;
        x.plane = 3;
        const Box3 region = x.region;
        const int depth = x.depth;
        for (int xi = 0; xi < 2; ++xi) {
            ModelNode& y = t.nodes[ys + xi];
            y.region = subdiv::half(region, 0, n.center.x, xi);
            y.depth = depth + 1;
            y.leaf = false;
            y.axis = 1;
            y.split = n.center.y;
            y.first = zs + 2 * xi;
            y.count = 2;
            y.step = false;
            for (int yi = 0; yi < 2; ++yi) {
                ModelNode& z = t.nodes[zs + 2 * xi + yi];
                z.region = subdiv::half(y.region, 1, n.center.y, yi);
                z.depth = depth + 2;
                z.leaf = false;
                z.axis = 2;
                z.split = n.center.z;
                z.first = os + 4 * xi + 2 * yi;
                z.count = 2;
                z.step = false;
                for (int zi = 0; zi < 2; ++zi) {
                    const std::uint32_t mo = z.first + zi;
                    ModelNode& o = t.nodes[mo];
                    o.region = subdiv::half(z.region, 2, n.center.z, zi);
                    o.depth = depth + 3;
                    work.push_back({n.index + static_cast<std::uint32_t>(xi | yi << 1 | zi << 2), mo});
                }
            }
        }
    }
    return t;
}

namespace {

const Registration reg{
    {"octree",
     "Glassner's octree: eight children at the centre",
     subdiv::param_specs(8, kMaxDepth, 1),
     [](const Scene& s, const Params& p) {
         return std::make_unique<Octree>(s, subdiv::read_options<Options>(p, kMaxDepth));
     }}};

}  // namespace
}  // namespace rtcost::octree
