#include "rtcost/scene.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>

#include <fmt/format.h>

#include "rtcost/error.hpp"
#include "util/rng.hpp"
#include <numbers>

namespace rtcost {

namespace {

// The intersection finds a polygon's hit on its plane and decides containment in the projection
// that drops the normal's largest axis. A non-planar polygon's hits therefore lie off its
// vertices' box, where no hierarchy looks. Moving each vertex along the dropped axis onto the
// plane keeps the projected outline (what the inside test reads) and puts the hits inside the
// vertices' box again. Nothing changes when every vertex is within 1e-6 of the polygon's size of
// its (float) plane.
enum class Flattening { none, rounding, nonplanar };

// Whether the vertices leave a plane fitted in double (Newell's normal through their centroid) by
// more than 1e-5 of the polygon's size: planar input written as text and read into floats stays
// far below that, while the float normal alone can put a thin planar quad 1e-6 off its plane.
bool visibly_nonplanar(const Vec3* v, std::uint32_t count, double size) {
    double n[3] = {0, 0, 0}, c[3] = {0, 0, 0};
    for (std::uint32_t i = 0; i < count; ++i) {
        const Vec3 a = v[i], b = v[(i + 1) % count];
        n[0] += (double(a.y) - b.y) * (double(a.z) + b.z);
        n[1] += (double(a.z) - b.z) * (double(a.x) + b.x);
        n[2] += (double(a.x) - b.x) * (double(a.y) + b.y);
        for (int k = 0; k < 3; ++k) c[k] += double(a[k]) / count;
    }
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(len > 0)) return true;
    double off = 0;
    for (std::uint32_t i = 0; i < count; ++i)
        off = std::max(off, std::fabs((n[0] * (v[i].x - c[0]) + n[1] * (v[i].y - c[1]) + n[2] * (v[i].z - c[2])) / len));
    return off > 1e-5 * size;
}

Flattening flatten_polygon(const Polygon& p, std::vector<Vec3>& pool) {
    Vec3* v = pool.data() + p.first;
    Box3 box;
    for (std::uint32_t i = 0; i < p.count; ++i) box.extend(v[i]);
    const Vec3 e = box.extent();
    const double size = std::sqrt(double(e.x) * e.x + double(e.y) * e.y + double(e.z) * e.z);
    const double n[3] = {p.normal.x, p.normal.y, p.normal.z};
    double off = 0;
    for (std::uint32_t i = 0; i < p.count; ++i)
        off = std::max(off, std::fabs(n[0] * v[i].x + n[1] * v[i].y + n[2] * v[i].z - double(p.plane_d)));
    if (!(off > 1e-6 * size)) return Flattening::none;
    const bool nonplanar = visibly_nonplanar(v, p.count, size);
    const int k = p.drop_axis, a = (k + 1) % 3, b = (k + 2) % 3;
    for (std::uint32_t i = 0; i < p.count; ++i)
        v[i][k] = static_cast<float>((double(p.plane_d) - n[a] * v[i][a] - n[b] * v[i][b]) / n[k]);
    return nonplanar ? Flattening::nonplanar : Flattening::rounding;
}

}  // namespace

std::string no_primitives_message(const std::vector<std::string>& warnings) {
    if (warnings.empty()) return "scene has no primitives";
    return fmt::format("scene has no primitives ({} warning{} while reading; the first: {})", warnings.size(),
                       warnings.size() == 1 ? "" : "s", warnings.front());
}

void check_scene(const Scene& s) {
    if (s.empty()) throw InputError(s.name, 0, no_primitives_message(s.warnings));
    const auto& sums = s.summaries();
    auto beyond = [](Vec3 v) {
        return std::fabs(v.x) > kMaxCoordinate || std::fabs(v.y) > kMaxCoordinate || std::fabs(v.z) > kMaxCoordinate;
    };
    for (std::uint32_t id = 0; id < sums.size(); ++id) {
        const Box3& b = sums[id].bounds;
        const std::string what = fmt::format("primitive {} ({})", id, prim_kind_name(sums[id].kind));
        if (b.empty() || !is_finite(b.lo) || !is_finite(b.hi))
            throw InputError(s.name, 0, what + " has no finite bounds");
        if (beyond(b.lo) || beyond(b.hi))
            throw InputError(s.name, 0,
                             fmt::format("{} reaches {:g}, beyond +-{:g}, the largest coordinate the float "
                                         "intersection and box tests handle (scale the scene down)",
                                         what, std::max({std::fabs(b.lo.x), std::fabs(b.lo.y), std::fabs(b.lo.z),
                                                         std::fabs(b.hi.x), std::fabs(b.hi.y), std::fabs(b.hi.z)}),
                                         kMaxCoordinate));
    }
    const Vec3 e = s.bounds().extent();
    const float extent = std::max({e.x, e.y, e.z});
    if (!(extent >= kMinSceneExtent))
        throw InputError(s.name, 0,
                         fmt::format("the scene's extent {:g} is below {:g}, the smallest the float arithmetic "
                                     "handles (scale the scene up)",
                                     extent, kMinSceneExtent));
    if (s.has_camera && (beyond(s.camera.from) || beyond(s.camera.at)))
        throw InputError(s.name, 0, fmt::format("the viewpoint lies beyond +-{:g}", kMaxCoordinate));
    for (const Light& l : s.lights)
        if (beyond(l.position)) throw InputError(s.name, 0, fmt::format("a light lies beyond +-{:g}", kMaxCoordinate));
}

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

