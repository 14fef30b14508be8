#pragma once
/// \file math.hpp
/// Small vector, box and ray types shared by every part of rtcost.
///
/// Written by hand (rather than taken from a linear-algebra library) because the traversal hot
/// paths need exactly these few float operations inlined, and nothing else.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace rtcost {

inline constexpr float kInf = std::numeric_limits<float>::infinity();

/// A 3-component float vector.
struct Vec3 {
    float x = 0, y = 0, z = 0;

    constexpr Vec3() = default;
    constexpr Vec3(float x_, float y_, float z_) : x(x_), y(y_), z(z_) {}

    constexpr float operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
    constexpr float& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }

    constexpr Vec3 operator+(Vec3 o) const { return {x + o.x, y + o.y, z + o.z}; }
    constexpr Vec3 operator-(Vec3 o) const { return {x - o.x, y - o.y, z - o.z}; }
    constexpr Vec3 operator-() const { return {-x, -y, -z}; }
    constexpr Vec3 operator*(float s) const { return {x * s, y * s, z * s}; }
    constexpr Vec3 operator/(float s) const { return {x / s, y / s, z / s}; }
    constexpr Vec3 operator*(Vec3 o) const { return {x * o.x, y * o.y, z * o.z}; }
    constexpr Vec3& operator+=(Vec3 o) { x += o.x; y += o.y; z += o.z; return *this; }
    constexpr bool operator==(const Vec3&) const = default;
};

