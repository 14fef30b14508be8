// Per-primitive unit tests with analytic answers: bounds, areas, ray parameters and normals of
// triangles, polygons (convex and concave), spheres and open cones/cylinders, including the hard
// rays (through edges and vertices, grazing, axis-parallel, starting inside) and the scene-level
// handling of degenerate primitives.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <optional>
#include <random>
#include <vector>

#include "rtcost/primitive.hpp"
#include "rtcost/scene.hpp"

namespace rtcost {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;

Ray make_ray(Vec3 o, Vec3 d, float tmin = 0, float tmax = kInf) {
    Ray r;
    r.o = o;
    r.d = d;
    r.tmin = tmin;
    r.tmax = tmax;
    return r;
}

std::optional<float> hit(const Triangle& p, const Ray& r) {
    float t = -1;
    if (intersect(p, r, t)) return t;
    return std::nullopt;
}
std::optional<float> hit(const Sphere& p, const Ray& r) {
    float t = -1;
    if (intersect(p, r, t)) return t;
    return std::nullopt;
}
std::optional<float> hit(const Cone& p, const Ray& r) {
    float t = -1;
    if (intersect(p, r, t)) return t;
    return std::nullopt;
}
std::optional<float> hit(const Scene& s, std::uint32_t id, const Ray& r) {
    float t = -1;
    if (s.intersect(id, r, t)) return t;
    return std::nullopt;
}

// Tolerance for a float ray parameter computed from exact analytic data.
float tol(float expected) { return 2e-6f * std::max(1.0f, std::fabs(expected)); }

// A hit at the expected parameter, within tol().
::testing::AssertionResult hit_at(std::optional<float> h, float expected) {
    if (!h) return ::testing::AssertionFailure() << "miss, expected a hit at t=" << expected;
    if (std::fabs(*h - expected) > tol(expected))
        return ::testing::AssertionFailure() << "hit at t=" << *h << ", expected " << expected;
    return ::testing::AssertionSuccess();
}
#define EXPECT_HIT_AT(opt, expected) EXPECT_TRUE(hit_at((opt), (expected)))

void expect_vec_near(Vec3 a, Vec3 b, float eps) {
    EXPECT_NEAR(a.x, b.x, eps);
    EXPECT_NEAR(a.y, b.y, eps);
    EXPECT_NEAR(a.z, b.z, eps);
}

void expect_box_eq(const Box3& b, Vec3 lo, Vec3 hi) {
    EXPECT_EQ(b.lo, lo);
    EXPECT_EQ(b.hi, hi);
}

// The interval is open: a hit exactly at tmax or tmin is rejected, one a float step inside is
// kept; tmax = t also proves no nearer hit exists in (tmin, t).
template <class F>
void expect_open_interval(F&& query, const Ray& r) {
    const std::optional<float> t = query(r);
    ASSERT_TRUE(t.has_value());
    Ray a = r;
    a.tmax = *t;
    EXPECT_FALSE(query(a).has_value()) << "hit at or beyond tmax=" << *t;
    a.tmax = std::nextafter(*t, kInf);
    ASSERT_TRUE(query(a).has_value());
    EXPECT_EQ(*query(a), *t);
    Ray b = r;
    b.tmin = std::nextafter(*t, -kInf);
    ASSERT_TRUE(query(b).has_value());
    EXPECT_EQ(*query(b), *t);
    b.tmin = *t;
    if (auto t2 = query(b)) {
        EXPECT_GT(*t2, *t) << "hit at tmin=" << *t;
    }
}

// ---------------------------------------------------------------------------------------------
// Triangles

const Triangle kTri{{0, 0, 0}, {2, 0, 0}, {0, 2, 0}};

TEST(PrimitiveTriangle, BoundsAndArea) {
    expect_box_eq(bounds(kTri), {0, 0, 0}, {2, 2, 0});
    EXPECT_FLOAT_EQ(area(kTri), 2.0f);
    // A right triangle in a general plane: legs (1,2,2) and (2,-2,1), both of length 3.
    Triangle t{{0, 0, 0}, {1, 2, 2}, {2, -2, 1}};
    expect_box_eq(bounds(t), {0, -2, 0}, {2, 2, 2});
    EXPECT_FLOAT_EQ(area(t), 4.5f);
    expect_box_eq(bounds(Triangle{{-1, 5, 3}, {4, -2, 7}, {0, 0, -6}}), {-1, -2, -6}, {4, 5, 7});
}

TEST(PrimitiveTriangle, NormalFollowsWinding) {
    expect_vec_near(normal_at(kTri), {0, 0, 1}, 1e-7f);
    expect_vec_near(normal_at(Triangle{kTri.v0, kTri.v2, kTri.v1}), {0, 0, -1}, 1e-7f);
    const float s = 1 / std::sqrt(2.0f);
    Vec3 n = normal_at(Triangle{{0, 0, 0}, {1, 0, 1}, {0, 1, 0}});  // the plane z = x
    expect_vec_near(n, {-s, 0, s}, 1e-6f);
}

TEST(PrimitiveTriangle, AnalyticHitsFromBothSides) {
    EXPECT_HIT_AT(hit(kTri, make_ray({0.5f, 0.5f, 3}, {0, 0, -1})), 3.0f);
    // t is in units of |d|.
    EXPECT_HIT_AT(hit(kTri, make_ray({0.5f, 0.5f, 3}, {0, 0, -2})), 1.5f);
    // Geometric hits: the back side counts too.
    EXPECT_HIT_AT(hit(kTri, make_ray({0.5f, 0.5f, -1}, {0, 0, 1})), 1.0f);
    // Oblique: from (0.5, 0.25, 2) along (0.25, 0.125, -1) lands on (1, 0.5, 0).
    EXPECT_HIT_AT(hit(kTri, make_ray({0.5f, 0.25f, 2}, {0.25f, 0.125f, -1})), 2.0f);
    // Along (0.25, 0.5, -1) it lands on (1, 1.25, 0), past the hypotenuse.
    EXPECT_FALSE(hit(kTri, make_ray({0.5f, 0.25f, 2}, {0.25f, 0.5f, -1})));
}

TEST(PrimitiveTriangle, Misses) {
    EXPECT_FALSE(hit(kTri, make_ray({1.5f, 1.5f, 3}, {0, 0, -1})));    // beyond the hypotenuse
    EXPECT_FALSE(hit(kTri, make_ray({-0.1f, 0.5f, 3}, {0, 0, -1})));   // left of the x = 0 edge
    EXPECT_FALSE(hit(kTri, make_ray({0.5f, -1e-5f, 3}, {0, 0, -1})));  // just below y = 0
    EXPECT_FALSE(hit(kTri, make_ray({1, 1.00001f, 3}, {0, 0, -1})));   // just past x + y = 2
    EXPECT_TRUE(hit(kTri, make_ray({1, 0.99999f, 3}, {0, 0, -1})));    // just inside it
    EXPECT_FALSE(hit(kTri, make_ray({0.5f, 0.5f, 3}, {0, 0, 1})));     // triangle behind the origin
    EXPECT_FALSE(hit(kTri, make_ray({0.5f, 0.5f, 1}, {1, 0, 0})));     // parallel above the plane
}

TEST(PrimitiveTriangle, EdgesAndVerticesOfOneTriangleAreInside) {
    // Convention: edge functions of exactly zero count as inside, so a lone triangle includes its
    // edges and vertices (three zero functions, a ray in the plane, is the only rejection).
    for (Vec3 p : {Vec3{1, 0, 0}, Vec3{0, 1, 0}, Vec3{1, 1, 0}, Vec3{0, 0, 0}, Vec3{2, 0, 0}, Vec3{0, 2, 0}}) {
        EXPECT_HIT_AT(hit(kTri, make_ray(p + Vec3{0, 0, 3}, {0, 0, -1})), 3.0f) << p.x << "," << p.y;
        EXPECT_HIT_AT(hit(kTri, make_ray(p - Vec3{0, 0, 2}, {0, 0, 1})), 2.0f) << p.x << "," << p.y;
    }
}

TEST(PrimitiveTriangle, GrazingRayInThePlaneMisses) {
    // The triangle projects to a segment along the ray: zero determinant, no hit.
    EXPECT_FALSE(hit(kTri, make_ray({-1, 0.5f, 0}, {1, 0, 0})));
    EXPECT_FALSE(hit(kTri, make_ray({-1, -1, 0}, {1, 1, 0})));  // through a vertex and the hypotenuse
    EXPECT_FALSE(hit(kTri, make_ray({0.5f, -3, 0}, {0, 1, 0})));
}

TEST(PrimitiveTriangle, AxisParallelAndZeroComponentDirections) {
    // A triangle in the plane x = 2, hit along +x (with signed zeros in the other components).
    Triangle tx{{2, 0, 0}, {2, 1, 0}, {2, 0, 1}};
    EXPECT_HIT_AT(hit(tx, make_ray({0, 0.25f, 0.25f}, {1, 0, 0})), 2.0f);
    EXPECT_HIT_AT(hit(tx, make_ray({0, 0.25f, 0.25f}, {1, -0.0f, 0.0f})), 2.0f);
    EXPECT_HIT_AT(hit(tx, make_ray({5, 0.25f, 0.25f}, {-1, -0.0f, -0.0f})), 3.0f);
    EXPECT_FALSE(hit(tx, make_ray({0, 0.75f, 0.75f}, {1, 0, 0})));
    // The plane z = x: straight down from z = 5, and along (1, 0, -1) with a zero y component.
    Triangle tz{{0, 0, 0}, {1, 0, 1}, {0, 1, 0}};
    EXPECT_HIT_AT(hit(tz, make_ray({0.25f, 0.25f, 5}, {0, 0, -1})), 4.75f);
    EXPECT_HIT_AT(hit(tz, make_ray({-2, 0.25f, 2.5f}, {1, 0, -1})), 2.25f);
    EXPECT_FALSE(hit(tz, make_ray({0.25f, -3, 0.25f}, {0, 1, 0})));  // lies in the plane z = x
}

TEST(PrimitiveTriangle, OpenInterval) {
    auto q = [](const Ray& r) { return hit(kTri, r); };
    expect_open_interval(q, make_ray({0.5f, 0.5f, 3}, {0, 0, -1}));
    expect_open_interval(q, make_ray({0.3f, 0.7f, -1.7f}, {0.1f, -0.2f, 1}));
    EXPECT_FALSE(hit(kTri, make_ray({0.5f, 0.5f, 3}, {0, 0, -1}, 0, 3)));
    EXPECT_FALSE(hit(kTri, make_ray({0.5f, 0.5f, 3}, {0, 0, -1}, 3, kInf)));
    EXPECT_FALSE(hit(kTri, make_ray({0.5f, 0.5f, 3}, {0, 0, -1}, 4, 10)));
}

// Random rays against a reference barycentric solve in double, away from the edges (the
// watertight tests cover those).
TEST(PrimitiveTriangle, RandomRaysMatchBarycentricReference) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-3, 3);
    const Triangle tri{{0.3f, -1.2f, 0.7f}, {2.1f, 0.4f, -0.5f}, {-0.8f, 1.5f, 1.1f}};
    int hits = 0, misses = 0;
    for (int i = 0; i < 4000; ++i) {
        // Half the rays aimed near the triangle, half anywhere.
        const Vec3 o{u(rng), u(rng), u(rng)};
        const Vec3 aim = (tri.v0 + tri.v1 + tri.v2) / 3 + Vec3{u(rng), u(rng), u(rng)} * 0.6f;
        Ray r = make_ray(o, i % 2 ? aim - o : Vec3{u(rng), u(rng), u(rng)});
        // Solve o + t d = v0 + b1 e1 + b2 e2 by Cramer's rule.
        const double e1[3] = {tri.v1.x - tri.v0.x, tri.v1.y - tri.v0.y, tri.v1.z - tri.v0.z};
        const double e2[3] = {tri.v2.x - tri.v0.x, tri.v2.y - tri.v0.y, tri.v2.z - tri.v0.z};
        const double s[3] = {r.o.x - tri.v0.x, r.o.y - tri.v0.y, r.o.z - tri.v0.z};
        const double d[3] = {r.d.x, r.d.y, r.d.z};
        auto det3 = [](const double* a, const double* b, const double* c) {
            return a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                   a[2] * (b[0] * c[1] - b[1] * c[0]);
        };
        const double nd[3] = {-d[0], -d[1], -d[2]};
        const double D = det3(nd, e1, e2);
        if (std::fabs(D) < 1e-3) continue;
        const double t = det3(s, e1, e2) / D, b1 = det3(nd, s, e2) / D, b2 = det3(nd, e1, s) / D;
        const double m = std::min({b1, b2, 1 - b1 - b2});
        if (std::fabs(m) < 1e-4 || std::fabs(t) < 1e-4) continue;
        auto got = hit(tri, r);
        if (m > 0 && t > 0) {
            ++hits;
            ASSERT_TRUE(got.has_value()) << i;
            EXPECT_NEAR(*got, t, 1e-5 * std::max(1.0, std::fabs(t))) << i;
        } else {
            ++misses;
            EXPECT_FALSE(got.has_value()) << i << " t=" << t << " min barycentric=" << m;
        }
    }
    EXPECT_GT(hits, 200);
    EXPECT_GT(misses, 200);
}

