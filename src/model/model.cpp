// The cost model's recursion, evaluated as visit probabilities over a hierarchy's model tree,
// with the geometric and the sampled estimators and the `exact` and `paper` presets.
#include "rtcost/model.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <stdexcept>

#include "rtcost/error.hpp"

namespace rtcost {

double UnitCosts::scalar(const CostVector& c) const {
    double s = per_ray + box * c.box + plane * c.plane + hop * c.hop + classify * c.classify;
    for (int k = 0; k < kPrimKinds; ++k) s += prim[k] * c.prim[k];
    return s;
}

UnitCosts UnitCosts::read(const std::string& path) {
    std::ifstream in(path);
    if (!in) throw InputError(path, 0, "no such file");
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(in);
    } catch (const nlohmann::json::parse_error& e) {
        throw InputError(path, 0, std::string("not a costs file: ") + e.what());
    }
    UnitCosts u;
    auto get = [&](const nlohmann::json& obj, const char* key, double& out) {
        if (!obj.contains(key)) return;
        if (!obj[key].is_number() || !std::isfinite(obj[key].get<double>()) || obj[key].get<double>() < 0)
            throw InputError(path, 0, std::string("'") + key + "' must be a non-negative number");
        out = obj[key].get<double>();
    };
    get(j, "box", u.box);
    get(j, "plane", u.plane);
    get(j, "hop", u.hop);
    get(j, "classify", u.classify);
    get(j, "per_ray", u.per_ray);
    if (j.contains("prim")) {
        for (int k = 0; k < kPrimKinds; ++k)
            get(j["prim"], std::string(prim_kind_name(static_cast<PrimKind>(k))).c_str(), u.prim[k]);
    }
    u.calibrated = j.value("unit", "") == "ns";
    return u;
}

CostVector measured_cost(const RayCounters& c) {
    CostVector v;
    double n = c.rays ? static_cast<double>(c.rays) : 1.0;
    v.box = c.box / n;
    v.plane = c.plane / n;
    v.hop = c.hop / n;
    v.classify = c.classify / n;
    for (int k = 0; k < kPrimKinds; ++k) v.prim[k] = c.prim[k] / n;
    v.steps = c.steps / n;
    v.leaves = c.leaves / n;
    v.empty_leaves = c.empty_leaves / n;
    return v;
}

namespace {

Box3 intersect(const Box3& a, const Box3& b) { return Box3{vmax(a.lo, b.lo), vmin(a.hi, b.hi)}; }

/// Area of a box that may be flat (one or two zero extents) or empty.
double surface(const Box3& b) {
    if (b.empty()) return 0;
    Vec3 e = b.extent();
    return 2.0 * (double(e.x) * e.y + double(e.y) * e.z + double(e.z) * e.x);
}

/// The surface a line must cross to meet the primitive, for Cauchy-Crofton: flat primitives
/// count both sides; an open cone or cylinder counts its convex hull (side and both rims' discs).
double crofton_area(const Scene& s, std::uint32_t id, const PrimSummary& p) {
    switch (p.kind) {
        case PrimKind::Triangle:
        case PrimKind::Polygon: return 2.0 * p.area;
        case PrimKind::Sphere: return p.area;
        case PrimKind::Cone: {
            const Cone& c = s.cones[s.prims[id].index];
            double rb = std::fabs(c.base_radius), ra = std::fabs(c.apex_radius);
            return p.area + std::numbers::pi * (rb * rb + ra * ra);
        }
    }
    return 0;
}

/// Share of a primitive's bounding box that lies in `region`, measured in the dimensions where
/// the box has extent (a flat box by area, a line by length).
double share_inside(const Box3& pb, const Box3& region) {
    // Wholly inside (every primitive of a BVH leaf): no divisions.
    if (pb.lo.x >= region.lo.x && pb.lo.y >= region.lo.y && pb.lo.z >= region.lo.z && pb.hi.x <= region.hi.x &&
        pb.hi.y <= region.hi.y && pb.hi.z <= region.hi.z)
        return 1;
    double f = 1;
    for (int k = 0; k < 3; ++k) {
        double ext = double(pb.hi[k]) - pb.lo[k];
        if (ext <= 0) {
            if (pb.lo[k] < region.lo[k] || pb.lo[k] > region.hi[k]) return 0;
            continue;
        }
        double lo = std::max(pb.lo[k], region.lo[k]), hi = std::min(pb.hi[k], region.hi[k]);
        f *= std::max(0.0, hi - lo) / ext;
    }
    return f;
}

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
    bool ordered = false;
    bool split = false;  ///< alpha, beta, gamma hold for this two-child node
};
static_assert(sizeof(NodeProbabilities) == 56);

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

