#pragma once
// What the model's files share (not public API): Crofton geometry, the recursion over a
// materialised model tree and its per-node probabilities, 5D beam weights.
#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#include <string>
#include <vector>

#include "rtcost/error.hpp"
#include "rtcost/model.hpp"
#include "rtcost/sample.hpp"

namespace rtcost {
struct RaySample;
}

namespace rtcost::model {

/// The segments of a sample's rays as far as the segments replay can follow them, for finding
/// the regions they reach (reached_model_tree prunes what no ray reaches): each ray's
/// reciprocal direction and end. A closest-hit search with culling (`cull`) visits no region
/// that starts at or beyond its hit, and cannot pass the nearest crossing, t_end, without
/// having found it in a region that holds it; an any-hit search ends at whichever occluder it
/// finds first, and one that visits everything never ends: tmax. A margin covers rounding; a
/// replay that still reaches a pruned node throws PrunedNodeReached.
struct ReplaySegments {
    std::vector<RayInv> inv;
    std::vector<float> ends;

    ReplaySegments() = default;
    ReplaySegments(const RaySample& sample, bool cull) {
        inv.reserve(sample.size());
        ends.reserve(sample.size());
        for (std::size_t i = 0; i < sample.size(); ++i) {
            const Ray& r = sample.rays.rays[i];
            inv.emplace_back(r);
            const bool ends_early = cull && sample.queries[i] == Query::Closest && sample.t_end[i] < r.tmax;
            ends.push_back(ends_early ? std::min(r.tmax, sample.t_end[i] + 1e-4f * std::fabs(sample.t_end[i]) + 1e-6f)
                                      : r.tmax);
        }
    }
};

/// The cost vector's scalar fields (its `prim` array aside), for sums field by field.
inline constexpr double CostVector::*kCostFields[] = {&CostVector::box,      &CostVector::plane, &CostVector::hop,
                                                     &CostVector::classify, &CostVector::steps, &CostVector::leaves,
                                                     &CostVector::empty_leaves, &CostVector::polygon_edges};

/// Whether any primitive's test walks polygon edges (Scene::edges_walked): where none does, the
/// recursions skip counting them.
inline bool walks_edges(const Scene& s) { return s.max_polygon_vertices() > 3; }

/// Polygon edges walked by a visit of leaf `m`: every primitive's test, or, where the model knows
/// only the expected polygon tests per visit (`polygon_tests`, an ordered search that may stop),
/// that many tests of the leaf's average polygon.
inline double leaf_edges(const ModelTree& t, const ModelNode& m, const Scene& s, double polygon_tests = -1) {
    double edges = 0, polygons = 0;
    for (std::uint32_t k = 0; k < m.count; ++k) {
        const std::uint32_t id = t.prims[m.first + k];
        edges += s.edges_walked(id);
        polygons += s.kind(id) == PrimKind::Polygon;
    }
    if (polygon_tests < 0) return edges;
    return polygons > 0 ? polygon_tests * edges / polygons : 0.0;
}

// ---- Cauchy-Crofton geometry (crofton.cpp)
Box3 intersect(const Box3& a, const Box3& b);
/// Area of a box that may be flat (one or two zero extents) or empty.
double surface(const Box3& b);
/// The surface a line must cross to meet the primitive: flat primitives count both sides; an
/// open cone or cylinder counts its convex hull (side and both rims' discs).
double crofton_area(const Scene& s, std::uint32_t id, const PrimSummary& p);
/// Share of a primitive's bounding box that lies in `region`, measured in the dimensions where
/// the box has extent (a flat box by area, a line by length).
double share_inside(const Box3& pb, const Box3& region);

// ---- The recursion over a materialised tree (recursion.cpp)
/// Per-node probabilities that drive the sampled estimator's recursion, counted by its probe.
struct NodeProbabilities {
    // Floats: one per node of trees with millions of nodes, and probabilities need no more.
    float handed = 0;  ///< segments handed to the node
    float alpha = 0, beta = 0, gamma = 0.5;  ///< left only, right only, left first when both
    /// Both children met: 1 - alpha - beta for a plane split; less for bounding volumes, whose
    /// children need not cover their parent.
    float both = 0;
    float p_hit = 0;   ///< P: the segment handed to the node hits inside its region
    /// P where the recursion uses it: among segments that meet both children of the parent
    /// with this node first (negative: use p_hit).
    float p_first = -1;
    float p_bv = 1;    ///< the segment meets the node's bounding volume (when it has one)
    /// A child of a node without a plane split: the share of the parent's visits that entered
    /// it.
    float entered = -1;
    /// With `ordered`: expected primitive tests per visit of a leaf, by kind, when the search
    /// may stop inside it (5D candidates searched in order; an any-hit query's leaves).
    std::array<float, kPrimKinds> tests{};
    /// A leaf: polygon edges walked per visit past its bounding volume, as the probe found them
    /// (a polygon's edges where the ray met its plane before the hit so far); negative: not
    /// learned (the recursion then charges every polygon's edges).
    float edges = -1;
    bool ordered = false;
    bool split = false;  ///< alpha, beta, gamma hold for this two-child node
};
static_assert(sizeof(NodeProbabilities) == 60);

/// The edges a leaf visit walks: as the probe learned them (NodeProbabilities::edges), else
/// those of every polygon tested (leaf_edges; `polygon_tests` as there).
inline double visit_edges(const ModelTree& t, const ModelNode& m, const Scene& s, const NodeProbabilities& q,
                          double polygon_tests = -1) {
    return q.edges >= 0 ? q.edges : leaf_edges(t, m, s, polygon_tests);
}

/// The segments estimator's per-node probabilities from the sample's rays `rays` (indices),
/// before the recursion (what predict_segments feeds it). Throws InputError for a 5D tree.
std::vector<NodeProbabilities> segment_probabilities(const ModelTree& t, const Scene& scene, const RaySample& sample,
                                                     std::span<const std::uint32_t> rays, const ModelOptions& opt);

/// Thrown by a probe that enters a node left out of a reached tree (SegmentsPredictor then
/// predicts on the whole tree).
struct PrunedNodeReached {};

/// Refuses `sample` when a crossing of one of its rays `rays` names a primitive beyond the
/// scene's `primitives` (a sample of another scene, which a version-1 file's missing
/// fingerprint cannot tell): InputError naming the sample's file.
inline void check_crossings_in_scene(const RaySample& sample, std::span<const std::uint32_t> rays,
                                     std::size_t primitives) {
    for (std::uint32_t i : rays)
        for (const Crossing& c : sample.crossings_of(i))
            if (c.prim >= primitives)
                throw InputError(sample.source(), 0, "primitive " + std::to_string(c.prim) + " is not in the scene (" +
                                                         std::to_string(primitives) +
                                                         " primitives): a sample of another scene?");
}

/// The segments estimator's answer to a test of primitive `id` by a ray whose known crossings
/// (nearest first) are `known`: a crossing nearer than the hit so far and before tmax is
/// recorded in `hit`. The model's probe and the designs' replays (design/replay.hpp) share it.
inline bool known_crossing_hit(std::span<const Crossing> known, std::uint32_t id, const Ray& ray, Hit& hit) {
    for (const Crossing& x : known)
        if (x.prim == id) {
            if (!(x.t < hit.t && x.t < ray.tmax)) return false;
            hit.t = x.t;
            hit.prim = static_cast<std::int32_t>(id);
            return true;
        }
    return false;
}

/// A ray's known crossings (nearest first) with a 256-bit filter of their primitives: a test of
/// a primitive the ray does not cross (most tests) is answered from the filter, without a scan of
/// the list (on shells' camera rays, through nested spheres, the scan was two thirds of every
/// replay). The same answers as known_crossing_hit.
class KnownCrossings {
public:
    KnownCrossings() = default;
    explicit KnownCrossings(std::span<const Crossing> known) : known_(known) {
        for (const Crossing& x : known) {
            const unsigned b = bucket(x.prim);
            filter_[b >> 6] |= std::uint64_t{1} << (b & 63);
        }
    }
    /// known_crossing_hit(list(), id, ray, hit).
    bool hit(std::uint32_t id, const Ray& ray, Hit& hit) const {
        const unsigned b = bucket(id);
        if (!((filter_[b >> 6] >> (b & 63)) & 1)) return false;
        return known_crossing_hit(known_, id, ray, hit);
    }
    std::span<const Crossing> list() const { return known_; }

private:
    // Fibonacci hashing: the top 8 bits of the id times 2^32 / phi, which spreads neighbouring ids.
    static unsigned bucket(std::uint32_t id) { return (id * 0x9E3779B1u) >> 24; }
    std::span<const Crossing> known_;
    std::uint64_t filter_[4] = {0, 0, 0, 0};
};

/// Each node's parent and traversal depth (the number of its ancestors that are steps), for the
/// sampled estimator's recursion over a materialised tree.
struct Walk {
    std::vector<int> parent;
    std::vector<int> tdepth;

