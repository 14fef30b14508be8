#pragma once
// The bounding volume hierarchy shared by the BVH builders (bvh-median, bvh-gs, bvh-sah): one
// node layout, one traversal template, one model-tree walk. Builders differ only in how they
// fill `BvhData`.

#include <algorithm>
#include <cstddef>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "../common/impl.hpp"
#include "../common/leaf_prims.hpp"
#include "../common/line_allocator.hpp"
#include "leaf_packs.hpp"
#include "pair_entry.hpp"

namespace rtcost::bvh {

/// 32 bytes. Children of an interior node are contiguous from `index`; a leaf's primitive
/// references are contiguous in BvhData::refs from `index`.
struct Node {
    Box3 box;
    std::uint32_t index = 0;
    std::uint32_t count : 31 = 0;
    std::uint32_t leaf : 1 = 1;
};
static_assert(sizeof(Node) == 32);

/// Bound on any node's fan-out and on depth; together they bound the traversal stack.
inline constexpr int kMaxFanout = 8;
inline constexpr int kMaxDepth = 100;

/// A node array placed so that each pair of siblings that starts at an odd index (as every
/// builder lays out a binary node's children: the root, then pairs) lies in one 64-byte cache
/// line: a binary visit reads both children's boxes and prefetches a child's pair as one line;
/// from malloc's 16-byte alignment every pair straddled two lines, the second never prefetched.
using NodeArray = std::vector<Node, LineAllocator<Node, 1>>;

struct BvhData {
    NodeArray nodes;                   ///< nodes[0] is the root
    std::vector<std::uint32_t> refs;   ///< primitive ids in leaf order
    std::vector<std::string> limits;   ///< bounds that stopped the build, for StructureStats::limits
};

/// Per-primitive bounds and centroids, computed once per build.
struct PrimInfo {
    std::vector<Box3> bounds;
    std::vector<Vec3> centroids;
    explicit PrimInfo(const Scene& s);
};

// The builders (one file each).
struct MedianOptions { int max_prims = 1; int max_depth = 64; };
BvhData build_median(const Scene& s, const MedianOptions& o);

struct GsOptions { int max_prims = 1; int max_depth = 64; int max_children = kMaxFanout; std::uint64_t seed = 1; };
BvhData build_gs(const Scene& s, const GsOptions& o);

struct SahOptions {
    int max_prims = 8;     ///< larger nodes are always split
    int max_depth = 64;
    int bins = 16;         ///< binned SAH bins per axis
    bool sweep = false;    ///< full sweep over sorted centroids instead of bins
    float c_trav = 1;      ///< cost of a traversal step, relative to...
    float c_isect = 1;     ///< ...one primitive test
};
BvhData build_sah(const Scene& s, const SahOptions& o);

/// bvh-sah's leaf costs for scene `s` (its `max_prims=auto` and `c_trav=auto`): larger leaves
/// (16, a step priced as 4 tests) for a mesh of at least 2^16 triangles, whose leaves are tested
/// four at a time (leaf_packs.hpp) and whose tree outgrows the cache, so that a step waits on
/// memory; SahOptions' defaults (8 and 1) otherwise. Measured against 8 and 1 on 256x256 rays,
/// one core: rings-mesh spd 21% and yxa_1 spd 18% faster, balls-mesh 5-10%, 2CylinderEngine 3%;
/// on teapot (9,264 triangles, a 0.7 MiB tree) the same change was 11-15% slower.
SahOptions sah_leaf_costs(const Scene& s, SahOptions o = {});
/// Whether `s` is such a mesh: at least 2^16 primitives, each tested as a triangle.
bool large_triangle_mesh(const Scene& s);

/// The BVH hierarchy over built data. `ordered`: near child first and children whose entry lies
/// beyond the current hit skipped; otherwise every child whose box the ray meets is visited, in
/// stored order, and no subtree is cut by a hit found (the paper's BVH case).
class Bvh final : public HierarchyImpl<Bvh> {
public:
    Bvh(const Scene& s, std::string name, BvhData data, bool ordered);

