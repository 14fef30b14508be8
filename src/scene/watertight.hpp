#pragma once
// The watertight ray-triangle test (Woop, Benthin and Wald 2013) split into what depends on the
// ray only (the axis permutation and the shear, three divisions) and what each triangle adds, so
// that a traversal testing many triangles per ray computes the former once. The same float
// operations in the same order as `intersect(const Triangle&, ...)`, which calls this: hits agree
// bit for bit (the library is built with -ffp-contract=off, so no fused multiply-add either).

#include <cmath>
#include <cstring>
#include <utility>

#include "rtcost/primitive.hpp"

namespace rtcost {

/// The ray's part of the watertight test: its largest direction component becomes z, and the
/// shear that makes the ray the +z axis.
struct RayShear {
    int kx = 0, ky = 1, kz = 2;
    float sx = 0, sy = 0, sz = 0;
    /// Unset: for a traversal of a scene without triangles, which never asks for it.
    RayShear() = default;
    explicit RayShear(const Vec3& d) : kz(max_axis(d)) {
        kx = (kz + 1) % 3;
        ky = (kx + 1) % 3;
        if (d[kz] < 0) std::swap(kx, ky);
        sx = d[kx] / d[kz];
        sy = d[ky] / d[kz];
        sz = 1.0f / d[kz];
    }
};

/// The end of the test with the edge values in double (primitives.cpp): the sign test, the
/// determinant and the hit distance.
bool watertight_finish_in_double(double u, double v, double w, float az, float bz, float cz, const Ray& ray,
                                 float& t);

/// Component `k` of `v` minus that of `o`, the components read from memory by index.
[[gnu::always_inline]] inline float axis_minus(const Vec3& v, const Vec3& o, int k) {
    float a, b;
    std::memcpy(&a, reinterpret_cast<const char*>(&v) + sizeof(float) * k, sizeof a);
    std::memcpy(&b, reinterpret_cast<const char*>(&o) + sizeof(float) * k, sizeof b);
    return a - b;
}

/// Watertight test of `tri` against `ray`, whose shear is `s` (= RayShear(ray.d)).
[[gnu::always_inline]] inline bool intersect(const Triangle& tri, const Ray& ray, const RayShear& s, float& t) {
    // Components by index read from memory (Vec3::operator[] selects among x, y, z by compares):
    // vertex minus origin on the permuted axes, the same subtractions as (tri.v0 - ray.o)[k].
    const struct {
        float x, y, z;
    } a{axis_minus(tri.v0, ray.o, s.kx), axis_minus(tri.v0, ray.o, s.ky), axis_minus(tri.v0, ray.o, s.kz)},
        b{axis_minus(tri.v1, ray.o, s.kx), axis_minus(tri.v1, ray.o, s.ky), axis_minus(tri.v1, ray.o, s.kz)},
        c{axis_minus(tri.v2, ray.o, s.kx), axis_minus(tri.v2, ray.o, s.ky), axis_minus(tri.v2, ray.o, s.kz)};
    const float ax = a.x - s.sx * a.z, ay = a.y - s.sy * a.z;
    const float bx = b.x - s.sx * b.z, by = b.y - s.sy * b.z;
    const float cx = c.x - s.sx * c.z, cy = c.y - s.sy * c.z;
    const float u1 = cx * by, u2 = cy * bx, v1 = ax * cy, v2 = ay * cx, w1 = bx * ay, w2 = by * ax;
    const float u = u1 - u2, v = v1 - v2, w = w1 - w2;
    const float az = s.sz * a.z, bz = s.sz * b.z, cz = s.sz * c.z;
    // Each edge value is a difference of two rounded products: its sign is certain only when it
    // exceeds their rounding (2^-24 of each); a long thin triangle's edge values cancel far
    // below that and would report hits beside the triangle.
    constexpr float kRound = 1.2e-7f;
    if (std::fabs(u) <= kRound * (std::fabs(u1) + std::fabs(u2)) ||
        std::fabs(v) <= kRound * (std::fabs(v1) + std::fabs(v2)) ||
        std::fabs(w) <= kRound * (std::fabs(w1) + std::fabs(w2)) || !std::isfinite(u + v + w)) {
        // An edge (nearly) through the ray, or products beyond float's range (huge or tiny
        // triangles): the decision in double, where the products of the sheared float
        // coordinates are exact and each difference is rounded once, so its sign is right.
        const double du = double(cx) * by - double(cy) * bx, dv = double(ax) * cy - double(ay) * cx,
                     dw = double(bx) * ay - double(by) * ax;
        return watertight_finish_in_double(du, dv, dw, az, bz, cz, ray, t);
    }
    if ((u < 0 || v < 0 || w < 0) && (u > 0 || v > 0 || w > 0)) return false;
    const float det = u + v + w;
    const float tt = (u * az + v * bz + w * cz) / det;
    // t is the barycentric mean of az, bz, cz: with det and t both above 1e-18 the largest term
    // is normal and the float sum is accurate. Below (tiny triangles, whose products are
    // subnormal) or beyond float's range, the same t again in double.
    if (!std::isfinite(tt) || !(std::fabs(det) >= 1e-18f) || !(std::fabs(tt) >= 1e-18f))
        return watertight_finish_in_double(u, v, w, az, bz, cz, ray, t);
    if (!(tt > ray.tmin && tt < ray.tmax)) return false;
    t = tt;
    return true;
}

}  // namespace rtcost
