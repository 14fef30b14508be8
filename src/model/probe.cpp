// The sampled estimator: a probe traversal of the model tree with real primitive tests counts
// each node's coefficients; the recursion predicts from them.
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "hierarchy/common/impl.hpp"
#include "model_internal.hpp"
#include "rtcost/error.hpp"
#include "rtcost/sample.hpp"

namespace rtcost::model {

namespace {

/// How a probe learns what a primitive test would find: a real test (the sampled estimator), or
/// a look-up in the ray's crossings known from its sample (the segments estimator: no
/// intersection is computed, whatever the hierarchy).
class PrimOracle {
public:
    explicit PrimOracle(const Scene& s) : s_(s) {}
    PrimOracle(const Scene& s, const RaySample& sample, std::span<const std::uint32_t> index)
        : s_(s), sample_(&sample), index_(index) {
        check_crossings_in_scene(sample, index, s.size());
    }
    /// Ray `i` of the probe's rays starts.
    void begin(std::size_t i) {
        if (sample_) known_ = KnownCrossings(sample_->crossings_of(index_[i]));
    }
    void end() { known_ = {}; }
    /// test_prim's answer: records a hit nearer than `hit.t`.
    bool test(std::uint32_t id, const Ray& ray, Hit& hit) {
        if (!sample_) return test_prim(s_, id, ray, hit, nc_);
        // A ray's crossings are a few (at most kMaxCrossings): a filter and a scan beat a table
        // over the scene's primitives, which cost a pass over the scene per prediction.
        return known_.hit(id, ray, hit);
    }

private:
    const Scene& s_;
    const RaySample* sample_ = nullptr;
    std::span<const std::uint32_t> index_;
    KnownCrossings known_;  // the current ray's crossings
    NoCount nc_;
};

Prediction predict_one_path(const ModelTree& t, const Walk& w, const Scene& scene, std::span<const Ray> training,
                            PrimOracle& oracle, const ModelOptions& opt, const UnitCosts& costs) {
    const std::size_t n = t.nodes.size();
    std::vector<double> handed(n, 0.0);
    std::vector<std::array<double, kPrimKinds>> tests(n, std::array<double, kPrimKinds>{});
    std::vector<double> edges(n, 0.0);
    const bool walks = walks_edges(scene);
    const Box3& root = t.nodes[0].region;
    const bool terminate = terminates(t, opt.query);
    std::size_t met = 0;
    for (std::size_t r = 0; r < training.size(); ++r) {
        const Ray& ray = training[r];
        double x[5];
        int k = 0;
        bool neg = false;
        double adk = 0;
        if (!classify_5d(ray, root, x, k, neg, adk)) continue;
        ++met;
        std::uint32_t node = 0;
        handed[0] += 1;
        node = t.nodes[0].first + static_cast<std::uint32_t>(2 * k + (neg ? 1 : 0));
        for (;;) {
            handed[node] += 1;
            const ModelNode& m = t.nodes[node];
            if (m.pruned) throw PrunedNodeReached{};  // a tree reached by other rays (reached_tree.cpp)
            if (m.leaf) break;
            node = m.first + beam_side(m, x);
        }
        // The ordered search, with real tests: a candidate starting beyond the nearest hit so
        // far is not tested (closest), the first hit ends it (any).
        const ModelNode& leaf = t.nodes[node];
        const double so = neg ? -double(ray.o[k]) : double(ray.o[k]);
        Hit hit;
        oracle.begin(r);
        for (std::uint32_t c = 0; c < leaf.count; ++c) {
            std::uint32_t id = t.prims[leaf.first + c];
            const double stop = terminate ? search_stop(so, std::min(hit.t, ray.tmax), adk, t.stop_margin) : kInf;
            if (forward_start(scene.prim_bounds(id), k, neg, t.search_pad) > stop) break;
            tests[node][static_cast<int>(scene.kind(id))] += 1;
            if (walks) edges[node] += scene.edges_walked(id, up_to_hit(ray, hit));
            if (oracle.test(id, ray, hit) && terminate && opt.query == Query::Any) break;
        }
        oracle.end();
    }
    std::vector<NodeProbabilities> prob(n);
    for (std::size_t i = 0; i < n; ++i) {
        const ModelNode& m = t.nodes[i];
        if (m.leaf) {
            prob[i].ordered = true;
            for (int k = 0; k < kPrimKinds; ++k) prob[i].tests[k] = handed[i] > 0 ? tests[i][k] / handed[i] : 0.0;
            prob[i].edges = handed[i] > 0 ? static_cast<float>(edges[i] / handed[i]) : -1.0f;
            continue;
        }
        for (std::uint32_t k = 0; k < m.count; ++k)
            prob[m.first + k].handed = handed[i] > 0 ? handed[m.first + k] / handed[i] : 0.0;
    }
    Prediction p = recurse(t, w, prob, scene, opt, costs);
    p.note = "5D: path probabilities and ordered-search lengths from a probe traversal of " +
             std::to_string(training.size()) + " rays";
    scale_to_share(p, t, training.empty() ? 0.0 : double(met) / double(training.size()), costs);
    return p;
}

/// The sampled estimator's probe traversal: walks the model tree with each training ray the way
/// the hierarchy's traversal does -- children front to back, real primitive tests, the query's
/// rule for ending -- and tallies per node what the recursion's coefficients are made of. The
/// recursion then reproduces the training rays' operation counts; its error on other rays is
/// that of the sample.
class Probe {
public:
    struct Tally {
        double handed = 0, gated = 0;                  // segments handed to the node; past its BV
        double left = 0, right = 0, both = 0, left_first = 0;  // a two-child node's children met
        double ended = 0;                              // visits after which nothing beyond was searched
        double first = 0, first_ends = 0;              // visited first of two met; and that ended it
        std::array<double, kPrimKinds> tests{};        // primitive tests in a leaf's visits
        double edges = 0;                              // polygon edges those tests walked
    };

