// Python bindings of scenes and ray distributions: rtcost.load, Scene, rtcost._make_rays.
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "rtcost/io.hpp"
#include "rtcost/report.hpp"

namespace rtcost::py {

namespace {

pb::tuple vec(Vec3 v) { return pb::make_tuple(v.x, v.y, v.z); }

/// make_rays without the GIL; returns (rays (N, 8) float32, kinds (N,) uint8, described).
pb::tuple make_rays_py(const Scene& scene, const std::string& dist, const std::string& size, std::size_t count,
                       std::uint64_t seed) {
    RaySpec spec;
    spec.name = dist;
    spec.size = size;
    spec.count = count;
    spec.seed = seed;
    RaySet set;
    {
        pb::gil_scoped_release release;
        set = make_rays(scene, spec);
    }
    pb::array_t<std::uint8_t> kinds(static_cast<pb::ssize_t>(set.kinds.size()));
    auto k = kinds.mutable_unchecked<1>();
    for (std::size_t i = 0; i < set.kinds.size(); ++i) k(static_cast<pb::ssize_t>(i)) = static_cast<std::uint8_t>(set.kinds[i]);
    return pb::make_tuple(rays_to_array(set.rays), kinds, set.described);
}

}  // namespace

void bind_scene(pb::module_& m) {
    pb::class_<Scene>(m, "Scene", "A scene: primitives, lights, camera (rtcost.load makes one).")
        .def_readonly("name", &Scene::name, "the path or builtin spec it came from")
        .def_property_readonly("primitives", &Scene::size, "number of primitives")
        .def("__len__", &Scene::size)
        .def_property_readonly(
            "by_kind", [](const Scene& s) { return to_python(to_json(s)["by_kind"]); },
            "primitive counts by kind: {'triangle': n, 'polygon': n, 'sphere': n, 'cone': n}")
        .def_property_readonly(
            "bounds", [](const Scene& s) { return pb::make_tuple(vec(s.bounds().lo), vec(s.bounds().hi)); },
            "((xlo, ylo, zlo), (xhi, yhi, zhi))")
        .def_property_readonly(
            "camera", [](const Scene& s) { return to_python(to_json(s)["camera"]); },
            "from, at, up, angle (vertical field of view, degrees), hither, resolution, from_file")
        .def_property_readonly("warnings", [](const Scene& s) { return s.warnings; },
                               "degenerate input skipped while loading, one 'file:line: problem' each")
        .def("info", [](const Scene& s) { return to_python(to_json(s)); }, "the summary `rtcost info --json` prints")
        .def("__repr__", [](const Scene& s) {
            return "<rtcost.Scene '" + s.name + "': " + std::to_string(s.size()) + " primitives>";
        });

    m.def(
        "load",
        [](const std::string& spec) {
            pb::gil_scoped_release release;
            return load_scene(spec);
        },
        pb::arg("path_or_builtin"),
        "Loads a scene: an NFF file, any mesh assimp reads, or 'builtin:balls[:level]' / 'builtin:tetra[:level]'.");
    m.def("_make_rays", &make_rays_py, pb::arg("scene"), pb::arg("dist"), pb::arg("size"), pb::arg("count"),
          pb::arg("seed"));
    m.def("distributions", &distribution_names, "names rtcost.rays accepts besides ray file paths");
    m.def("builtin_scenes", &builtin_scene_names, "names of the built-in scenes");
    pb::list kinds;
    for (int k = 0; k < kRayKinds; ++k) kinds.append(pb::str(std::string(ray_kind_name(static_cast<RayKind>(k)))));
    m.attr("RAY_KINDS") = kinds;
}

}  // namespace rtcost::py
