// BVH family: structure statistics, the model-tree walk and the registrations of the three
// builders.
#include "bvh.hpp"
#include "../common/tree_stats.hpp"

namespace rtcost::bvh {

PrimInfo::PrimInfo(const Scene& s) : bounds(s.size()), centroids(s.size()) {
    for (std::uint32_t i = 0; i < s.size(); ++i) {
        bounds[i] = s.prim_bounds(i);
        centroids[i] = bounds[i].center();
    }
}

Bvh::Bvh(const Scene& s, std::string name, BvhData data, bool ordered)
    : HierarchyImpl(s), name_(std::move(name)), d_(std::move(data)), ordered_(ordered), prims_(leaf_prims(s, d_.refs)),
      has_triangles_(std::any_of(prims_.begin(), prims_.end(), [](const LeafPrim& p) { return p.kind == PrimKind::Triangle; })) {
    // The leaves in leaf order (their references' order), so that their packs keep it.
    std::vector<std::uint32_t> leaves;
    for (std::uint32_t i = 0; i < d_.nodes.size(); ++i)
        if (d_.nodes[i].leaf) leaves.push_back(i);
    std::stable_sort(leaves.begin(), leaves.end(),
                     [&](std::uint32_t a, std::uint32_t b) { return d_.nodes[a].index < d_.nodes[b].index; });
    std::vector<std::pair<std::uint32_t, std::uint32_t>> ranges;
    ranges.reserve(leaves.size());
    for (std::uint32_t i : leaves) ranges.push_back({d_.nodes[i].index, std::uint32_t(d_.nodes[i].count)});
    const std::vector<std::uint32_t> lanes = packs_.pack(prims_, ranges);
    if (!packs_.active()) return;
    prims_ = {};  // the packs hold every reference
    walk_nodes_ = d_.nodes;
    for (std::size_t k = 0; k < leaves.size(); ++k) walk_nodes_[leaves[k]].index = lanes[k];
}

StructureStats Bvh::compute_structure() const {
    StructureStats s = tree_structure(
        d_.nodes, [](const Node& n) { return n.leaf != 0; }, [](const Node& n) { return std::uint32_t(n.count); });
    s.bytes = (d_.nodes.size() + walk_nodes_.size()) * sizeof(Node) + d_.refs.size() * sizeof(std::uint32_t) +
              prims_.size() * sizeof(LeafPrim) + packs_.bytes();
    s.limits = d_.limits;
    // A binary node's two boxes are tested at once (pair_entry); a wider node's one by one.
    s.box_lanes = std::all_of(d_.nodes.begin(), d_.nodes.end(), [](const Node& n) { return n.leaf || n.count == 2; }) ? 2 : 1;
    return s;
}

bool Bvh::emit_model_ordered(ModelSink& sink, std::span<const std::uint8_t> any_order) const {
    ModelFlags f(ModelFamily::Bvh, {.entered_box = 1});  // the paper: a box test per node entered
    f.cull = ordered_;
    f.cull_widened = ordered_;
    if (ordered_) f.occlusion_order = occlusion_;
    if (!sink.begin(f) || d_.nodes.empty()) return true;
    // Every builder lays leaves' references out depth first: a subtree's run of refs starts at
    // its leftmost leaf and ends with its rightmost.
    const bool runs = sink.leaf_order(d_.refs);
    auto emit = [&](auto&& self, std::uint32_t i) -> void {
        const Node& n = d_.nodes[i];
        if (runs) {
            std::uint32_t lo = i, hi = i;
            while (!d_.nodes[lo].leaf) lo = d_.nodes[lo].index;
            while (!d_.nodes[hi].leaf) hi = d_.nodes[hi].index + d_.nodes[hi].count - 1;
            sink.subtree(d_.nodes[lo].index, d_.nodes[hi].index + d_.nodes[hi].count);
        }
        ModelNode m;
        m.region = n.box;
        m.has_bv = true;
        m.bv = n.box;
        m.box = n.leaf ? 0.0f : static_cast<float>(n.count);  // a visit tests every child's box
        m.count = n.count;
        m.leaf = n.leaf;
        if (!n.leaf && n.count == 2 && !any_order.empty()) m.any_order = any_order[i] | kAnyOrderSet;
        if (n.leaf) {
            sink.node(m, std::span<const std::uint32_t>(d_.refs).subspan(n.index, n.count));
            return;
        }
        sink.node(m, {});
        if (sink.skip_children()) return;
        for (std::uint32_t k = 0; k < n.count; ++k) self(self, n.index + k);
    };
    emit(emit, 0);
    return true;
}

namespace {

// The traversal order the `order` parameter asks for, set on the built hierarchy.
std::unique_ptr<Bvh> ordered(const Scene& s, const char* name, BvhData data, const Params& p) {
    auto h = std::make_unique<Bvh>(s, name, std::move(data), !p.is("order", "none"));
    const bool leaves = p.is("order", "leaves") || p.is("any_order", "leaves");
    h->set_occlusion_order(leaves                         ? OcclusionOrder::LeavesFirst
                           : p.is("any_order", "stored") ? OcclusionOrder::Stored
                                                         : OcclusionOrder::AsClosest);
    return h;
}

const ParamSpec kOrder = ParamSpec::choice("order", "near", {"near", "leaves", "none"},
                                           "near: near child first, far child skipped beyond the current hit; "
                                           "leaves: as near, but occlusion queries enter leaf children first "
                                           "(any_order=leaves); none: every child met is visited, in stored order "
                                           "(the paper's BVH case)");
const ParamSpec kAnyOrder = ParamSpec::choice("any_order", "stored", {"stored", "nearest", "leaves"},
                                              "order of the children met in occlusion (any-hit) queries: stored "
                                              "(first child first, unsorted), nearest (as closest-hit queries), or "
                                              "leaves (leaf children first, then nearest)");
constexpr long long kMaxLeaf = 1 << 20;

const Registration median_reg{
    {"bvh-median",
     "Kay and Kajiya's BVH: object median cut on the longest axis",
     {ParamSpec::integer("max_prims", "1", 1, kMaxLeaf, "largest leaf"),
      ParamSpec::integer("max_depth", "64", 0, kMaxDepth, "deepest leaf (root at 0)"), kOrder, kAnyOrder},
     [](const Scene& s, const Params& p) {
         MedianOptions o;
         o.max_prims = static_cast<int>(p.integer("max_prims"));
         o.max_depth = static_cast<int>(p.integer("max_depth"));
         return ordered(s, "bvh-median", build_median(s, o), p);
     }},
    {{{}, kTestHits | kTestSampled | kTestSpdModel},
     {{"order=none"}, kTestHits}}};

const Registration gs_reg{
    {"bvh-gs",
     "Goldsmith and Salmon's BVH: incremental insertion minimising surface-area cost",
     {ParamSpec::integer("max_prims", "1", 1, kMaxLeaf, "largest leaf (1: one object per leaf, as in the original)"),
      ParamSpec::integer("max_depth", "64", 1, kMaxDepth, "deepest node"),
      ParamSpec::integer("max_children", "8", 2, kMaxFanout, "largest fan-out of a node"),
      ParamSpec::integer("seed", "1", 0, 1LL << 62,
                         "insertion order: shuffled with this seed; 0 = file order (which degenerates on "
                         "meshes stored row by row)"),
      kOrder, kAnyOrder},
     [](const Scene& s, const Params& p) {
         GsOptions o;
         o.max_prims = static_cast<int>(p.integer("max_prims"));
         o.max_depth = static_cast<int>(p.integer("max_depth"));
         o.max_children = static_cast<int>(p.integer("max_children"));
         o.seed = static_cast<std::uint64_t>(p.integer("seed"));
         return ordered(s, "bvh-gs", build_gs(s, o), p);
     },
     kLargeScene},  // insertion from the root, one object at a time: 10 s for a million
    {{{}, kTestHits | kTestSampled | kTestSpdModel},
     {{"seed=0"}, kTestHits},
     {{"seed=7", "max_prims=3"}, kTestHits},
     {{"seed=3", "max_children=6", "order=leaves"}, kTestHits | kTestSampled}}};

const Registration sah_reg{
    {"bvh-sah",
     "binned SAH BVH (Wald 2007); sweep=1 for the full sweep",
     {ParamSpec::integer("max_prims", "auto", 1, kMaxLeaf,
                         "largest leaf (bigger nodes are always split); auto: 16 on a mesh of at least 65,536 "
                         "triangles (tested four at a time), else 8",
                         {"auto"}),
      ParamSpec::integer("max_depth", "64", 0, kMaxDepth, "deepest leaf"),
      ParamSpec::integer("bins", "16", 2, 256, "bins per axis for the binned build"),
      ParamSpec::flag("sweep", "0", "1: evaluate every split of the sorted centroids (full sweep SAH)"),
      ParamSpec::real("c_trav", "auto", 0, 1e6,
                      "SAH cost of a traversal step; auto: 4 on a mesh of at least 65,536 triangles (its "
                      "tree outgrows the cache), else 1",
                      {"auto"}),
      ParamSpec::real("c_isect", "1", 1e-6, 1e6, "SAH cost of a primitive test"),
      kOrder, kAnyOrder},
     [](const Scene& s, const Params& p) {
         SahOptions o = sah_leaf_costs(s);
         if (!p.is("max_prims", "auto")) o.max_prims = static_cast<int>(p.integer("max_prims"));
         o.max_depth = static_cast<int>(p.integer("max_depth"));
         o.bins = static_cast<int>(p.integer("bins"));
         o.sweep = p.flag("sweep");
         if (!p.is("c_trav", "auto")) o.c_trav = static_cast<float>(p.real("c_trav"));
         o.c_isect = static_cast<float>(p.real("c_isect"));
         return ordered(s, "bvh-sah", build_sah(s, o), p);
     }},
    {{{}, kTestHits | kTestSampled | kTestSpdModel},
     {{"sweep=1", "order=none"}, kTestHits},
     {{"order=leaves"}, kTestHits | kTestSampled},
     {{"any_order=nearest"}, kTestHits | kTestSampled},
     {{"order=none"}, kTestSampled}}};

}  // namespace
}  // namespace rtcost::bvh
