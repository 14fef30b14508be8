// The designed hierarchies' shared parameters, their sample, and the sample's predicted cost.
#include <algorithm>
#include <array>
#include <filesystem>

#include "rtcost/design.hpp"
#include "rtcost/error.hpp"
#include "rtcost/rays.hpp"

namespace rtcost {

std::vector<ParamSpec> design_param_specs(const std::string& default_costs) {
    // Text, not a choice: hierarchies register during static initialisation, possibly before
    // the ray distributions do; make_rays names the known ones when the name is not one.
    return {ParamSpec::text("rays", "spd", "distribution the structure is designed for (any name rtcost rays takes)"),
            ParamSpec::text("size", "128x128",
                            "image size WxH of the camera-based rays the sample is drawn from (empty: the scene's)"),
            ParamSpec::integer("sample", "4096", 1, 1 << 20, "rays in the design sample (at most half the distribution)"),
            ParamSpec::integer("seed", "1", 0, 1LL << 62, "seed of the sample's draw (the distribution's own seed is 1)"),
            ParamSpec::text("costs", default_costs,
                            "ns per operation the design minimises: typical (built in, every family's time model), "
                            "typical-bvh (built in, a BVH's box test against its primitive tests), unit (the paper's operation "
                            "counts), ops (operation counts, a polygon's edges at the share of its test the built-in "
                            "time model gives them), or a costs file of rtcost calibrate (./ops: a file called ops)")};
}

DesignInput draw_design_input(const Scene& scene, const Params& p) {
    DesignInput in;
    in.spec.name = p.str("rays");
    in.spec.size = p.str("size");
    if (!in.spec.size.empty()) {  // named as the user gave it, not as the command line's --size
        int width, height;
        parse_size(in.spec.size, "--set size", width, height);
    }
    in.spec.seed = 1;
    in.count = static_cast<std::size_t>(p.integer("sample"));
    in.seed = static_cast<std::uint64_t>(p.integer("seed"));
    // A costs file called like a built-in table, named without a directory, would be taken for
    // the table: refused when asked for (a family's own default is the table, file or not).
    const std::string& costs = p.str("costs");
    std::error_code ec;
    if (costs != p.spec("costs").default_value && UnitCosts::built_in(costs) && std::filesystem::is_regular_file(costs, ec))
        throw InputError("--set costs", 0,
                         "'" + costs + "' names both a built-in cost table and a file in this directory: ./" + costs +
                             " for the file");
    in.costs = UnitCosts::named(costs);
    // One bvh-sah both makes the sample's rays (if the distribution is made by tracing: only
    // at the sample's pixels) and finds the sample's ends.
    auto reference = build_hierarchy(scene, "bvh-sah");
    in.sample = draw_sample(scene, in.spec, in.count, in.seed, *reference);
    in.reference = std::move(reference);
    return in;
}

namespace {

/// The sample's mean cost per ray, each ray predicted with its own query by `predict(rays, options)`.
template <class Predict>
double mean_by_query(const RaySample& sample, Predict&& predict) {
    std::array<std::vector<std::uint32_t>, 3> by_query;
    for (std::uint32_t i = 0; i < sample.size(); ++i) by_query[static_cast<int>(sample.queries[i])].push_back(i);
    double sum = 0;
    for (int q = 0; q < 3; ++q) {
        if (by_query[q].empty()) continue;
        ModelOptions o;
        o.query = static_cast<Query>(q);
        sum += predict(by_query[q], o).scalar * static_cast<double>(by_query[q].size());
    }
    return sample.size() ? sum / static_cast<double>(sample.size()) : 0;
}

}  // namespace

double sample_cost(const ModelTree& tree, const Scene& scene, const RaySample& sample, const UnitCosts& costs) {
    return mean_by_query(sample, [&](std::span<const std::uint32_t> rays, const ModelOptions& o) {
        return predict_segments(tree, scene, sample, rays, o, costs);
    });
}

double sample_cost(const Hierarchy& h, const Scene& scene, const RaySample& sample, const UnitCosts& costs) {
    SegmentsPredictor predictor(h, scene, sample);
    return mean_by_query(sample, [&](std::span<const std::uint32_t> rays, const ModelOptions& o) {
        return predictor.predict(rays, o, costs);
    });
}

}  // namespace rtcost