    std::string_view name() const override { return name_; }
    bool emit_model(ModelSink& sink) const override { return emit_model_ordered(sink, {}); }
    /// emit_model with an any-hit order byte per node (`any_order[i]` for node i, as
    /// ModelNode::any_order without its flag) on every two-child interior node; none if empty.
    bool emit_model_ordered(ModelSink& sink, std::span<const std::uint8_t> any_order) const;
    /// The built nodes and references (the model's and the statistics'; a leaf's `index` is its
    /// first reference in BvhData::refs).
    const BvhData& data() const { return d_; }
    /// The nodes as this BVH's walk reads them (a walk of another order copies them: bvh-design):
    /// data().nodes, but where the leaves' triangles are in packs (leaf_packs.hpp) a leaf's
    /// `index` is its first lane there (the packs start every leaf at a pack's first lane, so the
    /// references' positions no longer say where a leaf's triangles are).
    const NodeArray& walk_nodes() const { return walk_nodes_.empty() ? d_.nodes : walk_nodes_; }
    /// The leaves' triangles in packs, inactive where some reference is not tested as a triangle.
    const LeafPacks& packs() const { return packs_; }
    /// The order of an ordered BVH's any-hit (occlusion) queries. LeavesFirst: a node's leaf
    /// children before its interior ones (only a leaf can end the query), nearest first within
    /// each, a tie to the later child: a large occluder held high in the tree (a floor, a wall) is
    /// tested before everything nearer. Stored: the children met in stored order, first child
    /// first, with no comparison of their entries (as Embree's occlusion traversal): which child
    /// holds an occluder is not told by which is nearer, and the comparison's branch is
    /// mispredicted half the time (bvh-sah on balls-mesh's shadow rays: 10% faster for 3% more
    /// steps; on rings-mesh's, 14% fewer steps).
    void set_occlusion_order(OcclusionOrder o) { occlusion_ = o; }
    OcclusionOrder occlusion_order() const { return occlusion_; }

    /// For another walk of the same nodes (bvh-design's occlusion order): leaf `n` (of
    /// walk_nodes() or a copy) tested as this BVH's own walk tests it (with RealPrimTest, on its
    /// triangle copies in leaf order with the ray's shear `shear`, shear_of), counted alike; true
    /// when an any-hit query ends. `test` as trace_with takes it.
    template <class C, Query Q, class PrimTest>
    bool test_leaf_of(const Node& n, const Ray& ray, const RayShear& shear, Hit& hit, C& counting, bool& found,
                      PrimTest& test) const {
        return test_leaf<C, Q>(n.index, n.count, ray, shear, hit, counting, found, test);
    }
    /// The shear a walk hands test_leaf_of: made only for a tree with triangles to test.
    RayShear shear_of(const Ray& ray) const { return has_triangles_ ? RayShear(ray.d) : RayShear(); }
    /// Fetches the leaf primitives from `first` (a leaf's Node::index in walk_nodes()).
    void prefetch_prims(std::uint32_t first) const {
        __builtin_prefetch(packs_.active() ? packs_.at(first) : static_cast<const void*>(prims_.data() + first));
    }

    template <class C, Query Q>
    bool trace(const Ray& ray, Hit& hit, C& counting) const {
        return trace_with<C, Q>(ray, hit, counting, RealPrimTest{*scene_});
    }

