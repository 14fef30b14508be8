#pragma once
// kd-trees (`kd-median`, `kd-sah`): one node layout, one build driver, one traversal template.
// The builders differ only in how they choose a node's plane (median_builder.cpp,
// sah_builder.cpp).
//
// The root cell is the scene's bounding box. A primitive is referenced by every cell that
// spatial::overlaps says (assign=bounds: its bounding box meets the closed cell; exact: its
// surface does). kd-median keeps, per interior node, the bounding box of its primitives clipped
// to the cell (Fussell and Subramanian's node box), tested before the plane.
//
// Traversal (front to back, explicit stack): the ray's segment [t0, t1] inside the current cell
// is split at the plane; the near child gets [t0, ts], the far child [ts, t1] (closed: both
// when ts lies on an end), each widened by a relative 4e-7 so that rounding never loses a cell
// the ray really meets. A ray with no direction component on the split axis goes to the side
// holding its origin, and to both sides (left first) when it lies in the plane. A leaf ends the
// search when the closest hit so far lies inside its segment by a margin: cull_bound(t) <= t1
// (a hit further on may lie in a later cell behind a nearer one, and a hit within a relative
// 2^-16 of the exit may not be the nearest: a face that only starts beyond the plane, met where
// the ray crosses it, can round a float nearer -- rays through tetra's shared vertices did).
// The exception is the left of a plane the ray lies in: both sides then cover the same stretch
// of the ray, and although in exact arithmetic every primitive the ray meets there touches the
// plane (so is on both sides), the float intersection tests also report hits a rounding error
// off the plane -- planes sit exactly at (or one float beside) primitive edges -- so the right
// side is searched before the search may end.
// kd-median narrows the segment to the node box first (the box bounds every primitive's part
// inside the cell, so nothing is lost), which is what the model's gate box describes.
//
// Counters per ray: one `box` for the clip to the root cell. Per interior visit `interior(depth)`,
// then (kd-median) one `box` for the node box and, when the ray meets it, one `plane`; kd-sah: one
// `plane`. Per leaf visit `leaf(depth, n)`, then one `prim` per primitive test (mailbox=1: only
// first tests of a primitive in this ray).

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "../common/spatial.hpp"
#include "../common/impl.hpp"

