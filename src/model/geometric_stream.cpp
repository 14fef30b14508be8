// The geometric estimator: Cauchy-Crofton probabilities over the hierarchy's emitted tree, in
// one depth-first pass.
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "model_internal.hpp"
#include "rtcost/error.hpp"

namespace rtcost {

using namespace model;

/// The geometric estimator over an emitted tree (ModelSink), in one depth-first pass that keeps
/// only the open path: the recursion is linear in the children's costs, so each finished subtree
/// is summed up as its cost given that its root is visited, and a parent weights its children's
/// sums by their visit probabilities once all of them are in. No per-node array is made, so a
/// hierarchy of millions of nodes is read where it lies.
class GeometricStream final : public ModelSink {
public:
    GeometricStream(const Scene& scene, const ModelOptions& opt) : scene_(scene), opt_(opt) {}

    bool begin(const ModelFlags& f) override {
        flags_ = f;
        begun_ = true;
        paper_ = opt_.preset == Preset::Paper;
        terminate_ = terminates(f, opt_.query);
        // Each primitive's bounds, area and kind in scene order (the scene's summaries, or
        // computed here for a scene not finalized since it changed): the leaves list primitives
        // in an order that would make every lookup of their vertices a cache miss.
        sums_ = scene_.summaries();
        if (sums_.size() != scene_.size()) {
            own_sums_.resize(scene_.size());
            for (std::uint32_t id = 0; id < own_sums_.size(); ++id)
                own_sums_[id] = {scene_.prim_bounds(id), scene_.prim_area(id), scene_.kind(id)};
            sums_ = own_sums_;
        }
        return true;
    }

    void beam_node(const ModelNode& m, const ModelBeam& beam, std::span<const std::uint32_t> prims) override {
        beam_ = beam;  // read when the node is finished: a leaf at once
        node(m, prims);
    }

    void node(const ModelNode& m, std::span<const std::uint32_t> prims) override {
        Box3 visit = m.region;
        int tdepth = 0;
        if (top_ == 0 && !done_) root_region_ = m.region;
        if (top_ > 0) {
            const Open& parent = stack_[top_ - 1];
            visit = intersect(parent.gate, m.region);
            tdepth = parent.tdepth + (parent.m.step ? 1 : 0);
        } else if (done_) {
            throw std::logic_error("model tree: a second root");
        }
        if (top_ == stack_.size()) stack_.emplace_back();
        Open& o = stack_[top_++];
        o.m = m;
        o.visit = visit;
        o.gate = m.has_bv ? intersect(visit, m.bv) : visit;
        o.sv = surface(o.visit);
        o.sg = m.has_bv ? surface(o.gate) : o.sv;
        o.tdepth = tdepth;
        o.kids_done = 0;
        if (!m.leaf && o.kids.size() < m.count) o.kids.resize(m.count);
        if (m.step) max_tdepth_ = std::max(max_tdepth_, tdepth);
        if (m.leaf || m.count == 0) {
            finish(prims);
            // Close every ancestor whose last child this was.
            while (top_ > 0 && stack_[top_ - 1].kids_done == stack_[top_ - 1].m.count) finish({});
        }
    }