/// The cost vector's scalar fields (its `prim` array aside), for sums field by field.
constexpr double CostVector::*kCostFields[] = {&CostVector::box,   &CostVector::plane,  &CostVector::hop,
                                              &CostVector::classify, &CostVector::steps, &CostVector::leaves,
                                              &CostVector::empty_leaves};

/// y += w x.
void add_scaled(CostVector& y, const CostVector& x, double w) {
    for (auto f : kCostFields) y.*f += w * x.*f;
    for (int k = 0; k < kPrimKinds; ++k) y.prim[k] += w * x.prim[k];
}

/// Whether a hit found ends (part of) the search: an any-hit query stops at its first hit; a
/// closest-hit one skips what lies beyond, unless the traversal visits everything (ModelFlags::cull).
bool terminates(const ModelFlags& f, Query q) { return q == Query::Any || (q == Query::Closest && f.cull); }

/// The families whose `paper` node costs differ.
enum class Family { Bvh, Grid, Rc5d, Kd, Subdivision };

Family family_of(const std::string& f) {
    if (f == "bvh") return Family::Bvh;
    if (f == "grid") return Family::Grid;
    if (f == "rc5d") return Family::Rc5d;
    if (f == "kd") return Family::Kd;
    return Family::Subdivision;  // Kaplan's BSP, Glassner's octree
}

/// Adds the operations of one visit of `m` to `c`, scaled by `p` (visits) and `pg` (visits that
/// pass the node's bounding volume). `gamma` and `pb` (P of the first child, 0 without
/// termination) enter the paper's Kaplan/Glassner term only.
void charge_visit(CostVector& c, const ModelNode& m, Family f, bool paper, double p, double pg, double gamma,
                  double pb) {
    if (!paper) {
        c.box += p * m.box;
        c.plane += pg * m.plane;
        c.hop += pg * m.hop;
        c.classify += pg * m.classify;
        return;
    }
    if (f == Family::Bvh) {
        c.box += p;  // the paper charges a node's own box test when it is entered
    } else if (!m.leaf) {
        if (f == Family::Grid) c.hop += p;
        else if (f == Family::Rc5d) c.classify += p;
        else if (f == Family::Kd) { c.plane += p; c.box += p; }
        else {
            // Kaplan/Glassner: 1_cmp + [g (1 - P_B) + (1 - g)] n_f, the far region's entry.
            c.plane += p;
            c.box += p * (gamma * (1 - pb) + (1 - gamma));
        }
    }
}