namespace rtcost::kd {

/// Deepest leaf allowed (root at 0); bounds the traversal stack.
inline constexpr int kMaxDepth = 64;

/// 16 bytes. Interior: children at `index` (left, below the plane) and `index + 1`. Leaf
/// (axis 3): `count` references from KdData::refs[index].
struct Node {
    float split = 0;
    std::uint32_t index = 0;
    std::uint32_t count = 0;
    std::uint32_t axis = 3;
    bool leaf() const { return axis == 3; }
};
static_assert(sizeof(Node) == 16);

struct KdData {
    Box3 root;                         ///< the root cell (scene bounds)
    std::vector<Node> nodes;           ///< nodes[0] is the root
    std::vector<std::uint32_t> refs;   ///< primitive ids in leaf order
    std::vector<Box3> boxes;           ///< kd-median: per node, its primitives' box within its cell
};

/// A primitive reference during the build: its id and its bounding box clipped to the cell.
struct BuildRef {
    std::uint32_t id;
    Box3 box;
};

/// A chosen plane; axis -1 makes the node a leaf.
struct Split {
    int axis = -1;
    float pos = 0;
};

/// Chooses the plane of a node holding `refs` (more than max_prims, shallower than max_depth).
using Chooser = std::function<Split(const std::vector<BuildRef>& refs, const Box3& cell, int depth)>;

struct BuildOptions {
    int max_depth = 20;
    int max_prims = 1;
    spatial::Assign assign = spatial::Assign::Bounds;
    bool boxes = false;  ///< store each interior node's box (kd-median)
};

/// The default depth limit of Havran and Wald: 8 + 1.3 log2 N, at most kMaxDepth.
int default_max_depth(std::size_t n);

/// The depth limit every kd-tree declares: a number, or auto (default_max_depth).
inline const ParamSpec kMaxDepthParam = ParamSpec::integer(
    "max_depth", "auto", 0, kMaxDepth, "deepest leaf (root at 0); auto: 8 + 1.3 log2 N (Havran, Wald)", {"auto"});

/// Top-down build: the root cell is the scene box, each node split where `choose` says, its
/// references handed to the children they overlap (options.assign).
KdData build_tree(const Scene& s, const BuildOptions& o, const Chooser& choose);

// The two plane choosers (one file each).
struct MedianOptions { BuildOptions build; };
KdData build_median(const Scene& s, const MedianOptions& o);

struct SahOptions {
    BuildOptions build;
    float c_trav = 15;       ///< K_T of Wald and Havran
    float c_isect = 20;      ///< K_I
    float empty_bonus = 0.2f;  ///< cost x (1 - empty_bonus) when one side is empty
};
KdData build_sah(const Scene& s, const SahOptions& o);
/// kd-sah's plane for a node: the cheapest by the SAH, or axis -1 when none beats the leaf
/// (unless `must_split`: then the cheapest plane whatever the leaf costs; -1 only when the
/// cell is flat or no candidate lies inside it). kd-design terminates by the model instead.
Split sah_plane(const std::vector<BuildRef>& refs, const Box3& cell, const SahOptions& o, bool must_split);

/// Clips the segment [t0, t1] to box `b`; false when they do not meet. Both ends are widened by
/// a relative 4e-7 (about 7 ulp: the slab values' own rounding error is at most 3 ulp), so a
/// ray through a box's face, edge or corner is never lost. Zero direction components behave as
/// in box_entry: 0 * inf = NaN fails every compare and is ignored.
inline bool clip(const Box3& b, const RayInv& r, float& t0, float& t1) {
    for (int a = 0; a < 3; ++a) {
        // Faces by the direction's sign (as box_entry): a compare-and-swap with a NaN (origin in
        // a face's plane) rejected rays of direction -0 lying in that face.
        float tn = ((r.neg[a] ? b.hi[a] : b.lo[a]) - r.o[a]) * r.inv[a];
        float tf = ((r.neg[a] ? b.lo[a] : b.hi[a]) - r.o[a]) * r.inv[a];
        // Multiplication keeps infinities infinite (inf - inf would be NaN and accept).
        tn *= tn > 0 ? 0.9999996f : 1.0000004f;
        tf *= tf > 0 ? 1.0000004f : 0.9999996f;
        t0 = tn > t0 ? tn : t0;
        t1 = tf < t1 ? tf : t1;
    }
    return t0 <= t1;
}

class KdTree final : public HierarchyImpl<KdTree> {
public:
    KdTree(const Scene& s, std::string name, KdData data, bool mailbox)
        : HierarchyImpl(s), name_(std::move(name)), d_(std::move(data)), boxes_(!d_.boxes.empty()),
          mailbox_(mailbox) {}

    std::string_view name() const override { return name_; }
    bool emit_model(ModelSink& sink) const override;
    const KdData& data() const { return d_; }

    template <class C, Query Q>
    bool trace(const Ray& ray, Hit& hit, C& counting) const {
        return trace_with<C, Q>(ray, hit, counting, RealPrimTest{*scene_});
    }

    /// Whether Hierarchy::replay is the model tree's prediction (within rounding: the traversal
    /// widens each plane crossing by a few ulps, tests/test_replay.cpp): not with mailboxes,
    /// which the model does not know.
    bool replay_is_model() const { return !mailbox_; }

