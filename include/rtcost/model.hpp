#pragma once
/// \file model.hpp
/// Subramanian and Fussell's cost model over any hierarchy's model tree (hierarchy.hpp).
///
/// The recursion Cost(T_A) = Cost(A) + a H(B) + b H(C) + (1-a-b)[g (H(B) + (1-P_B) H(C)) +
/// (1-g)(H(C) + (1-P_C) H(B))] is linear in the children's costs, so it is evaluated as visit
/// probabilities: pi(root) = 1, pi(child) = pi(parent) q(child), and the predicted cost is
/// the sum over nodes of pi(N) times the operations a visit of N performs.

#include <array>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "rtcost/hierarchy.hpp"

namespace rtcost {

/// Expected operations per ray, by kind (the counters' units).
struct CostVector {
    double box = 0, plane = 0, hop = 0, classify = 0;
    std::array<double, kPrimKinds> prim{};
    double steps = 0, leaves = 0, empty_leaves = 0;
    /// Edges walked by the tests of polygons of more than three vertices (RayCounters::
    /// polygon_edges): not an operation of the paper's, priced by the time model alone.
    double polygon_edges = 0;

    double prim_tests() const { return prim[0] + prim[1] + prim[2] + prim[3]; }
};

/// y += w x, field by field.
void add_scaled(CostVector& y, const CostVector& x, double w);

/// Cost of one operation of each kind (default 1: pure operation counts; calibrated: ns).
///
/// A calibrated time model may also charge what no single operation explains: each traversal
/// step (the loop, the stack, the fetch of a node), box tests that a node's visit makes several
/// at once (StructureStats::box_lanes: bvh-wide's SIMD visit, a binary BVH's pair of children),
/// and the cache misses of a structure
/// larger than the cache. Unit costs charge none of these, so operation counts stay counts.
struct UnitCosts {
    double box = 1, plane = 1, hop = 1, classify = 1;
    std::array<double, kPrimKinds> prim{1, 1, 1, 1};
    double per_ray = 0;       ///< fixed cost of every ray (calibrated files: setup, clip, loop)
    double step = 0;          ///< per traversal step (CostVector::steps), besides its operations
    /// Per box test of a structure whose box tests are SIMD (box_lanes of 4 or more: bvh-wide);
    /// negative: as `box`.
    double box_simd = -1;
    /// Per box test of a structure that tests two boxes at once (box_lanes 2: the binary BVHs);
    /// negative: as `box`.
    double box_pair = -1;
    /// Per traversal step, for each doubling of the structure's bytes beyond `cache_bytes`: the
    /// memory a step waits on once the structure no longer fits in the cache.
    double cache = 0;
    double cache_bytes = 1 << 20;  ///< the cache the calibrating machine's structures fit in (its L2)
    /// Per edge of a polygon of more than three vertices tested (CostVector::polygon_edges),
    /// besides the polygon test's own price: the crossing test walks every edge.
    double polygon_edge = 0;
    bool calibrated = false;  ///< nanoseconds fitted by `rtcost calibrate`

