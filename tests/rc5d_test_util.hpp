#pragma once
// Helpers of the rc5d tests (test_rc5d.cpp, test_rc5d_hits.cpp): the hierarchy behind the
// interface, a two-sphere scene whose beams are known, and rays whose directions tie on their
// dominant axis, with the check that rc5d returns exactly the expected hits.
#include <random>
#include <stdexcept>

#include "../src/hierarchy/rc5d/rc5d.hpp"
#include "test_support.hpp"

namespace rtcost::test {

using rc5d::Rc5d;

inline const Rc5d& as_rc5d(const Hierarchy& h) {
    const Rc5d* r = dynamic_cast<const Rc5d*>(&h);
    if (!r) throw std::runtime_error("not rc5d");
    return *r;
}

// Two unit spheres on the x axis, A at 0 and B at 10: box [-1,11] x [-1,1] x [-1,1].
inline Scene two_spheres() {
    Scene s;
    s.add(Sphere{{0, 0, 0}, 1}, 0);
    s.add(Sphere{{10, 0, 0}, 1}, 0);
    s.finalize();
    return s;
}

// Directions whose dominant component ties with another (|dx| = |dy| and so on, and all
// three), with and without zero components, each ray aimed at a primitive's vertex or centre
// from a random distance, so that they hit; plus the same directions from random origins, and
// rays whose origins lie on the midplanes of the scene box (the first split planes).
inline std::vector<Ray> diagonal_rays(const Scene& s, std::size_t n, std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> uni(-1, 1), dist(0.1f, 3.0f);
    const Box3 b = s.bounds();
    const float size = std::max({b.extent().x, b.extent().y, b.extent().z});
    std::vector<Ray> rays;
    std::vector<Ray> origins = random_rays(b, n, seed + 5);
    for (std::size_t i = 0; i < n; ++i) {
        const float a = (rng() % 2 ? 1.0f : -1.0f) * (0.25f + std::fabs(uni(rng)));
        const float c = a * 0.999f * uni(rng);  // strictly smaller than |a|
        const float sa = rng() % 2 ? 1.0f : -1.0f, sb = rng() % 2 ? 1.0f : -1.0f;
        Vec3 d;
        switch (i % 9) {
            case 0: d = {a, sa * a, c}; break;       // |dx| = |dy|
            case 1: d = {a, c, sa * a}; break;       // |dx| = |dz|
            case 2: d = {c, a, sa * a}; break;       // |dy| = |dz|
            case 3: d = {a, sa * a, sb * a}; break;  // all three
            case 4: d = {a, sa * a, 0}; break;       // diagonal with a zero component
            case 5: d = {0, a, sa * a}; break;
            case 6: d = {a, 0, sa * a}; break;
            case 7: d = {a, 0.5f * a, -0.25f * a}; break;  // on the u, v split values 0.5, -0.25
            default: d = {0, 0, a}; break;           // axis-parallel
        }
        // Aimed at a primitive.
        const std::uint32_t id = static_cast<std::uint32_t>((i * 2654435761u) % s.size());
        const PrimRef& p = s.prims[id];
        Vec3 target = s.prim_bounds(id).center();
        if (p.kind == PrimKind::Triangle) target = s.triangles[p.index].v0;
        if (p.kind == PrimKind::Polygon) target = s.polygon_vertices[s.polygons[p.index].first];
        rays.push_back(Ray{target - d * (dist(rng) * size / std::fabs(a)), d});
        // From a random origin (inside the box for a third of them).
        rays.push_back(Ray{origins[i].o, d});
        // From a point on the box's midplanes.
        Vec3 o = origins[i].o;
        o[static_cast<int>(i % 3)] = b.center()[static_cast<int>(i % 3)];
        rays.push_back(Ray{o, d});
    }
    return rays;
}

inline std::vector<Ray> all_test_rays(const Scene& s, std::size_t n_random, std::uint64_t seed) {
    std::vector<Ray> rays = hard_rays(s, n_random, seed);
    std::vector<Ray> diag = diagonal_rays(s, n_random / 4 + 1000, seed + 100);
    rays.insert(rays.end(), diag.begin(), diag.end());
    return rays;
}

inline void expect_exact(const Scene& s, const std::vector<Ray>& rays, const std::vector<Hit>& want,
                         const std::vector<std::string>& set) {
    auto h = build_hierarchy(s, "rc5d", set);
    std::string first;
    EXPECT_EQ(count_mismatches(want, closest_hits(*h, rays), 0.0f, &first), 0u)
        << s.name << " " << ::testing::PrintToString(set) << ": " << first;
}

}  // namespace rtcost::test