// Rays aimed at points of the shared diagonal of a quad split into two triangles, in a general
// plane, from random origins on both sides: none may fall through the crack.
TEST(PrimitiveTriangle, WatertightAcrossSharedDiagonal) {
    const Vec3 p00{0.13f, -0.71f, 0.37f}, ex{1.91f, 0.37f, -0.53f}, ey{-0.29f, 1.73f, 0.61f};
    const Vec3 p10 = p00 + ex, p11 = p00 + ex + ey, p01 = p00 + ey;
    const Triangle a{p00, p10, p11}, b{p00, p11, p01};
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(-4, 4);
    int lost = 0;
    for (int i = 1; i < 2000; ++i) {
        const float s = static_cast<float>(i) / 2000;
        const Vec3 target = p00 + (p11 - p00) * s;
        const Vec3 o{u(rng), u(rng), u(rng)};
        const Ray r = make_ray(o, target - o);
        auto ta = hit(a, r), tb = hit(b, r);
        if (!ta && !tb) ++lost;
        for (auto t : {ta, tb}) {
            if (t) {
                EXPECT_NEAR(*t, 1.0f, 1e-4f);
            }
        }
    }
    EXPECT_EQ(lost, 0);
    // Axis-parallel rays on a non-dyadic diagonal: the float points are off the line by rounding.
    const Triangle c{{0, 0, 0}, {3, 0, 0}, {3, 7, 0}}, d{{0, 0, 0}, {3, 7, 0}, {0, 7, 0}};
    lost = 0;
    for (int i = 1; i < 1000; ++i) {
        const float s = static_cast<float>(i) / 1000;
        const Ray r = make_ray({3 * s, 7 * s, 1}, {0, 0, -1});
        if (!hit(c, r) && !hit(d, r)) ++lost;
    }
    EXPECT_EQ(lost, 0);
}

// A fan of six triangles around a centre vertex: rays through the centre always hit.
TEST(PrimitiveTriangle, WatertightThroughFanCentre) {
    const Vec3 c{0.37f, -0.21f, 0.59f};
    const Vec3 e1 = normalize(Vec3{1, 0.3f, -0.2f}), e2 = normalize(cross(Vec3{0.1f, 0.2f, 1}, e1));
    std::vector<Triangle> fan;
    for (int i = 0; i < 6; ++i) {
        const float a0 = kPi / 3 * i, a1 = kPi / 3 * (i + 1);
        fan.push_back({c, c + (e1 * std::cos(a0) + e2 * std::sin(a0)) * 1.3f, c + (e1 * std::cos(a1) + e2 * std::sin(a1)) * 1.3f});
    }
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-3, 3);
    int lost = 0;
    for (int i = 0; i < 3000; ++i) {
        const Vec3 o{u(rng), u(rng), u(rng)};
        const Ray r = make_ray(o, c - o);
        bool any = false;
        for (const Triangle& t : fan)
            if (auto h = hit(t, r)) {
                any = true;
                EXPECT_NEAR(*h, 1.0f, 1e-4f);
            }
        if (!any) ++lost;
    }
    EXPECT_EQ(lost, 0);
    // Exactly representable fan in z = 0, axis ray through the centre: every triangle has its
    // centre vertex on the ray, and edges are inclusive, so all six report it.
    std::vector<Triangle> flat;
    const Vec3 ring[6] = {{2, 0, 0}, {1, 2, 0}, {-1, 2, 0}, {-2, 0, 0}, {-1, -2, 0}, {1, -2, 0}};
    for (int i = 0; i < 6; ++i) flat.push_back({{0, 0, 0}, ring[i], ring[(i + 1) % 6]});
    for (const Triangle& t : flat) EXPECT_HIT_AT(hit(t, make_ray({0, 0, 5}, {0, 0, -1})), 5.0f);
}