    /// The traversal with the primitive test supplied by the caller (design/replay.hpp); with
    /// RealPrimTest, the leaves' own test of their triangle copies.
    template <class C, Query Q, class PrimTest>
    bool trace_with(const Ray& ray, Hit& hit, C& counting, PrimTest test) const {
        // Query::All never cuts by a hit found, which is the unordered walk.
        if constexpr (Q == Query::All) return walk<C, Q, false>(ray, hit, counting, test);
        // (An any-hit query ends at its first hit: the unordered walk is the ordered one in stored order.)
        else if (ordered_ && !(Q == Query::Any && occlusion_ == OcclusionOrder::Stored))
            return walk<C, Q, true>(ray, hit, counting, test);
        else return walk<C, Q, false>(ray, hit, counting, test);
    }

protected:
    StructureStats compute_structure() const override;

private:
    template <class C, Query Q, bool kOrdered, class PrimTest>
    bool walk(const Ray& ray, Hit& hit, C& counting, PrimTest& test) const {
        struct Entry {
            std::uint32_t node;
            float t;
            int depth;
        };
        // Stack bound: along any path at most kMaxFanout - 1 siblings wait per level.
        Entry stack[kMaxDepth * (kMaxFanout - 1) + 2];
        int sp = 0;
        const Node* nodes = walk_nodes().data();
        const RayInv ri(ray);
        const PairRay pair_ray(ri);
        // Three divisions a ray pays only where it reaches a leaf with triangles to test (not in a
        // scene of spheres, nor on the shadow rays of a mesh that reach no leaf).
        RayShear shear;
        bool sheared = !has_triangles_;
        counting.box();
        float t0 = box_entry(nodes[0].box, ri, ray.tmin, ray.tmax);
        if (t0 == kInf) return false;
        bool found = false;
        // The entry being visited; a binary node continues straight into its near child.
        Entry e{0, t0, 0};
        for (;;) {
            // One visit; `e` is then either set to the next entry directly (a binary node's
            // near child) or popped from the stack at `pop`.
            {
                if constexpr (kOrdered) {
                    if (e.t >= cull_bound(hit.t)) goto pop;  // the whole box lies beyond the current hit
                }
                const Node& n = nodes[e.node];
                if (n.leaf) {
                    counting.leaf(e.depth, n.count);
                    if (!sheared) shear = RayShear(ray.d), sheared = true;
                    if (test_leaf<C, Q>(n.index, n.count, ray, shear, hit, counting, found, test)) return true;
                    goto pop;
                }
                counting.interior(e.depth);
                const float limit = kOrdered ? std::min(cull_bound(hit.t), ray.tmax) : ray.tmax;
                if (n.count == 2) {
                    // Binary nodes (all but Goldsmith-Salmon's): no sort, and the near child is
                    // visited next without a trip through the stack.
                    counting.box();
                    counting.box();
                    // What either child's visit reads, fetched while their boxes are tested.
                    prefetch(nodes, nodes[n.index]);
                    prefetch(nodes, nodes[n.index + 1]);
                    float ta, tb;
                    pair_entry(nodes[n.index].box, nodes[n.index + 1].box, pair_ray, ray.tmin, limit, ta, tb);
                    Entry a{n.index, ta, e.depth + 1}, b{n.index + 1, tb, e.depth + 1};
                    if constexpr (kOrdered) {
                        if (second_first<Q>(nodes[a.node].leaf, nodes[b.node].leaf, ta, tb)) std::swap(a, b);
                    }
                    if (a.t != kInf) {
                        if (b.t != kInf) stack[sp++] = b;
                        e = a;
                        continue;
                    }
                    if (b.t != kInf) {
                        e = b;
                        continue;
                    }
                    goto pop;
                }
                Entry hits[kMaxFanout];
                int nh = 0;
                for (std::uint32_t k = 0; k < n.count; ++k) {
                    counting.box();
                    float t = box_entry(nodes[n.index + k].box, ri, ray.tmin, limit);
                    if (t != kInf) hits[nh++] = {n.index + k, t, e.depth + 1};
                }
                if constexpr (kOrdered) {
                    // Nearest last, so it is popped first (LeavesFirst: leaves last, each group
                    // nearest last). Fan-out is small: insertion sort.
                    const bool leaves_first = Q == Query::Any && occlusion_ == OcclusionOrder::LeavesFirst;
                    auto taken_before = [&](const Entry& x, const Entry& y) {
                        if (leaves_first) {
                            const bool lx = nodes[x.node].leaf, ly = nodes[y.node].leaf;
                            if (lx != ly) return lx;
                        }
                        return x.t < y.t;
                    };
                    for (int i = 1; i < nh; ++i) {
                        Entry x = hits[i];
                        int j = i - 1;
                        for (; j >= 0 && taken_before(hits[j], x); --j) hits[j + 1] = hits[j];
                        hits[j + 1] = x;
                    }
                    for (int i = 0; i < nh; ++i) stack[sp++] = hits[i];
                } else {
                    for (int i = nh - 1; i >= 0; --i) stack[sp++] = hits[i];
                }
            }
        pop:
            if (sp == 0) break;
            e = stack[--sp];
        }
        return found;
    }