constexpr Vec3 operator*(float s, Vec3 v) { return v * s; }
constexpr float dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
constexpr Vec3 cross(Vec3 a, Vec3 b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline float length(Vec3 v) { return std::sqrt(dot(v, v)); }
inline Vec3 normalize(Vec3 v) { return v / length(v); }
constexpr Vec3 vmin(Vec3 a, Vec3 b) { return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)}; }
constexpr Vec3 vmax(Vec3 a, Vec3 b) { return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)}; }
inline bool is_finite(Vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
/// Index of the component with the largest magnitude.
inline int max_axis(Vec3 v) {
    float ax = std::fabs(v.x), ay = std::fabs(v.y), az = std::fabs(v.z);
    return ax >= ay ? (ax >= az ? 0 : 2) : (ay >= az ? 1 : 2);
}

/// Axis-aligned bounding box; the default box is empty (lo = +inf, hi = -inf).
struct Box3 {
    Vec3 lo{kInf, kInf, kInf};
    Vec3 hi{-kInf, -kInf, -kInf};

    constexpr Box3() = default;
    constexpr Box3(Vec3 l, Vec3 h) : lo(l), hi(h) {}

    constexpr bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
    constexpr void extend(Vec3 p) { lo = vmin(lo, p); hi = vmax(hi, p); }
    constexpr void extend(const Box3& b) { lo = vmin(lo, b.lo); hi = vmax(hi, b.hi); }
    constexpr Vec3 extent() const { return hi - lo; }
    constexpr Vec3 center() const { return (lo + hi) * 0.5f; }
    /// Surface area; 0 for an empty box.
    constexpr float area() const {
        if (empty()) return 0;
        Vec3 e = extent();
        return 2 * (e.x * e.y + e.y * e.z + e.z * e.x);
    }
    constexpr bool contains(Vec3 p) const {
        return p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y && p.z >= lo.z && p.z <= hi.z;
    }
    constexpr bool overlaps(const Box3& b) const {
        return lo.x <= b.hi.x && b.lo.x <= hi.x && lo.y <= b.hi.y && b.lo.y <= hi.y &&
               lo.z <= b.hi.z && b.lo.z <= hi.z;
    }
};

inline Box3 join(Box3 a, const Box3& b) { a.extend(b); return a; }

/// A ray segment: points o + t d for t in the open interval (tmin, tmax).
/// The direction need not be normalised; t is measured in units of |d|.
struct Ray {
    Vec3 o, d;
    float tmin = 0, tmax = kInf;
};

/// Ray with precomputed reciprocal direction for slab tests. Zero direction components give
/// +-inf reciprocals, which the slab test handles (see box_hit).
struct RayInv {
    Vec3 o, d, inv;
    float tmin, tmax;
    /// Per axis, 1 when the direction is negative (-0 included): which box face is entered first.
    int neg[3];
    explicit RayInv(const Ray& r)
        : o(r.o), d(r.d), inv(1.0f / r.d.x, 1.0f / r.d.y, 1.0f / r.d.z), tmin(r.tmin), tmax(r.tmax),
          neg{std::signbit(inv.x) ? 1 : 0, std::signbit(inv.y) ? 1 : 0, std::signbit(inv.z) ? 1 : 0} {}
};

/// Slab test of a ray against a box over (tmin, tmax); returns the entry distance or +inf.
/// Robust for zero direction components: 0 * inf produces NaN, which std::min/std::max with the
/// NaN in the second argument discard, so an axis-parallel ray inside the slab is accepted and one
/// outside (both bounds of the same sign, +-inf) is rejected. The final bounds are multiplied by
/// 1 + 2 gamma(3) (Ize 2013) so that a ray through an edge or a vertex is never lost to rounding.
[[gnu::always_inline]] inline float box_entry(const Box3& b, const Vec3& o, const Vec3& inv, float tmin, float tmax) {
    float t0 = tmin, t1 = tmax;
    for (int a = 0; a < 3; ++a) {
        // Entry and exit faces by the reciprocal's sign, not by comparing the two values: with
        // the origin in a face's plane one of them is NaN (0 * inf), and a compare-and-swap would
        // leave the infinite one in the wrong slot for a direction of -0 (the ray rejected).
        const bool neg = std::signbit(inv[a]);
        float tn = ((neg ? b.hi[a] : b.lo[a]) - o[a]) * inv[a];
        float tf = ((neg ? b.lo[a] : b.hi[a]) - o[a]) * inv[a];
        tf *= 1.0000004f;  // 1 + 2*gamma(3): conservative against rounding
        t0 = tn > t0 ? tn : t0;
        t1 = tf < t1 ? tf : t1;
    }
    return t0 <= t1 ? t0 : kInf;
}

/// Where a traversal that culls by the nearest hit so far (`t`) stops entering boxes: a little
/// beyond it. A box's entry distance rounds up to a few ulps past the distance a primitive inside
/// it gets from its own test (a ray through a shared vertex met a triangle at 0.99999988 whose
/// box it entered at 1, behind another triangle's hit at 1), so boxes entered within a relative
/// 2^-16 of the hit are still searched: an extra visit, never a lost hit.
inline float cull_bound(float t) { return t * 1.0000153f; }

/// box_entry with the entry and exit faces chosen by the direction's signs (no compare and swap
/// per axis): the same result, for traversals that test many boxes per ray.
// Always inlined: called per child box in every traversal's inner loop, where a translation
// unit with many traversal instances (a design's replays) had GCC stop inlining it (bvh-design's
// closest-hit walk ran 30% slower).
[[gnu::always_inline]] inline float box_entry(const Box3& b, const RayInv& r, float tmin, float tmax) {
    const Vec3* f = &b.lo;  // f[0] = lo, f[1] = hi
    float t0 = tmin, t1 = tmax;
    const float nx = (f[r.neg[0]].x - r.o.x) * r.inv.x, fx = (f[1 - r.neg[0]].x - r.o.x) * r.inv.x * 1.0000004f;
    const float ny = (f[r.neg[1]].y - r.o.y) * r.inv.y, fy = (f[1 - r.neg[1]].y - r.o.y) * r.inv.y * 1.0000004f;
    const float nz = (f[r.neg[2]].z - r.o.z) * r.inv.z, fz = (f[1 - r.neg[2]].z - r.o.z) * r.inv.z * 1.0000004f;
    // NaN (0 * inf, a ray in a face's plane) fails every compare and is ignored, as above.
    t0 = nx > t0 ? nx : t0;
    t0 = ny > t0 ? ny : t0;
    t0 = nz > t0 ? nz : t0;
    t1 = fx < t1 ? fx : t1;
    t1 = fy < t1 ? fy : t1;
    t1 = fz < t1 ? fz : t1;
    return t0 <= t1 ? t0 : kInf;
}

/// A segment of a ray by its parameter, [t0, t1]; empty when t0 > t1 (or NaN).
struct Segment {
    float t0, t1;
    bool empty() const { return !(t0 <= t1); }
};

/// `s` clipped to box `b` (no widening: the model's probes, not the traversals' hit tests).
inline Segment clip_segment(const RayInv& ri, const Box3& b, Segment s) {
    for (int k = 0; k < 3; ++k) {
        float tn = (b.lo[k] - ri.o[k]) * ri.inv[k], tf = (b.hi[k] - ri.o[k]) * ri.inv[k];
        if (tn > tf) std::swap(tn, tf);
        // NaN (0 * inf: a ray in a face's plane) fails both compares and is ignored.
        s.t0 = tn > s.t0 ? tn : s.t0;
        s.t1 = tf < s.t1 ? tf : s.t1;
    }
    return s;
}

}  // namespace rtcost