// A bumpy height-field mesh: rays aimed at every interior vertex and edge midpoint, from random
// steep directions and from axis-parallel and one-zero-component directions, hit some triangle.
TEST(PrimitiveTriangle, WatertightOnMeshVerticesAndEdges) {
    constexpr int N = 12;
    auto P = [](int i, int j) {
        return Vec3{0.5f * i, 0.5f * j, 0.3f * std::sin(0.9f * i) * std::cos(0.7f * j) + 0.05f * i};
    };
    std::vector<Triangle> mesh;
    for (int i = 0; i < N; ++i)
        for (int j = 0; j < N; ++j) {
            // Alternate the split diagonal so that vertices have 4 or 8 incident triangles.
            if ((i + j) % 2 == 0) {
                mesh.push_back({P(i, j), P(i + 1, j), P(i + 1, j + 1)});
                mesh.push_back({P(i, j), P(i + 1, j + 1), P(i, j + 1)});
            } else {
                mesh.push_back({P(i, j), P(i + 1, j), P(i, j + 1)});
                mesh.push_back({P(i + 1, j), P(i + 1, j + 1), P(i, j + 1)});
            }
        }
    std::vector<Vec3> targets;
    for (int i = 1; i < N; ++i)
        for (int j = 1; j < N; ++j) {
            targets.push_back(P(i, j));
            targets.push_back((P(i, j) + P(i + 1, j)) * 0.5f);
            targets.push_back((P(i, j) + P(i, j + 1)) * 0.5f);
            // The diagonal that is an edge of this cell's split.
            if ((i + j) % 2 == 0) targets.push_back((P(i, j) + P(i + 1, j + 1)) * 0.5f);
            else targets.push_back((P(i + 1, j) + P(i, j + 1)) * 0.5f);
        }
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(-1, 1);
    // Directions within 27 degrees of the z axis: the surface tilts at most 38 degrees, so every
    // ray crosses it transversally (a ray grazing a ridge may rightly pass it by a rounding).
    const Vec3 fixed_dirs[] = {{0, 0, -1}, {0, 0, 1}, {0.3f, 0, -1}, {0, -0.4f, 1}, {-0.2f, 0.35f, -1}};
    int lost = 0, rays = 0;
    for (const Vec3& target : targets) {
        std::vector<Vec3> dirs(std::begin(fixed_dirs), std::end(fixed_dirs));
        for (int k = 0; k < 4; ++k) {
            dirs.push_back({0.35f * u(rng), 0.35f * u(rng), k % 2 ? 1.0f : -1.0f});
        }
        for (const Vec3& d : dirs) {
            const Ray r = make_ray(target - d * 4.0f, d);
            bool any = false;
            for (const Triangle& t : mesh)
                if (auto h = hit(t, r)) any = any || std::fabs(*h - 4.0f) < 1e-3f;
            lost += !any;
            ++rays;
        }
    }
    EXPECT_EQ(lost, 0) << "of " << rays << " rays";
}

// ---------------------------------------------------------------------------------------------
// Polygons. Boundary convention of the crossing test (polygons of 4+ vertices): with (a, b) the
// two axes kept by the projection (a = drop_axis + 1, b = drop_axis + 2, mod 3), a point on the
// boundary is inside exactly when the polygon covers the points just past it in +a (and then
// +b): edges facing -a and -b are inside, those facing +a and +b outside. So polygons tiling a
// region cover every point on a shared edge or vertex exactly once. Three-vertex polygons use
// the triangle test, whose edges and vertices are all inside.

std::uint32_t add_poly(Scene& s, const std::vector<Vec3>& v) {
    std::uint32_t id = ~0u;
    EXPECT_TRUE(s.add_polygon(v, 0, &id));
    return id;
}

// Points of a comb lying in the plane z = 1: base [0,10] x [0,1], teeth [2k, 2k+1] x [1,4].
std::vector<Vec3> comb() {
    std::vector<Vec3> v{{0, 0, 1}, {10, 0, 1}, {10, 1, 1}};
    for (int k = 4; k >= 0; --k) {
        const float x0 = 2.0f * k, x1 = x0 + 1;
        v.push_back({x1, 1, 1});
        v.push_back({x1, 4, 1});
        v.push_back({x0, 4, 1});
        if (k > 0) v.push_back({x0, 1, 1});
    }
    return v;  // ends at (0, 4); the closing edge runs down x = 0
}

std::optional<float> comb_hit(const Scene& s, std::uint32_t id, float x, float y) {
    return hit(s, id, make_ray({x, y, 5}, {0, 0, -1}));
}

TEST(PrimitivePolygon, CombSetupBoundsArea) {
    Scene s;
    const std::vector<Vec3> v = comb();
    ASSERT_EQ(v.size(), 22u);
    const std::uint32_t id = add_poly(s, v);
    const Polygon& p = s.polygons.at(0);
    EXPECT_EQ(p.count, 22u);
    expect_vec_near(p.normal, {0, 0, 1}, 0);  // counter-clockwise from +z
    EXPECT_EQ(p.plane_d, 1.0f);
    EXPECT_EQ(p.drop_axis, 2);
    expect_box_eq(s.prim_bounds(id), {0, 0, 1}, {10, 4, 1});
    EXPECT_FLOAT_EQ(s.prim_area(id), 25.0f);  // base 10 + five teeth of 3
}

TEST(PrimitivePolygon, CombNotchesMissTeethHit) {
    Scene s;
    const std::uint32_t id = add_poly(s, comb());
    for (int k = 0; k < 5; ++k) {
        EXPECT_HIT_AT(comb_hit(s, id, 0.5f + 2 * k, 2.5f), 4.0f) << "tooth " << k;
        EXPECT_HIT_AT(comb_hit(s, id, 0.5f + 2 * k, 3.99f), 4.0f) << "tooth " << k;
        EXPECT_FALSE(comb_hit(s, id, 1.5f + 2 * k, 2.5f)) << "notch " << k;
        EXPECT_FALSE(comb_hit(s, id, 1.5f + 2 * k, 1.01f)) << "notch " << k;
        EXPECT_HIT_AT(comb_hit(s, id, 1.5f + 2 * k, 0.99f), 4.0f) << "base under notch " << k;
    }
    EXPECT_FALSE(comb_hit(s, id, 5, 4.5f));   // above the teeth
    EXPECT_FALSE(comb_hit(s, id, 11, 0.5f));  // right of the base
    EXPECT_FALSE(comb_hit(s, id, 5, -0.5f));  // below the base
    // Either side, and from an oblique direction through a notch landing on a tooth.
    EXPECT_HIT_AT(hit(s, id, make_ray({2.5f, 2, -1}, {0, 0, 1})), 2.0f);
    EXPECT_HIT_AT(hit(s, id, make_ray({3.5f, 2, 2}, {-1, 0, -1})), 1.0f);  // lands on (2.5, 2)
    EXPECT_FALSE(hit(s, id, make_ray({2.5f, 2, 2}, {1, 0, -1})));          // lands on (3.5, 2)
}

TEST(PrimitivePolygon, CombBoundaryConvention) {
    Scene s;
    const std::uint32_t id = add_poly(s, comb());
    struct Case {
        float x, y;
        bool inside;
        const char* what;
    };
    const Case cases[] = {
        {5, 0, true, "bottom edge (faces -y)"},
        {5, 4, false, "top of a tooth (faces +y)"},
        {0, 0.5f, true, "left edge (faces -x)"},
        {10, 0.5f, false, "right edge (faces +x)"},
        {2, 2.5f, true, "left side of tooth [2,3]"},
        {1, 2.5f, false, "right side of tooth [0,1]"},
        {1.5f, 1, false, "bottom of a notch (top of the base)"},
        {9.5f, 1, false, "top of the base right of the last tooth"},
        {0, 0, true, "lower-left corner"},
        {10, 0, false, "lower-right corner"},
        {10, 1, false, "upper-right corner of the base"},
        {0, 4, false, "upper-left corner of a tooth"},
        {9, 4, false, "upper-right corner of a tooth"},
        {2, 1, true, "reflex corner: notch bottom meets a tooth's left side"},
        {1, 1, false, "reflex corner: a tooth's right side meets a notch bottom"},
    };
    for (const Case& c : cases) EXPECT_EQ(comb_hit(s, id, c.x, c.y).has_value(), c.inside) << c.what;
}

// Two quads sharing a slanted edge from (0,0) to (3,1), and four squares sharing a vertex: every
// point of the union's interior, shared edges and vertex included, is covered exactly once.
TEST(PrimitivePolygon, SharedEdgesAndVerticesCoveredExactlyOnce) {
    Scene s;
    const std::uint32_t a = add_poly(s, {{-1, 0, 0}, {0, 0, 0}, {3, 1, 0}, {-1, 1, 0}});
    const std::uint32_t b = add_poly(s, {{0, 0, 0}, {4, 0, 0}, {4, 1, 0}, {3, 1, 0}});
    auto count = [&](float x, float y, std::initializer_list<std::uint32_t> ids) {
        int n = 0;
        for (std::uint32_t id : ids) n += hit(s, id, make_ray({x, y, 2}, {0, 0, -1})).has_value();
        return n;
    };
    for (int k = 1; k < 16; ++k) {
        const float y = k / 16.0f;
        EXPECT_EQ(count(3 * y, y, {a, b}), 1) << "on the shared edge at y=" << y;
        // Just to the right of the edge is B, just to the left A.
        EXPECT_TRUE(hit(s, b, make_ray({3 * y + 1e-3f, y, 2}, {0, 0, -1})));
        EXPECT_TRUE(hit(s, a, make_ray({3 * y - 1e-3f, y, 2}, {0, 0, -1})));
    }
    for (int i = 1; i < 40; ++i)
        for (int j = 1; j < 8; ++j) EXPECT_EQ(count(i / 8.0f - 1, j / 8.0f, {a, b}), 1) << i << "," << j;

    std::uint32_t q[4];
    for (int k = 0; k < 4; ++k) {
        const float x0 = static_cast<float>(k % 2), y0 = static_cast<float>(k / 2);
        q[k] = add_poly(s, {{x0, y0, 0}, {x0 + 1, y0, 0}, {x0 + 1, y0 + 1, 0}, {x0, y0 + 1, 0}});
    }
    const auto quads = {q[0], q[1], q[2], q[3]};
    EXPECT_EQ(count(1, 1, quads), 1);
    EXPECT_TRUE(hit(s, q[3], make_ray({1, 1, 2}, {0, 0, -1})));  // the upper-right square owns it
    EXPECT_EQ(count(1, 0.5f, quads), 1);
    EXPECT_EQ(count(0.5f, 1, quads), 1);
    EXPECT_EQ(count(1.5f, 1, quads), 1);
    EXPECT_EQ(count(1, 1.5f, quads), 1);
}

