// Exact ray intersection, bounds and area of the four primitive kinds.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "rtcost/primitive.hpp"
#include "watertight.hpp"

namespace rtcost {

std::string_view prim_kind_name(PrimKind k) {
    switch (k) {
        case PrimKind::Triangle: return "triangle";
        case PrimKind::Polygon: return "polygon";
        case PrimKind::Sphere: return "sphere";
        case PrimKind::Cone: return "cone";
    }
    return "unknown";
}

namespace {

struct D3 {
    double x, y, z;
};
inline D3 d3(Vec3 v) { return {v.x, v.y, v.z}; }
inline D3 operator-(D3 a, D3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline D3 operator+(D3 a, D3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline D3 operator*(D3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
inline double dot(D3 a, D3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline double comp(D3 a, int i) { return i == 0 ? a.x : (i == 1 ? a.y : a.z); }

/// Nearest of two roots inside the open interval, or false.
inline bool nearest(double t0, double t1, float tmin, float tmax, float& t) {
    if (t0 > t1) std::swap(t0, t1);
    for (double r : {t0, t1}) {
        float f = static_cast<float>(r);
        if (f > tmin && f < tmax) {
            t = f;
            return true;
        }
    }
    return false;
}

/// Unit vector along `v`; +z when `v` is zero (a hit point rounded onto a tiny sphere's centre).
Vec3 unit(D3 v) {
    const double l = std::sqrt(dot(v, v));
    if (!(l > 0) || !std::isfinite(l)) return {0, 0, 1};
    return {static_cast<float>(v.x / l), static_cast<float>(v.y / l), static_cast<float>(v.z / l)};
}

/// Newell's normal: twice the vector area of a planar polygon, any shape.
D3 newell(const Vec3* v, std::uint32_t n) {
    D3 s{0, 0, 0};
    for (std::uint32_t i = 0; i < n; ++i) {
        D3 a = d3(v[i]), b = d3(v[(i + 1) % n]);
        s.x += (a.y - b.y) * (a.z + b.z);
        s.y += (a.z - b.z) * (a.x + b.x);
        s.z += (a.x - b.x) * (a.y + b.y);
    }
    return s;
}

}  // namespace

bool watertight_finish_in_double(double u, double v, double w, float az, float bz, float cz, const Ray& ray, float& t) {
    if ((u < 0 || v < 0 || w < 0) && (u > 0 || v > 0 || w > 0)) return false;
    const double det = u + v + w;
    if (det == 0.0) return false;
    const float tt = static_cast<float>((u * az + v * bz + w * cz) / det);
    if (!(tt > ray.tmin && tt < ray.tmax)) return false;
    t = tt;
    return true;
}

// Watertight test (Woop, Benthin, Wald 2013): translate to the ray origin, permute so that the
// ray's largest direction component is z, shear so that the ray is the +z axis; the 2D edge
// functions then decide containment consistently for triangles sharing an edge. Edge values of
// exactly zero are recomputed in double so that the sign test is exact where it matters.
bool intersect(const Triangle& tri, const Ray& ray, float& t) { return intersect(tri, ray, RayShear(ray.d), t); }

bool setup_polygon(Polygon& poly, std::span<const Vec3> pool) {
    if (poly.count < 3 || poly.first + poly.count > pool.size()) return false;
    const Vec3* v = pool.data() + poly.first;
    Box3 box;
    for (std::uint32_t i = 0; i < poly.count; ++i) {
        if (!is_finite(v[i])) return false;
        box.extend(v[i]);
    }
    const Vec3 ext = box.extent();
    const double scale = std::sqrt(double(ext.x) * ext.x + double(ext.y) * ext.y + double(ext.z) * ext.z);
    if (!(scale > 0)) return false;
    const D3 nw = newell(v, poly.count);
    const double nw_len = std::sqrt(dot(nw, nw));
    // Zero area: the vector area vanishes relative to the polygon's size.
    if (!(nw_len > 1e-12 * scale * scale)) return false;
    // NFF: the first three vertices give the facing; collinear ones fall back to Newell's normal.
    D3 e1 = d3(v[1]) - d3(v[0]), e2 = d3(v[2]) - d3(v[0]);
    D3 n{e1.y * e2.z - e1.z * e2.y, e1.z * e2.x - e1.x * e2.z, e1.x * e2.y - e1.y * e2.x};
    double n_len = std::sqrt(dot(n, n));
    if (!(n_len > 1e-9 * scale * scale)) {
        n = nw;
        n_len = nw_len;
    }
    D3 un = n * (1.0 / n_len);
    poly.normal = Vec3{static_cast<float>(un.x), static_cast<float>(un.y), static_cast<float>(un.z)};
    double d = 0;
    for (std::uint32_t i = 0; i < poly.count; ++i) d += dot(un, d3(v[i]));
    poly.plane_d = static_cast<float>(d / poly.count);
    poly.drop_axis = static_cast<std::uint8_t>(max_axis(poly.normal));
    return true;
}

// Plane hit, then even-odd crossing test in the plane of projection that drops the normal's
// largest axis; works for concave polygons (gear faces) as well as convex ones.
namespace {
// The polygon test's first step (shared with edges_walked, so that counting walks the same
// arithmetic): where the ray meets the plane, and whether that lies in (tmin, tmax).
bool plane_hit(const Polygon& poly, const Ray& ray, double& tt, float& tf) {
    const D3 n = d3(poly.normal), o = d3(ray.o), d = d3(ray.d);
    const double denom = dot(n, d);
    if (denom == 0.0) return false;
    tt = (static_cast<double>(poly.plane_d) - dot(n, o)) / denom;
    tf = static_cast<float>(tt);
    return tf > ray.tmin && tf < ray.tmax;
}
}  // namespace

std::uint32_t edges_walked(const Polygon& poly, const Ray& ray) {
    double tt;
    float tf;
    return poly.count > 3 && plane_hit(poly, ray, tt, tf) ? poly.count : 0;
}

bool intersect(const Polygon& poly, std::span<const Vec3> pool, const Ray& ray, float& t) {
    // A three-vertex polygon is a triangle: the watertight test is exact on shared edges whatever
    // the neighbours' projection planes, and faster than the crossing test in double.
    if (poly.count == 3) {
        const Vec3* v = pool.data() + poly.first;
        return intersect(Triangle{v[0], v[1], v[2]}, ray, t);
    }
    double tt;
    float tf;
    if (!plane_hit(poly, ray, tt, tf)) return false;
    const D3 p = d3(ray.o) + d3(ray.d) * tt;
    const int ia = (poly.drop_axis + 1) % 3, ib = (poly.drop_axis + 2) % 3;
    const double px = comp(p, ia), py = comp(p, ib);
    const Vec3* v = pool.data() + poly.first;
    bool inside = false;
    for (std::uint32_t i = 0, j = poly.count - 1; i < poly.count; j = i++) {
        const double xi = v[i][ia], yi = v[i][ib], xj = v[j][ia], yj = v[j][ib];
        if ((yi > py) != (yj > py)) {
            const double x = xi + (py - yi) * (xj - xi) / (yj - yi);
            if (px < x) inside = !inside;
        }
    }
    if (!inside) return false;
    t = tf;
    return true;
}

// Roots of |o + t d - c|^2 = r^2 in double, with the discriminant formed from the distance of
// the centre to the ray's line (not b^2 - ac), which keeps tiny far spheres accurate.
bool intersect(const Sphere& s, const Ray& ray, float& t) {
    const D3 oc = d3(ray.o) - d3(s.center), d = d3(ray.d);
    const double a = dot(d, d);
    const double b = dot(oc, d);
    const D3 f = oc - d * (b / a);
    const double r = s.radius;
    const double disc = r * r - dot(f, f);
    if (disc < 0) return false;
    const double c = dot(oc, oc) - r * r;
    const double q = -(b + std::copysign(std::sqrt(a * disc), b));
    if (q == 0) return nearest(0.0, 0.0, ray.tmin, ray.tmax, t);
    return nearest(c / q, q / a, ray.tmin, ray.tmax, t);
}

// The frustum's surface: points at axial distance s in [0, h] from the base, at distance
// rb + k s from the axis (k = (ra - rb) / h). Substituting the ray gives a quadratic in t.
bool intersect(const Cone& cone, const Ray& ray, float& t) {
    const D3 base = d3(cone.base), axis = d3(cone.apex) - base;
    const double h = std::sqrt(dot(axis, axis));
    if (!(h > 0)) return false;
    const D3 w = axis * (1.0 / h);
    const double rb = std::fabs(cone.base_radius), ra = std::fabs(cone.apex_radius);
    const double k = (ra - rb) / h;
    const D3 oc = d3(ray.o) - base, d = d3(ray.d);
    const double s0 = dot(oc, w), ds = dot(d, w);
    const D3 r0 = oc - w * s0, rd = d - w * ds;
    const double m = rb + k * s0;
    const double A = dot(rd, rd) - k * k * ds * ds;
    const double B = dot(r0, rd) - k * ds * m;
    const double C = dot(r0, r0) - m * m;
    double roots[2];
    int n = 0;
    // A is a difference of two terms; for a flat cone (k large) each is far larger than |d|^2,
    // and A's rounding is relative to them: a ray along a generator must not get a root from
    // a rounded A of the wrong sign (a false hit on a cone of radius 2e9 and axis 1).
    const double scale = dot(rd, rd) + k * k * ds * ds;
    if (std::fabs(A) <= 1e-12 * std::max(scale, dot(d, d))) {
        if (B == 0) return false;  // parallel to a generator: the line lies on or off the surface
        roots[n++] = -C / (2 * B);
    } else {
        const double disc = B * B - A * C;
        if (disc < 0) return false;
        const double q = -(B + std::copysign(std::sqrt(disc), B));
        roots[n++] = q / A;
        if (q != 0) roots[n++] = C / q;
    }
    if (n == 2 && roots[0] > roots[1]) std::swap(roots[0], roots[1]);
    for (int i = 0; i < n; ++i) {
        const double s = s0 + roots[i] * ds;
        if (s < 0 || s > h || rb + k * s < 0) continue;
        const float f = static_cast<float>(roots[i]);
        if (f > ray.tmin && f < ray.tmax) {
            t = f;
            return true;
        }
    }
    return false;
}

Box3 bounds(const Triangle& tri) {
    Box3 b;
    b.extend(tri.v0);
    b.extend(tri.v1);
    b.extend(tri.v2);
    return b;
}

Box3 bounds(const Polygon& poly, std::span<const Vec3> pool) {
    Box3 b;
    for (std::uint32_t i = 0; i < poly.count; ++i) b.extend(pool[poly.first + i]);
    return b;
}

Box3 bounds(const Sphere& s) {
    const float r = std::fabs(s.radius);
    return {s.center - Vec3{r, r, r}, s.center + Vec3{r, r, r}};
}

// A rim circle of radius r around unit axis w extends r * sqrt(1 - w_i^2) along axis i. The
// bounds are rounded outwards by a relative epsilon so that float rounding never clips the
// surface.
Box3 bounds(const Cone& c) {
    // The axis in double: a short one (1e-30) must not underflow to an empty box while the
    // intersection, in double, still meets the surface.
    const D3 a = d3(c.apex) - d3(c.base);
    const double h = std::sqrt(dot(a, a));
    Box3 b;
    if (!(h > 0)) return b;
    const Vec3 w{static_cast<float>(a.x / h), static_cast<float>(a.y / h), static_cast<float>(a.z / h)};
    const float rb = std::fabs(c.base_radius), ra = std::fabs(c.apex_radius);
    for (int pass = 0; pass < 2; ++pass) {
        const Vec3 centre = pass ? c.apex : c.base;
        const float r = pass ? ra : rb;
        Vec3 e{r * std::sqrt(std::max(0.0f, 1 - w.x * w.x)), r * std::sqrt(std::max(0.0f, 1 - w.y * w.y)),
               r * std::sqrt(std::max(0.0f, 1 - w.z * w.z))};
        b.extend(centre - e);
        b.extend(centre + e);
    }
    const Vec3 pad = (b.hi - b.lo) * 1e-6f + Vec3{1e-30f, 1e-30f, 1e-30f};
    return {b.lo - pad, b.hi + pad};
}

float area(const Triangle& tri) { return 0.5f * length(cross(tri.v1 - tri.v0, tri.v2 - tri.v0)); }

float area(const Polygon& poly, std::span<const Vec3> pool) {
    const D3 n = newell(pool.data() + poly.first, poly.count);
    return static_cast<float>(0.5 * std::sqrt(dot(n, n)));
}

float area(const Sphere& s) { return 4.0f * std::numbers::pi_v<float> * s.radius * s.radius; }

float area(const Cone& c) {
    const float h = length(c.apex - c.base);
    const float rb = std::fabs(c.base_radius), ra = std::fabs(c.apex_radius);
    return std::numbers::pi_v<float> * (rb + ra) * std::sqrt(h * h + (rb - ra) * (rb - ra));
}

// Normals in double: a tiny primitive's edge products underflow in float and would normalise
// to NaN, which shading would pass on to every secondary ray.
Vec3 normal_at(const Triangle& tri) {
    const D3 e1 = d3(tri.v1) - d3(tri.v0), e2 = d3(tri.v2) - d3(tri.v0);
    return unit({e1.y * e2.z - e1.z * e2.y, e1.z * e2.x - e1.x * e2.z, e1.x * e2.y - e1.y * e2.x});
}

Vec3 normal_at(const Sphere& s, Vec3 p) { return unit(d3(p) - d3(s.center)); }

Vec3 normal_at(const Cone& c, Vec3 p) {
    const D3 a = d3(c.apex) - d3(c.base);
    const double h = std::sqrt(dot(a, a));
    if (!(h > 0)) return {0, 0, 1};
    const D3 w = a * (1.0 / h);
    const D3 q = d3(p) - d3(c.base);
    const D3 radial = q - w * dot(q, w);
    const double k = (std::fabs(double(c.apex_radius)) - std::fabs(double(c.base_radius))) / h;
    const double rl = std::sqrt(dot(radial, radial));
    if (!(rl > 0)) return unit(w);  // the tip of a true cone
    return unit(radial * (1.0 / rl) - w * k);
}

}  // namespace rtcost
