// The model's cost of one ray: the recursion along the ray's own path through the model tree,
// with the probabilities that the search has ended learned from a sample (segments estimator).
// A per-pixel map of it shows where the model's termination probabilities mislead it (a
// measured map beside it shows the truth).
#include <algorithm>
#include <array>
#include <utility>

#include "model_internal.hpp"
#include "rtcost/error.hpp"
#include "rtcost/sample.hpp"

namespace rtcost {
using namespace model;

struct RayCostModel::Impl {
    ModelTree tree;
    const Scene* scene = nullptr;
    std::vector<NodeProbabilities> prob;
    std::vector<int> parent;
    bool terminate = false;
    bool walks = false;      // some primitive's test walks polygon edges (walks_edges)
    bool any_query = false;  // an any-hit query (its own child order where the tree declares one)

    // P that the search has ended in node x, where the recursion uses it: first of two met
    // (p_first), else of all its visits (p_hit).
    double p_end(std::uint32_t x) const { return prob[x].p_first >= 0 ? prob[x].p_first : prob[x].p_hit; }

    void charge(CostVector& c, const ModelNode& m, double p, double pg) const {
        charge_visit(c, m, nullptr, p, pg, 0.5, 0.0);
        if (m.step) c.steps += p;
    }

    // The node reached with probability p, its segment `seg` (not cut by any hit: where the
    // search ends is the model's to say).
    void visit(const RayInv& ri, std::uint32_t node, Segment seg, double p, CostVector& c) const {
        if (!(p > 0)) return;
        const ModelNode& m = tree.nodes[node];
        const NodeProbabilities& q = prob[node];
        Segment s = seg;
        if (m.has_bv) s = clip_segment(ri, m.bv, s);
        const double pg = s.empty() ? 0.0 : p;
        if (!(tree.locate && !m.leaf)) charge(c, m, p, pg);
        if (m.leaf) {
            c.leaves += p;
            if (m.count == 0) c.empty_leaves += p;
            double learned = 0;
            for (float t : q.tests) learned += t;
            // A leaf no sampled ray reached has no learned test count: all its primitives.
            if (terminate && q.ordered && learned > 0) {
                for (int k = 0; k < kPrimKinds; ++k) c.prim[k] += pg * q.tests[k];
                if (walks) c.polygon_edges += pg * visit_edges(tree, m, *scene, q, q.tests[static_cast<int>(PrimKind::Polygon)]);
            } else {
                for (std::uint32_t k = 0; k < m.count; ++k)
                    c.prim[static_cast<int>(scene->kind(tree.prims[m.first + k]))] += pg;
                if (walks) c.polygon_edges += pg * visit_edges(tree, m, *scene, q);
            }
            if (tree.locate)  // each cell is found by a descent from the root
                for (int a = parent[node]; a >= 0; a = parent[a]) charge(c, tree.nodes[a], p, p);
            return;
        }
        if (s.empty()) return;
        // Children met, nearest entry first where the traversal orders them (ties as the probe
        // breaks them); each later one is reached only if the search has not ended before it.
        std::array<std::pair<float, std::uint32_t>, 64> met;
        std::array<Segment, 64> segs;
        std::size_t nm = 0;
        for (std::uint32_t k = 0; k < m.count && nm < met.size(); ++k) {
            const Segment sc = clip_segment(ri, tree.nodes[m.first + k].region, s);
            if (!meets(tree, s, sc)) continue;
            segs[k] = sc;
            met[nm++] = {sc.t0, k};
        }
        const bool leaves_first = any_query && tree.occlusion_order == OcclusionOrder::LeavesFirst;
        if (any_query && (m.any_order & kAnyOrderSet)) {  // the node's own order (bvh-design's)
            if (nm == 2 && !any_order_first_child_first(m.any_order, ri.neg)) std::swap(met[0], met[1]);
        } else if (any_query && tree.occlusion_order == OcclusionOrder::Stored) {
            // stored order: as met
        } else if (tree.cull && m.count == 2 && !leaves_first)  // a binary node's tie: the first child
            std::stable_sort(met.begin(), met.begin() + nm, [](auto& a, auto& b) { return a.first < b.first; });
        else if (tree.cull || leaves_first)
            sort_children_met({met.data(), nm}, tree, m.first, leaves_first);
        double reach = pg;
        for (std::size_t i = 0; i < nm; ++i) {
            const std::uint32_t child = m.first + met[i].second;
            visit(ri, child, segs[met[i].second], reach, c);
            if (terminate) reach *= 1.0 - p_end(child);
        }
    }
};

RayCostModel::RayCostModel(ModelTree tree, const Scene& scene, const RaySample& sample,
                           std::span<const std::uint32_t> rays, const ModelOptions& opt) {
    auto impl = std::make_shared<Impl>();
    impl->prob = segment_probabilities(tree, scene, sample, rays, opt);
    const Walk w(tree);
    impl->parent = w.parent;
    impl->terminate = terminates(tree, opt.query);
    impl->any_query = opt.query == Query::Any;
    impl->tree = std::move(tree);
    impl->scene = &scene;
    impl->walks = walks_edges(scene);
    for (const ModelNode& m : impl->tree.nodes)
        if (!m.leaf && m.count > 64)
            throw InputError("model", 0, "a node with more than 64 children has no per-ray prediction");
    impl_ = std::move(impl);
}

CostVector RayCostModel::predict(const Ray& ray) const {
    const Impl& im = *impl_;
    CostVector c;
    c.box += im.tree.per_ray_box;  // every ray pays the root's clip test
    const RayInv ri(ray);
    const Segment whole{ray.tmin, ray.tmax};
    const Segment root = im.tree.gated ? clip_segment(ri, im.tree.nodes[0].region, whole) : whole;
    if (root.empty()) return c;
    c.hop += im.tree.per_entry_hop;
    im.visit(ri, 0, root, 1.0, c);
    return c;
}

}  // namespace rtcost
