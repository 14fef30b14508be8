#pragma once
/// \file design.hpp
/// Hierarchies designed by the cost model for the user's own rays: the parameters every designed
/// hierarchy shares (`rays`, `size`, `sample`, `seed`, `costs`), the design sample each draws,
/// the sample's predicted cost of a candidate structure, and `rtcost design`: each designed
/// structure beside its family's yardstick, predicted and measured on rays outside the sample.

#include <cstdint>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "rtcost/hierarchy.hpp"
#include "rtcost/model.hpp"
#include "rtcost/rays.hpp"
#include "rtcost/sample.hpp"

namespace rtcost {

/// The parameters of every designed hierarchy, with their defaults (rays=spd, sample=4096,
/// seed=1, size=128x128: the image of camera-based rays the sample is drawn from) and the
/// family's default `costs`: "typical" where typical ns per operation describe the family's
/// traversal time (BVHs, kd-trees: docs/design.md measured gains with them), "ops" (operation
/// counts, polygon edges at a share of a test) where they do not (the subdivisions' locate
/// traversals and grids, whose time the fit leaves 30-75% off and whose designs lost against
/// operation counts).
std::vector<ParamSpec> design_param_specs(const std::string& default_costs = "typical");

/// A designed hierarchy's sample and the costs it minimises.
struct DesignInput {
    RaySample sample;
    UnitCosts costs;
    RaySpec spec;               ///< the distribution the sample was drawn from
    std::size_t count = 4096;   ///< requested sample size
    std::uint64_t seed = 1;     ///< the draw's seed
    /// The bvh-sah (default parameters) that made the rays and found the sample's ends: a
    /// design that compares with bvh-sah's tree takes it rather than building it again.
    std::shared_ptr<const Hierarchy> reference;
};

/// Reads the design parameters from `p` and draws the sample: `sample` rays of the distribution
/// `rays` (seed 1 for the distribution, `seed` for the draw, as `rtcost eval --estimator
/// segments --seed` draws it), their ends found with a bvh-sah built here. The sample is
/// capped at half the distribution's rays. Throws InputError for bad values.
DesignInput draw_design_input(const Scene& scene, const Params& p);

/// The model's cost per ray of a model tree on the sample (segments estimator, each ray with
/// its own query), in `costs`' units.
double sample_cost(const ModelTree& tree, const Scene& scene, const RaySample& sample, const UnitCosts& costs);
/// The same for a hierarchy, materialising only the part of its tree the sample reaches
/// (SegmentsPredictor): what a design search calls for every candidate it builds.
double sample_cost(const Hierarchy& h, const Scene& scene, const RaySample& sample, const UnitCosts& costs);

/// One family in `rtcost design`.
struct DesignRow {
    std::string family;        ///< "grid", "bvh", ...
    std::string designed;      ///< e.g. "grid-design:rays=spd:sample=4096:seed=1"
    std::string yardstick;     ///< e.g. "grid:res=hetero"
    std::string structure;     ///< what the design chose (e.g. "res 40x31x12"), if it says
    double designed_build = 0, yardstick_build = 0;            ///< seconds
    double designed_predicted = 0, yardstick_predicted = 0;    ///< model cost per ray (sample)
    double designed_measured = 0, yardstick_measured = 0;      ///< measured cost per ray (test rays)
    double designed_ns = 0, yardstick_ns = 0;                  ///< single-thread ns per ray
    double embree_ns = 0;      ///< Embree's, on the same rays in the same run
    double gain = 0;           ///< 1 - designed_ns / yardstick_ns (0.2: 20% fewer ns per ray)
    /// With DesignOptions::control: the yardstick's ns per ray in a second evaluation of the
    /// designed one, the yardstick and Embree (built again, the yardstick first); 0 otherwise.
    double control_ns = 0;
};

struct DesignOptions {
    RaySpec rays;                         ///< the distribution (its seed: the rays')
    std::vector<std::string> families;    ///< empty: all
    std::size_t sample = 4096;
    std::uint64_t seed = 1;               ///< the sample's draw
    /// What the designs minimise and the table reports: a calibrated costs file (ns), "unit"
    /// or "ops" (operations), "typical", or empty: each family's default (design_param_specs), operations
    /// reported.
    std::string costs_file;
    /// Also build and evaluate each family's three structures a second time, the yardstick first
    /// (an A/A control): how far apart two evaluations time the yardstick, which where a
    /// structure's data land in memory moves by a few percent. Twice the time.
    bool control = false;
    std::function<void(const std::string&)> on_step;
};

struct DesignResult {
    std::string scene, distribution;
    std::size_t sample = 0, test_rays = 0;
    bool calibrated = false;            ///< the table is in a costs file's ns (else operations)
    /// What the designs minimised: each family's default, typical, unit or a file.
    std::string designed_for = "each family's default";
    std::vector<DesignRow> rows;
};

/// Families `rtcost design` knows, in order.
std::vector<std::string> design_families();

/// Builds each family's designed hierarchy and yardstick and evaluates both on the rays of the
/// distribution outside the design sample (single thread). Throws InputError for bad input.
DesignResult design(const Scene& scene, const DesignOptions& opt);

/// `{"results": [...]}` with each row's figures and the `--set` parameters to rebuild it.
nlohmann::json to_json(const DesignResult& r);
std::string design_table(const DesignResult& r);

}  // namespace rtcost