    /// Tests the leaf's `count` primitives from reference `first` (of packs_ where it has them,
    /// else prims_); true when an any-hit query ends.
    template <class C, Query Q, class PrimTest>
    bool test_leaf(std::uint32_t first, std::uint32_t count, const Ray& ray, const RayShear& shear, Hit& hit, C& counting,
                   bool& found, PrimTest& test) const {
        if (packs_.active()) {
            // A mesh: its triangles four at a time, the same tests, counts and order.
            if constexpr (std::is_same_v<PrimTest, RealPrimTest>) {
                return packs::test_range<C, Q>(packs_.packs.data(), first, count, packs::Shear<packs::F4>(shear, ray), ray,
                                               hit, counting, found);
            } else {
                for (std::uint32_t k = first; k < first + count; ++k) {
                    LeafPrim p;
                    if constexpr (requires { test.keep(0u, 0.0f, hit); }) p = packs_.prim(k);
                    else p.id = packs_.id(k);  // all such a test reads
                    if (test_one<C, Q>(p, ray, shear, hit, counting, found, test)) return true;
                }
                return false;
            }
        }
        for (const LeafPrim* p = prims_.data() + first; p != prims_.data() + first + count; ++p)
            if (test_one<C, Q>(*p, ray, shear, hit, counting, found, test)) return true;
        return false;
    }

    /// One reference of a leaf, as test_leaf tests it; true when an any-hit query ends.
    template <class C, Query Q, class PrimTest>
    bool test_one(const LeafPrim& p, const Ray& ray, const RayShear& shear, Hit& hit, C& counting, bool& found,
                  PrimTest& test) const {
        bool met;
        if constexpr (std::is_same_v<PrimTest, RealPrimTest>) {
            met = test_prim(*scene_, p, ray, shear, hit, counting);
        } else if constexpr (requires { test.keep(p.id, 0.0f, hit); }) {
            // A test that only sorts real hits (CrossingCollector) is given the leaves' own
            // exact test first, as a real trace is.
            Hit h = hit;
            met = test_prim(*scene_, p, ray, shear, h, counting) && test.keep(p.id, h.t, hit);
        } else {
            met = test(p.id, ray, hit, counting);
        }
        if (!met) return false;
        found = true;
        return Q == Query::Any;
    }

    /// An ordered visit of a binary node: whether the second child (a leaf if `lb`, entered at
    /// `tb`) goes first. Nearest first; LeavesFirst: a leaf child first, then the nearest,
    /// a tie to the second child.
    template <Query Q>
    bool second_first(bool la, bool lb, float ta, float tb) const {
        if (Q == Query::Any && occlusion_ == OcclusionOrder::LeavesFirst) return la != lb ? lb : !(ta < tb);
        return tb < ta;
    }

    /// Incoherent rays wait on memory: what a visit of `n` reads first, fetched ahead.
    /// `nodes`: walk_nodes(), which the walk holds.
    void prefetch(const Node* nodes, const Node& n) const {
        if (!n.leaf) __builtin_prefetch(nodes + n.index);
        else if (!packs_.active()) __builtin_prefetch(prims_.data() + n.index);
        else if (n.count > 0) {
            // Every line of the leaf's packs (a pack may start half a line in).
            const char* a = reinterpret_cast<const char*>(reinterpret_cast<std::uintptr_t>(packs_.at(n.index)) & ~std::uintptr_t{63});
            const char* b = static_cast<const char*>(packs_.at(n.index + n.count - 1)) + sizeof(TriPack<4>);
            for (; a < b; a += 64) __builtin_prefetch(a);
        }
    }

    std::string name_;
    BvhData d_;
    bool ordered_;
    OcclusionOrder occlusion_ = OcclusionOrder::AsClosest;
    std::vector<LeafPrim> prims_;  ///< BvhData::refs as their tests need them, in leaf order (none with packs_)
    LeafPacks packs_;              ///< the same in packs of four, for a mesh (every reference a triangle)
    NodeArray walk_nodes_;         ///< with packs_: d_.nodes, each leaf's index its first lane in packs_
    bool has_triangles_ = false;    ///< some LeafPrim is tested as a triangle (RayShear needed)
};

}  // namespace rtcost::bvh
