// Conversions between rtcost's values and Python's (JSON documents, ray arrays, kinds).
#include <string>

#include "bindings.hpp"
#include "rtcost/error.hpp"
#include "rtcost/io.hpp"

namespace rtcost::py {

pb::object to_python(const nlohmann::json& j) {
    using nlohmann::json;
    switch (j.type()) {
        case json::value_t::null: return pb::none();
        case json::value_t::boolean: return pb::bool_(j.get<bool>());
        case json::value_t::number_integer: return pb::int_(j.get<long long>());
        case json::value_t::number_unsigned: return pb::int_(j.get<unsigned long long>());
        case json::value_t::number_float: return pb::float_(j.get<double>());
        case json::value_t::string: return pb::str(j.get_ref<const std::string&>());
        case json::value_t::array: {
            pb::list out;
            for (const json& e : j) out.append(to_python(e));
            return out;
        }
        case json::value_t::object: {
            pb::dict out;
            for (auto it = j.begin(); it != j.end(); ++it) out[pb::str(it.key())] = to_python(it.value());
            return out;
        }
        default: return pb::none();
    }
}

std::vector<Ray> rays_from_array(const pb::array& a) {
    auto f = pb::array_t<float, pb::array::c_style | pb::array::forcecast>::ensure(a);
    if (!f || f.ndim() != 2 || f.shape(1) != 8)
        throw InputError("rays", 0, "expected an (N, 8) array of float32 (ox oy oz dx dy dz tmin tmax)");
    auto v = f.unchecked<2>();
    std::vector<Ray> rays(static_cast<std::size_t>(f.shape(0)));
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const auto r = static_cast<pb::ssize_t>(i);
        Ray& ray = rays[i];
        ray.o = {v(r, 0), v(r, 1), v(r, 2)};
        ray.d = {v(r, 3), v(r, 4), v(r, 5)};
        ray.tmin = v(r, 6);
        ray.tmax = v(r, 7);
        if (const std::string what = ray_problem(ray); !what.empty())
            throw InputError("rays", 0, "ray " + std::to_string(i) + ": " + what);
    }
    return rays;
}

pb::array_t<float> rays_to_array(const std::vector<Ray>& rays) {
    pb::array_t<float> out({static_cast<pb::ssize_t>(rays.size()), pb::ssize_t{8}});
    auto v = out.mutable_unchecked<2>();
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const Ray& ray = rays[i];
        const float f[8] = {ray.o.x, ray.o.y, ray.o.z, ray.d.x, ray.d.y, ray.d.z, ray.tmin, ray.tmax};
        for (int k = 0; k < 8; ++k) v(static_cast<pb::ssize_t>(i), k) = f[k];
    }
    return out;
}

std::vector<RayKind> kinds_from_object(const pb::object& kinds, std::size_t n) {
    if (kinds.is_none()) return std::vector<RayKind>(n, RayKind::File);
    auto k = pb::array_t<int, pb::array::c_style | pb::array::forcecast>::ensure(kinds);
    if (!k || k.ndim() != 1 || static_cast<std::size_t>(k.shape(0)) != n)
        throw InputError("kinds", 0, "expected one ray kind per ray (" + std::to_string(n) + ")");
    std::vector<RayKind> out(n);
    for (std::size_t i = 0; i < n; ++i) {
        int v = k.at(static_cast<pb::ssize_t>(i));
        if (v < 0 || v >= kRayKinds) throw InputError("kinds", 0, "ray " + std::to_string(i) + ": no ray kind " + std::to_string(v));
        out[i] = static_cast<RayKind>(v);
    }
    return out;
}

Query query_from_name(const std::string& name, const char* what) {
    if (name == "closest") return Query::Closest;
    if (name == "any") return Query::Any;
    if (name == "all") return Query::All;
    throw InputError(what, 0, "'" + name + "' is not one of closest, any, all");
}

}  // namespace rtcost::py
