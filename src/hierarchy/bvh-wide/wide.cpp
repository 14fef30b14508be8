// bvh-wide: collapsing the binned SAH tree into 4- or 8-wide nodes, the model tree, structural
// statistics and the registration.
#include "wide.hpp"

#include "../bvh/bvh.hpp"
#include "rtcost/error.hpp"

namespace rtcost::wide {

struct BvhWide::Data {
    int width = 8;
    std::vector<Node<4>> n4;
    std::vector<Node<8>> n8;
    Box3 root_box;
    std::uint32_t root_count = 0;
    int tri_lanes = 4;
    OcclusionOrder any_order = OcclusionOrder::AsClosest;
    struct alignas(kLeafAlign) Block {
        std::byte b[kLeafAlign];
    };
    std::vector<Block> leaves;  // the leaf arena (View::leaves)
};

namespace {

/// The binary nodes that become the lanes of one wide node: starting from binary node `i`'s
/// children, the interior lane of largest surface area is replaced by its two children until
/// `W` lanes are used or every lane is a leaf. Lanes keep the binary tree's left-to-right order.
template <int W>
int lanes_of(const bvh::BvhData& bd, std::uint32_t i, std::uint32_t (&lanes)[W]) {
    const bvh::Node& n = bd.nodes[i];
    if (n.leaf) {
        lanes[0] = i;  // only the root can be a leaf: a wide root with one leaf lane
        return 1;
    }
    int k = 0;
    for (std::uint32_t c = 0; c < n.count; ++c) lanes[k++] = n.index + c;
    while (k < W) {
        int best = -1;
        float best_area = -1;
        for (int j = 0; j < k; ++j) {
            const bvh::Node& c = bd.nodes[lanes[j]];
            if (!c.leaf && c.box.area() > best_area && k - 1 + static_cast<int>(c.count) <= W) {
                best = j;
                best_area = c.box.area();
            }
        }
        if (best < 0) break;
        const bvh::Node& c = bd.nodes[lanes[best]];
        const int add = static_cast<int>(c.count);
        for (int j = k - 1; j > best; --j) lanes[j + add - 1] = lanes[j];
        for (int a = 0; a < add; ++a) lanes[best + a] = c.index + static_cast<std::uint32_t>(a);
        k += add - 1;
    }
    return k;
}

template <int W>
std::uint32_t collapse(const bvh::BvhData& bd, std::vector<Node<W>>& out) {
    std::uint32_t root_lanes[W];
    const int root_count = lanes_of<W>(bd, 0, root_lanes);
    out.reserve(bd.nodes.size() / 2 + 1);
    out.emplace_back();
    auto fill = [&](auto&& self, std::uint32_t wide, const std::uint32_t* lanes, int count) -> void {
        std::uint32_t sub[W][W];
        int sub_count[W] = {};
        std::uint32_t sub_node[W] = {};
        Node<W> node;
        for (int k = 0; k < W; ++k) {
            for (int a = 0; a < 3; ++a) {
                node.b[2 * a][k] = kInf;
                node.b[2 * a + 1][k] = -kInf;
            }
            node.child[k] = kEmpty;
            node.count[k] = 0;
        }
        for (int k = 0; k < count; ++k) {
            const bvh::Node& c = bd.nodes[lanes[k]];
            for (int a = 0; a < 3; ++a) {
                node.b[2 * a][k] = c.box.lo[a];
                node.b[2 * a + 1][k] = c.box.hi[a];
            }
            if (c.leaf) {
                node.child[k] = kLeaf | c.index;
                node.count[k] = c.count;
            } else {
                sub_count[k] = lanes_of<W>(bd, lanes[k], sub[k]);
                sub_node[k] = static_cast<std::uint32_t>(out.size());
                out.emplace_back();
                node.child[k] = sub_node[k];
                node.count[k] = static_cast<std::uint32_t>(sub_count[k]);
            }
        }
        out[wide] = node;
        for (int k = 0; k < count; ++k)
            if (sub_count[k] > 0) self(self, sub_node[k], sub[k], sub_count[k]);
    };
    fill(fill, 0, root_lanes, root_count);
    out.shrink_to_fit();
    return static_cast<std::uint32_t>(root_count);
}

/// Triangle `id` as a pack stores it; false for other primitives (Scene::add_polygon stores a
/// polygon of three vertices as a triangle).
bool pack_triangle(const Scene& s, std::uint32_t id, Triangle& t) {
    const PrimRef& r = s.prims[id];
    if (r.kind != PrimKind::Triangle) return false;
    t = s.triangles[r.index];
    return true;
}

/// Appends a leaf to the arena: `tris` K to a pack, then `others`. Sets the lane's `child` and
/// `count` as View describes.
template <int K>
void append_packs(std::vector<BvhWide::Data::Block>& arena, const Scene& s, const std::vector<std::uint32_t>& tris,
                  const std::vector<std::uint32_t>& others, std::uint32_t& child, std::uint32_t& count) {
    const std::size_t packs = (tris.size() + K - 1) / K;
    const std::size_t bytes = packs * sizeof(TriPack<K>) + others.size() * sizeof(Other);
    const std::size_t offset = arena.size();
    if (offset >= kLeaf) throw InputError("bvh-wide", 0, "too many leaves");
    arena.resize(offset + (bytes + kLeafAlign - 1) / kLeafAlign);
    auto* pk = reinterpret_cast<TriPack<K>*>(arena.data() + offset);
    Triangle t;
    for (std::size_t p = 0; p < packs; ++p) {
        TriPack<K>& q = *new (pk + p) TriPack<K>{};
        for (int l = 0; l < K && p * K + l < tris.size(); ++l) {
            const std::uint32_t id = tris[p * K + l];
            pack_triangle(s, id, t);
            const Vec3 v[3] = {t.v0, t.v1, t.v2};
            for (int i = 0; i < 3; ++i)
                for (int a = 0; a < 3; ++a) q.v[3 * i + a][l] = v[i][a];
            q.id[l] = id;
        }
    }
    auto* o = reinterpret_cast<Other*>(pk + packs);
    for (std::size_t k = 0; k < others.size(); ++k) new (o + k) Other{others[k], s.kind(others[k])};
    child = kLeaf | static_cast<std::uint32_t>(offset);
    count = static_cast<std::uint32_t>(tris.size()) | static_cast<std::uint32_t>(others.size()) << 16;
}

/// Appends the leaf over `ids` to the arena: its triangles in packs (pack_lanes, wide.hpp), then its
/// other primitives.
template <int K>
void append_leaf(std::vector<BvhWide::Data::Block>& arena, const Scene& s, std::span<const std::uint32_t> ids,
                 std::uint32_t& child, std::uint32_t& count) {
    // Reused from leaf to leaf: a build appends some 100,000 leaves.
    thread_local std::vector<std::uint32_t> tris, others;
    tris.clear(), others.clear();
    Triangle t;
    for (std::uint32_t id : ids) (pack_triangle(s, id, t) ? tris : others).push_back(id);
    if (tris.size() > 0xffff || others.size() > 0xffff)
        throw InputError("bvh-wide", 0, "a leaf of more than 65535 primitives of one kind");
    if (pack_lanes(K, static_cast<std::uint32_t>(tris.size())) == 4) append_packs<4>(arena, s, tris, others, child, count);
    else append_packs<K>(arena, s, tris, others, child, count);
}

/// A leaf's ids read back from packs of `K`.
template <int K>
void read_leaf(const std::byte* at, std::uint32_t ntri, std::uint32_t nother, std::vector<std::uint32_t>& ids) {
    const auto* pk = reinterpret_cast<const TriPack<K>*>(at);
    for (std::uint32_t i = 0; i < ntri; ++i) ids.push_back(pk[i / K].id[i % K]);
    const auto* o = reinterpret_cast<const Other*>(pk + (ntri + K - 1) / K);
    for (std::uint32_t k = 0; k < nother; ++k) ids.push_back(o[k].id);
}

/// The primitive ids of a leaf lane, read back from the arena into `ids` (cleared first: one
/// buffer serves a whole emission).
template <int K>
void leaf_ids(const BvhWide::Data& d, std::uint32_t child, std::uint32_t count, std::vector<std::uint32_t>& ids) {
    ids.clear();
    const std::uint32_t ntri = count & 0xffffu, nother = count >> 16;
    const auto* at = reinterpret_cast<const std::byte*>(d.leaves.data() + (child & ~kLeaf));
    if (pack_lanes(K, ntri) == 4) read_leaf<4>(at, ntri, nother, ids);
    else read_leaf<K>(at, ntri, nother, ids);
}

/// Depth-first walk over the lanes: `leaf(box, first, packed counts, depth)` and
/// `interior(box, children, depth)`, which says whether to walk into the node.
template <int W, class Leaf, class Interior>
void walk_lanes(const std::vector<Node<W>>& nodes, Leaf&& leaf, Interior&& interior) {
    auto rec = [&](auto&& self, std::uint32_t i, int depth) -> void {
        const Node<W>& n = nodes[i];
        for (int k = 0; k < W && n.child[k] != kEmpty; ++k) {
            Box3 box{{n.b[0][k], n.b[2][k], n.b[4][k]}, {n.b[1][k], n.b[3][k], n.b[5][k]}};
            if (n.child[k] & kLeaf) {
                leaf(box, n.child[k] & ~kLeaf, n.count[k], depth + 1);
            } else {
                if (interior(box, n.count[k], depth + 1)) self(self, n.child[k], depth + 1);
            }
        }
    };
    if (!nodes.empty()) rec(rec, 0, 0);
}

/// Moves every leaf lane's primitives (refs of the binary tree) into the arena, depth first, so
/// that leaves lie in the order the traversal meets them.
template <int W, int K>
void pack_leaves(BvhWide::Data& d, std::vector<Node<W>>& nodes, const bvh::BvhData& bd, const Scene& s) {
    auto rec = [&](auto&& self, std::uint32_t i) -> void {
        for (int k = 0; k < W && nodes[i].child[k] != kEmpty; ++k) {
            const std::uint32_t c = nodes[i].child[k];
            if (c & kLeaf) {
                const std::span<const std::uint32_t> ids(bd.refs.data() + (c & ~kLeaf), nodes[i].count[k]);
                append_leaf<K>(d.leaves, s, ids, nodes[i].child[k], nodes[i].count[k]);
            } else {
                self(self, c);
            }
        }
    };
    if (!nodes.empty()) rec(rec, 0);
}

template <class F>
void with_nodes(const BvhWide::Data& d, F&& f) {
    if (d.width == 8) f(d.n8);
    else f(d.n4);
}

}  // namespace

BvhWide::BvhWide(const Scene& s, std::unique_ptr<Data> d, Walks walks)
    : HierarchyImpl(s), d_(std::move(d)), walks_(walks) {
    view_.width = d_->width;
    view_.nodes = d_->width == 8 ? static_cast<const void*>(d_->n8.data()) : static_cast<const void*>(d_->n4.data());
    view_.root_box = d_->root_box;
    view_.root_count = d_->root_count;
    view_.leaves = reinterpret_cast<const std::byte*>(d_->leaves.data());
    view_.tri_lanes = d_->tri_lanes;
    view_.scene = &s;
    view_.any_order = d_->any_order;
}

BvhWide::~BvhWide() = default;

StructureStats BvhWide::compute_structure() const {
    StructureStats s;
    with_nodes(*d_, [&](const auto& nodes) {
        s.interior = nodes.size();
        walk_lanes(
            nodes,
            [&](const Box3&, std::uint32_t, std::uint32_t packed, int depth) {
                const std::uint32_t n = (packed & 0xffffu) + (packed >> 16);
                ++s.leaves;
                s.empty_leaves += n == 0;
                s.references += n;
                s.depth = std::max(s.depth, depth);
            },
            [](const Box3&, std::uint32_t, int) { return true; });
        s.bytes = nodes.size() * sizeof(nodes[0]);
    });
    s.bytes += d_->leaves.size() * sizeof(Data::Block);
    s.box_lanes = view_.width;  // one slab test for all of a node's children
    return s;
}

bool BvhWide::emit_model(ModelSink& sink) const {
    ModelFlags f(ModelFamily::Bvh, {.entered_box = 1});  // the paper: a box test per node entered
    f.cull_widened = true;
    f.occlusion_order = d_->any_order;
    if (!sink.begin(f) || d_->root_count == 0) return true;
    ModelNode root;
    root.region = root.bv = d_->root_box;
    root.has_bv = true;
    root.box = static_cast<float>(d_->root_count);  // a visit tests every child's box
    root.count = d_->root_count;
    root.leaf = false;
    sink.node(root, {});
    if (sink.skip_children()) return true;
    std::vector<std::uint32_t> ids;
    with_nodes(*d_, [&](const auto& nodes) {
        walk_lanes(
            nodes,
            [&](const Box3& box, std::uint32_t child, std::uint32_t packed, int) {
                if (d_->tri_lanes == 8) leaf_ids<8>(*d_, child, packed, ids);
                else leaf_ids<4>(*d_, child, packed, ids);
                ModelNode m;
                m.region = m.bv = box;
                m.has_bv = true;
                m.count = static_cast<std::uint32_t>(ids.size());
                m.leaf = true;
                sink.node(m, ids);
            },
            [&](const Box3& box, std::uint32_t n, int) {
                ModelNode m;
                m.region = m.bv = box;
                m.has_bv = true;
                m.box = static_cast<float>(n);
                m.count = n;
                m.leaf = false;
                sink.node(m, {});
                return !sink.skip_children();
            });
    });
    return true;
}

namespace {

std::unique_ptr<Hierarchy> build(const Scene& s, const Params& p) {
    const bool avx2 = cpu_has_avx2();
    const std::string& simd = p.str("simd");
    if (simd == "avx2" && !avx2) throw InputError("bvh-wide", 0, "simd=avx2: this CPU does not run AVX2");
    const bool use_avx2 = avx2 && simd != "baseline";
    if (p.is("tri_lanes", "8") && !use_avx2)
        throw InputError("bvh-wide", 0, "tri_lanes=8: packs of eight are tested with AVX2 only (here: simd=baseline or a CPU without it)");
    const std::string& w = p.str("width");
    auto d = std::make_unique<BvhWide::Data>();
    d->width = w == "4" ? 4 : w == "8" ? 8 : (use_avx2 ? 8 : 4);
    bvh::SahOptions o;
    o.max_prims = static_cast<int>(p.integer("max_prims"));
    o.bins = static_cast<int>(p.integer("bins"));
    o.c_trav = static_cast<float>(p.real("c_trav"));
    o.max_depth = 64;  // bvh-sah's default; the wide tree is never deeper
    bvh::BvhData bd = bvh::build_sah(s, o);
    if (!s.empty()) {
        d->root_box = bd.nodes[0].box;
        d->root_count = d->width == 8 ? collapse<8>(bd, d->n8) : collapse<4>(bd, d->n4);
    }
    d->tri_lanes = use_avx2 && !p.is("tri_lanes", "4") ? 8 : 4;
    const std::string& ao = p.str("any_order");
    d->any_order = ao == "nearest"  ? OcclusionOrder::AsClosest
                   : ao == "leaves" ? OcclusionOrder::LeavesFirst
                                    : OcclusionOrder::Stored;
    if (d->width == 8) {
        if (d->tri_lanes == 8) pack_leaves<8, 8>(*d, d->n8, bd, s);
        else pack_leaves<8, 4>(*d, d->n8, bd, s);
    } else {
        if (d->tri_lanes == 8) pack_leaves<4, 8>(*d, d->n4, bd, s);
        else pack_leaves<4, 4>(*d, d->n4, bd, s);
    }
    const Walks walks = use_avx2 ? walks_avx2(d->width, d->tri_lanes) : walks_baseline(d->width);
    return std::make_unique<BvhWide>(s, std::move(d), walks);
}

const Registration reg{
    {"bvh-wide",
     "4- or 8-wide BVH collapsed from the binned SAH tree; SIMD box tests of all children, nearest first",
     {ParamSpec::choice("width", "auto", {"auto", "4", "8"},
                        "children per node: 4, 8, or auto (8 where the CPU runs AVX2, else 4)"),
      ParamSpec::choice("simd", "auto", {"auto", "baseline", "avx2"},
                        "instruction set of the traversal: auto, baseline (SSE2) or avx2"),
      ParamSpec::choice("any_order", "stored", {"stored", "leaves", "nearest"},
                        "order of the children met in any-hit (occlusion) queries: as stored, unsorted; leaf "
                        "children first, then nearest first; or nearest first, as closest-hit queries"),
      ParamSpec::choice("tri_lanes", "auto", {"auto", "4", "8"},
                        "triangles tested at once: 4, 8 (AVX2 only), or auto (8 where the CPU runs AVX2, else 4)"),
      ParamSpec::integer("max_prims", "16", 1, 64, "largest leaf of the SAH tree collapsed (bigger nodes are always split)"),
      ParamSpec::integer("bins", "16", 2, 256, "SAH bins per axis"),
      ParamSpec::real("c_trav", "4", 0, 1e6,
                      "SAH cost of a traversal step, relative to a primitive test (triangles are tested 4 or 8 at a "
                      "time, so leaves are larger than bvh-sah's)")},
     build},
    {{{}, kTestHits | kTestSampled},
     {{"width=4"}, kTestHits | kTestSampled},
     {{"any_order=nearest"}, kTestHits | kTestSampled},
     {{"any_order=leaves"}, kTestHits | kTestSampled},
     {{"width=8", "simd=baseline", "max_prims=1"}, kTestHits},
     {{"width=4", "simd=baseline", "max_prims=8"}, kTestHits},
     {{"tri_lanes=4"}, kTestHits}}};

}  // namespace
}  // namespace rtcost::wide