    Prediction result(const UnitCosts& costs) {
        if (!begun_ || !done_) throw InputError("model", 0, "this hierarchy has no model tree");
        if (top_ != 0) throw std::logic_error("model tree: the emission ended inside the tree");
        Prediction out;
        const Sums& r = root_.sums;
        CostVector& c = out.cost;
        c = r.c;
        out.visits_by_depth.assign(static_cast<std::size_t>(Sums::slot(max_tdepth_)) + 1, 0.0);
        for (int d = r.dlo; d < r.dhi; ++d) out.visits_by_depth[d] = r.depth[d];
        // Every ray pays the root's clip test; rays that meet the root pay the per-entry terms.
        c.box += flags_.per_ray_box;
        c.hop += flags_.per_entry_hop;
        out.scalar = costs.scalar(c);
        out.preset = paper_ ? "paper" : "exact";
        out.estimator = "geometric";
        out.note = flags_.one_path
                       ? "5D beams: probability of each beam under the line measure by numerical integration; ordered "
                         "candidates: P(search reaches j) = prod over earlier candidates of (1 - Crofton area / area of "
                         "the box around the leaf's candidates)"
                       : "P over several primitives: 1 - exp(-sum p_i), p_i = primitive area (both sides) x share of "
                         "its bounding box in the region / region area";
        return out;
    }

private:
    /// A finished subtree's expected operations given that its root is visited: the cost
    /// vector, leaf visits (each pays its descent again under `locate`) and steps per traversal
    /// depth, in [dlo, dhi) (depths past the counters' last, kMaxStatDepth - 1, are counted there).
    struct Sums {
        CostVector c;
        double leaf_visits = 0;
        int dlo = 0, dhi = 0;
        std::array<double, kMaxStatDepth> depth;  // only [dlo, dhi) is meaningful: nothing to clear
        static int slot(int d) { return std::min(d, kMaxStatDepth - 1); }
        void reset(int lo) {
            c = CostVector{};
            leaf_visits = 0;
            dlo = dhi = slot(lo);
        }
        void extend(int hi) {
            for (; dhi < hi; ++dhi) depth[dhi] = 0;
        }
        void add_depth(int d, double v) {
            d = slot(d);
            extend(d + 1);
            depth[d] += v;
        }
        /// this = wa * a + wb * b, from depth `lo` on (a's and b's depths start at or below it):
        /// a binary node's sums without clearing first.
        void weigh(const Sums& a, double wa, const Sums& b, double wb, int lo) {
            for (auto f : kCostFields) c.*f = wa * a.c.*f + wb * b.c.*f;
            for (int k = 0; k < kPrimKinds; ++k) c.prim[k] = wa * a.c.prim[k] + wb * b.c.prim[k];
            leaf_visits = wa * a.leaf_visits + wb * b.leaf_visits;
            dlo = slot(lo);
            dhi = std::max({dlo, a.dhi, b.dhi});
            for (int d = dlo; d < dhi; ++d)
                depth[d] = (d >= a.dlo && d < a.dhi ? wa * a.depth[d] : 0.0) +
                           (d >= b.dlo && d < b.dhi ? wb * b.depth[d] : 0.0);
        }
        /// this += w * o (o's depths start at or below this one's).
        void add(const Sums& o, double w) {
            add_scaled(c, o.c, w);
            leaf_visits += w * o.leaf_visits;
            extend(o.dhi);
            for (int d = o.dlo; d < o.dhi; ++d) depth[d] += w * o.depth[d];
        }
    };
    /// What a parent needs of a finished child.
    struct Done {
        double inside = 0;  // primitive (Crofton) area inside the child's visit region
        double sv = 0;      // surface of the child's visit region
        float p_hit = 0;
        Sums sums;
    };
    struct Open {
        ModelNode m;
        Box3 visit, gate;  // V(N): where a segment must pass for N to be visited; V within N's BV
        double sv = 0, sg = 0;
        int tdepth = 0;
        std::uint32_t kids_done = 0;
        std::vector<Done> kids;
    };

