// Adversarial geometry: coincident primitives, everything at one point, everything coplanar,
// huge and tiny coordinates, long thin triangles spanning the scene, a huge sphere around tiny
// ones, a single primitive. For each scene every registered hierarchy builds within a memory
// bound and returns brute force's closest hits (rel_tol 0) and its any-hit answers. Embree is
// built and traced too, but it is not held to brute force: it is not exact (its own float
// tests; see docs/reliability.md), so only that it answers is checked.
#include <random>

#include "test_support.hpp"

namespace rtcost::test {
namespace {

// What any hierarchy may hold for these small scenes: a build that needs more has lost its
// bound on memory.
constexpr std::uint64_t kMaxBytes = 64ull << 20;

struct Adversary {
    std::string name;
    Scene scene;
};

Scene finished(Scene s, const std::string& name) {
    s.name = name;
    s.finalize();
    return s;
}

Triangle scaled(const Triangle& t, float k, Vec3 at) { return {t.v0 * k + at, t.v1 * k + at, t.v2 * k + at}; }

// A small mixed scene in [-1, 1]^3: triangles, spheres, a cone, a quad.
Scene mixed(float k, Vec3 at) {
    Scene s;
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-1, 1);
    for (int i = 0; i < 40; ++i) {
        Vec3 c{u(rng), u(rng), u(rng)};
        Triangle t{c, c + Vec3{0.3f, u(rng) * 0.1f, 0}, c + Vec3{0, 0.3f, u(rng) * 0.2f}};
        s.add(scaled(t, k, at), 0);
    }
    for (int i = 0; i < 10; ++i) s.add(Sphere{Vec3{u(rng), u(rng), u(rng)} * k + at, 0.15f * k}, 0);
    s.add(Cone{Vec3{0, -0.5f, 0} * k + at, 0.2f * k, Vec3{0, 0.5f, 0} * k + at, 0.05f * k}, 0);
    Vec3 quad[4] = {Vec3{-1, -1, -1} * k + at, Vec3{1, -1, -1} * k + at, Vec3{1, 1, -1} * k + at,
                    Vec3{-1, 1, -1} * k + at};
    s.add_polygon(quad, 0);
    return s;
}

std::vector<Adversary> adversaries() {
    std::vector<Adversary> out;
    auto add = [&](const std::string& name, Scene s) { out.push_back({name, finished(std::move(s), name)}); };
    const Triangle tri{{-1, -1, 0}, {1, -1, 0.2f}, {0, 1, -0.1f}};
    {
        Scene s;  // 300 copies of one triangle and 300 of one sphere
        for (int i = 0; i < 300; ++i) s.add(tri, 0);
        for (int i = 0; i < 300; ++i) s.add(Sphere{{0.2f, 0.1f, 0}, 0.5f}, 0);
        add("coincident", std::move(s));
    }
    {
        Scene s;  // everything at one point: tiny spheres and triangles sharing one vertex
        for (int i = 0; i < 200; ++i) s.add(Sphere{{0.5f, 0.5f, 0.5f}, 1e-3f * (1 + i % 3)}, 0);
        for (int i = 0; i < 100; ++i) {
            const float a = 0.0628f * i;
            s.add(Triangle{{0.5f, 0.5f, 0.5f}, {0.5f + 1e-3f * std::cos(a), 0.5f + 1e-3f * std::sin(a), 0.5f},
                           {0.5f, 0.5f + 1e-3f * std::cos(a), 0.5f + 1e-3f * std::sin(a)}},
                  0);
        }
        add("one point", std::move(s));
    }
    {
        Scene s;  // everything in the plane z = 0
        std::mt19937 rng(3);
        std::uniform_real_distribution<float> u(-1, 1);
        for (int i = 0; i < 400; ++i) {
            Vec3 c{u(rng), u(rng), 0};
            s.add(Triangle{c, c + Vec3{0.2f * u(rng), 0.2f, 0}, c + Vec3{0.2f, 0.2f * u(rng), 0}}, 0);
        }
        add("coplanar", std::move(s));
    }
    add("huge (1e11)", mixed(1e11f, {3e11f, -2e11f, 1e11f}));
    add("tiny (1e-11)", mixed(1e-11f, {0, 0, 0}));
    add("offset 1e5", mixed(1.0f, {1e5f, 0, 0}));
    {
        Scene s;  // 400 long thin triangles, each spanning the scene, all overlapping
        std::mt19937 rng(11);
        std::uniform_real_distribution<float> u(-1, 1);
        for (int i = 0; i < 400; ++i) {
            Vec3 a{-1, u(rng), u(rng)}, b{1, u(rng), u(rng)};
            s.add(Triangle{a, b, a + Vec3{0, 1e-3f, 1e-3f}}, 0);
        }
        add("long thin", std::move(s));
    }
    {
        Scene s;  // a huge sphere with tiny ones inside
        s.add(Sphere{{0, 0, 0}, 1e4f}, 0);
        std::mt19937 rng(2);
        std::uniform_real_distribution<float> u(-1, 1);
        for (int i = 0; i < 300; ++i) s.add(Sphere{{u(rng), u(rng), u(rng)}, 1e-2f}, 0);
        add("huge sphere", std::move(s));
    }
    {
        Scene s;
        s.add(tri, 0);
        add("one triangle", std::move(s));
    }
    {
        Scene s;
        s.add(Sphere{{1, 2, 3}, 0.5f}, 0);
        add("one sphere", std::move(s));
    }
    {
        Scene s;
        s.add(Cone{{0, 0, 0}, 1, {0, 0, 2}, 0}, 0);
        add("one cone", std::move(s));
    }
    return out;
}

// Random rays from around the scene, rays aimed at primitives, and isotropic lines.
std::vector<Ray> rays_for(const Scene& s) {
    std::vector<Ray> rays = hard_rays(s, 1500, 17);
    std::vector<Ray> lines = line_rays(s.bounds(), 800, 9);
    rays.insert(rays.end(), lines.begin(), lines.end());
    return rays;
}

// Closest hits must agree exactly (the same primitive, the same t), except for ties: another
// primitive at the same distance up to the rounding of the scene's coordinates (coplanar
// overlapping triangles are hit at one t, which each triangle's arithmetic rounds differently,
// and a hierarchy that culls by box entry may keep either).
std::size_t mismatches(const Scene& s, std::span<const Ray> rays, std::span<const Hit> want, std::span<const Hit> got,
                       std::string* first) {
    const Vec3 e = s.bounds().extent();
    const float size = std::max({e.x, e.y, e.z});
    std::size_t bad = 0;
    for (std::size_t i = 0; i < want.size(); ++i) {
        bool ok = want[i].hit() == got[i].hit();
        if (ok && want[i].hit()) {
            float tol = 0;
            if (want[i].prim != got[i].prim) tol = 1e-6f * (std::fabs(want[i].t) + size / length(rays[i].d));
            ok = std::fabs(want[i].t - got[i].t) <= tol;
        }
        if (!ok && bad++ == 0)
            *first = "ray " + std::to_string(i) + ": want prim " + std::to_string(want[i].prim) + " t " +
                     std::to_string(want[i].t) + ", got prim " + std::to_string(got[i].prim) + " t " +
                     std::to_string(got[i].t);
    }
    return bad;
}

class Adversarial : public ::testing::TestWithParam<int> {};

TEST_P(Adversarial, EveryHierarchyBuildsWithinBoundsAndMatchesBruteForce) {
    static const std::vector<Adversary> all = adversaries();
    ASSERT_EQ(all.size(), 11u);
    const Adversary& adv = all[static_cast<std::size_t>(GetParam())];
    const Scene& s = adv.scene;
    ASSERT_FALSE(s.empty());
    EXPECT_NO_THROW(check_scene(s)) << adv.name;
    const std::vector<Ray> rays = rays_for(s);
    auto brute = build_hierarchy(s, "brute");
    const std::vector<Hit> want = closest_hits(*brute, rays);
    TraceOptions any;
    any.query = Query::Any;
    const std::vector<Hit> want_any = trace_rays(*brute, rays, any).hits;
    std::size_t hits = 0;
    for (const Hit& h : want) hits += h.hit();
    EXPECT_GT(hits, rays.size() / 50) << adv.name << ": the rays should meet the scene";
    for (const HierarchyInfo* info : hierarchies()) {
        SCOPED_TRACE(adv.name + " / " + info->name);
        auto h = build_hierarchy(s, info->name);
        const std::vector<Hit> got = closest_hits(*h, rays);
        const std::vector<Hit> got_any = trace_rays(*h, rays, any).hits;
        const StructureStats st = h->structure();
        // rc5d's bound is its memory cap (max_bytes, 1 GiB by default): coincident or long
        // overlapping primitives fill every beam, and it subdivides them to max_depth.
        EXPECT_LE(st.bytes, info->name == "rc5d" ? (1ull << 30) + (1ull << 20) : kMaxBytes);
        EXPECT_LE(st.depth, 64);
        if (info->name == "embree") {
            // Not the reference: it answers, with finite distances.
            for (const Hit& g : got)
                if (g.hit()) {
                    EXPECT_TRUE(std::isfinite(g.t));
                }
            continue;
        }
        std::string first;
        EXPECT_EQ(mismatches(s, rays, want, got, &first), 0u) << first;
        std::size_t any_bad = 0;
        for (std::size_t i = 0; i < rays.size(); ++i) any_bad += want_any[i].hit() != got_any[i].hit();
        EXPECT_EQ(any_bad, 0u) << "any-hit answers differ";
    }
}

INSTANTIATE_TEST_SUITE_P(Scenes, Adversarial, ::testing::Range(0, 11));  // adversaries().size()

TEST(AdversarialBounds, CoincidentCopiesKeepTheGridsReferencesAndTestsBoundedAndSaySo) {
    Scene s;
    for (int i = 0; i < 3000; ++i) s.add(Triangle{{-1, -1, 0}, {1, -1, 0}, {0, 1, 0.5f}}, 0);
    s = finished(std::move(s), "copies");
    auto h = build_hierarchy(s, "grid", {"density=4"});
    const StructureStats st = h->structure();
    // Every cell would hold every copy: a ray would test them once per cell crossed, so the
    // grid shrinks to one cell, and a ray tests each copy at most once, as brute force does.
    EXPECT_EQ(st.references, s.size());
    TraceOptions opt;
    opt.count = true;
    const TraceResult r = trace_rays(*h, random_rays(s.bounds(), 500, 3), opt);
    EXPECT_LE(r.counters.prim_tests(), 500 * s.size());
    ASSERT_EQ(st.limits.size(), 1u);
    EXPECT_NE(st.limits[0].find("reduced"), std::string::npos) << st.limits[0];
}

TEST(AdversarialBounds, SpdScenesAreNotLimited) {
    // The bounds stop only adversarial builds: the SPD scenes build as before.
    for (const char* name : {"balls", "tetra", "rings", "teapot"}) RTCOST_REQUIRE_SPD(name);
    for (const char* name : {"balls", "tetra", "rings", "teapot"}) {
        Scene s = load_scene(spd_path(name));
        for (const char* hname : {"grid", "bsp", "octree", "rc5d"}) {
            auto h = build_hierarchy(s, hname);
            EXPECT_TRUE(h->structure().limits.empty()) << name << " " << hname << ": " << h->structure().limits[0];
        }
    }
}

}  // namespace
}  // namespace rtcost::test