TEST(PrimitivePolygon, ConventionInAnotherProjection) {
    // Plane x = 2, normal +x: projection drops x and keeps (y, z).
    Scene s;
    const std::uint32_t id = add_poly(s, {{2, 0, 0}, {2, 1, 0}, {2, 1, 1}, {2, 0, 1}});
    EXPECT_EQ(s.polygons[0].drop_axis, 0);
    expect_vec_near(s.polygons[0].normal, {1, 0, 0}, 0);
    auto at = [&](float y, float z) { return hit(s, id, make_ray({5, y, z}, {-1, 0, 0})); };
    EXPECT_HIT_AT(at(0.5f, 0.5f), 3.0f);
    EXPECT_TRUE(at(0, 0.5f));   // faces -y
    EXPECT_FALSE(at(1, 0.5f));  // faces +y
    EXPECT_TRUE(at(0.5f, 0));   // faces -z
    EXPECT_FALSE(at(0.5f, 1));  // faces +z
    EXPECT_HIT_AT(hit(s, id, make_ray({-1, 0.5f, 0.5f}, {1, 0, 0})), 3.0f);  // from behind
}

TEST(PrimitivePolygon, ThreeVerticesUseTheInclusiveTriangleTest) {
    Scene s;
    const std::uint32_t tri = add_poly(s, {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}});
    const std::uint32_t quad = add_poly(s, {{0, 0, 0}, {2, 0, 0}, {2, 2, 0}, {0, 2, 0}});
    auto down = [](float x, float y) { return make_ray({x, y, 1}, {0, 0, -1}); };
    EXPECT_HIT_AT(hit(s, tri, down(1, 1)), 1.0f);  // hypotenuse
    EXPECT_HIT_AT(hit(s, tri, down(2, 0)), 1.0f);  // vertex on the +x side
    EXPECT_HIT_AT(hit(s, tri, down(0, 2)), 1.0f);  // vertex on the +y side
    EXPECT_FALSE(hit(s, quad, down(2, 0)));        // the quad's +x side is outside
    EXPECT_FALSE(hit(s, quad, down(0, 2)));        // and its +y side
    EXPECT_FLOAT_EQ(s.prim_area(tri), 2.0f);
    EXPECT_FLOAT_EQ(s.prim_area(quad), 4.0f);
}

TEST(PrimitivePolygon, GrazingAndOpenInterval) {
    Scene s;
    const std::uint32_t id = add_poly(s, comb());
    EXPECT_FALSE(hit(s, id, make_ray({-1, 0.5f, 1}, {1, 0, 0})));  // in the plane
    EXPECT_FALSE(hit(s, id, make_ray({0.5f, 2, 1}, {0, 1, 0})));   // in the plane, across a tooth
    EXPECT_FALSE(hit(s, id, make_ray({0.5f, 2, 1.5f}, {1, 0, 0})));
    auto q = [&](const Ray& r) { return hit(s, id, r); };
    expect_open_interval(q, make_ray({0.5f, 2, 5}, {0, 0, -1}));
    expect_open_interval(q, make_ray({4.3f, 0.2f, -2}, {0.1f, 0.3f, 1.7f}));
    EXPECT_FALSE(hit(s, id, make_ray({0.5f, 2, 5}, {0, 0, -1}, 0, 4)));
    EXPECT_FALSE(hit(s, id, make_ray({0.5f, 2, 5}, {0, 0, -1}, 4, kInf)));
    EXPECT_FALSE(hit(s, id, make_ray({0.5f, 2, 5}, {0, 0, 1})));  // plane behind the origin
}

TEST(PrimitivePolygon, CollinearFirstVerticesUseNewellNormal) {
    // The first three vertices are collinear: the normal comes from the whole outline.
    Scene s;
    const std::uint32_t id = add_poly(s, {{0, 0, 3}, {1, 0, 3}, {2, 0, 3}, {2, 1, 3}, {0, 1, 3}});
    expect_vec_near(s.polygons[0].normal, {0, 0, 1}, 1e-7f);
    EXPECT_FLOAT_EQ(s.polygons[0].plane_d, 3.0f);
    EXPECT_FLOAT_EQ(s.prim_area(id), 2.0f);
    EXPECT_HIT_AT(hit(s, id, make_ray({1.5f, 0.5f, 0}, {0, 0, 1})), 3.0f);
}

// A gear face as in the SPD gears scene: 36 trapezoidal teeth, 4 vertices each, 144 vertices.
struct Gear {
    static constexpr int kTeeth = 36;
    static constexpr double kIn = 1.0, kOut = 1.5;
    static constexpr double kFrac[4] = {0.0, 0.2, 0.5, 0.7};  // vertex angles, fractions of a pitch
    static double pitch() { return 2 * std::numbers::pi / kTeeth; }
    static double radius(int k) { return (k % 4 == 1 || k % 4 == 2) ? kOut : kIn; }
    static double angle(int k) { return pitch() * (k / 4 + kFrac[k % 4]); }
    // Area of a polygon star-shaped about the centre, from the polar vertex data.
    static double area() {
        double a = 0;
        for (int k = 0; k < 4 * kTeeth; ++k) {
            const int l = (k + 1) % (4 * kTeeth);
            a += 0.5 * radius(k) * radius(l) * std::sin(angle(l) - angle(k) + (l == 0 ? 2 * std::numbers::pi : 0));
        }
        return a;
    }
};

// The gear at centre c in the plane spanned by (u, v); returns the world point at polar (r, th).
struct GearFrame {
    Vec3 c, u, v, n;
    Vec3 at(double r, double th) const {
        return c + u * static_cast<float>(r * std::cos(th)) + v * static_cast<float>(r * std::sin(th));
    }
    std::vector<Vec3> outline() const {
        std::vector<Vec3> pts;
        for (int k = 0; k < 4 * Gear::kTeeth; ++k) pts.push_back(at(Gear::radius(k), Gear::angle(k)));
        return pts;
    }
};

void check_gear(const GearFrame& g) {
    Scene s;
    const std::vector<Vec3> pts = g.outline();
    ASSERT_EQ(pts.size(), 144u);
    const std::uint32_t id = add_poly(s, pts);
    EXPECT_GT(dot(s.polygons[0].normal, g.n), 1 - 1e-6f);  // first three vertices turn left
    EXPECT_NEAR(s.prim_area(id), Gear::area(), 2e-6 * Gear::area());
    const double rm = 0.5 * (Gear::kIn + Gear::kOut), p = Gear::pitch();
    const Vec3 side = g.u * 0.9f + g.v * 0.5f;  // an oblique approach, no zero components
    for (int i = 0; i < Gear::kTeeth; ++i) {
        const Vec3 tooth = g.at(rm, p * (i + 0.35)), notch = g.at(rm, p * (i + 0.85));
        // Along the normal from 3 units away, and obliquely with t = 1 at the target.
        EXPECT_HIT_AT(hit(s, id, make_ray(tooth + g.n * 3, -g.n)), 3.0f) << "tooth " << i;
        EXPECT_HIT_AT(hit(s, id, make_ray(tooth - g.n * 3 + side, g.n * 3 - side)), 1.0f) << "tooth " << i;
        EXPECT_FALSE(hit(s, id, make_ray(notch + g.n * 3, -g.n))) << "notch " << i;
        EXPECT_FALSE(hit(s, id, make_ray(notch + g.n * 3 + side, -g.n * 3 - side))) << "notch " << i;
        // The notch's floor is the chord between (kIn, 0.7 p) and (kIn, p): at mid-notch it lies
        // at kIn cos(0.15 p) = 0.99966, so radius 1.0 is in the notch and 0.995 in the body.
        EXPECT_FALSE(hit(s, id, make_ray(g.at(1.0, p * (i + 0.85)) + g.n, -g.n))) << "notch floor " << i;
        EXPECT_TRUE(hit(s, id, make_ray(g.at(0.995, p * (i + 0.85)) + g.n, -g.n))) << "body " << i;
        EXPECT_FALSE(hit(s, id, make_ray(g.at(1.51, p * (i + 0.35)) + g.n, -g.n))) << "past tooth " << i;
    }
    EXPECT_HIT_AT(hit(s, id, make_ray(g.c + g.n * 2, -g.n * 2)), 1.0f);  // the centre
}