    /// Sums up the node on top of the stack (a leaf with `prims`, or a node whose children are
    /// all done), hands the result to its parent and pops it.
    void finish(std::span<const std::uint32_t> prims) {
        Open& o = stack_[top_ - 1];
        Done& d = top_ >= 2 ? stack_[top_ - 2].kids[stack_[top_ - 2].kids_done++] : root_;
        const ModelNode& m = o.m;
        Sums& S = d.sums;
        if (flags_.one_path) {
            finish_one_path(o, d, prims);
            return;
        }
        const double pg = !m.has_bv ? 1.0 : o.sv > 0 ? static_cast<float>(o.sg / o.sv) : 0.0f;
        double inside = 0;
        if (m.leaf) {
            S.reset(o.tdepth);
            for (std::uint32_t id : prims) {
                const PrimSummary& g = sums_[id];
                inside += crofton_area(scene_, id, g) * share_inside(g.bounds, o.visit);
                S.c.prim[static_cast<int>(g.kind)] += pg;
                S.c.polygon_edges += pg * scene_.edges_walked(id);
            }
            S.c.leaves += 1;
            if (m.count == 0) S.c.empty_leaves += 1;
            S.leaf_visits = 1;
            own(S, o, 1.0, pg, 0.0);
        } else {
            const std::uint32_t k = m.count;
            for (std::uint32_t x = 0; x < k; ++x) inside += o.kids[x].inside;
            if (m.axis >= 0 && k == 2) {
                const Done &b = o.kids[0], &cc = o.kids[1];
                const float alpha = o.sg > 0 ? static_cast<float>(1 - cc.sv / o.sg) : 0.0f;
                const float beta = o.sg > 0 ? static_cast<float>(1 - b.sv / o.sg) : 0.0f;
                const double both = std::max(0.0f, 1 - alpha - beta);
                const double pb = terminate_ ? b.p_hit : 0.0, pc = terminate_ ? cc.p_hit : 0.0;
                const double g = 0.5;  // isotropic lines: either side first with equal probability
                S.weigh(b.sums, pg * (alpha + both * (g + (1 - g) * (1 - pc))), cc.sums,
                        pg * (beta + both * ((1 - g) + g * (1 - pb))), o.tdepth);
            } else {
                // Bounding volume children (or any node without a plane): child X is entered when
                // the segment meets it and no sibling met before it has ended the search. Siblings
                // are taken in random order: E[prod over those before X of (1 - met_j P_j)]
                // averaged over the position of X, by elementary symmetric polynomials.
                handed_.resize(k);
                weight_.resize(k);
                for (std::uint32_t x = 0; x < k; ++x)
                    handed_[x] = o.sg > 0 ? static_cast<float>(o.kids[x].sv / o.sg) : 0.0f;
                for (std::uint32_t x = 0; x < k; ++x) {
                    double survive = 1.0;
                    if (terminate_ && k == 2) {
                        // The other child is before X half the time; with the node's own order
                        // for an any-hit query, as often as its side's directions (half the
                        // lines go each way along its axis).
                        double other_first = 0.5;
                        if (opt_.query == Query::Any && (m.any_order & kAnyOrderSet)) {
                            const int pos[3] = {0, 0, 0}, neg[3] = {1, 1, 1};
                            const double first_child_first = 0.5 * any_order_first_child_first(m.any_order, pos) +
                                                             0.5 * any_order_first_child_first(m.any_order, neg);
                            other_first = x == 0 ? 1 - first_child_first : first_child_first;
                        }
                        survive = 1 - other_first * handed_[1 - x] * o.kids[1 - x].p_hit;
                    } else if (terminate_ && k > 2) {
                        e_.assign(k, 0.0);  // e[j]: elementary symmetric polynomial of degree j
                        e_[0] = 1;
                        std::uint32_t used = 0;
                        for (std::uint32_t y = 0; y < k; ++y) {
                            if (y == x) continue;
                            const double sy = 1 - handed_[y] * o.kids[y].p_hit;
                            ++used;
                            for (std::uint32_t j = used; j > 0; --j) e_[j] += e_[j - 1] * sy;
                        }
                        // X at position j (0-based) has j random siblings before it: mean of
                        // e_j / C(k-1, j) over j = 0..k-1.
                        double sum = 0, binom = 1;
                        for (std::uint32_t j = 0; j < k; ++j) {
                            sum += e_[j] / binom;
                            binom = binom * (k - 1 - j) / (j + 1);
                        }
                        survive = sum / k;
                    }
                    weight_[x] = pg * handed_[x] * survive;
                }
                if (k == 2) {
                    S.weigh(o.kids[0].sums, weight_[0], o.kids[1].sums, weight_[1], o.tdepth);
                } else {
                    S.reset(o.tdepth);
                    for (std::uint32_t x = 0; x < k; ++x) S.add(o.kids[x].sums, weight_[x]);
                }
            }
            own(S, o, 1.0, pg, terminate_ ? o.kids[0].p_hit : 0.0);
        }
        d.inside = inside;
        d.sv = o.sv;
        // P is read only where a hit ends (part of) the search, or by the paper's Kaplan term.
        d.p_hit = inside > 0 && o.sv > 0 && (terminate_ || paper_) ? 1 - std::exp(static_cast<float>(-inside / o.sv))
                                                                   : 0.0f;
        --top_;
        if (top_ == 0) done_ = true;
    }

