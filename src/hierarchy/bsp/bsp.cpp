// `bsp`: the build, structure statistics, the model tree and the registration.
#include <fmt/format.h>

#include "bsp.hpp"
#include "../common/tree_stats.hpp"

#include <algorithm>

namespace rtcost::bsp {

Bsp::Bsp(const Scene& s, const Options& o) : HierarchyImpl(s), o_(o), root_(s.bounds()) {
    const bool empty = s.empty() || root_.empty();
    if (empty) root_ = Box3{{0, 0, 0}, {0, 0, 0}};
    const subdiv::Assigner as(s, o.assign);
    std::vector<std::uint32_t> refs = empty ? std::vector<std::uint32_t>{} : as.all();
    nodes_.emplace_back();
    build(0, root_, 0, refs, as);
    nodes_.shrink_to_fit();
    refs_.shrink_to_fit();
}

void Bsp::make_leaf(std::uint32_t node, const std::vector<std::uint32_t>& refs) {
    Node& n = nodes_[node];
    n.axis = 3;
    n.index = static_cast<std::uint32_t>(refs_.size());
    n.count = static_cast<std::uint32_t>(refs.size());
    refs_.insert(refs_.end(), refs.begin(), refs.end());
}

// Recursion depth is at most max_depth <= kMaxDepth.
void Bsp::build(std::uint32_t node, const Box3& cell, int depth, std::vector<std::uint32_t>& refs,
                const subdiv::Assigner& as) {
    if (refs.size() <= static_cast<std::size_t>(o_.max_prims) || depth >= o_.max_depth) return make_leaf(node, refs);
    if (refs_.size() >= subdiv::kMaxRefs || nodes_.size() >= subdiv::kMaxNodes) {
        capped_ = true;
        return make_leaf(node, refs);
    }
    // At the top of each block of three levels (X, Y, Z: the block ends in the cell's octants,
    // the very cells an octree node makes), the growth guard: the references straddle so much
    // that the block would hardly separate them.
    if (depth % 3 == 0 && o_.growth < 9) {
        Box3 oct[8];
        const Vec3 c = subdiv::centre(cell);
        for (int k = 0; k < 8; ++k) oct[k] = subdiv::octant(cell, c, k);
        std::vector<std::uint8_t> omask;
        std::array<std::size_t, 8> ocounts;
        as.masks(refs, oct, 8, omask, ocounts);
        if (subdiv::hardly_separates(ocounts, refs.size(), o_.growth)) return make_leaf(node, refs);
    }
    const int a = depth % 3;
    const float s = subdiv::mid(cell.lo[a], cell.hi[a]);
    const Box3 halves[2] = {subdiv::half(cell, a, s, 0), subdiv::half(cell, a, s, 1)};
    std::vector<std::uint8_t> mask;
    std::array<std::size_t, 8> counts;
    as.masks(refs, halves, 2, mask, counts);
    if (o_.split_pays && !o_.split_pays(cell, refs.size(), halves, counts.data(), 2)) return make_leaf(node, refs);
    std::vector<std::uint32_t> lo = subdiv::Assigner::select(refs, mask, 0, counts[0]);
    std::vector<std::uint32_t> hi = subdiv::Assigner::select(refs, mask, 1, counts[1]);
    std::vector<std::uint32_t>().swap(refs);  // free the parent's list before descending
    const std::uint32_t first = static_cast<std::uint32_t>(nodes_.size());
    nodes_.resize(nodes_.size() + 2);
    Node& n = nodes_[node];
    n.axis = static_cast<std::uint32_t>(a);
    n.split = s;
    n.index = first;
    n.count = 0;
    build(first, halves[0], depth + 1, lo, as);
    build(first + 1, halves[1], depth + 1, hi, as);
}

StructureStats Bsp::compute_structure() const {
    if (capped_) {
        StructureStats s = compute_tree();
        s.limits.push_back(fmt::format("bsp: subdivision stopped at {} references or {} nodes (the memory bound); "
                                       "leaves below it hold more primitives than max_prims",
                                       subdiv::kMaxRefs, subdiv::kMaxNodes));
        return s;
    }
    return compute_tree();
}

StructureStats Bsp::compute_tree() const {
    StructureStats s = tree_structure(nodes_, [](const Node& n) { return n.leaf(); }, [](const Node&) { return 2u; });
    s.bytes = nodes_.size() * sizeof(Node) + refs_.size() * sizeof(std::uint32_t);
    return s;
}

// One model node per BSP node (same indices): a visit costs one plane compare and is one step;
// with `locate` the model charges every leaf visit its whole descent again.
bool Bsp::emit_model(ModelSink& sink) const {
    ModelFlags f(ModelFamily::Bsp);
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
        const int a = static_cast<int>(n.axis);
        m.leaf = false;
        m.count = 2;
        m.axis = static_cast<std::int8_t>(a);
        m.split = n.split;
        m.plane = 1;
        sink.node(m, {});
        for (int side = 0; side < 2; ++side) self(self, n.index + side, subdiv::half(region, a, n.split, side));
    };
    emit(emit, 0, root_);
    return true;
}

namespace {

const Registration reg{
    {"bsp",
     "Kaplan's BSP tree: binary, spatial mid-plane, axes X, Y, Z in turn",
     subdiv::param_specs(20, kMaxDepth, 2),
     [](const Scene& s, const Params& p) {
         return std::make_unique<Bsp>(s, subdiv::read_options<Options>(p));
     }},
    {{{}, kTestHits | kTestSampled | kTestSpdModel | kTestSubdivision},
     {{"traversal=recursive", "assign=exact", "mailbox=1"}, kTestHits | kTestSubdivision},
     {{"traversal=recursive"}, kTestSampled | kTestSubdivision},
     {{"assign=exact", "mailbox=1"}, kTestSubdivision},
     {{"max_depth=0"}, kTestSubdivision},
     {{"max_depth=0", "traversal=recursive"}, kTestSubdivision},
     {{"max_prims=1", "max_depth=30", "growth=7"}, kTestSubdivision}}};

}  // namespace
}  // namespace rtcost::bsp
