// rc5d's hits against brute force, exactly: face-diagonal directions, zero components, origins
// inside the box and on split planes, tmin/tmax, every query, counting on and off.
#include "rc5d_test_util.hpp"

namespace rtcost::test {
namespace {

// --- exact hits ------------------------------------------------------------------------------

const std::vector<std::vector<std::string>> kSets = {
    {},
    {"max_prims=1", "max_depth=40"},
    {"max_depth=0"},
    {"max_depth=7"},
    {"build=eager", "max_depth=12", "max_prims=4"},
};

TEST(Rc5dHits, BuiltinBallsMatchBruteForceExactly) {
    Scene s = builtin_scene("balls", 2);
    auto rays = all_test_rays(s, 20000, 11);
    auto want = closest_hits(*build_hierarchy(s, "brute"), rays);
    for (const auto& set : kSets) expect_exact(s, rays, want, set);
}

TEST(Rc5dHits, BuiltinTetraMatchesBruteForceExactly) {
    Scene s = builtin_scene("tetra", 4);
    auto rays = all_test_rays(s, 20000, 12);
    auto want = closest_hits(*build_hierarchy(s, "brute"), rays);
    for (const auto& set : kSets) expect_exact(s, rays, want, set);
}

TEST(Rc5dHits, SpdRingsMatchesBruteForceExactly) {
    RTCOST_REQUIRE_SPD("rings");
    Scene s = load_scene(spd_path("rings"));
    auto rays = all_test_rays(s, 8000, 13);
    auto want = closest_hits(*build_hierarchy(s, "brute"), rays);
    expect_exact(s, rays, want, {});
    expect_exact(s, rays, want, {"max_prims=2", "max_depth=35"});
}

TEST(Rc5dHits, SpdTetraMatchesBruteForceExactly) {
    RTCOST_REQUIRE_SPD("tetra");
    Scene s = load_scene(spd_path("tetra"));
    auto rays = all_test_rays(s, 8000, 14);
    auto want = closest_hits(*build_hierarchy(s, "brute"), rays);
    expect_exact(s, rays, want, {});
    expect_exact(s, rays, want, {"max_depth=30", "max_bytes=2000000"});
}

TEST(Rc5dHits, SegmentsWithTminAndTmaxMatchBruteForce) {
    Scene s = builtin_scene("balls", 2);
    std::vector<Ray> rays = all_test_rays(s, 6000, 21);
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<float> uni(0, 1);
    const float size = s.bounds().extent().x;
    for (Ray& r : rays) {
        const float len = length(r.d);
        r.tmin = uni(rng) * size / len;
        if (uni(rng) < 0.5f) r.tmax = r.tmin + uni(rng) * size / len;
    }
    auto want = closest_hits(*build_hierarchy(s, "brute"), rays);
    std::size_t hits = 0;
    for (const Hit& h : want) hits += h.hit();
    ASSERT_GT(hits, rays.size() / 20);
    for (const auto& set : kSets) expect_exact(s, rays, want, set);
}

TEST(Rc5dHits, AnyAndAllQueriesAgreeWithClosest) {
    Scene s = builtin_scene("tetra", 4);
    auto rays = all_test_rays(s, 5000, 31);
    auto want = closest_hits(*build_hierarchy(s, "brute"), rays);
    auto h = build_hierarchy(s, "rc5d");
    TraceOptions opt;
    opt.query = Query::Any;
    TraceResult any = trace_rays(*h, rays, opt);
    opt.query = Query::All;
    opt.count = true;
    TraceResult all = trace_rays(*h, rays, opt);
    TraceOptions copt;
    copt.count = true;
    TraceResult closest = trace_rays(*h, rays, copt);
    std::size_t bad = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        bad += any.hits[i].hit() != want[i].hit();
        float t;
        if (any.hits[i].hit()) bad += !s.intersect(static_cast<std::uint32_t>(any.hits[i].prim), rays[i], t);
    }
    EXPECT_EQ(bad, 0u);
    std::string first;
    EXPECT_EQ(count_mismatches(want, all.hits, 0.0f, &first), 0u) << first;
    // All tests every candidate of the beam: never fewer tests than the ordered search, and the
    // same path.
    EXPECT_GT(all.counters.prim_tests(), closest.counters.prim_tests());
    EXPECT_EQ(all.counters.classify, closest.counters.classify);
    EXPECT_EQ(all.counters.steps, closest.counters.steps);
}

TEST(Rc5dHits, CountingDoesNotChangeHits) {
    Scene s = builtin_scene("balls", 2);
    auto rays = all_test_rays(s, 5000, 41);
    auto h = build_hierarchy(s, "rc5d");
    TraceOptions opt;
    TraceResult fast = trace_rays(*h, rays, opt);
    opt.count = true;
    TraceResult counted = trace_rays(*h, rays, opt);
    for (std::size_t i = 0; i < rays.size(); ++i) {
        EXPECT_EQ(fast.hits[i].t, counted.hits[i].t);
        EXPECT_EQ(fast.hits[i].prim, counted.hits[i].prim);
    }
}

// A disabled sweep over every SPD scene and the two meshes, against brute force exactly and
// against Embree (run with --gtest_also_run_disabled_tests; the lead's cross-check covers it).
TEST(Rc5dHits, DISABLED_AllSpdScenesAndMeshes) {
    std::vector<std::string> specs;
    for (const char* n : {"balls", "gears", "mount", "rings", "teapot", "tetra", "tree", "lattice", "shells", "sombrero"})
        if (std::filesystem::exists(spd_path(n))) specs.push_back(spd_path(n));
    for (const char* m : {"/usr/share/assimp/models/OBJ/spider.obj", "/usr/share/assimp/models/PLY/Wuson.ply"})
        if (std::filesystem::exists(m)) specs.push_back(m);
    for (const std::string& spec : specs) {
        Scene s = load_scene(spec);
        auto rays = all_test_rays(s, 20000, 51);
        auto want = closest_hits(*build_hierarchy(s, "brute"), rays);
        expect_exact(s, rays, want, {});
        expect_exact(s, rays, want, {"max_depth=45", "max_prims=2"});
        expect_exact(s, rays, want, {"max_depth=10", "build=eager"});
        // rc5d equals brute force exactly, so it differs from Embree exactly where brute force
        // does (Embree's own rounding: the lead's cross-check bounds that).
        auto embree = closest_hits(*build_hierarchy(s, "embree"), std::span(rays).first(20000));
        auto got = closest_hits(*build_hierarchy(s, "rc5d"), std::span(rays).first(20000));
        std::string first;
        EXPECT_EQ(count_mismatches(embree, got, 1e-4f, &first),
                  count_mismatches(embree, std::span(want).first(20000), 1e-4f))
            << spec << ": " << first;
    }
}

}  // namespace
}  // namespace rtcost::test
