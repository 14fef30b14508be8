#pragma once
/// \file model_tree.hpp
/// A hierarchy as the cost model sees it: nodes with regions, bounding volumes, planes and the
/// operations a visit costs; the flags that the nodes alone do not say; and the sink through
/// which a hierarchy emits them (Hierarchy::emit_model).

#include <cstdint>
#include <span>
#include <vector>

#include "rtcost/math.hpp"

namespace rtcost {

/// One node of a hierarchy as the cost model sees it (see the cost-model docs): a region, an
/// optional bounding volume tested before the node is entered, an optional separating plane, the
/// operations one visit costs, and either children or the primitives of a leaf.
struct ModelNode {
    Box3 region;                 ///< R(A): the node's box (a BVH node's bounding box)
    Box3 bv;                     ///< the bounding volume tested (BVH: equals `region`)
    bool has_bv = false;         ///< a box test against `bv` precedes entering the node's children
    bool leaf = true;
    std::int8_t axis = -1;       ///< separating plane axis, -1 for none (BVH)
    float split = 0;             ///< separating plane position on `axis`
    std::uint32_t first = 0;     ///< first child (in ModelTree::nodes) or first primitive (in ModelTree::prims)
    std::uint32_t count = 0;     ///< number of children, or of primitives for a leaf
    int depth = 0;               ///< root at 0 (in model-tree levels)
    /// Operations one visit of this node performs besides primitive tests, in counter units
    /// (e.g. a kd-median node: one box and one plane; an octree's three binary levels: the
    /// first carries the visit, the other two none).
    float box = 0, plane = 0, hop = 0, classify = 0;
    bool step = true;            ///< a visit is one traversal step (N_TS)
    /// A subtree left out of a tree materialised for a ray sample (reached_model_tree): no
    /// segment of the sample meets it, so the node stands for it as an empty leaf.
    bool pruned = false;
    /// 5D ray classification: the children split one of the five dimensions at `split`:
    /// `beam_dim` 0..2 origin, 3 u, 4 v (the node's directions are its ModelBeam).
    std::int8_t beam_dim = -1;
    /// A two-child node whose any-hit (occlusion) query enters its children in an order of its
    /// own, by the sign of the ray's direction on one axis (bvh-design's `occlusion=sample`):
    /// kAnyOrderSet, the axis in bits 0-1, the second child first for a positive direction
    /// (bit 2), for a negative one (bit 3). 0: as the tree's flags order children.
    std::uint8_t any_order = 0;
};

/// ModelNode::any_order's flag that the node declares its own any-hit order.
inline constexpr std::uint8_t kAnyOrderSet = 0x80;

/// Whether a ray whose direction's sign bits are `neg` (RayInv::neg) enters the first child of a
/// node with any_order `o` first (the flag is not read: bvh-design's order bytes, which lack it,
/// are decoded alike).
inline bool any_order_first_child_first(std::uint8_t o, const int neg[3]) {
    return !((o >> (2 + neg[o & 3])) & 1);
}

/// A 5D ray classification node's directions (`ModelNode::region` is its origin box): dominant
/// axis `axis` and its sign, u and v ranges (the other two direction components over
/// |d[axis]|, lower axis first). Only rc5d's trees carry them (ModelSink::beam_node).
struct ModelBeam {
    std::int8_t axis = -1;  ///< -1: not a beam (the root of the six direction cubes)
    bool negative = false;
    float u[2] = {-1, 1}, v[2] = {-1, 1};
};

/// A hierarchy's family, as the model tree declares it (a label for its users: the model reads
/// what a node costs from the tree, never from the family).
enum class ModelFamily : std::uint8_t {
    Bvh,     ///< bounding volume hierarchies (and brute force, a one-leaf BVH)
    Bsp,     ///< Kaplan's BSP tree
    Octree,  ///< Glassner's octree
    Kd,      ///< kd-trees
    Grid,    ///< uniform grids
    Rc5d,    ///< Arvo and Kirk's 5D ray classification
};

/// What the seed paper's formula for a family (the `paper` preset) charges a node visit, as the
/// hierarchy declares it: every node entered (a BVH's box test), every interior visit, and, for
/// Kaplan's and Glassner's trees, the far region's entry 1_cmp + [g (1 - P_B) + (1 - g)] n_f
/// in place of `interior_box` (g the share of visits that cross the plane, P_B the near child's
/// chance to end the search).
struct PaperCharges {
    float entered_box = 0;
    float interior_box = 0, interior_plane = 0, interior_hop = 0, interior_classify = 0;
    bool far_entry = false;
};

/// How an any-hit (occlusion) query orders the children it meets, where the whole tree has one
/// order (a node may have its own: ModelNode::any_order).
enum class OcclusionOrder : std::uint8_t {
    /// As a closest-hit query orders them (nearest entry first where the tree culls).
    AsClosest,
    /// Leaf children first (only a leaf can end the query), nearest entry first within leaves and
    /// within interior nodes, a tie to the later child (`any_order=leaves`).
    LeavesFirst,
    /// In stored order, first child first, whatever their entries (`any_order=stored`).
    Stored,
};

/// The flags of a model tree: what the nodes alone do not say about the traversal.
struct ModelFlags {
    /// Every hierarchy names its family and the paper's charges: there is no default.
    ModelFlags(ModelFamily f, PaperCharges p) : family(f), paper(p) {}
    ModelFamily family;
    PaperCharges paper;
    /// Leaves are found by descending from the root for every cell (Kaplan's and Glassner's
    /// `locate` traversal): each leaf visit pays the operations of all its ancestors again.
    bool locate = false;
    /// Operations every ray pays once whatever it meets (e.g. the root box test), and those a
    /// ray that enters the root pays once more or less (a grid's first cell has no hop: -1).
    float per_ray_box = 1, per_entry_hop = 0;
    /// A ray follows exactly one root-to-leaf path (5D classification: the children of a node
    /// are disjoint sets of rays), whose leaf candidates are searched in order of their start
    /// along the dominant axis and the search stops early.
    bool one_path = false;
    /// The ordered search of a one-path leaf, as the traversal runs it: a candidate's start is
    /// its bounding box's near face moved outwards by `search_pad` (in float, as the traversal
    /// stores it), and the search stops once a start lies beyond the current hit's dominant
    /// coordinate plus `stop_margin` times the magnitudes of that coordinate's two terms.
    /// Without these, candidates whose near face lies in the hit's plane (coplanar faces) were
    /// predicted untested while the traversal tests them.
    float search_pad = 0;
    double stop_margin = 0;
    /// A closest-hit query skips what lies beyond the nearest hit found so far (false: the
    /// traversal visits everything the segment meets, e.g. a BVH with `order=none`).
    bool cull = true;
    /// Culling compares with cull_bound(hit) (math.hpp), a relative 2^-16 beyond the hit, rather
    /// than with the hit itself (the BVHs' traversals).
    bool cull_widened = false;
    /// A ray that misses the root's region ends at the root test (false: every ray enters the
    /// root whatever it meets, as brute force's does).
    bool gated = true;
    /// The order in which an any-hit query visits the children it meets.
    OcclusionOrder occlusion_order = OcclusionOrder::AsClosest;
    /// A child whose region a stretch of the ray (not a single point) only touches -- the ray
    /// passing exactly through an edge or corner of its cell -- is entered: a grid's 3DDDA passes
    /// a corner one axis at a time. False: the traversal crosses an edge or corner in one step and
    /// enters only the cells the ray runs through (octrees and BSP trees; a camera ray through
    /// the scene's centre meets their central edges).
    bool point_touches = true;
};

/// A hierarchy flattened for the model: `nodes[0]` is the root; the children of a node are
/// contiguous. Binary for space subdivisions; a BVH node may have more than two children
/// (Goldsmith and Salmon's trees are n-ary), each entered through its own box test.
struct ModelTree : ModelFlags {
    /// An empty tree (a hierarchy the model cannot see into); emit_model's flags replace these.
    ModelTree() : ModelFlags(ModelFamily::Bvh, {.entered_box = 1}) {}
    std::vector<ModelNode> nodes;
    std::vector<std::uint32_t> prims;  ///< leaf primitive references
    std::vector<ModelBeam> beams;      ///< per node of a 5D classification tree; empty otherwise
};

/// Receives a hierarchy's model tree depth first (Hierarchy::emit_model), so that the model
/// can read a hierarchy of millions of nodes where it lies instead of copying it: `begin` once,
/// then `node` for every node in pre-order, a node with `count` children being followed by its
/// children's whole subtrees, in order.
class ModelSink {
public:
    virtual ~ModelSink() = default;
    /// The tree's flags, before its root. Returning false ends the emission there (a sink that
    /// only asks whether there is a model tree).
    virtual bool begin(const ModelFlags& flags) = 0;
    /// One node. `m.first` and `m.depth` are not read (the order says them); a leaf's
    /// primitive ids are `prims`, `m.count` of them.
    virtual void node(const ModelNode& m, std::span<const std::uint32_t> prims) = 0;
    /// One node of a 5D classification tree, with its directions; a sink that does not read
    /// them takes it as node().
    virtual void beam_node(const ModelNode& m, const ModelBeam& beam, std::span<const std::uint32_t> prims) {
        (void)beam;
        node(m, prims);
    }
    /// Asked by an emitter right after an interior node: true when the sink has no use for that
    /// node's subtree, which the emitter then leaves out (nothing of it is emitted). An emitter
    /// that never asks emits every node, and a sink takes either. A ray sample reaches a small
    /// part of a large tree: reading the rest only to drop it cost more than the prediction.
    virtual bool skip_children() { return false; }
    /// Offered by an emitter right after `begin` when each of its subtrees holds a contiguous
    /// run of one array of primitive references (a BVH whose leaves lie in pre-order): `refs` is
    /// that array. A sink that returns true is told each node's run by `subtree` just before the
    /// node. (The segments estimator learns from it which nodes hold a ray's hit without a pass
    /// over the whole tree.)
    virtual bool leaf_order(std::span<const std::uint32_t> refs) {
        (void)refs;
        return false;
    }
    /// The run refs[lo, hi) of the node emitted next, after leaf_order returned true.
    virtual void subtree(std::uint32_t lo, std::uint32_t hi) {
        (void)lo;
        (void)hi;
    }
};

/// Emits a materialised model tree into `sink`, depth first (what Hierarchy::emit_model does
/// for a hierarchy).
void emit_model(const ModelTree& tree, ModelSink& sink);

}  // namespace rtcost
