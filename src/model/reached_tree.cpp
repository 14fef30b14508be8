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
#include "rtcost/sample.hpp"

namespace rtcost {

namespace {

/// A segment of one sample ray, as far as it reaches into the node being emitted.
struct Reach {
    std::uint32_t ray;
    Segment s;
};

/// Materialises an emitted tree like Hierarchy::model_tree, but stands a subtree that none of
/// the sample's segments meets by a pruned empty leaf (its nodes are read and dropped). Which
/// segments reach a node is found the way the probe finds it: the parent's segment (clipped to
/// the parent's bounding volume) clipped to the child's region.
class ReachCollector final : public ModelCollector {
public:
    ReachCollector(ModelTree& t, const RaySample& sample) : ModelCollector(t), sample_(sample) {}

    bool begin(const ModelFlags& f) override {
        ModelCollector::begin(f);
        one_path_ = f.one_path;
        if (!one_path_) seg_ = model::ReplaySegments(sample_, f.cull);
        return true;
    }

private:
    bool keep(const ModelNode& m, int depth) override { return one_path_ ? classify(m, depth) : collect(m, depth); }

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
        auto add = [&](std::uint32_t ray, Segment s) {
            s = clip_segment(seg_.inv[ray], m.region, s);
            if (s.empty()) return;
            // The node's children see the segment within its bounding volume.
            if (m.has_bv) s = clip_segment(seg_.inv[ray], m.bv, s);
            out.push_back({ray, s});
        };
        if (depth == 0) {
            for (std::uint32_t i = 0; i < seg_.inv.size(); ++i) {
                const Segment whole{sample_.rays.rays[i].tmin, seg_.ends[i]};
                if (t_.gated) {
                    add(i, whole);
                } else {
                    Segment s = whole;  // every ray enters an ungated root
                    if (m.has_bv) s = clip_segment(seg_.inv[i], m.bv, s);
                    out.push_back({i, s});
                }
            }
            return !out.empty();
        }
        bool any = false;
        for (const Reach& r : by_depth_[depth - 1]) {
            if (r.s.empty()) continue;  // met the parent's region, not its bounding volume
            const std::size_t before = out.size();
            add(r.ray, r.s);
            any |= out.size() > before;
        }
        return any;
    }

    const RaySample& sample_;
    bool one_path_ = false;
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

ModelTree reached_model_tree(const Hierarchy& h, const RaySample& sample) {
    ModelTree t;
    ReachCollector c(t, sample);
    h.emit_model(c);
    return t;
}

}  // namespace

SegmentsPredictor::SegmentsPredictor(const Hierarchy& h, const Scene& scene, const RaySample& sample,
                                     std::size_t nodes)
    : h_(h), scene_(scene), sample_(sample) {
    const auto start = std::chrono::steady_clock::now();
    // A tree of a few nodes per sample ray (a BVH) is reached nearly everywhere: finding where
    // the segments reach would repeat the replay's clipping for nothing, so it is taken whole.
    if (nodes == 0) {
        const StructureStats st = h.structure();
        nodes = st.interior + st.leaves;
    }
    whole_ = nodes <= kWholeNodesPerRay * std::max<std::size_t>(sample.size(), 1);
    tree_ = whole_ ? h.model_tree() : reached_model_tree(h, sample);
    tree_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

Prediction SegmentsPredictor::predict(std::span<const std::uint32_t> rays, const ModelOptions& opt,
                                      const UnitCosts& costs) {
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
