// The part of a hierarchy's model tree that a ray sample can reach. A probe of a few thousand
// segments reaches a small share of a large tree (an octree of 10^6 nodes), and writing out the
// whole tree, then a tally and a probability per node, costs far more than the probe itself:
// fresh memory is paid for page by page. So the tree is materialised as it is emitted, keeping a
// node's subtree only when some segment of the sample meets its region.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "hierarchy/common/model_collector.hpp"
#include "model_internal.hpp"
#include "rtcost/error.hpp"
#include "rtcost/sample.hpp"

namespace rtcost {

namespace {

/// A segment of one sample ray, as far as it reaches into the node being emitted. In a BVH,
/// `full` is the whole ray's segment there, and `free` says that the node may be searched
/// before the ray's hit is found, so everything the whole ray meets below it may be visited.
struct Reach {
    std::uint32_t ray;
    Segment s;
    Segment full;
    bool free;
};

/// Where each node of an emitted tree lies in pre-order, and its subtree's extent: a first
/// pass over a BVH, so that the reached tree knows which nodes hold a ray's hit.
class PreorderIndex final : public ModelSink {
public:
    explicit PreorderIndex(std::size_t prims) : leaf_of(prims, ~0u) {}
    std::vector<std::uint32_t> end;      ///< per node (pre-order): one past its subtree's last node
    std::vector<std::uint32_t> leaf_of;  ///< per primitive: its leaf (pre-order), ~0u if none

    bool read = false;                   ///< whether the tree was read (a BVH searched front to back)

    /// Reads only a BVH searched front to back (the emitter stops otherwise).
    bool begin(const ModelFlags& f) override { return read = f.family == ModelFamily::Bvh && f.cull; }
    void node(const ModelNode& m, std::span<const std::uint32_t> prims) override {
        const auto k = static_cast<std::uint32_t>(end.size());
        end.push_back(k + 1);
        if (!open_.empty()) --open_.back().left;
        if (!m.leaf && m.count > 0) {
            open_.push_back({k, m.count});
            return;
        }
        for (std::uint32_t p : prims)
            if (p < leaf_of.size()) leaf_of[p] = k;
        while (!open_.empty() && open_.back().left == 0) {
            end[open_.back().node] = static_cast<std::uint32_t>(end.size());
            open_.pop_back();
        }
    }

private:
    struct Open {
        std::uint32_t node, left;
    };
    std::vector<Open> open_;
};

/// Materialises an emitted tree like Hierarchy::model_tree, but stands a subtree that none of
/// the sample's segments meets by a pruned empty leaf (its nodes are read and dropped). Which
/// segments reach a node is found the way the probe finds it: the parent's segment (clipped to
/// the parent's bounding volume) clipped to the child's region.
class ReachCollector final : public ModelCollector {
public:
    /// `order`: the tree's pre-order index (PreorderIndex) for a BVH whose emitter does not
    /// offer its leaf order, else null.
    ReachCollector(ModelTree& t, const RaySample& sample, const PreorderIndex* order)
        : ModelCollector(t), sample_(sample), order_(order) {}

    /// A BVH that neither offered its leaf order nor came with a pre-order index: nothing was
    /// kept, and the tree is to be read again with one (reached_model_tree).
    bool abandoned() const { return abandoned_; }

    bool begin(const ModelFlags& f) override {
        ModelCollector::begin(f);
        one_path_ = f.one_path;
        if (!one_path_) seg_ = model::ReplaySegments(sample_, f.cull);
        // A BVH's children overlap: a closest-hit search enters a child met before the one that
        // holds its hit, and searches it whole (on the whole ray, no hit known yet), reaching
        // nodes beyond where the ray ends. Cells of a subdivision never overlap: a search past
        // its end has stopped. Which nodes hold a ray's hit is found from the leaf order the
        // emitter offers (leaf_order), else from the pre-order index.
        const bool bvh = f.family == ModelFamily::Bvh && f.cull;
        overlapping_ = bvh && order_;
        awaiting_ = bvh && !order_;
        ranges_ = false;
        cursor_ = 0;
        if (overlapping_)
            end_keys([&](std::uint32_t prim, auto&& add) {
                if (prim < order_->leaf_of.size()) add(order_->leaf_of[prim]);
            });
        return true;
    }

