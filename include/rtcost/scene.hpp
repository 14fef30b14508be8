#pragma once
/// \file scene.hpp
/// A scene: primitives of four kinds with materials, positional lights, background and camera.
///
/// Primitive ids are 0-based in input order (file order for NFF, mesh then face order for
/// meshes). Each id maps to a kind and an index into that kind's array; hierarchies store ids.

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "rtcost/primitive.hpp"

namespace rtcost {

/// NFF material (`f r g b Kd Ks Shine T ior`).
struct Material {
    Vec3 color{1, 1, 1};
    float kd = 1, ks = 0, shine = 0, t = 0, ior = 1;
};

struct Light {
    Vec3 position;
    Vec3 color{1, 1, 1};
};

/// NFF viewpoint (`v`): angle is the full vertical field of view in degrees.
struct Camera {
    Vec3 from{0, 0, 1}, at{0, 0, 0}, up{0, 1, 0};
    float angle = 45;
    float hither = 0;
    int width = 512, height = 512;
};

/// Where a primitive lives: its kind, index into that kind's array and its material.
struct PrimRef {
    PrimKind kind;
    std::uint32_t index;
    std::uint32_t material;
};

/// What builders and the cost model read of every primitive, computed once by Scene::finalize.
struct PrimSummary {
    Box3 bounds;
    float area = 0;
    PrimKind kind = PrimKind::Triangle;
};

/// Largest coordinate magnitude of a scene (vertices, sphere and cone extents, camera, lights)
/// and of a ray origin. Beyond it the float arithmetic of the box tests, the surface-area costs
/// and Embree's reference no longer hold; loading refuses it (InputError) instead of answering
/// wrongly.
inline constexpr float kMaxCoordinate = 1e12f;
/// Smallest extent (largest side of the bounds) of a whole scene; below it squared lengths
/// underflow in float. Loading refuses it.
inline constexpr float kMinSceneExtent = 1e-12f;

class Scene;
/// Checks a finalized scene against the limits above and that every primitive has finite,
/// non-empty bounds; throws InputError(scene.name, 0, problem) otherwise, or for an empty scene
/// (naming the warnings about what was skipped).
void check_scene(const Scene& scene);
/// "scene has no primitives", with how many were skipped and the first reason, when any were.
std::string no_primitives_message(const std::vector<std::string>& warnings);

class Scene {
public:
    std::string name;  ///< file path or builtin spec it came from

    // Geometry, by kind. `prims[id]` says which array and index hold primitive `id`.
    std::vector<PrimRef> prims;
    std::vector<Triangle> triangles;
    std::vector<Polygon> polygons;
    std::vector<Vec3> polygon_vertices;  ///< pool shared by all polygons
    std::vector<Sphere> spheres;
    std::vector<Cone> cones;

    std::vector<Material> materials;
    std::vector<Light> lights;
    Vec3 background{0, 0, 0};
    Camera camera;
    bool has_camera = false;  ///< false: the camera was framed from the bounds

    /// Degenerate or otherwise skipped input, one message per problem ("file:line: problem").
    std::vector<std::string> warnings;

    std::size_t size() const { return prims.size(); }
    bool empty() const { return prims.empty(); }

    /// Appenders; each returns the new primitive's id.
    std::uint32_t add(const Triangle& t, std::uint32_t material);
    std::uint32_t add(const Sphere& s, std::uint32_t material);
    std::uint32_t add(const Cone& c, std::uint32_t material);
    /// Adds a polygon over `verts`; returns false (adding nothing) when it is degenerate. One of
    /// three vertices is added as a Triangle (the same test and hits). A
    /// polygon of more than three vertices that is not planar (a vertex off its plane by more
    /// than 1e-6 of its size) is flattened onto the plane of its normal, keeping its outline in
    /// the projection the intersection uses; `flattened` (if given) says so when the polygon is
    /// non-planar beyond what float rounding of planar input explains (1e-5 of its size off a
    /// plane fitted in double), which is what a reader warns about.
    bool add_polygon(std::span<const Vec3> verts, std::uint32_t material, std::uint32_t* id = nullptr,
                     bool* flattened = nullptr);

    /// Bounds and area of primitive `id` (from summaries() once finalized).
    Box3 prim_bounds(std::uint32_t id) const;
    float prim_area(std::uint32_t id) const;
    /// Every primitive's bounds, area and kind, by id, as of the last finalize() (empty before).
    const std::vector<PrimSummary>& summaries() const { return summaries_; }
    /// A hash of every primitive's kind, bounds and area as of the last finalize(): what a ray
    /// sample records of the scene it was drawn on, so that one drawn on another scene is told
    /// apart (RaySample::scene). Not a cryptographic hash.
    std::uint64_t fingerprint() const { return fingerprint_; }
    PrimKind kind(std::uint32_t id) const { return prims[id].kind; }
    /// Edges a test of primitive `id` walks (RayCounters::polygon_edges): a polygon of more than
    /// three vertices, by its crossing test, each of its edges; no other primitive any. With
    /// `ray` (its tmax the nearest hit so far), only when the ray meets the polygon's plane in
    /// (tmin, tmax): what the test does; without, the edges a test may walk (the model's count).
    std::uint32_t edges_walked(std::uint32_t id) const {
        if (prims[id].kind != PrimKind::Polygon) return 0;
        const std::uint32_t n = polygons[prims[id].index].count;
        return n > 3 ? n : 0;
    }
    /// The most vertices of any polygon (0 without polygons; set by finalize).
    std::uint32_t max_polygon_vertices() const { return max_polygon_vertices_; }
    std::uint32_t edges_walked(std::uint32_t id, const Ray& ray) const {
        if (prims[id].kind != PrimKind::Polygon) return 0;
        return rtcost::edges_walked(polygons[prims[id].index], ray);
    }

    /// Exact intersection of primitive `id`; see primitive.hpp.
    inline bool intersect(std::uint32_t id, const Ray& ray, float& t) const {
        const PrimRef& p = prims[id];
        switch (p.kind) {
            case PrimKind::Triangle: return rtcost::intersect(triangles[p.index], ray, t);
            case PrimKind::Polygon: return rtcost::intersect(polygons[p.index], polygon_vertices, ray, t);
            case PrimKind::Sphere: return rtcost::intersect(spheres[p.index], ray, t);
            case PrimKind::Cone: return rtcost::intersect(cones[p.index], ray, t);
        }
        return false;
    }

    /// Fills `hit.ng` (unit geometric normal) for a hit found by any hierarchy.
    void complete_hit(const Ray& ray, Hit& hit) const;

    /// Bounds of all primitives (cached after finalize()).
    const Box3& bounds() const { return bounds_; }
    /// Counts of primitives by kind, indexed by PrimKind.
    std::array<std::size_t, kPrimKinds> kind_counts() const;
    /// Bytes of geometry held (primitive arrays and pools).
    std::size_t bytes() const;

    /// Computes the primitives' summaries and bounds and, when the input had no camera, a default one framing the bounds; adds
    /// a default light when there is none and a default material when there is none.
    void finalize();

private:
    /// The camera finalize() gives a scene without one: centred on `centre`, the bounds' radius.
    Camera default_camera(Vec3 centre, float radius) const;

    Box3 bounds_;
    std::vector<PrimSummary> summaries_;
    std::uint32_t max_polygon_vertices_ = 0;
    std::uint64_t fingerprint_ = 0;
};

}  // namespace rtcost
