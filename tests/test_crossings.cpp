// Hierarchy::crossings, how a ray sample learns how its rays end: every hierarchy's first
// crossings against brute force's (every primitive tested), on hard rays.
#include <algorithm>

#include "rtcost/sample.hpp"
#include "test_support.hpp"

namespace rtcost::test {
namespace {

/// Every primitive the ray meets in (tmin, tmax) at its nearest parameter, nearest first.
std::vector<Crossing> all_crossings(const Scene& s, const Ray& ray) {
    std::vector<Crossing> out;
    for (std::uint32_t id = 0; id < s.size(); ++id) {
        float t;
        if (s.intersect(id, ray, t)) out.push_back({id, t});
    }
    std::stable_sort(out.begin(), out.end(), [](const Crossing& a, const Crossing& b) { return a.t < b.t; });
    return out;
}

std::vector<Crossing> crossings_of(const Hierarchy& h, const Ray& ray, std::size_t k) {
    std::vector<Crossing> out(k);
    out.resize(h.crossings(ray, out));
    return out;
}

/// Whether the ray meets two primitives at one parameter, to within the rounding of primitives
/// meeting at one point (1e-6 relative, as count_mismatches allows), up to its (k + 1)-th
/// crossing: a tie a search may keep either way, and where a box around one primitive may start
/// a hair beyond the other. Every crossing counts, a sphere's or cone's exit too: a restarted
/// query that starts at an exit tied with another primitive's entry skips that entry.
bool tied(const Scene& s, const Ray& ray, const std::vector<Crossing>& nearest, std::size_t k) {
    if (nearest.empty()) return false;
    const float last = nearest[std::min(k, nearest.size() - 1)].t;
    std::vector<float> ts;
    for (std::uint32_t id = 0; id < s.size(); ++id) {
        Ray r = ray;
        float t;
        for (int n = 0; n < 4 && r.tmin <= last && s.intersect(id, r, t); ++n) {
            ts.push_back(t);
            r.tmin = t;
        }
    }
    std::sort(ts.begin(), ts.end());
    for (std::size_t i = 1; i < ts.size() && ts[i - 1] <= last; ++i)
        if (ts[i] - ts[i - 1] <= 1e-6f * std::fabs(ts[i])) return true;
    return false;
}

/// Checks every hierarchy's first k crossings of `rays`; returns how many rays have ties.
std::size_t expect_crossings_match(const Scene& s, std::span<const Ray> rays, std::size_t k) {
    std::vector<std::vector<Crossing>> want;
    for (const Ray& r : rays) want.push_back(all_crossings(s, r));
    std::size_t untied = 0, met = 0;
    std::vector<char> has_tie(rays.size());
    for (std::size_t i = 0; i < rays.size(); ++i) {
        has_tie[i] = tied(s, rays[i], want[i], k);
        untied += !has_tie[i];
        met += !want[i].empty();
    }
    // A real share of the rays meets something.
    EXPECT_GT(met, rays.size() / 20);
    for (const auto& [name, set] : registered_variants(kTestHits)) {
        auto h = build_hierarchy(s, name, set);
        if (!h->counted()) continue;  // embree: its own intersection tests
        std::size_t bad = 0;
        std::string first;
        for (std::size_t i = 0; i < rays.size(); ++i) {
            const std::vector<Crossing> got = crossings_of(*h, rays[i], k);
            bool ok;
            if (!has_tie[i]) {
                // Exactly brute force's first k.
                const std::size_t n = std::min(k, want[i].size());
                ok = got.size() == n && std::equal(got.begin(), got.end(), want[i].begin(), [](auto& a, auto& b) {
                         return a.prim == b.prim && a.t == b.t;
                     });
            } else {
                // Ties: nearest first, none twice, the first as near as brute force's closest
                // hit (to the same rounding), each a primitive the ray meets, at its nearest
                // parameter or beyond (a restarted query starting at a tie skips the entry of
                // the primitive it did not report and finds its exit).
                ok = !got.empty() && got.size() <= k &&
                     got.front().t - want[i].front().t <= 1e-6f * std::fabs(want[i].front().t);
                for (std::size_t j = 0; ok && j < got.size(); ++j) {
                    auto it = std::find_if(want[i].begin(), want[i].end(),
                                           [&](const Crossing& c) { return c.prim == got[j].prim; });
                    ok = it != want[i].end() && it->t <= got[j].t && (j == 0 || got[j - 1].t <= got[j].t) &&
                         std::count_if(got.begin(), got.end(), [&](auto& c) { return c.prim == got[j].prim; }) == 1;
                }
            }
            if (!ok && bad++ == 0) first = "ray " + std::to_string(i);
        }
        EXPECT_EQ(bad, 0u) << name << " " << ::testing::PrintToString(set) << ": first at " << first;
    }
    return rays.size() - untied;
}

TEST(Crossings, EveryHierarchyFindsBruteForcesFirstCrossings) {
    for (const char* spec : {"builtin:balls:2", "builtin:tetra:4"}) {
        const Scene s = load_scene(spec);
        const std::vector<Ray> rays = hard_rays(s, 3000, 11);
        SCOPED_TRACE(spec);
        const std::size_t ties = expect_crossings_match(s, rays, kMaxCrossings);
        // Rays aimed at vertices and edges meet the triangles there at one parameter.
        if (!s.triangles.empty()) {
            EXPECT_GT(ties, 100u);
        }
        expect_crossings_match(s, std::span(rays).first(2000), 3);
    }
}

TEST(Crossings, SpdScenesWithPolygonsAndCones) {
    for (const char* name : {"gears", "tree"}) {
        const std::string path = spd_path(name);
        if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " not present";
        const Scene s = load_scene(path);
        SCOPED_TRACE(name);
        // Every fourth of the hard rays: brute force over these scenes is the slow part.
        std::vector<Ray> rays;
        const std::vector<Ray> hard = hard_rays(s, 1000, 3);
        for (std::size_t i = 0; i < hard.size(); i += 4) rays.push_back(hard[i]);
        EXPECT_GT(expect_crossings_match(s, rays, kMaxCrossings), 50u);
    }
}

TEST(Crossings, OneTraversalKeepsEveryPrimitiveMetAtTheSameParameter) {
    // Two copies of one triangle and a third behind them: a ray through them meets the copies
    // at the same parameter. Restarted closest-hit queries would keep one copy.
    Scene s;
    const Triangle a{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    s.add(a, 0);
    s.add(Triangle{{0, 0, 2}, {1, 0, 2}, {0, 1, 2}}, 0);
    s.add(a, 0);
    s.finalize();
    const Ray ray{{0.25f, 0.25f, -1}, {0, 0, 1}, 0, kInf};
    for (const char* name : {"bvh-sah", "kd-sah", "grid", "octree"}) {
        auto h = build_hierarchy(s, name);
        const std::vector<Crossing> got = crossings_of(*h, ray, kMaxCrossings);
        ASSERT_EQ(got.size(), 3u) << name;
        EXPECT_EQ(got[0].t, 1.0f) << name;
        EXPECT_EQ(got[1].t, 1.0f) << name;
        EXPECT_NE(got[0].prim, got[1].prim) << name;
        EXPECT_EQ(got[2].prim, 1u) << name;
        EXPECT_EQ(got[2].t, 3.0f) << name;
        // Room for two: the nearest two, the copies.
        const std::vector<Crossing> two = crossings_of(*h, ray, 2);
        ASSERT_EQ(two.size(), 2u) << name;
        EXPECT_EQ(two[1].t, 1.0f) << name;
        // A segment ending before the far one.
        Ray shorter = ray;
        shorter.tmax = 2;
        EXPECT_EQ(crossings_of(*h, shorter, kMaxCrossings).size(), 2u) << name;
    }
}

TEST(Crossings, ASampleFoundWithOneTraversalEqualsBruteForces) {
    // find_ends through a BVH and through brute force (restarted queries): the same ends on a
    // scene without ties among its crossings' parameters on these rays.
    const Scene s = load_scene("builtin:balls:2");
    RaySpec spec;
    spec.name = "diffuse";
    spec.size = "64x64";
    auto bvh = build_hierarchy(s, "bvh-sah");
    auto brute = build_hierarchy(s, "brute");
    RaySample a = draw_sample(s, spec, 500, 3, *bvh);
    RaySample b = a;
    find_ends(b, *brute);
    ASSERT_EQ(a.size(), 500u);
    EXPECT_EQ(a.t_end, b.t_end);
    EXPECT_EQ(a.first, b.first);
    ASSERT_EQ(a.crossings.size(), b.crossings.size());
    EXPECT_GT(a.crossings.size(), a.size() / 4);
    for (std::size_t i = 0; i < a.crossings.size(); ++i) {
        EXPECT_EQ(a.crossings[i].prim, b.crossings[i].prim) << i;
        EXPECT_EQ(a.crossings[i].t, b.crossings[i].t) << i;
    }
}

}  // namespace
}  // namespace rtcost::test
