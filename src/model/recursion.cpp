// The model's recursion over a materialised tree, evaluated as visit probabilities; the
// presets' node costs.
#include <cmath>

#include "model_internal.hpp"

namespace rtcost::model {

/// Adds the operations of one visit of `m` to `c`, scaled by `p` (visits) and `pg` (visits that
/// pass the node's bounding volume): the node's own operations, or with `paper` the charges the
/// hierarchy declared for the paper's formula. `gamma` and `pb` (P of the first child, 0 without
/// termination) enter the Kaplan/Glassner far-entry term only.
void charge_visit(CostVector& c, const ModelNode& m, const PaperCharges* paper, double p, double pg, double gamma,
                  double pb) {
    if (!paper) {
        c.box += p * m.box;
        c.plane += pg * m.plane;
        c.hop += pg * m.hop;
        c.classify += pg * m.classify;
        return;
    }
    c.box += p * paper->entered_box;
    if (m.leaf) return;
    c.plane += p * paper->interior_plane;
    c.hop += p * paper->interior_hop;
    c.classify += p * paper->interior_classify;
    c.box += p * (paper->far_entry ? gamma * (1 - pb) + (1 - gamma) : paper->interior_box);
}

/// The sampled estimator's recursion: q(child | parent visited) for every node from per-node
/// probabilities counted by the probe (the recursion's coefficients), then pi and the cost vector.
Prediction recurse(const ModelTree& t, const Walk& w, const std::vector<NodeProbabilities>& prob, const Scene& scene,
                   const ModelOptions& opt, const UnitCosts& costs) {
    const std::size_t n = t.nodes.size();
    const bool terminate = terminates(t, opt.query);
    const bool paper = opt.preset == Preset::Paper;
    std::vector<double> pi(n, 0.0);
    pi[0] = 1.0;
    Prediction out;
    CostVector& c = out.cost;
    auto add_visit = [&](int depth, double p) {
        if (depth >= static_cast<int>(out.visits_by_depth.size())) out.visits_by_depth.resize(depth + 1, 0.0);
        out.visits_by_depth[depth] += p;
    };
    auto charge = [&](const ModelNode& m, double p, double pg, std::size_t i) {
        const double pb = paper && terminate && !m.leaf ? prob[m.first].p_hit : 0.0;
        charge_visit(c, m, paper ? &t.paper : nullptr, p, pg, prob[i].gamma, pb);
    };

    // Primitive kinds: scenes of one kind (most meshes) need no look-up per reference; an array
    // of the scene's kinds (a look-up in scene.prims would miss the cache) costs a pass over the
    // scene, more than a prediction from a sample that reaches a few leaves.
    const auto counts = scene.kind_counts();
    int only = -1;
    for (int k = 0; k < kPrimKinds; ++k)
        if (counts[k] == scene.size() && scene.size() > 0) only = k;
    const bool walks = walks_edges(scene);
    std::vector<std::uint8_t> kind;
    if (only < 0) {
        kind.resize(scene.size());
        for (std::uint32_t id = 0; id < kind.size(); ++id) kind[id] = static_cast<std::uint8_t>(scene.kind(id));
    }
    for (std::size_t i = 0; i < n; ++i) {
        const ModelNode& m = t.nodes[i];
        const NodeProbabilities& q = prob[i];
        const double p = pi[i];
        const double pg = p * (m.has_bv ? q.p_bv : 1.0);
        if (!(t.locate && !m.leaf)) {
            charge(m, p, pg, i);
            if (m.step) {
                c.steps += p;
                add_visit(w.tdepth[i], p);
            }
        }
        if (m.leaf) {
            c.leaves += p;
            if (m.count == 0) c.empty_leaves += p;
            if (terminate && q.ordered) {
                for (int k = 0; k < kPrimKinds; ++k) c.prim[k] += pg * q.tests[k];
                if (walks) c.polygon_edges += pg * visit_edges(t, m, scene, q, q.tests[static_cast<int>(PrimKind::Polygon)]);
            } else {
                if (only >= 0) {
                    c.prim[only] += pg * m.count;
                } else {
                    for (std::uint32_t k = 0; k < m.count; ++k) c.prim[kind[t.prims[m.first + k]]] += pg;
                }
                if (walks) c.polygon_edges += pg * visit_edges(t, m, scene, q);
            }
            if (t.locate) {
                // Every cell is found by a descent from the root: its ancestors' work again.
                for (int a = w.parent[i]; a >= 0; a = w.parent[a]) {
                    const ModelNode& am = t.nodes[a];
                    charge(am, p, p, static_cast<std::size_t>(a));
                    if (am.step) {
                        c.steps += p;
                        add_visit(w.tdepth[a], p);
                    }
                }
            }
            continue;
        }
        // Children's conditional visit probabilities.
        if (t.one_path) {
            // Disjoint sets of rays: each ray goes to exactly one child, no sibling can stop it.
            for (std::uint32_t k = 0; k < m.count; ++k) pi[m.first + k] = pg * prob[m.first + k].handed;
        } else if (q.split) {
            const std::uint32_t b = m.first, cc = m.first + 1;
            const double both = q.both;
            auto p_end = [&](std::uint32_t x) { return prob[x].p_first >= 0 ? prob[x].p_first : prob[x].p_hit; };
            const double pb = terminate ? p_end(b) : 0.0, pc = terminate ? p_end(cc) : 0.0;
            double g = q.gamma;
            pi[b] = pg * (q.alpha + both * (g + (1 - g) * (1 - pc)));
            pi[cc] = pg * (q.beta + both * ((1 - g) + g * (1 - pb)));
        } else {
            // Children of any other node: the share of the parent's visits that entered each, as
            // the sampled estimator's probe counted it (no order of the siblings to assume).
            for (std::uint32_t x = 0; x < m.count; ++x)
                pi[m.first + x] = pg * std::max(0.0f, prob[m.first + x].entered);
        }
    }
    // Every ray pays the root's clip test; rays that meet the root pay the per-entry terms.
    c.box += t.per_ray_box;
    c.hop += t.per_entry_hop * pi[0];
    out.scalar = costs.scalar(c);
    out.preset = paper ? "paper" : "exact";
    return out;
}

/// The share of rays that meet the root: the recursion predicts per ray that does; every ray
/// still pays the root test.
void scale_to_share(Prediction& p, const ModelTree& t, double share, const UnitCosts& costs) {
    CostVector& c = p.cost;
    c.box -= t.per_ray_box;
    for (auto f : kCostFields) c.*f *= share;
    for (auto& v : c.prim) v *= share;
    for (auto& v : p.visits_by_depth) v *= share;
    c.box += t.per_ray_box;
    p.scalar = costs.scalar(c);
}

}  // namespace rtcost::model