/// The sampled estimator's recursion: q(child | parent visited) for every node from per-node
/// probabilities counted by the probe (the recursion's coefficients), then pi and the cost vector.
Prediction evaluate(const ModelTree& t, const Walk& w, const std::vector<NodeProbabilities>& prob,
                    const Scene& scene, const ModelOptions& opt, const UnitCosts& costs) {
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
    const Family fam = family_of(t.family);
    auto charge = [&](const ModelNode& m, double p, double pg, std::size_t i) {
        const double pb = paper && terminate && !m.leaf ? prob[m.first].p_hit : 0.0;
        charge_visit(c, m, fam, paper, p, pg, prob[i].gamma, pb);
    };

    // Primitive kinds in scene order: looking each reference up in scene.prims would miss the cache.
    std::vector<std::uint8_t> kind(scene.size());
    for (std::uint32_t id = 0; id < kind.size(); ++id) kind[id] = static_cast<std::uint8_t>(scene.kind(id));
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
            } else {
                for (std::uint32_t k = 0; k < m.count; ++k)
                    c.prim[kind[t.prims[m.first + k]]] += pg;
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

// ---- 5D ray classification under the line measure ----------------------------------------
// A line entering the root box B through face f at a point x with direction w has density
// |w . n_f| dA dw (the invariant measure of lines). A beam is a set of (entry point, direction):
// its weight is the sum over the faces of B it touches of area(face within its origin box) times
// the integral over its directions entering that face of |w . n_f|. With w = (s e_k + u e_i1 +
// v e_i2) / r, r = sqrt(1 + u^2 + v^2), dw = du dv / r^3, the integrand is |component| / r^4.
// Integrated by Gauss-Legendre quadrature (the integrands are smooth once split at 0).

double gauss_2d(double u0, double u1, double v0, double v1, int which, double sign) {
    static constexpr double x[8] = {-0.9602898564975363, -0.7966664774136267, -0.5255324099163290,
                                    -0.1834346424956498, 0.1834346424956498,  0.5255324099163290,
                                    0.7966664774136267,  0.9602898564975363};
    static constexpr double w[8] = {0.1012285362903763, 0.2223810344533745, 0.3137066458778873,
                                    0.3626837833783620, 0.3626837833783620, 0.3137066458778873,
                                    0.2223810344533745, 0.1012285362903763};
    // which: 0 = constant component (the dominant axis), 1 = u, 2 = v; only where sign*comp > 0.
    auto part = [&](double a0, double a1, double b0, double b1) {
        if (!(a1 > a0) || !(b1 > b0)) return 0.0;
        double hu = 0.5 * (a1 - a0), cu = 0.5 * (a1 + a0), hv = 0.5 * (b1 - b0), cv = 0.5 * (b1 + b0);
        double sum = 0;
        for (int i = 0; i < 8; ++i) {
            double u = cu + hu * x[i];
            for (int j = 0; j < 8; ++j) {
                double v = cv + hv * x[j];
                double r2 = 1 + u * u + v * v;
                double comp = which == 0 ? 1.0 : which == 1 ? sign * u : sign * v;
                sum += w[i] * w[j] * std::max(0.0, comp) / (r2 * r2);
            }
        }
        return sum * hu * hv;
    };
    // Split at 0 on the axis whose component changes sign, so each piece is smooth.
    if (which == 1 && u0 < 0 && u1 > 0) return part(u0, 0, v0, v1) + part(0, u1, v0, v1);
    if (which == 2 && v0 < 0 && v1 > 0) return part(u0, u1, v0, 0) + part(u0, u1, 0, v1);
    return part(u0, u1, v0, v1);
}

/// Line-measure weight of a beam whose origins lie in `o` (inside root box `b`).
double beam_weight(const ModelNode& m, const Box3& b) {
    const int k = m.beam_axis;
    const int i1 = k == 0 ? 1 : 0;  // the other axis carries v
    const double s = m.beam_negative ? -1.0 : 1.0;
    const Box3& o = m.region;
    double total = 0;
    for (int a = 0; a < 3; ++a) {
        const int p = (a + 1) % 3, q = (a + 2) % 3;
        const double area = (double(o.hi[p]) - o.lo[p]) * (double(o.hi[q]) - o.lo[q]);
        for (int side = 0; side < 2; ++side) {
            // side 0: the low face (outward normal -e_a): entering needs w_a > 0.
            const bool touches = side == 0 ? o.lo[a] <= b.lo[a] : o.hi[a] >= b.hi[a];
            if (!touches || area <= 0) continue;
            const double dir = side == 0 ? 1.0 : -1.0;
            double integral;
            if (a == k) integral = s * dir > 0 ? gauss_2d(m.beam_u[0], m.beam_u[1], m.beam_v[0], m.beam_v[1], 0, 1) : 0;
            else if (a == i1) integral = gauss_2d(m.beam_u[0], m.beam_u[1], m.beam_v[0], m.beam_v[1], 1, dir);
            else integral = gauss_2d(m.beam_u[0], m.beam_u[1], m.beam_v[0], m.beam_v[1], 2, dir);
            total += area * integral;
        }
    }
    return total;
}

/// Forward start of a primitive along a beam's dominant axis (its bounding box's near face).
double forward_start(const Box3& pb, int k, bool negative) { return negative ? -double(pb.hi[k]) : double(pb.lo[k]); }

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

Prediction predict_one_path_sampled(const ModelTree& t, const Walk& w, const Scene& scene,
                                    std::span<const Ray> training, const ModelOptions& opt, const UnitCosts& costs) {
    const std::size_t n = t.nodes.size();
    std::vector<double> handed(n, 0.0);
    std::vector<std::array<double, kPrimKinds>> tests(n, std::array<double, kPrimKinds>{});
    const Box3& root = t.nodes[0].region;
    const bool terminate = terminates(t, opt.query);
    std::size_t met = 0;
    NoCount nc;
    for (std::size_t r = 0; r < training.size(); ++r) {
        const Ray& ray = training[r];
        const RayInv ri(ray);
        if (box_entry(root, ri.o, ri.inv, ray.tmin, ray.tmax) == kInf) continue;
        const int k = max_axis(ray.d);
        const double adk = std::fabs(double(ray.d[k]));
        if (!(adk > 0)) continue;
        ++met;
        // The classification point: the ray's point at max(tmin, box entry), clamped to the box.
        double t0 = ray.tmin;
        for (int a = 0; a < 3; ++a) {
            if (ray.d[a] == 0) continue;
            double bound = ray.d[a] > 0 ? root.lo[a] : root.hi[a];
            t0 = std::max(t0, (bound - double(ray.o[a])) / double(ray.d[a]));
        }
        double x[5];
        for (int a = 0; a < 3; ++a)
            x[a] = std::clamp(double(ray.o[a]) + (ray.d[a] != 0 ? t0 * double(ray.d[a]) : 0.0), double(root.lo[a]),
                              double(root.hi[a]));
        const int i1 = k == 0 ? 1 : 0, i2 = k == 2 ? 1 : 2;
        x[3] = float(ray.d[i1] / float(adk));
        x[4] = float(ray.d[i2] / float(adk));
        const bool neg = ray.d[k] < 0;
        std::uint32_t node = 0;
        handed[0] += 1;
        node = t.nodes[0].first + static_cast<std::uint32_t>(2 * k + (neg ? 1 : 0));
        for (;;) {
            handed[node] += 1;
            const ModelNode& m = t.nodes[node];
            if (m.leaf) break;
            node = m.first + (float(x[m.beam_dim]) >= m.split ? 1u : 0u);
        }
        // The ordered search, with real tests: a candidate starting beyond the nearest hit so
        // far is not tested (closest), the first hit ends it (any).
        const ModelNode& leaf = t.nodes[node];
        const double so = neg ? -double(ray.o[k]) : double(ray.o[k]);
        Hit hit;
        for (std::uint32_t c = 0; c < leaf.count; ++c) {
            std::uint32_t id = t.prims[leaf.first + c];
            const double stop = terminate ? so + double(std::min(hit.t, ray.tmax)) * adk : kInf;
            if (forward_start(scene.prim_bounds(id), k, neg) > stop) break;
            tests[node][static_cast<int>(scene.kind(id))] += 1;
            if (test_prim(scene, id, ray, hit, nc) && terminate && opt.query == Query::Any) break;
        }
    }
    std::vector<NodeProbabilities> prob(n);
    for (std::size_t i = 0; i < n; ++i) {
        const ModelNode& m = t.nodes[i];
        if (m.leaf) {
            prob[i].ordered = true;
            for (int k = 0; k < kPrimKinds; ++k) prob[i].tests[k] = handed[i] > 0 ? tests[i][k] / handed[i] : 0.0;
            continue;
        }
        for (std::uint32_t k = 0; k < m.count; ++k)
            prob[m.first + k].handed = handed[i] > 0 ? handed[m.first + k] / handed[i] : 0.0;
    }
    Prediction p = evaluate(t, w, prob, scene, opt, costs);
    p.estimator = "sampled";
    p.note = "5D: path probabilities and ordered-search lengths from a probe traversal of " +
             std::to_string(training.size()) + " training rays";
    scale_to_share(p, t, training.empty() ? 0.0 : double(met) / double(training.size()), costs);
    return p;
}

/// A segment of a ray by its parameter, [t0, t1]; empty when t0 > t1 (or NaN).
struct Seg {
    float t0, t1;
    bool empty() const { return !(t0 <= t1); }
};

Seg clip(const RayInv& ri, const Box3& b, Seg s) {
    for (int k = 0; k < 3; ++k) {
        float tn = (b.lo[k] - ri.o[k]) * ri.inv[k], tf = (b.hi[k] - ri.o[k]) * ri.inv[k];
        if (tn > tf) std::swap(tn, tf);
        // NaN (0 * inf: a ray in a face's plane) fails both compares and is ignored.
        s.t0 = tn > s.t0 ? tn : s.t0;
        s.t1 = tf < s.t1 ? tf : s.t1;
    }
    return s;
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
    };

    Probe(const ModelTree& t, const Scene& s, Query q)
        : t_(t), s_(s), any_(q == Query::Any), cull_(q == Query::Closest && t.cull), tally_(t.nodes.size()) {}

    /// One training ray; false when it misses the root.
    bool run(const Ray& ray) {
        ray_ = &ray;
        ri_ = RayInv(ray);
        hit_ = Hit{};
        found_ = false;
        const Seg root = clip(ri_, t_.nodes[0].region, Seg{ray.tmin, ray.tmax});
        if (root.empty()) return false;
        visit(0, root);
        return true;
    }

    const std::vector<Tally>& tally() const { return tally_; }

private:
    // Nothing more is searched: an any-hit query has its hit.
    bool done() const { return any_ && found_; }
    // A closest-hit traversal skips a segment that starts at or beyond the nearest hit so far.
    bool beyond(const Seg& s) const { return cull_ && s.t0 >= hit_.t; }
    // A child's segment, cut at the nearest hit so far when the traversal culls by it.
    Seg child(std::uint32_t c, const Seg& s) const {
        Seg x = clip(ri_, t_.nodes[c].region, s);
        if (cull_ && hit_.t < x.t1) x.t1 = hit_.t;
        return x;
    }

    void visit(std::uint32_t node, Seg s) {
        const ModelNode& m = t_.nodes[node];
        Tally& ty = tally_[node];
        ty.handed += 1;
        if (m.has_bv) {
            s = clip(ri_, m.bv, s);
            if (s.empty()) return;
        }
        ty.gated += 1;
        if (m.leaf) {
            for (std::uint32_t k = 0; k < m.count; ++k) {
                const std::uint32_t id = t_.prims[m.first + k];
                ty.tests[static_cast<int>(s_.kind(id))] += 1;
                if (test_prim(s_, id, *ray_, hit_, nc_)) {
                    found_ = true;
                    if (any_) break;
                }
            }
        } else if (m.count == 2) {
            const Seg sl = child(m.first, s), sr = child(m.first + 1, s);
            const bool l = !sl.empty(), r = !sr.empty();
            if (l && r) {
                ty.both += 1;
                // Nearer entry first, a tie (a ray starting inside both) to the first child; a
                // BVH without order: stored order.
                const bool left_first = !t_.cull || sl.t0 <= sr.t0;
                ty.left_first += left_first;
                const std::uint32_t near = left_first ? m.first : m.first + 1;
                const Seg& far = left_first ? sr : sl;
                tally_[near].first += 1;
                visit(near, left_first ? sl : sr);
                const bool ends = done() || beyond(far);
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
                const Seg sc = child(m.first + k, s);
                if (!sc.empty()) met[nm++] = {sc.t0, m.first + k};
            }
            // Ties (a ray starting inside several) go to the later child, as the traversal's sort does.
            if (t_.cull)
                std::sort(met.begin(), met.begin() + nm,
                          [](auto& a, auto& b) { return a.first < b.first || (a.first == b.first && a.second > b.second); });
            for (std::size_t k = 0; k < nm && !done(); ++k) {
                const Seg sc = child(met[k].second, s);
                if (!beyond(sc)) visit(met[k].second, sc);
            }
        }
        ty.ended += done() || (cull_ && hit_.t <= s.t1);
    }

    const ModelTree& t_;
    const Scene& s_;
    const bool any_, cull_;
    std::vector<Tally> tally_;
    const Ray* ray_ = nullptr;
    RayInv ri_{Ray{}};
    Hit hit_;
    bool found_ = false;
    NoCount nc_;
};

}  // namespace

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
        fam_ = family_of(f.family);
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
                        // The other child is before X half the time.
                        survive = 0.5 * (2 - handed_[1 - x] * o.kids[1 - x].p_hit);
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
            weight = beam_weight(m, root_region_);
            // Ordered search: candidate j is tested unless an earlier one ended the search; each
            // earlier candidate is hit with p = its Crofton area over the surface of the box
            // around the leaf's candidates (an approximation: independence, no occlusion order).
            Box3 around;
            for (std::uint32_t id : prims) around.extend(sums_[id].bounds);
            const double sa = surface(around);
            std::array<double, kPrimKinds> tests{};
            double alive = 1;
            for (std::uint32_t id : prims) {
                const PrimSummary& g = sums_[id];
                tests[static_cast<int>(g.kind)] += alive;
                if (terminate_) alive *= 1 - (sa > 0 ? std::min(1.0, crofton_area(scene_, id, g) / sa) : 0.0);
                else S.c.prim[static_cast<int>(g.kind)] += 1;
            }
            if (terminate_)
                for (int k = 0; k < kPrimKinds; ++k) S.c.prim[k] += static_cast<float>(tests[k]);
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
        charge_visit(S.c, m, fam_, paper_, times, gated, 0.5, pb);
        if (m.step) {
            S.c.steps += times;
            S.add_depth(o.tdepth, times);
        }
    }

    const Scene& scene_;
    ModelOptions opt_;
    ModelFlags flags_;
    Family fam_ = Family::Bvh;
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

Prediction predict_sampled(const ModelTree& t, const Scene& scene, std::span<const Ray> training,
                           const ModelOptions& opt, const UnitCosts& costs) {
    if (t.nodes.empty()) throw InputError("model", 0, "this hierarchy has no model tree");
    Walk w(t);
    if (t.one_path) return predict_one_path_sampled(t, w, scene, training, opt, costs);
    const std::size_t n = t.nodes.size();
    Probe probe(t, scene, opt.query);
    std::size_t met = 0;
    for (const Ray& ray : training) met += probe.run(ray);
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
    Prediction p = evaluate(t, w, prob, scene, opt, costs);
    p.estimator = "sampled";
    p.note = "probabilities from a probe traversal of " + std::to_string(training.size()) + " training rays";
    scale_to_share(p, t, training.empty() ? 0.0 : static_cast<double>(met) / training.size(), costs);
    return p;
}

}  // namespace rtcost
