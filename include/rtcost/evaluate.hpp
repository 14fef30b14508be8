#pragma once
/// \file evaluate.hpp
/// The evaluation rtcost exists for: hierarchies built over one scene, each one's cost per ray
/// predicted by the model and measured on the same rays, side by side and ranked. `rtcost eval`
/// is this call plus printing; the report, the design command and the Python module call it too.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "rtcost/hierarchy.hpp"
#include "rtcost/model.hpp"
#include "rtcost/rays.hpp"
#include "rtcost/stats.hpp"

namespace rtcost {

/// One hierarchy to evaluate: a registered name and its `key=value` parameters.
struct HierarchyRequest {
    std::string name;
    std::vector<std::string> params;
    /// "name" or "name:key=value[:key=value...]".
    std::string label() const;
};

/// Parses a hierarchy list: "all", or comma-separated "name[:key=value[:key=value...]]" (e.g.
/// "bvh-gs:seed=1,octree:max_depth=6,grid"). "all" is every registered hierarchy that makes
/// sense over `primitives` primitives (no embree; none over its HierarchyInfo::all_up_to: brute
/// above kBruteLimit, the slow builders above kLargeScene). Throws InputError naming `what` for
/// an unknown name or a malformed entry.
std::vector<HierarchyRequest> parse_hierarchy_list(std::string_view list, std::size_t primitives,
                                                   const std::string& what = "--hierarchy");
/// The hierarchies that "all" leaves out over `primitives` primitives (embree aside), by name.
std::vector<std::string> left_out_of_all(std::string_view list, std::size_t primitives);

/// Above this many primitives `all` leaves brute force out (ask for it by name), and brute force
/// asked for is measured on a subset of the rays: about kBruteTests primitive tests in all.
inline constexpr std::size_t kBruteLimit = kBruteInAll;
inline constexpr std::size_t kBruteTests = 200'000'000;
/// Rays per kind in the geometric estimator's visibility sample (draw_visibility_sample).
inline constexpr std::size_t kVisibilityRays = 2048;

struct EvalRow;

/// What to evaluate and how.
struct EvalOptions {
    std::vector<HierarchyRequest> hierarchies;
    /// Hierarchies "all" left out at this scene's size (left_out_of_all), reported with the result.
    std::vector<std::string> left_out;
    /// Estimators and presets to evaluate; the first of each gives the headline prediction.
    std::vector<Estimator> estimators{Estimator::Sampled};
    std::vector<Preset> presets{Preset::Exact};
    Query query = Query::Closest;      ///< every ray kind but the occlusion ones
    Query occlusion = Query::Any;      ///< shadow and ambient-occlusion rays
    std::size_t sample = 20000;        ///< training rays at most (sampled estimator)
    /// Segments estimator: rays in the sample drawn from the distribution (0: 2% of the rays,
    /// at most 4,096 and at least 256 where there are four times as many), its seed, or a
    /// sample file (`rtcost sample`) instead.
    std::size_t segments = 0;
    std::uint64_t sample_seed = 1;
    std::string sample_file;
    UnitCosts costs;                   ///< unit costs (calibrated: ns) for the scalar cost
    int threads = 0;                   ///< counting passes: 0 for all cores
    int timing_threads = 1;            ///< timed passes (single-thread by default: rankings by time)
    /// Timed passes over the test rays: `repeat` of them, or (repeat 0) as many as add up to
    /// `min_seconds`; the median is reported with the spread.
    int repeat = 0;
    double min_seconds = 0.2;
    /// Time the hierarchies in rounds, one pass of each per round in a new (seeded) order, after
    /// all are built and counted (all are kept in memory until then), instead of one after the
    /// other: a change in the machine's load or clock during the run then weighs on every
    /// hierarchy alike, so their ratio (a designed structure's gain over its yardstick) is not
    /// the load's. Passes repeat the same rays, which the branch predictor learns: on a few
    /// thousand rays a structure is timed faster alone, or beside an identical twin, than beside
    /// another structure of the same traversal code; compare structures timed in one company.
    bool interleave_timing = false;
    /// Called as each step of each hierarchy starts ("build NAME", "counting NAME", "timing
    /// NAME", "model NAME"), with the progress of the trace passes (step, rays done, rays), and
    /// with each finished row.
    std::function<void(const std::string& step)> on_step;
    std::function<void(const std::string& step, std::size_t done, std::size_t total)> on_progress;
    std::function<void(const EvalRow& row)> on_row;
};

/// One hierarchy's evaluation.
struct EvalRow {
    std::string name;                  ///< HierarchyRequest::label()
    StructureStats structure;
    bool modelled = false;             ///< the model sees into it (not embree)
    bool lazy = false;                 ///< grown by the rays (rc5d's default)
    std::vector<Prediction> predictions;  ///< every estimator x preset asked for; [0] the headline
    bool counted = true;               ///< its traversal counts operations (not embree)
    std::size_t measured_rays = 0;     ///< test rays measured (brute force on a large scene: a subset)
    CostVector measured;               ///< counted operations per ray
    double measured_scalar = 0;        ///< measured operations in unit costs
    double error = 0;                  ///< (headline - measured) / measured
    double mrays_per_s = 0;            ///< measured speed (wall clock) on `threads` threads
    double ns_per_ray = 0;             ///< measured CPU time per ray (median of the timed passes)
    int repeats = 1;                   ///< timed passes
    double time_spread = 0;            ///< (slowest - fastest) / median of the timed passes
    int threads = 1;
    std::vector<double> measured_visits;  ///< measured traversal steps per depth per ray
    /// Seconds one single-thread trace of the segments sample's rays takes (each kind with its
    /// query; not counted), after the predictions (the segments replay among them); 0 without one.
    double sample_trace_seconds = 0;
    /// 1 = cheapest, 0 = not ranked: by predicted cost (ns when the costs are calibrated), by
    /// counted operations (in unit costs), and by measured time.
    int rank_predicted = 0, rank_measured = 0, rank_time = 0;