TEST(PrimitivePolygon, GearFace144VerticesConcave) {
    check_gear({{0.25f, -0.5f, 2}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}});
    // Tilted so that the projection drops x.
    const Vec3 n = normalize(Vec3{2, -1, 1.2f});
    const Vec3 u = normalize(cross(Vec3{0, 0, 1}, n));
    check_gear({{-3, 1.5f, 0.75f}, u, cross(n, u), n});
}

TEST(PrimitivePolygon, GearBoundsAreExact) {
    GearFrame g{{0.25f, -0.5f, 2}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    Scene s;
    const std::uint32_t id = add_poly(s, g.outline());
    const Box3 b = s.prim_bounds(id);
    // Extreme vertices: (kOut, 2 deg) in x, (kOut, 88/92 deg) in y; exact vertex box.
    const double c2 = Gear::kOut * std::cos(0.2 * Gear::pitch());
    EXPECT_NEAR(b.hi.x, 0.25 + c2, 1e-6);
    EXPECT_NEAR(b.lo.x, 0.25 - c2, 1e-6);
    EXPECT_NEAR(b.hi.y, -0.5 + c2, 1e-6);
    EXPECT_NEAR(b.lo.y, -0.5 - c2, 1e-6);
    EXPECT_EQ(b.lo.z, 2.0f);
    EXPECT_EQ(b.hi.z, 2.0f);
}

// ---------------------------------------------------------------------------------------------
// Spheres

const Sphere kSph{{1, 2, 3}, 2};

TEST(PrimitiveSphere, BoundsAndArea) {
    expect_box_eq(bounds(kSph), {-1, 0, 1}, {3, 4, 5});
    EXPECT_FLOAT_EQ(area(kSph), 16 * kPi);
    // Negative radius (inside visible) is the same surface.
    expect_box_eq(bounds(Sphere{{1, 2, 3}, -2}), {-1, 0, 1}, {3, 4, 5});
    EXPECT_FLOAT_EQ(area(Sphere{{1, 2, 3}, -2}), 16 * kPi);
    EXPECT_FLOAT_EQ(area(Sphere{{0, 0, 0}, 0.5f}), kPi);
}

TEST(PrimitiveSphere, AxisRaysFromOutside) {
    EXPECT_HIT_AT(hit(kSph, make_ray({1, 2, -5}, {0, 0, 1})), 6.0f);
    EXPECT_HIT_AT(hit(kSph, make_ray({1, 2, -5}, {0, 0, 4})), 1.5f);
    for (int axis = 0; axis < 3; ++axis)
        for (float sign : {1.0f, -1.0f}) {
            Vec3 d{0, 0, 0};
            d[axis] = sign;
            const Ray r = make_ray(kSph.center - d * 10, d);
            EXPECT_HIT_AT(hit(kSph, r), 8.0f) << axis << " " << sign;
            expect_vec_near(normal_at(kSph, r.o + r.d * *hit(kSph, r)), -d, 1e-6f);
        }
}

TEST(PrimitiveSphere, DiagonalRay) {
    // Along (1,1,1) through the centre (4,4,4): hits at t = 4 -+ r / sqrt(3).
    const float r = 1.7f;
    const Sphere s{{4, 4, 4}, r};
    EXPECT_HIT_AT(hit(s, make_ray({0, 0, 0}, {1, 1, 1})), 4 - r / std::sqrt(3.0f));
    EXPECT_HIT_AT(hit(s, make_ray({0, 0, 0}, {1, 1, 1}, 4)), 4 + r / std::sqrt(3.0f));
}

TEST(PrimitiveSphere, OriginInsideHitsFarSide) {
    for (int axis = 0; axis < 3; ++axis)
        for (float sign : {1.0f, -1.0f}) {
            Vec3 d{0, 0, 0};
            d[axis] = sign;
            EXPECT_HIT_AT(hit(kSph, make_ray(kSph.center, d)), 2.0f);
        }
    EXPECT_HIT_AT(hit(kSph, make_ray({1, 2, 3.5f}, {0, 0, -1})), 2.5f);
    EXPECT_HIT_AT(hit(kSph, make_ray({1, 2, 3.5f}, {0, 0, 1})), 1.5f);
    EXPECT_HIT_AT(hit(kSph, make_ray({1, 2, 3.5f}, {0, 0, 0.5f})), 3.0f);
    // Off-axis: from (1, 2.6, 3) along +x, the far point is at x = 1 + sqrt(4 - 0.36).
    EXPECT_HIT_AT(hit(kSph, make_ray({1, 2.6f, 3}, {1, 0, 0})), std::sqrt(4 - 0.36f));
}

TEST(PrimitiveSphere, GrazingTangentRays) {
    // Tangent to the sphere at (3, 2, 3): a double root, counted as a hit.
    EXPECT_HIT_AT(hit(kSph, make_ray({3, 2, -5}, {0, 0, 1})), 8.0f);
    EXPECT_HIT_AT(hit(kSph, make_ray({1, -5, 5}, {0, 1, 0})), 7.0f);
    EXPECT_FALSE(hit(kSph, make_ray({3.001f, 2, -5}, {0, 0, 1})));
    auto in = hit(kSph, make_ray({2.999f, 2, -5}, {0, 0, 1}));
    ASSERT_TRUE(in);
    EXPECT_NEAR(*in, 8 - std::sqrt(4 - 1.999f * 1.999f), 1e-4f);
}

TEST(PrimitiveSphere, OriginOnSurface) {
    // t = 0 is outside the open interval: leaving the surface misses, entering hits the far side.
    EXPECT_FALSE(hit(kSph, make_ray({1, 2, 5}, {0, 0, 1})));
    EXPECT_HIT_AT(hit(kSph, make_ray({1, 2, 5}, {0, 0, -1})), 4.0f);
    EXPECT_FALSE(hit(kSph, make_ray({1, 2, 8}, {0, 0, 1})));  // sphere behind
}

TEST(PrimitiveSphere, OpenIntervalSelectsRoot) {
    const Ray r = make_ray({1, 2, -5}, {0, 0, 1});  // roots 6 and 10
    EXPECT_HIT_AT(hit(kSph, make_ray(r.o, r.d, 7, kInf)), 10.0f);
    EXPECT_HIT_AT(hit(kSph, make_ray(r.o, r.d, 6, kInf)), 10.0f);
    EXPECT_FALSE(hit(kSph, make_ray(r.o, r.d, 0, 6)));
    EXPECT_HIT_AT(hit(kSph, make_ray(r.o, r.d, 0, 6.5f)), 6.0f);
    EXPECT_FALSE(hit(kSph, make_ray(r.o, r.d, 10, kInf)));
    EXPECT_FALSE(hit(kSph, make_ray(r.o, r.d, 6.5f, 10)));
    auto q = [](const Ray& x) { return hit(kSph, x); };
    expect_open_interval(q, r);
    expect_open_interval(q, make_ray({0.3f, 2.9f, 3.3f}, {0.2f, -0.7f, 0.4f}));  // from inside
}

TEST(PrimitiveSphere, NegativeRadiusSameHits) {
    const Sphere neg{kSph.center, -2};
    for (const Ray& r : {make_ray({1, 2, -5}, {0, 0, 1}), make_ray({1, 2, 3.5f}, {0, 0, 1}),
                         make_ray({3, 2, -5}, {0, 0, 1}), make_ray({4, 2, -5}, {0, 0, 1})}) {
        auto a = hit(kSph, r), b = hit(neg, r);
        ASSERT_EQ(a.has_value(), b.has_value());
        if (a) {
            EXPECT_EQ(*a, *b);
        }
    }
}

TEST(PrimitiveSphere, TinyFarSphere) {
    // Radius 1e-2 at distance 1e4: the discriminant from the centre's distance to the line keeps
    // this exact where b^2 - ac would cancel.
    const Sphere s{{0, 0, 1e4f}, 1e-2f};
    EXPECT_NEAR(*hit(s, make_ray({0, 0, 0}, {0, 0, 1})), 1e4f - 1e-2f, 1e-3f);
    EXPECT_TRUE(hit(s, make_ray({0.0099f, 0, 0}, {0, 0, 1})));
    EXPECT_FALSE(hit(s, make_ray({0.0101f, 0, 0}, {0, 0, 1})));
    EXPECT_TRUE(hit(s, make_ray({0, 0, 0}, {0.0099e-4f, 0, 1})));
    EXPECT_FALSE(hit(s, make_ray({0, 0, 0}, {0.0101e-4f, 0, 1})));
    // At 1e7 even double b^2 - ac loses r^2 = 1e-6 entirely (ulp of 1e14 is 0.016).
    const Sphere far{{0, 0, 1e7f}, 1e-3f};
    EXPECT_TRUE(hit(far, make_ray({0.0009f, 0, 0}, {0, 0, 1})));
    EXPECT_TRUE(hit(far, make_ray({0, -0.0009f, 0}, {0, 0, 1})));
    EXPECT_FALSE(hit(far, make_ray({0.0011f, 0, 0}, {0, 0, 1})));
    EXPECT_FALSE(hit(far, make_ray({0, -0.0011f, 0}, {0, 0, 1})));
}

TEST(PrimitiveSphere, RandomRaysLandOnSurfaceWithRadialNormals) {
    std::mt19937 rng(13);
    std::uniform_real_distribution<float> u(-4, 4);
    const Sphere s{{0.3f, -0.4f, 0.2f}, 1.3f};
    int hits = 0;
    for (int i = 0; i < 3000; ++i) {
        const Vec3 o{u(rng), u(rng), u(rng)};
        const Vec3 d = (s.center + Vec3{u(rng), u(rng), u(rng)} * 0.4f) - o;
        const Ray r = make_ray(o, d);
        auto t = hit(s, r);
        const bool inside = length(o - s.center) < s.radius;
        if (inside) {
            ASSERT_TRUE(t) << "a ray from inside always hits";
        }
        if (!t) continue;
        ++hits;
        const Vec3 p = o + d * *t;
        EXPECT_NEAR(length(p - s.center), s.radius, 2e-5f);
        const Vec3 n = normal_at(s, p);
        EXPECT_NEAR(length(n), 1.0f, 1e-6f);
        expect_vec_near(n, (p - s.center) / s.radius, 2e-5f);
        // Nearest root: none in (0, t); from outside the ray enters against the normal.
        EXPECT_FALSE(hit(s, make_ray(o, d, 0, *t)));
        if (inside) {
            EXPECT_GT(dot(n, d), 0);
        } else {
            EXPECT_LT(dot(n, d), 0);
        }
    }
    EXPECT_GT(hits, 1500);
}

// ---------------------------------------------------------------------------------------------
// Cones and cylinders (open, no caps)

const Cone kCyl{{0, 0, 0}, 1, {0, 0, 2}, 1};
const Cone kFrustum{{0, 0, 0}, 2, {0, 0, 2}, 1};  // radius 2 - z / 2
const Cone kTip{{0, 0, 0}, 1, {0, 0, 1}, 0};      // a true cone, tip at (0,0,1)

// Bounds are tight up to a relative padding of 1e-6 (rounded outwards).
void expect_box_near(const Box3& b, Vec3 lo, Vec3 hi) {
    const Vec3 e = hi - lo;
    for (int a = 0; a < 3; ++a) {
        const float eps = 1e-5f * std::max(1.0f, e[a]);
        EXPECT_LE(b.lo[a], lo[a]) << a;
        EXPECT_GE(b.lo[a], lo[a] - eps) << a;
        EXPECT_GE(b.hi[a], hi[a]) << a;
        EXPECT_LE(b.hi[a], hi[a] + eps) << a;
    }
}

TEST(PrimitiveCone, BoundsAndArea) {
    expect_box_near(bounds(kCyl), {-1, -1, 0}, {1, 1, 2});
    expect_box_near(bounds(kFrustum), {-2, -2, 0}, {2, 2, 2});
    expect_box_near(bounds(kTip), {-1, -1, 0}, {1, 1, 1});
    // Along (1,1,0)/sqrt2: a rim of radius r spans r/sqrt2 in x and y, r in z.
    const float s = 1 / std::sqrt(2.0f);
    expect_box_near(bounds(Cone{{0, 0, 0}, 1, {4, 4, 0}, 0.5f}), {-s, -s, -1}, {4 + 0.5f * s, 4 + 0.5f * s, 1});
    EXPECT_FLOAT_EQ(area(kCyl), 4 * kPi);                       // 2 pi r h
    EXPECT_FLOAT_EQ(area(kFrustum), 3 * kPi * std::sqrt(5.0f));  // pi (r0 + r1) slant
    EXPECT_FLOAT_EQ(area(kTip), kPi * std::sqrt(2.0f));
    EXPECT_FLOAT_EQ(area(Cone{{0, 0, 2}, -1, {0, 0, 0}, -2}), 3 * kPi * std::sqrt(5.0f));
}

TEST(PrimitiveCone, SurfacePointsInsideBounds) {
    std::mt19937 rng(17);
    std::uniform_real_distribution<float> u(0, 1);
    const Cone c{{1.3f, -0.2f, 0.7f}, 0.8f, {-0.4f, 2.2f, 1.9f}, 0.3f};
    const Box3 b = bounds(c);
    const Vec3 w = normalize(c.apex - c.base);
    const Vec3 e1 = normalize(cross(w, Vec3{0.3f, 0.1f, 1})), e2 = cross(w, e1);
    for (int i = 0; i < 2000; ++i) {
        const float s = i < 1000 ? static_cast<float>(i % 2) : u(rng), phi = 2 * kPi * u(rng);
        const float r = c.base_radius + (c.apex_radius - c.base_radius) * s;
        const Vec3 p = c.base + (c.apex - c.base) * s + (e1 * std::cos(phi) + e2 * std::sin(phi)) * r;
        EXPECT_TRUE(b.contains(p)) << p.x << " " << p.y << " " << p.z;
    }
}

TEST(PrimitiveCone, CylinderSideHitsAndNormals) {
    const Vec3 dirs[] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}};
    for (const Vec3& d : dirs) {
        const Ray r = make_ray(Vec3{0, 0, 1} - d * 5, d);
        EXPECT_HIT_AT(hit(kCyl, r), 4.0f);
        const Vec3 n = normal_at(kCyl, r.o + r.d * *hit(kCyl, r));
        expect_vec_near(n, -d, 1e-6f);  // lateral: radial, no axial part
    }
    EXPECT_HIT_AT(hit(kCyl, make_ray({-5, 0, 1}, {2, 0, 0})), 2.0f);
    // Off-centre chord: enters at x = -sqrt(1 - 0.36).
    EXPECT_HIT_AT(hit(kCyl, make_ray({-5, 0.6f, 1}, {1, 0, 0})), 5 - 0.8f);
}