    /// The traversal with the primitive test supplied by the caller (design/replay.hpp).
    template <class C, Query Q, class PrimTest>
    bool trace_with(const Ray& ray, Hit& hit, C& counting, PrimTest test) const {
        if (boxes_)
            return mailbox_ ? walk<C, Q, true, true>(ray, hit, counting, test)
                            : walk<C, Q, true, false>(ray, hit, counting, test);
        return mailbox_ ? walk<C, Q, false, true>(ray, hit, counting, test)
                        : walk<C, Q, false, false>(ray, hit, counting, test);
    }

protected:
    StructureStats compute_structure() const override;

private:
    template <class C, Query Q, bool kBoxes, bool kMailbox, class PrimTest>
    bool walk(const Ray& ray, Hit& hit, C& counting, PrimTest& test) const {
        struct Entry {
            std::uint32_t node;
            float t0, t1;
            int depth;
            bool may_end;  // false below a plane the ray lies in, until its left side is done
        };
        Entry stack[kMaxDepth + 2];  // at most one far child waits per level
        int sp = 0;
        counting.box();
        const RayInv ri(ray);
        Entry e{0, ray.tmin, ray.tmax, 0, true};
        if (d_.root.empty() || !clip(d_.root, ri, e.t0, e.t1)) return false;
        spatial::Mailbox* mb = nullptr;
        if constexpr (kMailbox) mb = &spatial::Mailbox::begin_ray(this, scene_->size());
        const Node* nodes = d_.nodes.data();
        bool found = false;
        for (;;) {
            const Node& n = nodes[e.node];
            if (n.leaf()) {
                counting.leaf(e.depth, n.count);
                for (std::uint32_t k = 0; k < n.count; ++k) {
                    const std::uint32_t id = d_.refs[n.index + k];
                    if constexpr (kMailbox) {
                        if (!mb->first_visit(id)) continue;
                    }
                    if (test(id, ray, hit, counting)) {
                        found = true;
                        if constexpr (Q == Query::Any) return true;
                    }
                }
                // A hit before the cell's exit is in this cell: nothing later is nearer. Within a
                // relative 2^-16 of the exit (cull_bound) the next cell is searched too: a face
                // that only starts there (beyond the plane) may be met a float or two nearer.
                if constexpr (Q != Query::All) {
                    if (e.may_end && cull_bound(hit.t) <= e.t1) return found;
                }
                if (sp == 0) return found;
                e = stack[--sp];
                continue;
            }
            counting.interior(e.depth);
            if constexpr (kBoxes) {
                counting.box();
                if (!clip(d_.boxes[e.node], ri, e.t0, e.t1)) {
                    if (sp == 0) return found;
                    e = stack[--sp];
                    continue;
                }
            }
            counting.plane();
            const int a = static_cast<int>(n.axis);
            const std::uint32_t left = n.index, right = n.index + 1;
            const int depth = e.depth + 1;
            if (!(std::fabs(ri.inv[a]) < kInf)) {
                // Parallel to the plane (zero or denormal direction component).
                if (ri.o[a] < n.split) e = {left, e.t0, e.t1, depth, e.may_end};
                else if (ri.o[a] > n.split) e = {right, e.t0, e.t1, depth, e.may_end};
                else {
                    // In the plane: both sides cover the same stretch of the ray, so a hit in
                    // the left side ends nothing until the right side has been searched too.
                    stack[sp++] = {right, e.t0, e.t1, depth, e.may_end};
                    e = {left, e.t0, e.t1, depth, false};
                }
                continue;
            }
            // The crossing, widened like clip(): the near side keeps [t0, ts_hi], the far side
            // [ts_lo, t1], so each child's segment holds the true one despite rounding (planes
            // sit exactly at vertices, where a ray through a corner would otherwise be lost).
            const float ts = (n.split - ri.o[a]) * ri.inv[a];
            const float ts_lo = ts * (ts > 0 ? 0.9999996f : 1.0000004f);
            const float ts_hi = ts * (ts > 0 ? 1.0000004f : 0.9999996f);
            const std::uint32_t near = ri.neg[a] ? right : left, far = ri.neg[a] ? left : right;
            const bool want_near = e.t0 <= ts_hi, want_far = ts_lo <= e.t1;
            if (want_near && want_far) {
                stack[sp++] = {far, std::max(ts_lo, e.t0), e.t1, depth, e.may_end};
                e = {near, e.t0, std::min(ts_hi, e.t1), depth, e.may_end};
            } else if (want_near) {
                e = {near, e.t0, e.t1, depth, e.may_end};
            } else {
                e = {far, e.t0, e.t1, depth, e.may_end};
            }
        }
    }

    std::string name_;
    KdData d_;
    bool boxes_;
    bool mailbox_;
};

}  // namespace rtcost::kd
