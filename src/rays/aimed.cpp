// `aimed` rays: incoherent rays that nearly all hit. Each starts at a uniform point of a sphere
// around the scene (twice its bounding sphere) and points at a uniformly random point of a
// primitive chosen uniformly at random, so it meets that primitive or something in front of it.
#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "rtcost/rays.hpp"
#include "util/rng.hpp"

namespace rtcost {
namespace {

Vec3 on_triangle(Vec3 a, Vec3 b, Vec3 c, Rng& rng) {
    const double s = std::sqrt(rng.uniform()), u = rng.uniform();
    const float wa = static_cast<float>(1 - s), wb = static_cast<float>(s * (1 - u)), wc = static_cast<float>(s * u);
    return a * wa + b * wb + c * wc;
}

/// A uniform point of the polygon's fan from its first vertex, each triangle weighed by its
/// area (exact for convex polygons; a concave one may give a point just outside it).
Vec3 on_polygon(const Polygon& p, const std::vector<Vec3>& pool, Rng& rng) {
    const Vec3* v = pool.data() + p.first;
    double total = 0;
    for (std::uint32_t i = 1; i + 1 < p.count; ++i) total += length(cross(v[i] - v[0], v[i + 1] - v[0]));
    double pick = rng.uniform() * total;
    std::uint32_t i = 1;
    for (; i + 2 < p.count; ++i) {
        pick -= length(cross(v[i] - v[0], v[i + 1] - v[0]));
        if (pick <= 0) break;
    }
    return on_triangle(v[0], v[i], v[i + 1], rng);
}

/// A uniform point of the cone's lateral surface: the axial position by the inverse of its
/// area distribution (density in proportion to the radius there), then a uniform angle.
Vec3 on_cone(const Cone& c, Rng& rng) {
    const Vec3 axis = c.apex - c.base;
    const Vec3 w = normalize(axis);
    const Vec3 a = std::fabs(w.x) < 0.9f ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
    const Vec3 e1 = normalize(cross(w, a)), e2 = cross(w, e1);
    const double rb = std::fabs(c.base_radius), ra = std::fabs(c.apex_radius), k = ra - rb;
    const double x = rng.uniform() * (rb + 0.5 * k);  // the area up to s is rb s + k s^2 / 2
    const double s = std::fabs(k) < 1e-12 * (rb + ra) ? x / rb : (-rb + std::sqrt(rb * rb + 2 * k * x)) / k;
    const double r = rb + k * s, phi = 2 * std::numbers::pi * rng.uniform();
    return c.base + axis * static_cast<float>(s) + e1 * static_cast<float>(r * std::cos(phi)) +
           e2 * static_cast<float>(r * std::sin(phi));
}

}  // namespace

std::vector<Ray> aimed_rays(const Scene& scene, std::size_t n, std::uint64_t seed) {
    return aimed_rays(scene, n, seed, 0.0);
}

std::vector<Ray> aimed_rays(const Scene& scene, std::size_t n, std::uint64_t seed, double by_area) {
    std::vector<Ray> rays;
    if (scene.empty()) return rays;
    std::vector<double> cdf;
    if (by_area > 0) {
        cdf.resize(scene.size());
        double sum = 0;
        for (std::uint32_t id = 0; id < scene.size(); ++id) cdf[id] = sum += std::max(0.0, double(scene.prim_area(id)));
        if (!(sum > 0)) cdf.clear();
    }
    rays.reserve(n);
    Rng rng(seed);
    const Vec3 centre = scene.bounds().center();
    const float radius = std::max(length(scene.bounds().extent()), 1e-30f);  // twice the half-diagonal
    while (rays.size() < n) {
        const Vec3 o = centre + rng.direction() * radius;
        auto id = static_cast<std::uint32_t>(rng.uniform() * static_cast<double>(scene.size()));
        if (!cdf.empty() && rng.uniform() < by_area)
            id = static_cast<std::uint32_t>(std::upper_bound(cdf.begin(), cdf.end(), rng.uniform() * cdf.back()) - cdf.begin());
        const PrimRef& p = scene.prims[std::min<std::size_t>(id, scene.size() - 1)];
        Vec3 target;
        switch (p.kind) {
            case PrimKind::Triangle: {
                const Triangle& t = scene.triangles[p.index];
                target = on_triangle(t.v0, t.v1, t.v2, rng);
                break;
            }
            case PrimKind::Polygon: target = on_polygon(scene.polygons[p.index], scene.polygon_vertices, rng); break;
            case PrimKind::Sphere: {
                const Sphere& s = scene.spheres[p.index];
                target = s.center + rng.direction() * std::fabs(s.radius);
                break;
            }
            case PrimKind::Cone: target = on_cone(scene.cones[p.index], rng); break;
        }
        const Vec3 d = target - o;
        if (!(length(d) > 0) || !is_finite(d)) continue;
        rays.push_back(Ray{o, normalize(d), 0, kInf});
    }
    return rays;
}

namespace {
const RayDistributionRegistration kAimed{
    {.name = "aimed",
     .description = "incoherent rays that hit: from a sphere around the scene to random points of its primitives (--count, --seed)",
     .order = 70,
     .seeded_draws = true,
     .benchmarked = true,
     .make = [](const Scene& scene, const RaySpec& spec, const RayMaking&) {
         return one_kind(aimed_rays(scene, spec.count, spec.seed), RayKind::Test,
                         fmt::format("aimed {} seed {}", spec.count, spec.seed));
     }}};
}  // namespace

}  // namespace rtcost