    explicit Walk(const ModelTree& t) : parent(t.nodes.size(), -1), tdepth(t.nodes.size(), 0) {
        for (std::size_t i = 0; i < t.nodes.size(); ++i) {
            const ModelNode& m = t.nodes[i];
            if (m.leaf) continue;
            for (std::uint32_t k = 0; k < m.count; ++k) {
                parent[m.first + k] = static_cast<int>(i);
                tdepth[m.first + k] = tdepth[i] + (m.step ? 1 : 0);
            }
        }
    }
};

/// Whether a hit found ends (part of) the search: an any-hit query stops at its first hit; a
/// closest-hit one skips what lies beyond, unless the traversal visits everything (ModelFlags::cull).
/// Whether the traversal enters a child whose clipped segment is `x`, its parent's being `s`:
/// when `x` is not empty, except a single point of a longer `s` in a tree whose traversal steps
/// over edges and corners (ModelFlags::point_touches false).
inline bool meets(const ModelFlags& f, const Segment& s, const Segment& x) {
    if (x.empty()) return false;
    return f.point_touches || x.t0 < x.t1 || !(s.t0 < s.t1);
}

inline bool terminates(const ModelFlags& f, Query q) { return q == Query::Any || (q == Query::Closest && f.cull); }

/// Sorts the children a segment meets, (entry t, child index) with the child at `t.nodes[base +
/// index]`, into the order an ordered traversal enters them: nearest first, a tie (a ray starting
/// inside several) to the later child; with `leaves_first` (an any-hit query of a tree that
/// declares OcclusionOrder::LeavesFirst) leaf children before interior ones.
inline void sort_children_met(std::span<std::pair<float, std::uint32_t>> met, const ModelTree& t, std::uint32_t base,
                              bool leaves_first) {
    std::sort(met.begin(), met.end(), [&](const auto& a, const auto& b) {
        if (leaves_first) {
            const bool la = t.nodes[base + a.second].leaf, lb = t.nodes[base + b.second].leaf;
            if (la != lb) return la;
        }
        return a.first < b.first || (a.first == b.first && a.second > b.second);
    });
}

/// Adds the operations of one visit of `m` to `c`, scaled by `p` (visits) and `pg` (visits that
/// pass the node's bounding volume): the node's own, or the tree's declared `paper` charges
/// (null: the exact preset). `gamma` and `pb` (P of the first child, 0 without termination)
/// enter the Kaplan/Glassner far-entry term only.
void charge_visit(CostVector& c, const ModelNode& m, const PaperCharges* paper, double p, double pg, double gamma,
                  double pb);

/// The recursion: q(child | parent visited) for every node from per-node probabilities (the
/// recursion's coefficients), then pi and the cost vector.
Prediction recurse(const ModelTree& t, const Walk& w, const std::vector<NodeProbabilities>& prob, const Scene& scene,
                   const ModelOptions& opt, const UnitCosts& costs);

/// The share of rays that meet the root: the recursion predicts per ray that does; every ray
/// still pays the root test.
void scale_to_share(Prediction& p, const ModelTree& t, double share, const UnitCosts& costs);

// ---- 5D ray classification (beams.cpp)
/// Line-measure weight of a beam with directions `m` whose origins lie in `o` (inside root box `b`).
double beam_weight(const ModelBeam& m, const Box3& o, const Box3& b);
/// Forward start of a primitive along a beam's dominant axis: its bounding box's near face,
/// moved outwards by `pad` in float as the 5D traversal pads its boxes (ModelFlags::search_pad).
inline double forward_start(const Box3& pb, int k, bool negative, float pad = 0) {
    return negative ? -double(pb.hi[k] + pad) : double(pb.lo[k] - pad);
}
/// A ray's point in 5D ray space as a one-path (5D) traversal classifies it: `x` the entry point
/// (the ray's point at max(tmin, root box entry), clamped to `root`) and the direction's (u, v)
/// on the face of its dominant axis `k` (sign `neg`, magnitude `adk`). False when the ray
/// misses `root` or has no direction: it reaches no cube. The probe and the reached tree share
/// it, so that both follow each ray down the same path.
inline bool classify_5d(const Ray& ray, const Box3& root, double x[5], int& k, bool& neg, double& adk) {
    const RayInv ri(ray);
    if (box_entry(root, ri.o, ri.inv, ray.tmin, ray.tmax) == kInf) return false;
    k = max_axis(ray.d);
    adk = std::fabs(double(ray.d[k]));
    if (!(adk > 0)) return false;
    double t0 = ray.tmin;
    for (int a = 0; a < 3; ++a) {
        if (ray.d[a] == 0) continue;
        const double bound = ray.d[a] > 0 ? root.lo[a] : root.hi[a];
        t0 = std::max(t0, (bound - double(ray.o[a])) / double(ray.d[a]));
    }
    for (int a = 0; a < 3; ++a)
        x[a] = std::clamp(double(ray.o[a]) + (ray.d[a] != 0 ? t0 * double(ray.d[a]) : 0.0), double(root.lo[a]),
                          double(root.hi[a]));
    const int i1 = k == 0 ? 1 : 0, i2 = k == 2 ? 1 : 2;
    x[3] = float(ray.d[i1] / float(adk));
    x[4] = float(ray.d[i2] / float(adk));
    neg = ray.d[k] < 0;
    return true;
}
/// The child of a 5D node that a ray's point `x` falls in (0 below the split, 1 at or above).
inline std::uint32_t beam_side(const ModelNode& m, const double x[5]) { return float(x[m.beam_dim]) >= m.split ? 1u : 0u; }

/// Where a one-path leaf's ordered search stops: the dominant coordinate of the parameter `t`
/// (`so` the origin's, `adk` the direction's magnitude on that axis), plus the traversal's
/// relative `margin` (ModelFlags::stop_margin). Infinite for an infinite `t`.
inline double search_stop(double so, float t, double adk, double margin) {
    if (!(t < kInf)) return kInf;
    const double dist = double(t) * adk;
    return so + dist + margin * (std::fabs(so) + std::fabs(dist));
}

}  // namespace rtcost::model