TEST(PrimitiveCone, CylinderFromInsideHitsWall) {
    EXPECT_HIT_AT(hit(kCyl, make_ray({0, 0, 1}, {1, 0, 0})), 1.0f);
    EXPECT_HIT_AT(hit(kCyl, make_ray({0, 0, 1}, {0, -1, 0})), 1.0f);
    EXPECT_HIT_AT(hit(kCyl, make_ray({0.5f, 0, 1}, {-1, 0, 0})), 1.5f);
    EXPECT_HIT_AT(hit(kCyl, make_ray({0.5f, 0, 1}, {1, 0, 0})), 0.5f);
    // Climbing: from (0,0,0.5) along (0.6, 0, 0.8) reaches radius 1 at t = 1/0.6, z = 1.833.
    EXPECT_HIT_AT(hit(kCyl, make_ray({0, 0, 0.5f}, {0.6f, 0, 0.8f})), 1 / 0.6f);
    // Too steep: leaves through the open top before reaching the wall.
    EXPECT_FALSE(hit(kCyl, make_ray({0, 0, 0.5f}, {0.3f, 0, 1})));
}

TEST(PrimitiveCone, AxisParallelRaysMissOpenCylinder) {
    EXPECT_FALSE(hit(kCyl, make_ray({0, 0, -5}, {0, 0, 1})));    // along the axis, through both ends
    EXPECT_FALSE(hit(kCyl, make_ray({0, 0, 1}, {0, 0, 1})));     // along the axis from inside
    EXPECT_FALSE(hit(kCyl, make_ray({0.5f, 0, 1}, {0, 0, -1})));  // parallel, inside
    EXPECT_FALSE(hit(kCyl, make_ray({3, 0, -1}, {0, 0, 1})));     // parallel, outside
    // On a generator of the surface: the quadratic degenerates; convention: no hit.
    EXPECT_FALSE(hit(kCyl, make_ray({1, 0, -1}, {0, 0, 1})));
}

TEST(PrimitiveCone, CylinderEndsAreOpen) {
    EXPECT_FALSE(hit(kCyl, make_ray({-5, 0, 2.5f}, {1, 0, 0})));   // above
    EXPECT_FALSE(hit(kCyl, make_ray({-5, 0, -0.5f}, {1, 0, 0})));  // below
    // Enters the open bottom and meets the inside wall at (1, 0, 1).
    EXPECT_HIT_AT(hit(kCyl, make_ray({0, 0, -1}, {0.5f, 0, 1})), 2.0f);
    // Near crossing at z = 2.5 is past the top; the far one at z = 0.5 is the inside wall.
    EXPECT_HIT_AT(hit(kCyl, make_ray({-3, 0, 4.5f}, {1, 0, -1})), 4.0f);
    // Rims belong to the surface: exactly through the top rim point (-1, 0, 2).
    EXPECT_HIT_AT(hit(kCyl, make_ray({-5, 0, 2}, {1, 0, 0})), 4.0f);
}