    bool leaf_order(std::span<const std::uint32_t> refs) override {
        if (!awaiting_) return false;
        awaiting_ = false;
        overlapping_ = ranges_ = true;
        // Where each end primitive lies in refs: one pass over refs, looking up a bitmap of the
        // primitives some ray ends at.
        std::vector<std::uint32_t> wanted;
        for (std::uint32_t i = 0; i < sample_.size(); ++i)
            if (seg_.ends[i] < sample_.rays.rays[i].tmax)
                for (const Crossing& c : sample_.crossings_of(i))
                    if (c.t <= seg_.ends[i]) wanted.push_back(c.prim);
        std::uint32_t top = 0;
        for (std::uint32_t p : wanted) top = std::max(top, p + 1);
        std::vector<bool> is_end(top, false);
        for (std::uint32_t p : wanted) is_end[p] = true;
        std::vector<std::pair<std::uint32_t, std::uint32_t>> at;  // (primitive, position in refs)
        for (std::uint32_t k = 0; k < refs.size(); ++k)
            if (refs[k] < top && is_end[refs[k]]) at.push_back({refs[k], k});
        std::sort(at.begin(), at.end());
        end_keys([&](std::uint32_t prim, auto&& add) {
            auto it = std::lower_bound(at.begin(), at.end(), std::pair<std::uint32_t, std::uint32_t>{prim, 0});
            for (; it != at.end() && it->first == prim; ++it) add(it->second);
        });
        return true;
    }

    void subtree(std::uint32_t lo, std::uint32_t hi) override {
        lo_ = lo;
        hi_ = hi;
    }

private:
    /// Fills each ray's end keys (ends_at_, end_keys_): `key_of(prim, add)` calls add(key) for
    /// each place of a primitive the ray's search ends at (a tie keeps several). The nodes
    /// above those places hold the hit.
    template <class KeyOf>
    void end_keys(KeyOf&& key_of) {
        ends_at_.assign(sample_.size() + 1, 0);
        end_leaves_.clear();
        for (std::uint32_t i = 0; i < sample_.size(); ++i) {
            if (seg_.ends[i] < sample_.rays.rays[i].tmax)
                for (const Crossing& c : sample_.crossings_of(i))
                    if (c.t <= seg_.ends[i]) key_of(c.prim, [&](std::uint32_t key) { end_leaves_.push_back(key); });
            ends_at_[i + 1] = static_cast<std::uint32_t>(end_leaves_.size());
        }
    }

    bool keep(const ModelNode& m, int depth) override {
        if (awaiting_) {  // a BVH that did not offer its leaf order
            abandoned_ = true;
            return false;
        }
        if (one_path_) return classify(m, depth);
        // This node's place in pre-order; the next one asked is past its subtree if it is dropped.
        node_ = cursor_;
        const bool kept = collect(m, depth);
        if (overlapping_ && !ranges_) cursor_ = kept ? node_ + 1 : order_->end.at(node_);
        return kept;
    }

    /// 5D trees classify rays instead of clipping them: a node is kept when some sample ray's
    /// 5D point falls in it, found as the probe follows each ray (classify_5d, beam_side).
    /// Nodes arrive in pre-order, so the one at `depth` is the next child of the last node kept
    /// one level up.
    bool classify(const ModelNode& m, int depth) {
        if (static_cast<std::size_t>(depth) + 1 >= paths_.size()) {
            paths_.resize(depth + 2);
            ordinal_.resize(depth + 2, 0);
            parent_.resize(depth + 2);
        }
        std::vector<std::uint32_t>& out = paths_[depth];
        out.clear();
        if (depth == 0) {
            points_.assign(sample_.size(), {});
            for (std::uint32_t i = 0; i < sample_.size(); ++i) {
                Point& p = points_[i];
                int k = 0;
                bool neg = false;
                double adk = 0;
                if (!model::classify_5d(sample_.rays.rays[i], m.region, p.x, k, neg, adk)) continue;
                p.cube = static_cast<std::uint32_t>(2 * k + (neg ? 1 : 0));
                out.push_back(i);
            }
        } else {
            const std::uint32_t side = ordinal_[depth]++;
            for (std::uint32_t i : paths_[depth - 1])
                if ((depth == 1 ? points_[i].cube : model::beam_side(parent_[depth - 1], points_[i].x)) == side)
                    out.push_back(i);
        }
        ordinal_[depth + 1] = 0;
        parent_[depth] = m;
        return !out.empty();
    }

