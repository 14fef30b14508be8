#include "rtcost/scene.hpp"

#include <cmath>
#include <numbers>

namespace rtcost {

std::uint32_t Scene::add(const Triangle& t, std::uint32_t material) {
    prims.push_back({PrimKind::Triangle, static_cast<std::uint32_t>(triangles.size()), material});
    triangles.push_back(t);
    return static_cast<std::uint32_t>(prims.size() - 1);
}

std::uint32_t Scene::add(const Sphere& s, std::uint32_t material) {
    prims.push_back({PrimKind::Sphere, static_cast<std::uint32_t>(spheres.size()), material});
    spheres.push_back(s);
    return static_cast<std::uint32_t>(prims.size() - 1);
}

std::uint32_t Scene::add(const Cone& c, std::uint32_t material) {
    prims.push_back({PrimKind::Cone, static_cast<std::uint32_t>(cones.size()), material});
    cones.push_back(c);
    return static_cast<std::uint32_t>(prims.size() - 1);
}

bool Scene::add_polygon(std::span<const Vec3> verts, std::uint32_t material, std::uint32_t* id) {
    Polygon p;
    p.first = static_cast<std::uint32_t>(polygon_vertices.size());
    p.count = static_cast<std::uint32_t>(verts.size());
    polygon_vertices.insert(polygon_vertices.end(), verts.begin(), verts.end());
    if (!setup_polygon(p, polygon_vertices)) {
        polygon_vertices.resize(p.first);
        return false;
    }
    prims.push_back({PrimKind::Polygon, static_cast<std::uint32_t>(polygons.size()), material});
    polygons.push_back(p);
    if (id) *id = static_cast<std::uint32_t>(prims.size() - 1);
    return true;
}

Box3 Scene::prim_bounds(std::uint32_t id) const {
    if (id < summaries_.size()) return summaries_[id].bounds;
    const PrimRef& p = prims[id];
    switch (p.kind) {
        case PrimKind::Triangle: return rtcost::bounds(triangles[p.index]);
        case PrimKind::Polygon: return rtcost::bounds(polygons[p.index], polygon_vertices);
        case PrimKind::Sphere: return rtcost::bounds(spheres[p.index]);
        case PrimKind::Cone: return rtcost::bounds(cones[p.index]);
    }
    return {};
}

float Scene::prim_area(std::uint32_t id) const {
    if (id < summaries_.size()) return summaries_[id].area;
    const PrimRef& p = prims[id];
    switch (p.kind) {
        case PrimKind::Triangle: return rtcost::area(triangles[p.index]);
        case PrimKind::Polygon: return rtcost::area(polygons[p.index], polygon_vertices);
        case PrimKind::Sphere: return rtcost::area(spheres[p.index]);
        case PrimKind::Cone: return rtcost::area(cones[p.index]);
    }
    return 0;
}

void Scene::complete_hit(const Ray& ray, Hit& hit) const {
    if (!hit.hit()) return;
    const PrimRef& p = prims[hit.prim];
    Vec3 point = ray.o + ray.d * hit.t;
    switch (p.kind) {
        case PrimKind::Triangle: hit.ng = normal_at(triangles[p.index]); break;
        case PrimKind::Polygon: hit.ng = polygons[p.index].normal; break;
        case PrimKind::Sphere: hit.ng = normal_at(spheres[p.index], point); break;
        case PrimKind::Cone: hit.ng = normal_at(cones[p.index], point); break;
    }
}

std::array<std::size_t, kPrimKinds> Scene::kind_counts() const {
    return {triangles.size(), polygons.size(), spheres.size(), cones.size()};
}

std::size_t Scene::bytes() const {
    return prims.capacity() * sizeof(PrimRef) + triangles.capacity() * sizeof(Triangle) +
           polygons.capacity() * sizeof(Polygon) + polygon_vertices.capacity() * sizeof(Vec3) +
           spheres.capacity() * sizeof(Sphere) + cones.capacity() * sizeof(Cone) +
           summaries_.capacity() * sizeof(PrimSummary) +
           materials.capacity() * sizeof(Material) + lights.capacity() * sizeof(Light);
}

void Scene::finalize() {
    // Computed afresh: the geometry may have changed since the last call.
    summaries_.clear();
    std::vector<PrimSummary> sums(prims.size());
    bounds_ = Box3{};
    for (std::uint32_t id = 0; id < prims.size(); ++id) {
        sums[id] = {prim_bounds(id), prim_area(id), prims[id].kind};
        bounds_.extend(sums[id].bounds);
    }
    summaries_ = std::move(sums);
    if (materials.empty()) materials.push_back(Material{});
    if (empty()) return;
    Vec3 c = bounds_.center();
    float radius = 0.5f * length(bounds_.extent());
    if (!has_camera) {
        // Frame the bounding sphere from a three-quarter view, the usual default of mesh viewers.
        Camera cam;
        cam.angle = 45;
        float dist = radius / std::sin(0.5f * cam.angle * std::numbers::pi_v<float> / 180.0f);
        cam.at = c;
        cam.from = c + normalize(Vec3{1, 0.6f, 0.8f}) * (dist * 1.05f);
        cam.up = Vec3{0, 1, 0};
        cam.hither = radius * 1e-3f;
        camera = cam;
    }
    if (lights.empty()) {
        // One light over the camera's shoulder so that a default render is lit.
        Vec3 dir = normalize(camera.from - camera.at);
        lights.push_back({c + (dir + Vec3{0, 1, 0}) * (2 * radius), {1, 1, 1}});
    }
}

}  // namespace rtcost