TEST(PrimitiveCone, CylinderGrazing) {
    EXPECT_HIT_AT(hit(kCyl, make_ray({1, -5, 1}, {0, 1, 0})), 5.0f);  // tangent line
    EXPECT_FALSE(hit(kCyl, make_ray({1.001f, -5, 1}, {0, 1, 0})));
}

TEST(PrimitiveCone, FrustumHitsAndLateralNormal) {
    EXPECT_HIT_AT(hit(kFrustum, make_ray({-5, 0, 1}, {1, 0, 0})), 3.5f);  // radius 1.5 at z = 1
    const Vec3 p{-1.5f, 0, 1};
    const Vec3 n = normal_at(kFrustum, p);
    expect_vec_near(n, Vec3{-1, 0, 0.5f} / std::sqrt(1.25f), 1e-6f);
    EXPECT_NEAR(dot(n, Vec3{1, 0, 2}), 0, 1e-6f);  // perpendicular to the generator
    EXPECT_NEAR(dot(n, Vec3{0, 1, 0}), 0, 1e-6f);  // and to the rim circle
    EXPECT_HIT_AT(hit(kFrustum, make_ray({0, 0, 1}, {1, 0, 0})), 1.5f);    // from inside
    EXPECT_HIT_AT(hit(kFrustum, make_ray({0, 0, 1.5f}, {0, 1, 0})), 1.25f);
    // Along the axis: the extended cone's tip (z = 4) is past the apex rim: no hit.
    EXPECT_FALSE(hit(kFrustum, make_ray({0, 0, -3}, {0, 0, 1})));
    EXPECT_FALSE(hit(kFrustum, make_ray({0, 0, 1}, {0, 0, -1})));
    // Straight down at radius 1.5: meets the surface at z = 1.
    EXPECT_HIT_AT(hit(kFrustum, make_ray({1.5f, 0, 5}, {0, 0, -1})), 4.0f);
    // Reversed ends (base at the top) and negative radii describe the same surface.
    const Cone flipped{{0, 0, 2}, -1, {0, 0, 0}, -2};
    for (const Ray& r : {make_ray({-5, 0, 1}, {1, 0, 0}), make_ray({0, 0, 1}, {1, 0, 0}),
                         make_ray({1.5f, 0, 5}, {0, 0, -1}), make_ray({0, 0, -3}, {0, 0, 1})}) {
        auto a = hit(kFrustum, r), b = hit(flipped, r);
        ASSERT_EQ(a.has_value(), b.has_value());
        if (a) {
            EXPECT_NEAR(*a, *b, tol(*a));
        }
    }
    expect_vec_near(normal_at(flipped, p), n, 1e-6f);
}

TEST(PrimitiveCone, TrueConeTipAndMirrorNappe) {
    // Along the axis the ray meets the surface only at the tip, a double root at t = 2.
    EXPECT_HIT_AT(hit(kTip, make_ray({0, 0, -1}, {0, 0, 1})), 2.0f);
    // The quadratic's mirror nappe above the tip is not part of the cone.
    EXPECT_FALSE(hit(kTip, make_ray({-5, 0, 1.5f}, {1, 0, 0})));
    EXPECT_HIT_AT(hit(kTip, make_ray({-5, 0, 0.5f}, {1, 0, 0})), 4.5f);
    EXPECT_HIT_AT(hit(kTip, make_ray({0, 0, 0.5f}, {0, 1, 0})), 0.5f);  // from inside
    // Parallel to the generator (1,0,0)-(0,0,1): the quadratic is linear, one root, at
    // (-0.75, 0, 0.25) where radius 0.5 + t meets 1 - t.
    EXPECT_HIT_AT(hit(kTip, make_ray({-0.5f, 0, 0}, {-1, 0, 1})), 0.25f);
    EXPECT_FALSE(hit(kTip, make_ray({-0.5f, 0, 0}, {1, 0, -1})));  // the same line, backwards
    const float s = 1 / std::sqrt(2.0f);
    expect_vec_near(normal_at(kTip, {-0.5f, 0, 0.5f}), {-s, 0, s}, 1e-6f);
}

TEST(PrimitiveCone, TiltedCylinder) {
    const Cone c{{0, 0, 0}, 1, {4, 4, 0}, 1};  // axis along (1,1,0)
    EXPECT_HIT_AT(hit(c, make_ray({2, 2, 5}, {0, 0, -1})), 4.0f);
    expect_vec_near(normal_at(c, {2, 2, 1}), {0, 0, 1}, 1e-6f);
    EXPECT_HIT_AT(hit(c, make_ray({2, 2, 0}, {0, 0, 1})), 1.0f);  // from the axis
    // Perpendicular to the axis in the xy plane: distance to the wall is 1.
    EXPECT_HIT_AT(hit(c, make_ray({2, 2, 0}, {1, -1, 0})), 1 / std::sqrt(2.0f));
    EXPECT_FALSE(hit(c, make_ray({-1, -1, 0}, {1, 1, 0})));  // along the axis
    EXPECT_FALSE(hit(c, make_ray({2, 2, 0.5f}, {1, 1, 0})));  // parallel inside
    EXPECT_FALSE(hit(c, make_ray({5, 5, 0}, {0, 0, 1})));     // beyond the apex end
}

TEST(PrimitiveCone, OpenInterval) {
    auto q = [](const Ray& r) { return hit(kFrustum, r); };
    expect_open_interval(q, make_ray({-5, 0, 1}, {1, 0, 0}));
    expect_open_interval(q, make_ray({0.2f, -0.1f, 0.9f}, {0.3f, 0.8f, 0.2f}));  // from inside
    // Roots at 3.5 and 6.5 along the x axis at z = 1.
    EXPECT_HIT_AT(hit(kFrustum, make_ray({-5, 0, 1}, {1, 0, 0}, 3.5f, kInf)), 6.5f);
    EXPECT_FALSE(hit(kFrustum, make_ray({-5, 0, 1}, {1, 0, 0}, 0, 3.5f)));
    EXPECT_FALSE(hit(kFrustum, make_ray({-5, 0, 1}, {1, 0, 0}, 6.5f, kInf)));
    EXPECT_FALSE(hit(kFrustum, make_ray({-5, 0, 1}, {1, 0, 0}, 4, 6)));
}

TEST(PrimitiveCone, RandomRaysLandOnSurfaceWithLateralNormals) {
    const Cone c{{1.3f, -0.2f, 0.7f}, 0.8f, {-0.4f, 2.2f, 1.9f}, 0.3f};
    const Vec3 axis = c.apex - c.base;
    const float h = length(axis);
    const Vec3 w = axis / h;
    std::mt19937 rng(19);
    std::uniform_real_distribution<float> u(-3, 3), f(0, 1);
    int hits = 0;
    for (int i = 0; i < 3000; ++i) {
        // Aim near points of the axis, from outside or (a third of the rays) from inside.
        const Vec3 target = c.base + axis * f(rng) + Vec3{u(rng), u(rng), u(rng)} * 0.15f;
        const Vec3 o = i % 3 == 0 ? c.base + axis * (0.2f + 0.6f * f(rng)) : Vec3{u(rng), u(rng), u(rng)} * 2;
        const Ray r = make_ray(o, target - o);
        auto t = hit(c, r);
        if (!t) continue;
        ++hits;
        const Vec3 p = o + r.d * *t, q = p - c.base;
        const float s = dot(q, w);
        const float rho = length(q - w * s);
        EXPECT_GE(s, -1e-5f);
        EXPECT_LE(s, h + 1e-5f);
        EXPECT_NEAR(rho, c.base_radius + (c.apex_radius - c.base_radius) * s / h, 2e-5f);
        const Vec3 n = normal_at(c, p);
        EXPECT_NEAR(length(n), 1.0f, 1e-6f);
        // Perpendicular to the generator through p and to the rim circle's tangent there.
        const Vec3 radial = normalize(q - w * s);
        const Vec3 gen = (c.apex + radial * c.apex_radius) - (c.base + radial * c.base_radius);
        EXPECT_NEAR(dot(n, normalize(gen)), 0, 1e-5f);
        EXPECT_NEAR(dot(n, cross(w, radial)), 0, 1e-5f);
        EXPECT_GT(dot(n, radial), 0);  // outward
        EXPECT_FALSE(hit(c, make_ray(o, r.d, 0, *t))) << "not the nearest root";
    }
    EXPECT_GT(hits, 1000);
}

// ---------------------------------------------------------------------------------------------
// The scene: dispatch by id, complete_hit normals, nearest hit, degenerate input.