    Probe(const ModelTree& t, const Scene& s, PrimOracle& oracle, Query q)
        : t_(t), s_(s), oracle_(oracle), any_(q == Query::Any), cull_(q == Query::Closest && t.cull),
          cuts_(cull_ && t.family != ModelFamily::Kd), walks_(walks_edges(s)), tally_(t.nodes.size()) {}

    /// One training ray; false when it misses the root.
    bool run(const Ray& ray) {
        ray_ = &ray;
        ri_ = RayInv(ray);
        hit_ = Hit{};
        found_ = false;
        leaf_t1_ = kInf;
        const Segment whole{ray.tmin, ray.tmax};
        const Segment root = t_.gated ? clip_segment(ri_, t_.nodes[0].region, whole) : whole;
        if (root.empty()) return false;
        visit(0, root);
        return true;
    }

    const std::vector<Tally>& tally() const { return tally_; }

private:
    // Nothing more is searched: an any-hit query has its hit.
    bool done() const { return any_ && found_; }
    // A closest-hit traversal skips a segment that starts at or beyond the nearest hit so far (a
    // kd-tree's never does: it stops at the leaf that holds the hit, kd_ends).
    bool beyond(const Segment& s) const { return cuts_ && s.t0 >= bound(); }
    // A kd-tree's traversal ends after a cell whose segment ends at `t1` once the nearest hit's
    // bound lies inside it (kd::KdTree).
    bool kd_ends(float t1) const { return found_ && bound() <= t1; }
    // What the traversal culls by: the nearest hit, or a little beyond it (ModelFlags::cull_widened).
    float bound() const { return t_.cull_widened ? cull_bound(hit_.t) : hit_.t; }
    // A child's segment, cut at the nearest hit so far when the traversal culls by it; empty
    // where the traversal does not enter it (model::meets), and where it starts at or beyond
    // that hit: no traversal enters a region there (a BVH pops it, a subdivision has stopped at
    // the cell before), and a region that begins in the hit's plane (gears' coplanar faces)
    // is not entered either. A kd-tree's traversal cuts nothing: its cells' segments are
    // whole, and it ends at a leaf (kd_ends).
    Segment child(std::uint32_t c, const Segment& s) const {
        Segment x = clip_segment(ri_, t_.nodes[c].region, s);
        if (cuts_ && bound() < x.t1) x.t1 = bound();
        if (!meets(t_, s, x) || beyond(x)) x = Segment{kInf, -kInf};
        return x;
    }