    /// Fills the segments that reach the node at `depth` from its parent's (depth - 1) and
    /// says whether there are any. Depth first, the last list one level up is the parent's.
    bool collect(const ModelNode& m, int depth) {
        if (static_cast<std::size_t>(depth) >= by_depth_.size()) by_depth_.resize(depth + 1);
        std::vector<Reach>& out = by_depth_[depth];
        out.clear();
        // `s` clipped to the node's region (`met`: the region is met), and within it to its
        // bounding volume (`s`: what its children see, empty when the volume is not met).
        struct Clipped {
            bool met;
            Segment s;
        };
        auto clip = [&](std::uint32_t ray, Segment s) -> Clipped {
            s = clip_segment(seg_.inv[ray], m.region, s);
            if (s.empty()) return {false, s};
            if (m.has_bv) s = clip_segment(seg_.inv[ray], m.bv, s);
            return {true, s};
        };
        if (depth == 0) {
            for (std::uint32_t i = 0; i < seg_.inv.size(); ++i) {
                const Ray& ray = sample_.rays.rays[i];
                const Segment whole{ray.tmin, seg_.ends[i]}, line{ray.tmin, ray.tmax};
                // Without a hit known in advance, the whole ray.
                const bool free = overlapping_ && ends_at_[i] == ends_at_[i + 1];
                if (t_.gated) {
                    const Clipped c = clip(i, whole), f = overlapping_ ? clip(i, line) : c;
                    if (c.met || (free && f.met)) out.push_back({i, free ? f.s : c.s, f.s, free});
                } else {
                    Segment s = whole, full = line;  // every ray enters an ungated root
                    if (m.has_bv) s = clip_segment(seg_.inv[i], m.bv, s), full = clip_segment(seg_.inv[i], m.bv, full);
                    out.push_back({i, free ? full : s, full, free});
                }
            }
            return !out.empty();
        }
        bool any = false;
        for (const Reach& r : by_depth_[depth - 1]) {
            if (r.s.empty()) continue;  // met the parent's region, not its bounding volume
            if (!overlapping_) {
                const Clipped c = clip(r.ray, r.s);
                if (!c.met) continue;
                out.push_back({r.ray, c.s, c.s, false});
                any = true;
                continue;
            }
            const Clipped f = clip(r.ray, r.full);
            if (!f.met) continue;
            bool free = r.free;
            Segment s = f.s;
            if (!free) {
                const Clipped c = clip(r.ray, r.s);
                if (!c.met) continue;  // entered only past the ray's end: never searched
                // Off the path to the hit, a node entered before the ray's end may be searched
                // before the hit is known: on the whole ray.
                free = !on_hit_path(r.ray);
                if (!free) s = c.s;
            }
            out.push_back({r.ray, s, f.s, free});
            any = true;
        }
        return any;
    }

    /// Whether the node being asked holds the leaf where ray `i`'s closest hit is found.
    bool on_hit_path(std::uint32_t i) const {
        // The node's run of refs (leaf order), or its pre-order subtree.
        const std::uint32_t lo = ranges_ ? lo_ : node_, hi = ranges_ ? hi_ : order_->end[node_];
        for (std::uint32_t k = ends_at_[i]; k < ends_at_[i + 1]; ++k)
            if (end_leaves_[k] >= lo && end_leaves_[k] < hi) return true;
        return false;
    }

