// bvh-wide: its lanes, its counts and its model tree, for both widths and both instruction sets.
#include "rtcost/sample.hpp"
#include "test_support.hpp"

namespace rtcost::test {
namespace {

const std::vector<std::vector<std::string>> kWide = {
    {"width=4"}, {"width=8"}, {"width=4", "simd=baseline"}, {"width=8", "simd=baseline"}};

TEST(BvhWide, NodesHoldAtMostWidthChildrenAndEveryPrimitiveOnce) {
    Scene s = builtin_scene("balls", 2);
    for (const auto& set : kWide) {
        auto h = build_hierarchy(s, "bvh-wide", set);
        const int w = set[0] == "width=4" ? 4 : 8;
        const ModelTree t = h->model_tree();
        ASSERT_FALSE(t.nodes.empty());
        EXPECT_EQ(t.family, ModelFamily::Bvh);
        std::vector<int> seen(s.size(), 0);
        for (const ModelNode& n : t.nodes) {
            if (n.leaf) {
                EXPECT_GE(n.count, 1u);
                EXPECT_LE(n.count, 16u);  // max_prims=16
                continue;
            }
            EXPECT_GE(n.count, 1u);
            EXPECT_LE(n.count, static_cast<std::uint32_t>(w));
            EXPECT_EQ(n.box, static_cast<float>(n.count));  // a visit tests every child's box
            for (std::uint32_t k = 0; k < n.count; ++k) {
                const ModelNode& c = t.nodes[n.first + k];
                // A child's box lies inside its parent's.
                EXPECT_TRUE(n.region.contains(c.region.lo) && n.region.contains(c.region.hi));
            }
        }
        for (std::uint32_t id : t.prims) ++seen[id];
        for (int v : seen) EXPECT_EQ(v, 1);
        const StructureStats st = h->structure();
        EXPECT_EQ(st.references, s.size());
        EXPECT_GE(st.leaves, st.interior + 1);
        // Collapsing fills the nodes: over the same small-leaf SAH tree, a mean fan-out well
        // above binary (measured: 3.18 four-wide, 4.09 eight-wide) and half the depth or less.
        Scene big = builtin_scene("balls", 3);
        std::vector<std::string> small_leaves = set;
        small_leaves.insert(small_leaves.end(), {"max_prims=2", "c_trav=1"});
        const StructureStats wide = build_hierarchy(big, "bvh-wide", small_leaves)->structure();
        const double fanout = static_cast<double>(wide.interior - 1 + wide.leaves) / static_cast<double>(wide.interior);
        EXPECT_GT(fanout, w == 8 ? 3.6 : 3.0);
        const StructureStats bin = build_hierarchy(big, "bvh-sah", {"max_prims=2"})->structure();
        EXPECT_EQ(wide.leaves, bin.leaves);  // the same leaves, regrouped
        EXPECT_LE(2 * wide.depth, bin.depth);
    }
}

TEST(BvhWide, BothInstructionSetsAndWidthsCountAlikeAndHitAlike) {
    Scene s = builtin_scene("tetra", 4);
    auto rays = hard_rays(s, 20000, 5);
    // The default's triangle packs (8 lanes with AVX2, and 4 for leaves of at most four
    // triangles) and packs of 4 throughout (tri_lanes=4) against the baseline's.
    for (const char* w : {"width=4", "width=8"}) {
        auto a = build_hierarchy(s, "bvh-wide", {w, "simd=baseline"});
        for (const char* lanes : {"tri_lanes=auto", "tri_lanes=4"}) {
            std::vector<std::string> set{w, lanes};
            auto b = build_hierarchy(s, "bvh-wide", set);
            TraceOptions opt;
            opt.count = true;
            for (Query q : {Query::Closest, Query::Any, Query::All}) {
                opt.query = q;
                TraceResult ra = trace_rays(*a, rays, opt), rb = trace_rays(*b, rays, opt);
                EXPECT_EQ(ra.counters, rb.counters) << w << " " << lanes;
                for (std::size_t i = 0; i < rays.size(); ++i) {
                    EXPECT_EQ(ra.hits[i].prim, rb.hits[i].prim);
                    EXPECT_EQ(ra.hits[i].t, rb.hits[i].t);
                }
            }
        }
    }
    EXPECT_THROW(build_hierarchy(s, "bvh-wide", {"simd=baseline", "tri_lanes=8"}), InputError);
}

TEST(BvhWide, ARayMissingTheRootPaysOneBoxTestAndNoStep) {
    Scene s = builtin_scene("balls", 2);
    auto h = build_hierarchy(s, "bvh-wide");
    const Box3 b = s.bounds();
    RayCounters c;
    Hit hit;
    // Parallel to the scene box, beside it.
    h->all(Ray{b.hi + b.extent(), {1, 0, 0}, 0, kInf}, hit, c);
    EXPECT_FALSE(hit.hit());
    EXPECT_EQ(c.box, 1u);
    EXPECT_EQ(c.steps, 0u);
    // Through the middle: the root node's children are all tested.
    RayCounters d;
    h->all(Ray{b.center() - Vec3{2 * b.extent().x, 0, 0}, {1, 0, 0}, 0, kInf}, hit, d);
    EXPECT_TRUE(hit.hit());
    EXPECT_GE(d.box, 1 + h->model_tree().nodes[0].count);
    EXPECT_GT(d.steps, d.leaves);
}

TEST(BvhWide, TheSampledEstimatorReproducesTheTrainingRaysCounts) {
    // As ModelSampled does for the other hierarchies: on its own training rays the sampled
    // estimator's walk is the traversal's (nearest first, ties as the traversal breaks them).
    // balls: spheres and a ground polygon (scalar leaves); tetra: triangles (packed leaves).
    for (const char* name : {"balls", "tetra"}) {
        Scene s = builtin_scene(name, name[0] == 'b' ? 2 : 4);
        std::vector<Ray> rays = camera_rays(s.camera, 48, 48);
        std::vector<Ray> more = random_rays(s.bounds(), 3000, 21);
        rays.insert(rays.end(), more.begin(), more.end());
        for (const auto& set : std::vector<std::vector<std::string>>{
                 {"width=4"}, {"width=8"}, {"width=8", "max_prims=1", "c_trav=1"}, {"width=4", "simd=baseline"}}) {
            auto h = build_hierarchy(s, "bvh-wide", set);
            const ModelTree t = h->model_tree();
            for (Query q : {Query::Closest, Query::Any, Query::All}) {
                RayCounters total;
                for (const Ray& r : rays) {
                    Hit hit;
                    if (q == Query::Closest)
                        h->closest(r, hit, total);
                    else if (q == Query::Any)
                        h->any(r, hit, total);
                    else
                        h->all(r, hit, total);
                }
                const CostVector m = measured_cost(total);
                ModelOptions o;
                o.query = q;
                const Prediction p = predict_sampled(t, s, rays, o);
                const std::string what = std::string(name) + " " + ::testing::PrintToString(set) + " query " +
                                         std::to_string(static_cast<int>(q));
                EXPECT_NEAR(p.cost.box, m.box, 1e-3 * m.box + 1e-9) << what;
                EXPECT_NEAR(p.cost.prim_tests(), m.prim_tests(), 1e-3 * m.prim_tests() + 1e-9) << what;
                EXPECT_NEAR(p.cost.steps, m.steps, 1e-3 * m.steps + 1e-9) << what;
                EXPECT_NEAR(p.cost.leaves, m.leaves, 1e-3 * m.leaves + 1e-9) << what;
            }
        }
    }
}

TEST(BvhWide, ItsReplayOfASamplePredictsWhatItsModelTreePredicts) {
    // The segments estimator replays a sample through the wide walk itself, each primitive
    // answered from the ray's known crossings (a packed leaf's triangles one by one, in lane
    // order): the model tree's prediction, without materialising the tree.
    // balls: spheres and a ground polygon (scalar leaves); tetra: triangles (packed leaves).
    for (const char* name : {"balls", "tetra"}) {
        Scene s = builtin_scene(name, name[0] == 'b' ? 2 : 4);
        auto ref = build_hierarchy(s, "bvh-sah");
        RaySet set;
        set.rays = camera_rays(s.camera, 40, 40);
        std::vector<Ray> more = random_rays(s.bounds(), 1500, 23);
        set.rays.insert(set.rays.end(), more.begin(), more.end());
        set.kinds.assign(set.rays.size(), RayKind::Test);
        const RaySample smp = draw_sample_from(s, set, 600, 3, *ref);
        const std::vector<std::uint32_t> idx = indices(smp.size());
        for (const auto& params : std::vector<std::vector<std::string>>{{"width=4"},
                                                                        {"width=8"},
                                                                        {"width=8", "tri_lanes=4"},
                                                                        {"width=8", "max_prims=1", "c_trav=1"},
                                                                        {"width=4", "simd=baseline"},
                                                                        {"width=8", "simd=baseline", "any_order=nearest"}}) {
            auto h = build_hierarchy(s, "bvh-wide", params);
            for (Query q : {Query::Closest, Query::Any}) {
                const std::string what = std::string(name) + " " + ::testing::PrintToString(params) + " query " +
                                         std::to_string(static_cast<int>(q));
                RayCounters replayed;
                ASSERT_TRUE(h->replay(smp, idx, q, replayed)) << what;
                EXPECT_EQ(replayed.rays, idx.size()) << what;
                ModelOptions o;
                o.query = q;
                SegmentsPredictor traversal(*h, s, smp), tree(*h, s, smp, 0, SegmentsPredictor::Via::ModelTree);
                const Prediction a = traversal.predict(idx, o), b = tree.predict(idx, o);
                EXPECT_NE(a.note.find("the hierarchy's traversal"), std::string::npos) << what;
                EXPECT_EQ(traversal.tree_seconds(), 0.0) << what << ": a replay materialises nothing";
                ASSERT_GT(b.cost.prim_tests(), 0.0) << what;
                EXPECT_NEAR(a.cost.box, b.cost.box, 1e-6 * b.cost.box) << what;
                EXPECT_NEAR(a.cost.prim_tests(), b.cost.prim_tests(), 1e-6 * b.cost.prim_tests()) << what;
                EXPECT_NEAR(a.cost.steps, b.cost.steps, 1e-6 * b.cost.steps) << what;
                EXPECT_NEAR(a.cost.leaves, b.cost.leaves, 1e-6 * b.cost.leaves) << what;
                EXPECT_NEAR(a.scalar, b.scalar, 1e-6 * b.scalar) << what;
            }
        }
    }
}

TEST(BvhWide, RejectsAnUnknownWidth) {
    Scene s = builtin_scene("tetra", 2);
    EXPECT_THROW(build_hierarchy(s, "bvh-wide", {"width=5"}), InputError);
    EXPECT_THROW(build_hierarchy(s, "bvh-wide", {"simd=neon"}), InputError);
}

TEST(BvhWide, EmptySceneMissesEverything) {
    Scene s;
    s.finalize();
    auto h = build_hierarchy(s, "bvh-wide");
    Hit hit;
    h->closest(Ray{{0, 0, 0}, {0, 0, 1}, 0, kInf}, hit);
    EXPECT_FALSE(hit.hit());
}

TEST(BvhWide, ModelIsExactOnLinesForBothWidths) {
    Scene balls = builtin_scene("balls", 2);
    Scene tetra = builtin_scene("tetra", 3);
    for (const auto& set : kWide) {
        expect_model_exact(balls, "bvh-wide", set);
        expect_model_exact(tetra, "bvh-wide", set);
    }
}

class WideSpd : public ::testing::TestWithParam<std::string> {};

// Exact hits against brute force on these scenes: bvh-wide's variants in test_hierarchies.cpp.
TEST_P(WideSpd, TheModelIsExactOnLines) {
    RTCOST_REQUIRE_SPD(GetParam());
    Scene s = load_scene(spd_path(GetParam()));
    expect_model_exact(s, "bvh-wide", {}, 100000, 4);
    expect_model_exact(s, "bvh-wide", {"width=4"}, 100000, 4);
}

INSTANTIATE_TEST_SUITE_P(Spd, WideSpd,
                         ::testing::Values("balls", "gears", "mount", "rings", "teapot", "tetra", "tree", "lattice",
                                           "shells", "sombrero"));

}  // namespace
}  // namespace rtcost::test