    const Prediction* headline() const { return predictions.empty() ? nullptr : &predictions.front(); }
};

/// A scene fingerprint as `eval --json` writes it (`scene_fingerprint`: 16 hex digits, a JSON
/// number losing bits beyond 2^53 in most readers).
std::string fingerprint_text(std::uint64_t fingerprint);

/// Everything `rtcost eval` reports.
struct EvalResult {
    std::string scene;
    std::size_t primitives = 0;
    std::uint64_t scene_fingerprint = 0;  ///< Scene::fingerprint(): which scene it evaluated
    std::string distribution;          ///< RaySet::described
    std::size_t test_rays = 0, training_rays = 0;
    std::size_t sample_rays = 0;       ///< the segments estimator's sample (disjoint from the test rays)
    std::size_t distribution_rays = 0; ///< every ray of the distribution, before any was set apart
    double sample_seconds = 0;         ///< drawing it (once for every hierarchy), or reading it
    std::string sample_file;           ///< where it was read from (EvalOptions::sample_file); empty: drawn
    /// The geometric estimator's visibility sample (draw_visibility_sample; under termination).
    std::size_t visibility_rays = 0;
    double visibility_seconds = 0;
    /// How the rays were split: "none", "fresh draw" (lines, random), "pseudo-random half", or
/// "sample" (the segments estimator's sample left out of the test rays).
    std::string split;
    Query query = Query::Closest, occlusion = Query::Any;
    std::vector<std::pair<std::string, std::size_t>> rays_by_kind;  ///< test rays per kind
    std::vector<Estimator> estimators;
    std::vector<Preset> presets;
    bool calibrated = false;
    std::vector<EvalRow> rows;
    std::vector<std::string> left_out;  ///< EvalOptions::left_out
};

/// Evaluates `opt.hierarchies` over `scene` on the rays `spec` names. With the sampled
/// estimator the training rays are disjoint from the test rays: a fresh draw with another seed
/// for random distributions, otherwise a pseudo-random half of the rays, thinned to `sample`.
/// Throws InputError for bad requests.
EvalResult evaluate(const Scene& scene, const RaySpec& spec, const EvalOptions& opt);
/// The same on a given ray set (e.g. rays from a file or from Python): the training rays are a
/// pseudo-random half of `rays`.
EvalResult evaluate(const Scene& scene, RaySet rays, const EvalOptions& opt);

/// The `rtcost eval --json` document of `r` (with `visits_by_depth` when `by_depth`).
nlohmann::json to_json(const EvalResult& r, bool by_depth = false);
/// The text tables `rtcost eval` prints (with visits per depth when `by_depth`): the header
/// (scene, rays, split, queries, model), the column names, one line per row, and the summary
/// (rankings, every prediction, costs by kind).
std::string eval_table(const EvalResult& r, bool by_depth = false);
std::string eval_header(const EvalResult& r);
std::string eval_columns();
std::string eval_row(const EvalRow& row);
std::string eval_summary(const EvalResult& r, bool by_depth = false);

/// The order in which round `round` (0, 1, ...) of interleaved timing passes over `n` timed
/// structures: a permutation of 0..n-1, new each round and the same in every run and on every
/// standard library. A pass finds the caches and branch predictors as the previous pass left
/// them; one fixed order had each structure always follow the same one.
std::vector<std::size_t> timing_order(std::size_t n, int round);

/// What `rtcost calibrate` measures on one scene: each hierarchy of `hierarchies` built, counted on
/// `rays` with one thread, and timed `repeat` times (CPU time, the fastest pass kept: the least
/// disturbed by the machine), in rounds of one pass each in timing_order -- all built first, so
/// that a slow spell of the machine falls on every hierarchy alike rather than on the one whose
/// rank it would change -- or, `sequential`, right after its build and freed once timed (less
/// memory). Counted before timed, so that a lazily built structure (rc5d) is whole when timed.
/// Hierarchies that count nothing (embree) are left out. `on_passes(n)`: n more of the
/// hierarchies x (1 + repeat) passes done (a left-out hierarchy's all at once). Labels are
/// "LABEL on SCENE".
std::vector<CalibrationSample> measure_for_calibration(const Scene& scene, const RaySet& rays,
                                                       const std::vector<HierarchyRequest>& hierarchies, int repeat,
                                                       bool sequential,
                                                       const std::function<void(std::size_t n)>& on_passes = {});

/// Spearman's rank correlation of `x` and `y` (same length; ties ranked in order, 0 for fewer
/// than two values): how alike a prediction ranks what was measured.
double rank_correlation(std::span<const double> x, std::span<const double> y);

std::string_view estimator_name(Estimator e);
std::string_view preset_name(Preset p);
std::string_view query_name(Query q);

}  // namespace rtcost