    const RaySample& sample_;
    const PreorderIndex* order_;
    bool one_path_ = false;
    bool overlapping_ = false;
    bool awaiting_ = false;   // a BVH: its leaf order is expected before its first node
    bool ranges_ = false;     // a BVH read with its leaf order: end keys are positions in refs
    bool abandoned_ = false;
    std::uint32_t lo_ = 0, hi_ = 0;  // the run of refs of the node asked (ranges_)
    std::uint32_t node_ = 0, cursor_ = 0;  // BVH: the node asked, and the next one's pre-order index
    std::vector<std::uint32_t> ends_at_;   // BVH: ray i's end leaves are end_leaves_[ends_at_[i], ends_at_[i + 1])
    std::vector<std::uint32_t> end_leaves_;  // BVH: each ray's end keys (leaf pre-order indices or refs positions)
    model::ReplaySegments seg_;
    std::vector<std::vector<Reach>> by_depth_;
    // 5D: each sample ray's point and cube; per depth, the rays in the node last kept there,
    // that node, and the number of its siblings seen so far.
    struct Point {
        double x[5] = {};
        std::uint32_t cube = ~0u;
    };
    std::vector<Point> points_;
    std::vector<std::vector<std::uint32_t>> paths_;
    std::vector<std::uint32_t> ordinal_;
    std::vector<ModelNode> parent_;
};

ModelTree reached_model_tree(const Hierarchy& h, const Scene& scene, const RaySample& sample) {
    {
        ModelTree t;
        ReachCollector c(t, sample, nullptr);
        h.emit_model(c);
        if (!c.abandoned()) return t;
    }
    // A BVH that does not offer its leaf order is read twice: once for where each node and
    // leaf lies (which nodes hold each ray's hit), then materialised.
    ModelTree t;
    PreorderIndex order(scene.size());
    h.emit_model(order);
    ReachCollector c(t, sample, order.read ? &order : nullptr);
    h.emit_model(c);
    return t;
}

}  // namespace

SegmentsPredictor::SegmentsPredictor(const Hierarchy& h, const Scene& scene, const RaySample& sample,
                                     std::size_t size, Via via)
    : h_(h), scene_(scene), sample_(sample), size_(size), via_(via) {}

void SegmentsPredictor::materialise() {
    if (materialised_) return;
    const auto start = std::chrono::steady_clock::now();
    // A tree of a few nodes and references per sample ray (a BVH) is reached nearly everywhere:
    // finding where the segments reach would repeat the replay's clipping for nothing, so it is
    // taken whole. (Not by nodes alone: a 5D tree's few thousand nodes may hold millions of
    // references, all copied by a whole tree.)
    std::size_t size = size_;
    if (size == 0) {
        const StructureStats st = h_.structure();
        size = st.interior + st.leaves + st.references;
    }
    whole_ = size <= kWholeItemsPerRay * std::max<std::size_t>(sample_.size(), 1);
    tree_ = whole_ ? h_.model_tree() : reached_model_tree(h_, scene_, sample_);
    materialised_ = true;
    tree_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

const ModelTree& SegmentsPredictor::tree() {
    materialise();
    return tree_;
}

namespace {

/// The prediction of a replay's counters: what the model tree's recursion reports, per ray.
Prediction replayed(const RayCounters& counters, std::size_t rays, const UnitCosts& costs) {
    Prediction p;
    p.cost = measured_cost(counters);
    p.scalar = costs.scalar(p.cost);
    const double n = counters.rays ? static_cast<double>(counters.rays) : 1.0;
    for (int d = 0; d < kMaxStatDepth; ++d) p.visits_by_depth.push_back(counters.visits[d] / n);
    while (!p.visits_by_depth.empty() && p.visits_by_depth.back() == 0) p.visits_by_depth.pop_back();
    p.preset = "exact";
    p.estimator = "segments";
    p.note = "probabilities from " + std::to_string(rays) +
             " sampled segments replayed through the hierarchy's traversal, each ending where its known crossings "
             "end it (no primitive tests)";
    return p;
}

}  // namespace

Prediction SegmentsPredictor::predict(std::span<const std::uint32_t> rays, const ModelOptions& opt,
                                      const UnitCosts& costs) {
    // (Not Query::All: a BVH's traversal that never ends walks a polygon's edges only up to the
    // nearest hit so far, where the model tree's probe walks them to the segment's end. Nor no
    // rays at all: the model tree still charges each ray the root's test.)
    if (via_ == Via::Traversal && opt.preset == Preset::Exact && opt.query != Query::All && !rays.empty()) {
        for (std::uint32_t i : rays)
            if (i >= sample_.size()) throw std::out_of_range("predict_segments: ray index beyond the sample");
        model::check_crossings_in_scene(sample_, rays, scene_.size());  // as the model tree's probe refuses it
        RayCounters counters;
        try {
            if (h_.replay(sample_, rays, opt.query, counters)) return replayed(counters, rays.size(), costs);
        } catch (const model::PrunedNodeReached&) {
            // A cell the hierarchy left unbuilt where its own sample did not reach: the model tree.
        }
    }
    materialise();
    if (!whole_) {
        try {
            return predict_segments(tree_, scene_, sample_, rays, opt, costs);
        } catch (const model::PrunedNodeReached&) {
            // A segment ran on past where the sample said its search ends (e.g. a query other
            // than the sample's): the whole tree, once, for this and every later prediction.
            const auto start = std::chrono::steady_clock::now();
            tree_ = h_.model_tree();
            whole_ = true;
            tree_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        }
    }
    return predict_segments(tree_, scene_, sample_, rays, opt, costs);
}

}  // namespace rtcost