    /// A 5D classification node: its children are disjoint sets of rays, each taken with its
    /// share of the node's line-measure weight (`Done::inside` holds the weight here); a leaf's
    /// candidates are searched in order and the search may stop at each.
    void finish_one_path(const Open& o, Done& d, std::span<const std::uint32_t> prims) {
        const ModelNode& m = o.m;
        Sums& S = d.sums;
        S.reset(o.tdepth);
        double weight = 0;
        if (m.leaf) {
            weight = beam_weight(beam_, m.region, root_region_);
            // Ordered search: candidate j is tested unless an earlier one ended the search; each
            // earlier candidate is hit with p = its Crofton area over the surface of the box
            // around the leaf's candidates (an approximation: independence, no occlusion order).
            Box3 around;
            for (std::uint32_t id : prims) around.extend(sums_[id].bounds);
            const double sa = surface(around);
            std::array<double, kPrimKinds> tests{};
            double alive = 1, edges = 0;
            for (std::uint32_t id : prims) {
                const PrimSummary& g = sums_[id];
                tests[static_cast<int>(g.kind)] += alive;
                edges += alive * scene_.edges_walked(id);
                if (terminate_) alive *= 1 - (sa > 0 ? std::min(1.0, crofton_area(scene_, id, g) / sa) : 0.0);
                else S.c.prim[static_cast<int>(g.kind)] += 1;
            }
            if (terminate_)
                for (int k = 0; k < kPrimKinds; ++k) S.c.prim[k] += static_cast<float>(tests[k]);
            S.c.polygon_edges += edges;
            S.c.leaves += 1;
            if (m.count == 0) S.c.empty_leaves += 1;
        } else {
            for (std::uint32_t x = 0; x < m.count; ++x) weight += o.kids[x].inside;
            for (std::uint32_t x = 0; x < m.count; ++x)
                S.add(o.kids[x].sums, weight > 0 ? static_cast<float>(o.kids[x].inside / weight) : 0.0f);
        }
        own(S, o, 1.0, 1.0, 0.0);
        d.inside = weight;
        --top_;
        if (top_ == 0) done_ = true;
    }

    /// The node's own operations: once per visit, or, under `locate`, once per leaf visit below
    /// it (every cell is found by a descent from the root).
    void own(Sums& S, const Open& o, double p, double pg, double pb) {
        const ModelNode& m = o.m;
        const double times = flags_.locate && !m.leaf ? S.leaf_visits : p;
        const double gated = flags_.locate && !m.leaf ? times : pg;
        charge_visit(S.c, m, paper_ ? &flags_.paper : nullptr, times, gated, 0.5, pb);
        if (m.step) {
            S.c.steps += times;
            S.add_depth(o.tdepth, times);
        }
    }

    const Scene& scene_;
    ModelOptions opt_;
    ModelFlags flags_{ModelFamily::Bvh, {.entered_box = 1}};  // begin() sets the tree's own
    ModelBeam beam_;  // the directions of the last 5D node emitted
    bool paper_ = false, terminate_ = false, begun_ = false, done_ = false;
    std::span<const PrimSummary> sums_;
    std::vector<PrimSummary> own_sums_;
    std::vector<Open> stack_;
    std::size_t top_ = 0;
    Done root_;
    int max_tdepth_ = 0;
    std::vector<float> handed_;
    std::vector<double> weight_;
    Box3 root_region_;  // 5D: the root box, whose faces the lines enter through
    std::vector<double> e_;
};

Prediction predict_geometric(const ModelTree& t, const Scene& scene, const ModelOptions& opt, const UnitCosts& costs) {
    if (t.nodes.empty()) throw InputError("model", 0, "this hierarchy has no model tree");
    GeometricStream g(scene, opt);
    emit_model(t, g);
    return g.result(costs);
}

Prediction predict_geometric(const Hierarchy& h, const ModelOptions& opt, const UnitCosts& costs) {
    GeometricStream g(h.scene(), opt);
    h.emit_model(g);
    return g.result(costs);
}

}  // namespace rtcost
