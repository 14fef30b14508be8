// Python binding of the evaluation (`rtcost eval`): rtcost._rtcost._evaluate returns the
// `rtcost eval --json` document as Python objects; python/rtcost/_evaluate.py makes the table.
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "rtcost/error.hpp"
#include "rtcost/evaluate.hpp"
#include "rtcost/model.hpp"

namespace rtcost::py {

namespace {

/// As `eval --estimator`: names, "both" (sampled, geometric) or "all"; the first is the headline.
std::vector<Estimator> estimators_from(const std::vector<std::string>& names) {
    std::vector<Estimator> out;
    for (const auto& n : names) {
        if (n == "geometric") out.push_back(Estimator::Geometric);
        else if (n == "sampled") out.push_back(Estimator::Sampled);
        else if (n == "segments") out.push_back(Estimator::Segments);
        else if (n == "both") out.insert(out.end(), {Estimator::Sampled, Estimator::Geometric});
        else if (n == "all") out.insert(out.end(), {Estimator::Segments, Estimator::Sampled, Estimator::Geometric});
        else throw InputError("estimator", 0, "'" + n + "': geometric, sampled, segments, a list of them, both or all");
    }
    if (out.empty()) throw InputError("estimator", 0, "no estimator named");
    return out;
}

std::vector<Preset> presets_from(const std::vector<std::string>& names) {
    std::vector<Preset> out;
    for (const auto& n : names) {
        if (n == "exact") out.push_back(Preset::Exact);
        else if (n == "paper") out.push_back(Preset::Paper);
        else if (n == "both") out.insert(out.end(), {Preset::Exact, Preset::Paper});
        else throw InputError("preset", 0, "'" + n + "' is not one of exact, paper, both");
    }
    if (out.empty()) throw InputError("preset", 0, "no preset named");
    return out;
}

/// `rays` is a distribution name or ray file (then size, count, seed make the RaySpec, as the
/// CLI's --rays) or an (N, 8) array with its kinds.
pb::object evaluate_py(const Scene& scene, const std::string& hierarchies, const pb::object& rays,
                       const pb::object& kinds, const std::string& size, std::size_t count, std::uint64_t seed,
                       const std::vector<std::string>& estimators, const std::vector<std::string>& presets,
                       const std::string& query, const std::string& shadow, std::size_t sample,
                       const std::string& sample_file, const std::string& costs, int threads, bool by_depth) {
    EvalOptions opt;
    opt.hierarchies = parse_hierarchy_list(hierarchies, scene.size(), "hierarchies");
    opt.left_out = left_out_of_all(hierarchies, scene.size());
    opt.estimators = estimators_from(estimators);
    opt.presets = presets_from(presets);
    opt.query = query_from_name(query);
    opt.occlusion = query_from_name(shadow, "shadow");
    if (opt.occlusion == Query::All) throw InputError("shadow", 0, "'all' is not one of closest, any");
    // As `eval --sample N` (0: the defaults), `--sample-file`; the sample's seed is the rays'.
    if (sample > 0) opt.sample = opt.segments = sample;
    opt.sample_file = sample_file;
    opt.sample_seed = seed;
    if (!costs.empty()) opt.costs = UnitCosts::read(costs);
    opt.threads = threads;
    EvalResult result;
    if (pb::isinstance<pb::str>(rays)) {
        RaySpec spec;
        spec.name = rays.cast<std::string>();
        spec.size = size;
        spec.count = count;
        spec.seed = seed;
        pb::gil_scoped_release release;
        result = evaluate(scene, spec, opt);
    } else {
        RaySet set;
        set.rays = rays_from_array(rays);
        set.kinds = kinds_from_object(kinds, set.rays.size());
        set.described = "array of " + std::to_string(set.rays.size()) + " rays";
        pb::gil_scoped_release release;
        result = evaluate(scene, std::move(set), opt);
    }
    return to_python(to_json(result, by_depth));
}

}  // namespace

void bind_evaluate(pb::module_& m) {
    m.def("_evaluate", &evaluate_py, pb::arg("scene"), pb::arg("hierarchies"), pb::arg("rays"), pb::arg("kinds"),
          pb::arg("size"), pb::arg("count"), pb::arg("seed"), pb::arg("estimators"), pb::arg("presets"),
          pb::arg("query"), pb::arg("shadow"), pb::arg("sample"), pb::arg("sample_file"), pb::arg("costs"), pb::arg("threads"),
          pb::arg("by_depth"));
}

}  // namespace rtcost::py