TEST(PrimitiveScene, DispatchBoundsAreasAndNormals) {
    Scene s;
    const std::uint32_t sph = s.add(Sphere{{0, 0, 15}, 1}, 0);
    const std::uint32_t tri = s.add(Triangle{{-1, -1, 10}, {1, -1, 10}, {0, 1, 10}}, 0);
    std::uint32_t poly = ~0u;
    ASSERT_TRUE(s.add_polygon(std::vector<Vec3>{{-2, -2, 5}, {2, -2, 5}, {2, 2, 5}, {-2, 2, 5}}, 0, &poly));
    const std::uint32_t cone = s.add(Cone{{0, 0, -1}, 3, {0, 0, 1}, 3}, 0);
    EXPECT_EQ(sph, 0u);
    EXPECT_EQ(tri, 1u);
    EXPECT_EQ(poly, 2u);
    EXPECT_EQ(cone, 3u);
    EXPECT_EQ(s.size(), 4u);
    EXPECT_EQ(s.kind(poly), PrimKind::Polygon);
    EXPECT_EQ(s.kind(cone), PrimKind::Cone);
    EXPECT_EQ(s.kind_counts(), (std::array<std::size_t, kPrimKinds>{1, 1, 1, 1}));
    EXPECT_EQ(prim_kind_name(PrimKind::Cone), "cone");

    expect_box_eq(s.prim_bounds(sph), {-1, -1, 14}, {1, 1, 16});
    expect_box_eq(s.prim_bounds(tri), {-1, -1, 10}, {1, 1, 10});
    expect_box_eq(s.prim_bounds(poly), {-2, -2, 5}, {2, 2, 5});
    expect_box_near(s.prim_bounds(cone), {-3, -3, -1}, {3, 3, 1});
    EXPECT_FLOAT_EQ(s.prim_area(sph), 4 * kPi);
    EXPECT_FLOAT_EQ(s.prim_area(tri), 2.0f);
    EXPECT_FLOAT_EQ(s.prim_area(poly), 16.0f);
    EXPECT_FLOAT_EQ(s.prim_area(cone), 12 * kPi);

    s.finalize();
    expect_box_near(s.bounds(), {-3, -3, -1}, {3, 3, 16});
    EXPECT_FALSE(s.materials.empty());

    // Straight down the z axis: sphere (t 4, 6), triangle 10, polygon 15; the cylinder's wall
    // is never on the axis.
    const Ray down = make_ray({0, 0, 20}, {0, 0, -1});
    EXPECT_HIT_AT(hit(s, sph, down), 4.0f);
    EXPECT_HIT_AT(hit(s, tri, down), 10.0f);
    EXPECT_HIT_AT(hit(s, poly, down), 15.0f);
    EXPECT_FALSE(hit(s, cone, down));
    auto nearest = [&](const Ray& r) {
        Hit h;
        for (std::uint32_t id = 0; id < s.size(); ++id)
            if (auto t = hit(s, id, make_ray(r.o, r.d, r.tmin, std::min(r.tmax, h.t)))) {
                h.t = *t;
                h.prim = static_cast<std::int32_t>(id);
            }
        s.complete_hit(r, h);
        return h;
    };
    Hit h = nearest(down);
    EXPECT_EQ(h.prim, static_cast<std::int32_t>(sph));
    expect_vec_near(h.ng, {0, 0, 1}, 1e-6f);
    // Past the sphere's exit at exactly t = 6 (open interval): the triangle.
    h = nearest(make_ray(down.o, down.d, 6, kInf));
    EXPECT_EQ(h.prim, static_cast<std::int32_t>(tri));
    EXPECT_FLOAT_EQ(h.t, 10);
    expect_vec_near(h.ng, {0, 0, 1}, 1e-6f);
    h = nearest(make_ray(down.o, down.d, 10, kInf));
    EXPECT_EQ(h.prim, static_cast<std::int32_t>(poly));
    expect_vec_near(h.ng, s.polygons[0].normal, 0);
    // From inside the cylinder, sideways: its wall, with a radial normal.
    h = nearest(make_ray({0, 0, 0.5f}, {0, 1, 0}));
    EXPECT_EQ(h.prim, static_cast<std::int32_t>(cone));
    EXPECT_FLOAT_EQ(h.t, 3);
    expect_vec_near(h.ng, {0, 1, 0}, 1e-6f);
    // A miss leaves the hit untouched.
    h = nearest(make_ray({10, 10, 10}, {1, 0, 0}));
    EXPECT_FALSE(h.hit());
    EXPECT_EQ(h.t, kInf);
}

TEST(PrimitiveScene, DegeneratePolygonsAreRefused) {
    Scene s;
    std::uint32_t id = 77;
    auto refused = [&](const std::vector<Vec3>& v) {
        const std::size_t prims = s.size(), pool = s.polygon_vertices.size();
        const bool added = s.add_polygon(v, 0, &id);
        EXPECT_EQ(s.size(), prims);
        EXPECT_EQ(s.polygon_vertices.size(), pool);  // the pool is rolled back
        return !added;
    };
    add_poly(s, {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}});  // a good one first
    id = 77;
    EXPECT_TRUE(refused({{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {3, 3, 3}}));  // collinear
    EXPECT_TRUE(refused({{1, 2, 3}, {1, 2, 3}, {1, 2, 3}}));             // coincident
    EXPECT_TRUE(refused({{0, 0, 0}, {1, 0, 0}}));                        // too few vertices
    EXPECT_TRUE(refused({{0, 0, 0}, {1, 0, 0}, {kInf, 1, 0}}));          // not finite
    EXPECT_EQ(id, 77u) << "the id is only written on success";
    EXPECT_EQ(s.polygons.size(), 1u);
}

TEST(PrimitiveScene, ZeroAreaTriangleIsNeverHit) {
    // Scene::add keeps any triangle (the mesh reader filters zero-area ones); a degenerate one has
    // no area and a zero determinant for every ray, even through its vertices and along its line.
    Scene s;
    const std::uint32_t id = s.add(Triangle{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}, 0);
    EXPECT_EQ(s.prim_area(id), 0.0f);
    expect_box_eq(s.prim_bounds(id), {0, 0, 0}, {2, 0, 0});
    for (float x : {0.0f, 0.5f, 1.0f, 2.0f}) {
        EXPECT_FALSE(hit(s, id, make_ray({x, 0, 1}, {0, 0, -1}))) << x;
        EXPECT_FALSE(hit(s, id, make_ray({x, 1, 0}, {0, -1, 0}))) << x;
        EXPECT_FALSE(hit(s, id, make_ray({x, -1, 1}, {0, 1, -1}))) << x;
    }
    EXPECT_FALSE(hit(s, id, make_ray({-1, 0, 0}, {1, 0, 0})));  // along its line
    const std::uint32_t point = s.add(Triangle{{1, 1, 1}, {1, 1, 1}, {1, 1, 1}}, 0);
    EXPECT_EQ(s.prim_area(point), 0.0f);
    EXPECT_FALSE(hit(s, point, make_ray({1, 1, 0}, {0, 0, 1})));
}

TEST(PrimitiveScene, CoincidentConeEndsAddNothing) {
    // Scene::add keeps it (the NFF reader warns and skips it); it has no lateral surface: empty
    // bounds, no hits, and finalize's scene bounds ignore it.
    Scene s;
    const std::uint32_t good = s.add(Sphere{{0, 0, 0}, 1}, 0);
    const std::uint32_t flat = s.add(Cone{{5, 5, 5}, 2, {5, 5, 5}, 1}, 0);
    EXPECT_TRUE(s.prim_bounds(flat).empty());
    for (const Ray& r : {make_ray({5, 5, 0}, {0, 0, 1}), make_ray({0, 5, 5}, {1, 0, 0}),
                         make_ray({5, 6.5f, 0}, {0, 0, 1}), make_ray({5, 5, 5}, {1, 0, 0})})
        EXPECT_FALSE(hit(s, flat, r));
    s.finalize();
    expect_box_eq(s.bounds(), s.prim_bounds(good).lo, s.prim_bounds(good).hi);
}

TEST(PrimitiveScene, ZeroRadiusSphereIsAPoint) {
    // Scene::add keeps it (the NFF reader warns and skips it): no area, a point box, and only a
    // ray exactly through the centre touches it (the double root of a tangent ray).
    Scene s;
    const std::uint32_t id = s.add(Sphere{{1, 2, 3}, 0}, 0);
    EXPECT_EQ(s.prim_area(id), 0.0f);
    expect_box_eq(s.prim_bounds(id), {1, 2, 3}, {1, 2, 3});
    EXPECT_HIT_AT(hit(s, id, make_ray({1, 2, 0}, {0, 0, 1})), 3.0f);
    EXPECT_FALSE(hit(s, id, make_ray({1, 2.001f, 0}, {0, 0, 1})));
    EXPECT_FALSE(hit(s, id, make_ray({1, 2, 4}, {0, 0, 1})));
}

}  // namespace
}  // namespace rtcost
