// The evaluation as a user reads it: hierarchy lists with their own parameters, brute force and
// Embree where they belong, the query of every ray kind, repeated timings and rankings by time,
// camera and lights from the command line, a default camera that sees the mesh, and the order of
// interleaved timing rounds.
#include <algorithm>
#include <array>
#include <set>

#include <fmt/format.h>

#include "rtcost/evaluate.hpp"
#include "test_support.hpp"

namespace rtcost::test {
namespace {

TEST(EvalList, PerHierarchyParametersAndTheMeaningOfAll) {
    const auto list = parse_hierarchy_list("bvh-gs:seed=1,octree:max_depth=6:max_prims=4,grid", 100);
    ASSERT_EQ(list.size(), 3u);
    EXPECT_EQ(list[0].name, "bvh-gs");
    EXPECT_EQ(list[0].params, std::vector<std::string>{"seed=1"});
    EXPECT_EQ(list[1].params, (std::vector<std::string>{"max_depth=6", "max_prims=4"}));
    EXPECT_EQ(list[1].label(), "octree:max_depth=6:max_prims=4");
    EXPECT_TRUE(list[2].params.empty());
    EXPECT_THROW(parse_hierarchy_list("bvh-gs:seed", 100), InputError);
    EXPECT_THROW(parse_hierarchy_list("no-such-tree", 100), InputError);
    EXPECT_THROW(parse_hierarchy_list(",", 100), InputError);
    auto has = [](const std::vector<HierarchyRequest>& v, const std::string& n) {
        return std::any_of(v.begin(), v.end(), [&](const HierarchyRequest& r) { return r.name == n; });
    };
    EXPECT_TRUE(has(parse_hierarchy_list("all", kBruteLimit), "brute"));
    EXPECT_FALSE(has(parse_hierarchy_list("all", kBruteLimit + 1), "brute"));
    EXPECT_FALSE(has(parse_hierarchy_list("all", 10), "embree"));
    // Large scenes: the slow builders leave all, and left_out_of_all names exactly those.
    const auto large = parse_hierarchy_list("all", kLargeScene + 1);
    const auto out = left_out_of_all("all", kLargeScene + 1);
    for (const char* slow : {"brute", "bvh-gs", "kd-median", "kd-sah", "kd-design", "grid-design", "octree-design"}) {
        EXPECT_FALSE(has(large, slow)) << slow;
        EXPECT_NE(std::find(out.begin(), out.end(), slow), out.end()) << slow;
    }
    for (const char* kept : {"bvh-sah", "bvh-wide", "grid", "octree", "bsp", "rc5d", "bvh-design"})
        EXPECT_TRUE(has(large, kept)) << kept;
    EXPECT_EQ(large.size() + out.size() + 1, hierarchies().size());  // embree: never in all
    EXPECT_TRUE(has(parse_hierarchy_list("all", kLargeScene), "kd-sah"));
    EXPECT_EQ(left_out_of_all("all", kLargeScene), std::vector<std::string>{"brute"});
    EXPECT_TRUE(left_out_of_all("bvh-sah,kd-sah", kLargeScene + 1).empty());
}

TEST(EvalRun, EmbreeIsTimedNotCountedAndRanksOnlyByTime) {
    Scene s = builtin_scene("balls", 2);
    EvalOptions opt;
    opt.hierarchies = parse_hierarchy_list("bvh-sah,embree,grid", s.size());
    opt.estimators = {Estimator::Segments};
    opt.repeat = 3;
    RaySpec spec;
    spec.size = "64x64";
    const EvalResult r = evaluate(s, spec, opt);
    ASSERT_EQ(r.rows.size(), 3u);
    const EvalRow& e = r.rows[1];
    EXPECT_FALSE(e.counted);
    EXPECT_FALSE(e.modelled);
    EXPECT_EQ(e.rank_measured, 0);
    EXPECT_EQ(e.rank_predicted, 0);
    EXPECT_GE(e.rank_time, 1);
    for (const EvalRow& row : r.rows) EXPECT_EQ(row.repeats, 3);
    EXPECT_GE(r.rows[0].rank_measured, 1);
    const auto j = to_json(r);
    EXPECT_TRUE(j["results"][1]["measured"].is_null());
    EXPECT_TRUE(j["results"][1]["rank_measured"].is_null());
    EXPECT_EQ(j["results"][1]["time"]["repeats"], 3);
    const std::string text = eval_table(r);
    EXPECT_NE(text.find("embree is timed only"), std::string::npos) << text;
    EXPECT_NE(text.find("by measured time"), std::string::npos);
}

TEST(EvalRun, ShadowRaysAreLabelledAnyHit) {
    Scene s = builtin_scene("balls", 2);
    EvalOptions opt;
    opt.hierarchies = parse_hierarchy_list("bvh-sah", s.size());
    opt.estimators = {Estimator::Segments};
    opt.repeat = 1;
    RaySpec spec;
    spec.name = "shadow";
    spec.size = "64x64";
    const auto j = to_json(evaluate(s, spec, opt));
    EXPECT_EQ(j["queries"]["shadow"], "any");
    ASSERT_EQ(j["queries"].size(), 1u);
}

// Rays that miss the scene box still cost brute force every primitive: both probed estimators
// must say so (once -67% on meshes whose camera rays mostly miss).
TEST(EvalRun, BruteForceIsPredictedOnRaysThatMissTheScene) {
    Scene s = builtin_scene("tetra", 3);
    // Look past the scene: most camera rays miss it.
    ViewSpec v;
    const Vec3 c = s.bounds().center(), e = s.bounds().extent();
    v.camera = fmt::format("{},{},{},{},{},{},0,1,0,60", c.x + 3 * e.x, c.y, c.z + 3 * e.z, c.x + 2 * e.x, c.y, c.z);
    apply_view(s, v);
    EvalOptions opt;
    opt.hierarchies = parse_hierarchy_list("brute,bvh-sah", s.size());
    opt.estimators = {Estimator::Segments, Estimator::Sampled};
    opt.repeat = 1;
    RaySpec spec;
    spec.size = "96x96";
    const EvalResult r = evaluate(s, spec, opt);
    const EvalRow& b = r.rows[0];
    ASSERT_EQ(b.name, "brute");
    EXPECT_NEAR(b.measured.prim_tests(), double(s.size()), 1e-9);
    for (const Prediction& p : b.predictions)
        EXPECT_NEAR(p.cost.prim_tests(), double(s.size()), 0.02 * s.size()) << p.estimator;
    // The segments sample's rays are traced too, for what they cost a trace.
    for (const EvalRow& row : r.rows) EXPECT_GT(row.sample_trace_seconds, 0) << row.name;
}

TEST(EvalView, CameraAndLightsFromOptionsAndBadOnesRefused) {
    Scene s = builtin_scene("balls", 1);
    apply_view(s, ViewSpec{"0,5,10,0,0,0,0,1,0,40", {"1,2,3", "-4,5,6"}});
    EXPECT_EQ(s.camera.from, (Vec3{0, 5, 10}));
    EXPECT_EQ(s.camera.angle, 40.0f);
    ASSERT_EQ(s.lights.size(), 2u);
    EXPECT_EQ(s.lights[1].position, (Vec3{-4, 5, 6}));
    for (const char* bad : {"1,2,3", "0,0,0,0,0,0,0,1,0,40", "0,0,1,0,0,0,0,0,1,40", "0,0,1,0,0,0,0,1,0,200",
                            "0,0,1,0,0,0,0,1,0,nan", "a,b,c,d,e,f,g,h,i,j"})
        EXPECT_THROW(apply_view(s, ViewSpec{bad, {}}), InputError) << bad;
    EXPECT_THROW(apply_view(s, ViewSpec{"", {"1,2"}}), InputError);
}

// A plate, as a terrain mesh is: framing its bounding sphere left about a fifth of the pixels
// on it; framing its box from above leaves more than a third.
TEST(EvalView, TheDefaultCameraFramesAThinMesh) {
    Scene s;
    s.name = "plate";
    const float w = 10, h = 0.5f, d = 10;
    const Vec3 p[8] = {{0, 0, 0}, {w, 0, 0}, {w, h, 0}, {0, h, 0}, {0, 0, d}, {w, 0, d}, {w, h, d}, {0, h, d}};
    const int faces[6][4] = {{0, 1, 2, 3}, {5, 4, 7, 6}, {4, 0, 3, 7}, {1, 5, 6, 2}, {3, 2, 6, 7}, {4, 5, 1, 0}};
    for (const auto& f : faces) {
        s.add(Triangle{p[f[0]], p[f[1]], p[f[2]]}, 0);
        s.add(Triangle{p[f[0]], p[f[2]], p[f[3]]}, 0);
    }
    s.finalize();
    auto h2 = build_hierarchy(s, "brute");
    // The image's aspect follows the plate's projected extent (512 on its long side).
    EXPECT_EQ(std::max(s.camera.width, s.camera.height), 512);
    const auto rays = camera_rays(s.camera, s.camera.width / 8, s.camera.height / 8);
    std::size_t hits = 0;
    for (const Ray& r : rays) {
        Hit hit;
        h2->closest(r, hit);
        hits += hit.hit();
    }
    EXPECT_GT(hits, rays.size() / 3) << hits << " of " << rays.size();
    // Every corner of the box is in view: inside the frustum of the angle (which spans the rows'
    // centres) and the aspect.
    const Vec3 fwd = normalize(s.camera.at - s.camera.from);
    const Vec3 right = normalize(cross(fwd, s.camera.up)), up = cross(right, fwd);
    const double tan_v = std::tan(0.5 * 45 * 3.14159265 / 180), tan_h = tan_v * s.camera.width / s.camera.height;
    for (const Vec3& q : p) {
        const Vec3 v = q - s.camera.from;
        EXPECT_LE(std::fabs(dot(v, right)) / dot(v, fwd), tan_h * 1.001);
        EXPECT_LE(std::fabs(dot(v, up)) / dot(v, fwd), tan_v * 1.001);
    }
}

TEST(RankCorrelation, SpearmansRhoOfKnownRankings) {
    const std::vector<double> a{1, 2, 3, 4}, same{10, 20, 30, 40}, reversed{4, 3, 2, 1}, swapped{1, 3, 2, 4};
    EXPECT_DOUBLE_EQ(rank_correlation(a, same), 1.0);
    EXPECT_DOUBLE_EQ(rank_correlation(a, reversed), -1.0);
    EXPECT_DOUBLE_EQ(rank_correlation(a, swapped), 0.8);  // one adjacent swap: 1 - 6 * 2 / (4 * 15)
    EXPECT_DOUBLE_EQ(rank_correlation(std::vector<double>{1}, std::vector<double>{2}), 0.0);
}

TEST(TimingOrder, EachRoundAPermutationNewEachRoundTheSameEveryRun) {
    constexpr std::size_t n = 5;
    constexpr int rounds = 400;
    std::array<int, n> first{};
    std::array<std::array<int, n>, n> after{};  // after[a][b]: rounds in which b was timed right after a
    std::set<std::vector<std::size_t>> seen;
    for (int r = 0; r < rounds; ++r) {
        const std::vector<std::size_t> order = timing_order(n, r);
        ASSERT_EQ(order, timing_order(n, r));
        std::vector<std::size_t> sorted = order;
        std::sort(sorted.begin(), sorted.end());
        ASSERT_EQ(sorted, (std::vector<std::size_t>{0, 1, 2, 3, 4}));
        ++first[order[0]];
        for (std::size_t i = 1; i < n; ++i) ++after[order[i - 1]][order[i]];
        seen.insert(order);
    }
    EXPECT_GT(seen.size(), 80u);  // of the 120 orders
    // Uniform: each structure first in about a fifth of the rounds, and each followed by each other
    // one in about a fifth (expected 80 of 400, standard deviation 8).
    for (std::size_t a = 0; a < n; ++a) {
        EXPECT_GT(first[a], 50) << a;
        EXPECT_LT(first[a], 110) << a;
        for (std::size_t b = 0; b < n; ++b)
            if (b != a) {
                EXPECT_GT(after[a][b], 50) << a << " then " << b;
                EXPECT_LT(after[a][b], 110) << a << " then " << b;
            }
    }
    // The same on every standard library: mt19937_64's raw words, Fisher-Yates by hand.
    EXPECT_EQ(timing_order(n, 0), (std::vector<std::size_t>{1, 4, 3, 2, 0}));
    EXPECT_TRUE(timing_order(0, 3).empty());
    EXPECT_EQ(timing_order(1, 3), std::vector<std::size_t>{0});
}

}  // namespace
}  // namespace rtcost::test
