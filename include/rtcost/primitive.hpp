#pragma once
/// \file primitive.hpp
/// The four primitive kinds of rtcost and their exact ray intersection.
///
/// Every primitive reports its bounds, its surface area and, for a ray, the nearest parameter
/// t in the open interval (tmin, tmax) where the ray meets its surface. Hits are geometric:
/// either side of a surface counts (shading faces the normal towards the ray later).

#include <cstdint>
#include <span>
#include <string_view>

#include "rtcost/math.hpp"

namespace rtcost {

/// Primitive kinds; the order is the order of the per-type `prim` counters.
enum class PrimKind : std::uint8_t { Triangle = 0, Polygon = 1, Sphere = 2, Cone = 3 };
inline constexpr int kPrimKinds = 4;
/// Lower-case name used in reports and JSON ("triangle", "polygon", "sphere", "cone").
std::string_view prim_kind_name(PrimKind k);

/// Triangle with vertices in counter-clockwise order seen from the front.
struct Triangle {
    Vec3 v0, v1, v2;
};

/// Planar polygon, any vertex count >= 3, convex or concave. Its vertices live in the scene's
/// polygon vertex pool; `normal` is the unit plane normal from the first three vertices (NFF
/// convention) or, when those are collinear, from Newell's method over all vertices.
struct Polygon {
    std::uint32_t first = 0;  ///< index of the first vertex in the pool
    std::uint32_t count = 0;  ///< number of vertices
    Vec3 normal;              ///< unit normal
    float plane_d = 0;        ///< plane: dot(normal, p) == plane_d
    std::uint8_t drop_axis = 0;  ///< axis dropped for the 2D inside test (largest |normal| component)
};

/// Sphere; `inside` marks the NFF negative-radius form (inside visible). Intersection is the
/// same either way (hits are geometric).
struct Sphere {
    Vec3 center;
    float radius = 0;
};

/// Open truncated cone or cylinder between two circles, no end caps.
struct Cone {
    Vec3 base;          ///< centre of the base circle
    float base_radius = 0;
    Vec3 apex;          ///< centre of the apex circle
    float apex_radius = 0;
};

/// Result of a closest-hit query.
struct Hit {
    float t = kInf;          ///< ray parameter of the hit (units of |d|), +inf on a miss
    std::int32_t prim = -1;  ///< primitive id, -1 on a miss
    Vec3 ng;                 ///< unit geometric normal (filled by Scene::complete_hit)
    bool hit() const { return prim >= 0; }
};

// Exact ray-primitive intersection. Each returns true and sets `t` when the ray meets the
// primitive at some t in (tmin, tmax); `t` is then the nearest such parameter.

/// Watertight ray-triangle test (Woop, Benthin and Wald 2013): rays through shared edges and
/// vertices hit at least one of the triangles that share them; none fall through.
bool intersect(const Triangle& tri, const Ray& ray, float& t);
/// Polygon test: plane hit, then a crossing-number inside test in the plane of projection.
bool intersect(const Polygon& poly, std::span<const Vec3> pool, const Ray& ray, float& t);
/// Edges the polygon test walks for `ray`: every one of a polygon of more than three vertices
/// whose plane the ray meets in (tmin, tmax), else none (a triangle takes the watertight test).
std::uint32_t edges_walked(const Polygon& poly, const Ray& ray);
/// Sphere test, origin inside included (then the far root is returned).
bool intersect(const Sphere& s, const Ray& ray, float& t);
/// Open cone/cylinder test, origin inside included, no end caps.
bool intersect(const Cone& c, const Ray& ray, float& t);

Box3 bounds(const Triangle& tri);
Box3 bounds(const Polygon& poly, std::span<const Vec3> pool);
Box3 bounds(const Sphere& s);
/// Tight bounds of the two rims (the surface lies within the convex hull of its rims).
Box3 bounds(const Cone& c);

float area(const Triangle& tri);
float area(const Polygon& poly, std::span<const Vec3> pool);
float area(const Sphere& s);
/// Lateral area of the frustum: pi (r1 + r2) * slant height.
float area(const Cone& c);

/// Unit geometric normal at surface point `p` (not faced towards any ray).
Vec3 normal_at(const Triangle& tri);
Vec3 normal_at(const Sphere& s, Vec3 p);
Vec3 normal_at(const Cone& c, Vec3 p);

/// Fills a Polygon's normal, plane and projection axis from its vertices. Returns false when the
/// polygon is degenerate (zero area or all vertices collinear).
bool setup_polygon(Polygon& poly, std::span<const Vec3> pool);

}  // namespace rtcost