    void visit(std::uint32_t node, Segment s) {
        const ModelNode& m = t_.nodes[node];
        if (m.pruned) throw PrunedNodeReached{};
        Tally& ty = tally_[node];
        ty.handed += 1;
        if (m.has_bv) {
            s = clip_segment(ri_, m.bv, s);
            if (s.empty()) return;
        }
        ty.gated += 1;
        if (m.leaf) {
            leaf_t1_ = s.t1;
            for (std::uint32_t k = 0; k < m.count; ++k) {
                const std::uint32_t id = t_.prims[m.first + k];
                ty.tests[static_cast<int>(s_.kind(id))] += 1;
                if (walks_) ty.edges += s_.edges_walked(id, up_to_hit(*ray_, hit_));
                if (oracle_.test(id, *ray_, hit_)) {
                    found_ = true;
                    if (any_) break;
                }
            }
        } else if (m.count == 2) {
            const Segment sl = child(m.first, s), sr = child(m.first + 1, s);
            const bool l = !sl.empty(), r = !sr.empty();
            if (l && r) {
                ty.both += 1;
                // Nearer entry first, a tie (a ray starting inside both) to the first child; a
                // BVH without order: stored order. A kd-tree's traversal takes the side the ray
                // comes from first (by its direction), so a tie there goes to that side: a ray
                // entering a cell split one float beside a face it hits (kd-sah's planes) meets
                // both sides at once, and the thin side holding the face ends the search.
                bool left_first = !t_.cull || sl.t0 <= sr.t0;
                if (t_.cull && sl.t0 == sr.t0 && t_.family == ModelFamily::Kd && m.axis >= 0 && m.axis < 3 &&
                    std::fabs(ri_.inv[m.axis]) < kInf)
                    left_first = !ri_.neg[m.axis];
                if (any_ && t_.occlusion_order == OcclusionOrder::LeavesFirst) {
                    const bool ll = t_.nodes[m.first].leaf, lr = t_.nodes[m.first + 1].leaf;
                    left_first = ll != lr ? ll : sl.t0 < sr.t0;
                }
                if (any_ && t_.occlusion_order == OcclusionOrder::Stored) left_first = true;
                if (any_ && (m.any_order & kAnyOrderSet)) left_first = any_order_first_child_first(m.any_order, ri_.neg);
                ty.left_first += left_first;
                const std::uint32_t near = left_first ? m.first : m.first + 1;
                const Segment& far = left_first ? sr : sl;
                tally_[near].first += 1;
                visit(near, left_first ? sl : sr);
                bool ends = done() || beyond(far);
                // A kd-tree's traversal widens the near side's end by a relative 4e-7 against
                // rounding (kd::KdTree), so a hit that far past the plane (a face lying in it)
                // ends the search before the far side, unless its cull_bound lies beyond. Not for
                // a ray in the plane: both sides then cover the same stretch, and the traversal
                // searches both.
                if (!ends && cull_ && t_.family == ModelFamily::Kd && m.axis >= 0 && m.axis < 3 &&
                    std::fabs(ri_.inv[m.axis]) < kInf) {
                    // The traversal decides at the last leaf it searched, whose segment kd-median's
                    // node boxes may have narrowed below the near side's.
                    ends = kd_ends(leaf_t1_ * (leaf_t1_ > 0 ? 1.0000004f : 0.9999996f));
                }
                tally_[near].first_ends += ends;
                if (!ends) visit(left_first ? m.first + 1 : m.first, far);
            } else if (l) {
                ty.left += 1;
                visit(m.first, sl);
            } else if (r) {
                ty.right += 1;
                visit(m.first + 1, sr);
            }
        } else {
            // More children (Goldsmith-Salmon's BVH): those met, nearest entry first.
            std::array<std::pair<float, std::uint32_t>, 64> met;
            std::size_t nm = 0;
            for (std::uint32_t k = 0; k < m.count && nm < met.size(); ++k) {
                const Segment sc = child(m.first + k, s);
                if (!sc.empty()) met[nm++] = {sc.t0, m.first + k};
            }
            const bool leaves_first = any_ && t_.occlusion_order == OcclusionOrder::LeavesFirst;
            if ((t_.cull || leaves_first) && !(any_ && t_.occlusion_order == OcclusionOrder::Stored))
                sort_children_met({met.data(), nm}, t_, 0, leaves_first);
            for (std::size_t k = 0; k < nm && !done(); ++k) {
                const Segment sc = child(met[k].second, s);
                if (!beyond(sc)) visit(met[k].second, sc);
            }
        }
        ty.ended += done() || (cull_ && (cuts_ ? hit_.t <= s.t1 : kd_ends(s.t1)));
    }

    const ModelTree& t_;
    const Scene& s_;
    PrimOracle& oracle_;
    const bool any_, cull_;
    const bool cuts_;   // culling cuts segments at the nearest hit (all but kd-trees)
    const bool walks_;  // some polygon's test walks edges (walks_edges)
    std::vector<Tally> tally_;
    const Ray* ray_ = nullptr;
    RayInv ri_{Ray{}};
    Hit hit_;
    bool found_ = false;
    float leaf_t1_ = kInf;  // the segment's end in the last leaf searched
};

}  // namespace

}  // namespace rtcost::model