    /// Operations, steps and the fixed cost (no structure known: box tests priced at `box`, no
    /// cache term).
    double scalar(const CostVector& c) const;
    /// The time model of a structure: as scalar(c), with its box tests priced as box_price of its
    /// lanes and the cache term for its size.
    double scalar(const CostVector& c, const StructureStats& s) const;
    /// A box test of a structure that tests `box_lanes` boxes at once (StructureStats::box_lanes):
    /// `box_simd` for 4 or more, `box_pair` for 2, where known; `box` otherwise.
    double box_price(int box_lanes) const;
    /// The cache term's factor: log2(bytes / cache_bytes), 0 for a structure that fits.
    double cache_doublings(std::uint64_t bytes) const;
    /// Reads a costs file (JSON `{"unit": "ns", "box": ns, "plane": ns, ..., "per_ray": ns,
    /// "step": ns, "box_simd": ns, "box_pair": ns, "cache": ns, "cache_bytes": bytes,
    /// "polygon_edge": ns, "prim": {"triangle": ns, ...}}`; the time model's terms are optional:
    /// `box_simd` and `box_pair` then price those box tests as `box`, `step`, `cache` and
    /// `polygon_edge` are 0).
    static UnitCosts read(const std::string& path);
    /// Typical nanoseconds per operation, built in: what the designed hierarchies minimise
    /// unless told otherwise, because operation counts alone trade box tests for primitive
    /// tests that cost several times more (docs/design.md). Fitted by `rtcost calibrate` on one
    /// machine (unit_costs.cpp says which); their ratios, not their nanoseconds, steer a design.
    static UnitCosts typical();
    /// A BVH's margins, built in: ns per box test (its step's share included) against ns per
    /// primitive test of each kind, as they move between BVHs of one scene and distribution
    /// (scripts/bvh-prices.py; unit_costs.cpp says where). What bvh-design minimises by default:
    /// typical() takes its step price from every family's traversal and its primitive prices
    /// across scenes, and priced a BVH's polygon test at half a node visit where the margin
    /// between BVHs is more than one.
    static UnitCosts typical_bvh();
    /// "unit" (the paper's operation counts), "ops" (operation counts with each polygon edge a
    /// crossing test walks at the share of the test typical() gives it), "typical" (typical()),
    /// "typical-bvh" (typical_bvh()) or a costs file's path (`./ops` names a file called ops).
    static UnitCosts named(const std::string& name);
    /// Whether named() takes `name` as one of its built-in tables rather than a costs file.
    static bool built_in(const std::string& name) {
        return name == "unit" || name == "ops" || name == "typical" || name == "typical-bvh";
    }
};

/// One calibration run: the measured operations per ray and the measured single-thread
/// nanoseconds per ray of one hierarchy on one ray set.
struct CalibrationSample {
    std::string label;  ///< e.g. "bvh-sah on balls"
    CostVector ops;
    double ns_per_ray = 0;
    StructureStats structure;  ///< the structure's bytes and box lanes (the time model's extra terms)
};

/// Which terms a calibration fits besides the operations and the fixed cost per ray.
struct TimeTerms {
    bool steps = true;  ///< UnitCosts::step
    /// UnitCosts::box_simd and box_pair (else box tests made several at once are priced as any)
    bool simd = true;
    bool cache = true;  ///< UnitCosts::cache
    /// UnitCosts::polygon_edge, timed on this machine's crossing test (not fitted: see
    /// calibrate.cpp) and taken out of each run's time before the rest is fitted.
    bool edges = true;
};

struct Calibration {
    UnitCosts costs;                ///< fitted ns per operation (calibrated = true)
    std::vector<double> predicted;  ///< fitted ns per ray for each sample
    /// Unknowns (box, plane, hop, classify, prims..., per_ray, step, box_simd, cache, box_pair,
    /// polygon_edge: the last, timed on polygons rather than fitted) the data
    /// determined.
    std::vector<bool> fitted;
    double rms_relative = 0;        ///< root mean square of (predicted - measured) / measured
};

/// Non-negative least squares of ns_per_ray = UnitCosts::scalar(ops, structure), each sample
/// weighted by 1 / ns_per_ray (relative errors count alike). Kinds that no sample performs keep
/// cost 0 and are reported as not fitted (box_simd, box_pair: -1, priced as `box`). `cache_bytes`: the cache
/// the cache term counts doublings beyond (0: this machine's L2). The primitive prices are then
/// fitted again, each pulled toward the mean of the kinds tested with the weight of the first
/// fit's rms relative residual (runs that a time model explains exactly are not moved; a price
/// noisy runs fix poorly stays near the others), and at least weakly when the first fit priced a
/// tested kind at 0 (one the samples cannot tell from another). Throws InputError with fewer samples
/// than fitted unknowns.
/// `edge_ns`: the ns per polygon edge (terms.edges) when known, negative: timed here
/// (polygon_edge_ns).
Calibration calibrate(std::span<const CalibrationSample> samples, const TimeTerms& terms = {},
                      double cache_bytes = 0, double edge_ns = -1);

/// Nanoseconds per edge of the polygon test's crossing loop on this machine, timed on regular
/// polygons of 8 and 64 vertices (what calibrate prices UnitCosts::polygon_edge at).
double polygon_edge_ns();

/// This machine's L2 cache in bytes (1 MiB when the system does not say).
double cache_size_bytes();

/// Writes `c` as a costs file that UnitCosts::read reads (atomically).
void write_costs(const std::string& path, const Calibration& c, std::span<const CalibrationSample> samples);

/// The measured counterpart of a CostVector: per-ray means of the counters.
CostVector measured_cost(const RayCounters& c);

enum class Preset {
    Exact,  ///< every operation the traversal performs, in the counters' units
    Paper,  ///< the seed paper's formulas per family, errata fixed
};

enum class Estimator {
    Geometric,  ///< surface-area (Cauchy-Crofton) probabilities for isotropic lines; no rays traced
    Sampled,    ///< probabilities counted from a training sample of rays
    Segments,   ///< probabilities from a ray sample's ended segments (sample.hpp): no primitive tests
};

struct ModelOptions {
    Preset preset = Preset::Exact;
    /// Query::All: no early termination (P = 0 everywhere). Closest and Any terminate.
    Query query = Query::Closest;
};

/// A prediction: the cost vector, its scalar, and visit probabilities per model depth.
struct Prediction {
    CostVector cost;
    double scalar = 0;
    std::vector<double> visits_by_depth;  ///< expected traversal steps per depth (the counters' units)
    std::string estimator, preset;
    /// How P over several primitives was approximated (geometric estimator).
    std::string note;
    double seconds = 0;  ///< time the prediction took (set by evaluate)
};

/// Geometric estimator: probabilities from surface areas of each node's entry region for
/// isotropic lines through the root box. P of a node over several primitives is approximated
/// by the Poisson form 1 - exp(-sum p_i), p_i = S_i / S(region) with S_i the primitive's area
/// seen from both sides (2x for flat primitives), scaled by the share of its bounding box
/// inside the region. 5D classification trees (ModelTree::one_path): each beam's probability
/// under the line measure by numerical integration.
Prediction predict_geometric(const ModelTree& tree, const Scene& scene, const ModelOptions& opt,
                             const UnitCosts& costs = {});
/// The same, reading the hierarchy's nodes where they lie (Hierarchy::emit_model) in one depth-
/// first pass that keeps only the open path: no copy of the tree, no array per node. Throws
/// InputError for a hierarchy the model cannot see into.
Prediction predict_geometric(const Hierarchy& h, const ModelOptions& opt, const UnitCosts& costs = {});

/// Sampled estimator: a probe traversal of the model tree with each training ray -- children
/// front to back, real primitive tests, the query's rule for ending (opt.query) -- fills alpha,
/// beta, gamma, P and the tests per leaf visit; the recursion then predicts from those ratios.
/// On the training rays themselves the prediction equals the traversal's counts; on other rays
/// of the same distribution it errs by the sample's noise.
Prediction predict_sampled(const ModelTree& tree, const Scene& scene, std::span<const Ray> training,
                           const ModelOptions& opt, const UnitCosts& costs = {});

struct RaySample;

/// Segments estimator: the same probe and recursion as predict_sampled, but the probe learns
/// where each ray's search ends from the sample's known crossings (sample.hpp) instead of
/// testing primitives, so one sample, drawn once per scene and distribution, predicts any
/// hierarchy over the scene. `rays` are the sample's indices to use (e.g. those of one kind,
/// traced with opt.query). Throws InputError for a sample of another scene.
Prediction predict_segments(const ModelTree& tree, const Scene& scene, const RaySample& sample,
                            std::span<const std::uint32_t> rays, const ModelOptions& opt, const UnitCosts& costs = {});

/// The segments estimator over a hierarchy rather than a materialised tree. A sample reaches a
/// small part of a large tree, and materialising the whole tree (then a tally per node) costs
/// far more than replaying the sample: so only the subtrees that some sample segment meets, up
/// to where the sample says it ends, are materialised (the others stand as pruned empty leaves,
/// ModelNode::pruned). Should a replay still enter a pruned node, the whole tree is materialised
/// and the prediction made again on it: the result is that of predict_segments on the whole
/// tree either way.
class SegmentsPredictor {
public:
    /// How a prediction is made.
    enum class Via {
        /// The hierarchy's own traversal replays the sample (Hierarchy::replay) where it can and
        /// the preset is Exact: the same prediction, within rounding, without materialising the
        /// model tree (a tenth of the time on a BVH). The model tree elsewhere.
        Traversal,
        /// Always the part of the model tree the sample reaches, materialised.
        ModelTree,
    };
    /// `h`, `scene` and `sample` must outlive the predictor. `size`: the hierarchy's nodes and
    /// references (StructureStats interior + leaves + references) when the caller has its
    /// structure() already (0: counted here, a walk over the whole hierarchy). The model tree
    /// is materialised when a prediction first needs it.
    SegmentsPredictor(const Hierarchy& h, const Scene& scene, const RaySample& sample, std::size_t size = 0,
                      Via via = Via::Traversal);
    /// predict_segments over the sample's rays `rays`.
    Prediction predict(std::span<const std::uint32_t> rays, const ModelOptions& opt, const UnitCosts& costs = {});
    /// Seconds spent materialising trees so far (the reached one, and the whole one if needed).
    double tree_seconds() const { return tree_seconds_; }
    /// The tree predictions through the model tree are made on (pruned until a replay needed the
    /// whole one), materialised if no prediction has needed it yet.
    const ModelTree& tree();
    /// A hierarchy of at most this many nodes and references per sample ray is materialised
    /// whole. References count: a 5D tree of a few thousand nodes may hold millions of them.
    static constexpr std::size_t kWholeItemsPerRay = 32;

private:
    void materialise();

    const Hierarchy& h_;
    const Scene& scene_;
    const RaySample& sample_;
    std::size_t size_;
    Via via_;
    ModelTree tree_;
    bool materialised_ = false;
    bool whole_ = false;
    double tree_seconds_ = 0;
};

/// The model's cost of single rays (per-pixel predicted heat maps): each ray's own geometry
/// says which nodes its segment meets and in which order, as the traversal would; whether the
/// search has ended before a node is reached is the model's probability, learned from a ray
/// sample's ended segments as predict_segments learns it, never from the ray's own hit. The
/// expectation over the sample's rays is close to predict_segments's. Not for 5D trees.
class RayCostModel {
public:
    /// Learns from the sample's rays `rays` (indices; e.g. those of one kind, traced with
    /// opt.query). Keeps `tree`; `scene` must outlive the model. Throws InputError for a tree
    /// without nodes or a 5D one.
    RayCostModel(ModelTree tree, const Scene& scene, const RaySample& sample, std::span<const std::uint32_t> rays,
                 const ModelOptions& opt);
    /// The expected operations of `ray` (with opt.query's termination).
    CostVector predict(const Ray& ray) const;

private:
    struct Impl;
    std::shared_ptr<const Impl> impl_;
};

}  // namespace rtcost