bool Scene::add_polygon(std::span<const Vec3> verts, std::uint32_t material, std::uint32_t* id, bool* flattened) {
    Polygon p;
    p.first = static_cast<std::uint32_t>(polygon_vertices.size());
    p.count = static_cast<std::uint32_t>(verts.size());
    polygon_vertices.insert(polygon_vertices.end(), verts.begin(), verts.end());
    if (!setup_polygon(p, polygon_vertices)) {
        polygon_vertices.resize(p.first);
        return false;
    }
    if (flattened) *flattened = false;
    if (p.count == 3) {
        // A polygon of three vertices is a triangle: the same exact test (intersect(Polygon)
        // makes it), so it is stored, counted and priced as one. Kept apart, its tests were
        // priced at a polygon's fitted ns, which polygons whose edges carry their cost set.
        const Triangle t{polygon_vertices[p.first], polygon_vertices[p.first + 1], polygon_vertices[p.first + 2]};
        polygon_vertices.resize(p.first);
        const std::uint32_t added = add(t, material);
        if (id) *id = added;
        return true;
    }
    const Flattening f = p.count > 3 ? flatten_polygon(p, polygon_vertices) : Flattening::none;
    if (f != Flattening::none) {
        if (flattened) *flattened = f == Flattening::nonplanar;
        if (!setup_polygon(p, polygon_vertices)) {
            polygon_vertices.resize(p.first);
            return false;
        }
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
    // Every value's bits mixed in turn (mix64, a bijection): order and value both count.
    auto mix = [](std::uint64_t h, std::uint64_t v) { return mix64(h ^ v); };
    fingerprint_ = mix(0, summaries_.size());
    for (const PrimSummary& p : summaries_) {
        const float f[7] = {p.bounds.lo.x, p.bounds.lo.y, p.bounds.lo.z, p.bounds.hi.x, p.bounds.hi.y, p.bounds.hi.z, p.area};
        std::uint64_t h = static_cast<std::uint64_t>(p.kind);
        for (float x : f) h = mix(h, std::bit_cast<std::uint32_t>(x));
        fingerprint_ = mix(fingerprint_, h);
    }
    max_polygon_vertices_ = 0;
    for (const Polygon& p : polygons) max_polygon_vertices_ = std::max(max_polygon_vertices_, p.count);
    if (materials.empty()) materials.push_back(Material{});
    if (empty()) return;
    Vec3 c = bounds_.center();
    // In double: a huge scene's squared extent overflows float, a tiny one's underflows. A scene
    // without extent (not one that loading accepts) still gets a finite camera.
    const Vec3 ext = bounds_.extent();
    float radius = static_cast<float>(0.5 * std::sqrt(double(ext.x) * ext.x + double(ext.y) * ext.y + double(ext.z) * ext.z));
    if (!(radius > 0) || !std::isfinite(radius)) radius = 1;
    if (!has_camera) camera = default_camera(c, radius);
    if (lights.empty()) {
        // One key light, 60 degrees round from the camera and higher on the camera's side (above
        // or below): what the camera sees is lit, and casts shadows that the camera sees (a light
        // at the eye hides every shadow, and shadow rays would then almost never be stopped).
        const Vec3 d = normalize(camera.from - camera.at);
        const float cs = 0.5f, sn = 0.8660254f;
        const Vec3 side = normalize(Vec3{d.x * cs - d.z * sn, d.y < 0 ? -1.0f : 1.0f, d.x * sn + d.z * cs});
        lights.push_back({c + side * (2 * radius), {1, 1, 1}});
    }
}

}  // namespace rtcost