namespace rtcost {
using namespace model;

namespace {

/// Probes `rays` (through `oracle`) and turns the tallies into the recursion's coefficients;
/// `met` counts the rays that meet the root. Not for 5D trees (predict_one_path).
std::vector<NodeProbabilities> probe_probabilities(const ModelTree& t, const Scene& scene, std::span<const Ray> rays,
                                                   PrimOracle& oracle, const ModelOptions& opt, std::size_t& met) {
    const std::size_t n = t.nodes.size();
    Probe probe(t, scene, oracle, opt.query);
    met = 0;
    for (std::size_t r = 0; r < rays.size(); ++r) {
        oracle.begin(r);
        met += probe.run(rays[r]);
        oracle.end();
    }
    const auto& tally = probe.tally();
    std::vector<NodeProbabilities> prob(n);
    for (std::size_t i = 0; i < n; ++i) {
        const ModelNode& m = t.nodes[i];
        const Probe::Tally& ty = tally[i];
        NodeProbabilities& q = prob[i];
        q.p_bv = ty.handed > 0 ? ty.gated / ty.handed : 0.0;
        q.p_hit = ty.gated > 0 ? ty.ended / ty.gated : 0.0;
        // P conditioned the way the recursion uses it: this node first, its sibling still ahead.
        if (ty.first > 0) q.p_first = ty.first_ends / ty.first;
        if (m.leaf) {
            // Tests per visit: all of the leaf's, but an any-hit query stops at its first hit.
            q.ordered = true;
            for (int k = 0; k < kPrimKinds; ++k) q.tests[k] = ty.gated > 0 ? ty.tests[k] / ty.gated : 0.0;
            q.edges = ty.gated > 0 ? static_cast<float>(ty.edges / ty.gated) : -1.0f;
            continue;
        }
        if (m.count == 2) {
            q.split = true;
            q.alpha = ty.gated > 0 ? ty.left / ty.gated : 0.0;
            q.beta = ty.gated > 0 ? ty.right / ty.gated : 0.0;
            q.both = ty.gated > 0 ? ty.both / ty.gated : 0.0;
            q.gamma = ty.both > 0 ? ty.left_first / ty.both : 0.5;
        } else {
            // The probe knows which children were entered after the earlier ones: no order to assume.
            for (std::uint32_t k = 0; k < m.count; ++k)
                prob[m.first + k].entered = ty.gated > 0 ? tally[m.first + k].handed / ty.gated : 0.0;
        }
    }
    return prob;
}

/// Either estimator: probe `rays` (through `oracle`), turn the tallies into the recursion's
/// coefficients, predict.
Prediction predict_probed(const ModelTree& t, const Scene& scene, std::span<const Ray> rays, PrimOracle& oracle,
                          const ModelOptions& opt, const UnitCosts& costs) {
    if (t.nodes.empty()) throw InputError("model", 0, "this hierarchy has no model tree");
    Walk w(t);
    if (t.one_path) return predict_one_path(t, w, scene, rays, oracle, opt, costs);
    std::size_t met = 0;
    const std::vector<NodeProbabilities> prob = probe_probabilities(t, scene, rays, oracle, opt, met);
    Prediction p = recurse(t, w, prob, scene, opt, costs);
    scale_to_share(p, t, rays.empty() ? 0.0 : static_cast<double>(met) / rays.size(), costs);
    return p;
}

}  // namespace

Prediction predict_sampled(const ModelTree& t, const Scene& scene, std::span<const Ray> training,
                           const ModelOptions& opt, const UnitCosts& costs) {
    PrimOracle real(scene);
    Prediction p = predict_probed(t, scene, training, real, opt, costs);
    p.estimator = "sampled";
    p.note = "probabilities from a probe traversal of " + std::to_string(training.size()) +
             " training rays with real primitive tests" + (t.one_path ? " (5D: " + p.note + ")" : "");
    return p;
}

namespace model {
std::vector<NodeProbabilities> segment_probabilities(const ModelTree& t, const Scene& scene, const RaySample& sample,
                                                     std::span<const std::uint32_t> rays, const ModelOptions& opt) {
    if (t.nodes.empty()) throw InputError("model", 0, "this hierarchy has no model tree");
    if (t.one_path) throw InputError("model", 0, "5D ray classification has no per-ray prediction");
    std::vector<Ray> subset;
    subset.reserve(rays.size());
    for (std::uint32_t i : rays) subset.push_back(sample.rays.rays.at(i));
    PrimOracle known(scene, sample, rays);
    std::size_t met = 0;
    return probe_probabilities(t, scene, subset, known, opt, met);
}
}  // namespace model

Prediction predict_segments(const ModelTree& t, const Scene& scene, const RaySample& sample,
                            std::span<const std::uint32_t> rays, const ModelOptions& opt, const UnitCosts& costs) {
    std::vector<Ray> subset;
    subset.reserve(rays.size());
    for (std::uint32_t i : rays) {
        if (i >= sample.size()) throw std::out_of_range("predict_segments: ray index beyond the sample");
        subset.push_back(sample.rays.rays[i]);
    }
    PrimOracle known(scene, sample, rays);
    Prediction p = predict_probed(t, scene, subset, known, opt, costs);
    p.estimator = "segments";
    p.note = "probabilities from " + std::to_string(rays.size()) +
             " sampled segments replayed through the tree, each ending where its known crossings end it (no "
             "primitive tests)";
    return p;
}

}  // namespace rtcost
