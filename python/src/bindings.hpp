#pragma once
// Shared pieces of the Python bindings (module `rtcost._rtcost`): conversions between rtcost's
// types and Python's, and the functions each binding file registers its part of the module with.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <nlohmann/json.hpp>
#include <vector>

#include "rtcost/hierarchy.hpp"
#include "rtcost/rays.hpp"

namespace rtcost::py {

namespace pb = pybind11;

/// A JSON value as the Python object json.loads would give (dict, list, float, int, str, ...).
pb::object to_python(const nlohmann::json& j);

/// Rays from a numpy array of shape (N, 8) (ox oy oz dx dy dz tmin tmax, any float dtype),
/// checked by the ray file's rules; throws InputError("rays", 0, "ray I: problem").
std::vector<Ray> rays_from_array(const pb::array& a);
/// Rays as a new (N, 8) float32 array.
pb::array_t<float> rays_to_array(const std::vector<Ray>& rays);
/// Ray kinds from a 1-d integer array of RayKind values (one per ray), or File for None.
std::vector<RayKind> kinds_from_object(const pb::object& kinds, std::size_t n);

/// Parses "closest", "any" or "all"; throws InputError naming `what` otherwise.
Query query_from_name(const std::string& name, const char* what = "query");

/// A built hierarchy with the assignments it was built with (its parameters' values).
struct PyHierarchy {
    std::unique_ptr<Hierarchy> h;
    std::vector<std::string> set;
};

void bind_scene(pb::module_& m);
void bind_hierarchy(pb::module_& m);
void bind_evaluate(pb::module_& m);

}  // namespace rtcost::py
