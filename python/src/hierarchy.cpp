// Python bindings of hierarchies: Scene.build, Hierarchy.trace, Hierarchy.structure and the list
// of registered hierarchies. Building and tracing run without the GIL.
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "rtcost/error.hpp"
#include "rtcost/report.hpp"
#include "rtcost/trace.hpp"

namespace rtcost::py {

namespace {

/// A parameter value as `--set` takes it: True/False as 1/0, numbers and strings as written.
std::string param_text(const pb::handle& v) {
    if (pb::isinstance<pb::bool_>(v)) return v.cast<bool>() ? "1" : "0";
    if (pb::isinstance<pb::str>(v)) return v.cast<std::string>();
    return pb::str(v).cast<std::string>();
}

PyHierarchy build_py(const Scene& scene, const std::string& name, const pb::kwargs& params) {
    PyHierarchy out;
    for (const auto& [k, v] : params) out.set.push_back(k.cast<std::string>() + "=" + param_text(v));
    pb::gil_scoped_release release;
    out.h = build_hierarchy(scene, name, out.set);
    return out;
}

/// What Hierarchy.trace returns.
struct PyTrace {
    pb::array_t<std::int32_t> prim;
    pb::array_t<float> t;
    std::size_t rays = 0, hits = 0;
    double seconds = 0;
    int threads = 1;
    pb::object counters = pb::none(), by_kind = pb::none();
};

PyTrace trace_py(const PyHierarchy& ph, const pb::array& rays, const pb::object& kinds, const std::string& query,
                 const std::string& shadow, bool count, int threads) {
    RaySet set;
    set.rays = rays_from_array(rays);
    set.kinds = kinds_from_object(kinds, set.rays.size());
    TraceOptions opt;
    opt.query = query_from_name(query);
    opt.threads = threads;
    const Query occlusion = query_from_name(shadow, "shadow");
    if (occlusion == Query::All) throw InputError("shadow", 0, "'all' is not one of closest, any");
    TraceResult timed, counted;
    {
        pb::gil_scoped_release release;
        // As `rtcost trace`: the timed pass is the fast path; counting is a second pass.
        timed = trace_ray_set(*ph.h, set, opt, occlusion);
        if (count) {
            opt.count = true;
            counted = trace_ray_set(*ph.h, set, opt, occlusion);
        }
    }
    PyTrace out;
    const auto n = static_cast<pb::ssize_t>(set.rays.size());
    out.prim = pb::array_t<std::int32_t>(n);
    out.t = pb::array_t<float>(n);
    auto p = out.prim.mutable_unchecked<1>();
    auto t = out.t.mutable_unchecked<1>();
    for (pb::ssize_t i = 0; i < n; ++i) {
        p(i) = timed.hits[static_cast<std::size_t>(i)].prim;
        t(i) = timed.hits[static_cast<std::size_t>(i)].t;
    }
    out.rays = set.rays.size();
    out.hits = timed.hit_count;
    out.seconds = timed.seconds;
    out.threads = timed.threads;
    nlohmann::json by_kind = nlohmann::json::object();
    for (int k = 0; k < kRayKinds; ++k) {
        if (!timed.rays_by_kind[k]) continue;
        nlohmann::json e = {{"rays", timed.rays_by_kind[k]}, {"hits", timed.hits_by_kind[k]}};
        if (count) e["per_ray"] = per_ray_json(counted.counters_by_kind[k]);
        by_kind[std::string(ray_kind_name(static_cast<RayKind>(k)))] = e;
    }
    out.by_kind = to_python(by_kind);
    if (count) out.counters = to_python(per_ray_json(counted.counters));
    return out;
}

nlohmann::json params_json(const PyHierarchy& ph) {
    return rtcost::params_json(Params(find_hierarchy(ph.h->name())->params, ph.set).values());
}

}  // namespace

void bind_hierarchy(pb::module_& m) {
    pb::class_<PyTrace>(m, "TraceResult", "Hits and counters of one Hierarchy.trace.")
        .def_readonly("prim", &PyTrace::prim, "int32 primitive id per ray, -1 for a miss")
        .def_readonly("t", &PyTrace::t, "float32 ray parameter of the hit per ray, +inf for a miss")
        .def_readonly("rays", &PyTrace::rays)
        .def_readonly("hits", &PyTrace::hits, "number of rays that hit")
        .def_readonly("seconds", &PyTrace::seconds, "traversal time of the fast (uncounted) pass")
        .def_readonly("threads", &PyTrace::threads)
        .def_readonly("counters", &PyTrace::counters,
                      "per-ray means as `trace --json`'s per_ray (None when count=False)")
        .def_readonly("by_kind", &PyTrace::by_kind, "rays, hits and per_ray by ray kind, as `trace --json`")
        .def("__repr__", [](const PyTrace& r) {
            return "<rtcost.TraceResult: " + std::to_string(r.rays) + " rays, " + std::to_string(r.hits) + " hits>";
        });

    pb::class_<PyHierarchy>(m, "Hierarchy", "An acceleration structure built over a scene (Scene.build).")
        .def_property_readonly("name", [](const PyHierarchy& ph) { return std::string(ph.h->name()); })
        .def_property_readonly("_assignments", [](const PyHierarchy& ph) { return ph.set; },
                               "the `key=value` assignments it was built with")
        .def_property_readonly("params", [](const PyHierarchy& ph) { return to_python(params_json(ph)); },
                               "every parameter's value, defaults included")
        .def(
            "structure",
            [](const PyHierarchy& ph) {
                nlohmann::json j = to_json(ph.h->structure());
                j["hierarchy"] = ph.h->name();
                j["params"] = params_json(ph);
                return to_python(j);
            },
            "N_IN, N_V, N_EV, N_OIV, depth, bytes, seconds (build), as `build --json`")
        .def("_trace", &trace_py, pb::arg("rays"), pb::kw_only(), pb::arg("kinds") = pb::none(),
             pb::arg("query") = "closest", pb::arg("shadow") = "any", pb::arg("count") = true,
             pb::arg("threads") = 0,
             "Traces an (N, 8) array of rays (ox oy oz dx dy dz tmin tmax). `kinds` (one RAY_KINDS index per "
             "ray) makes shadow and AO rays `shadow` queries, as `rtcost trace` does for ray sets.")
        .def("__repr__", [](const PyHierarchy& ph) { return "<rtcost.Hierarchy " + std::string(ph.h->name()) + ">"; });

    m.def("_build", &build_py, pb::arg("scene"), pb::arg("name"), pb::keep_alive<0, 1>());
    m.def(
        "hierarchies",
        [] {
            pb::list out;
            for (const HierarchyInfo* info : hierarchies()) {
                pb::list params;
                for (const ParamSpec& p : info->params)
                    params.append(pb::dict(pb::arg("name") = p.name, pb::arg("default") = to_python(param_json(p.default_value)),
                                           pb::arg("help") = p.help, pb::arg("kind") = std::string(param_kind_name(p.kind)),
                                           pb::arg("domain") = p.domain()));
                out.append(pb::dict(pb::arg("name") = info->name, pb::arg("description") = info->description,
                                    pb::arg("params") = params));
            }
            return out;
        },
        "every registered hierarchy with its parameters and defaults (as `rtcost list`)");
}

}  // namespace rtcost::py
