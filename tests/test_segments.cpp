// The segments estimator: replaying a ray sample through any hierarchy's model tree with no
// primitive tests gives back exactly what the sampled probe counts with real ones, so the
// estimator's only error is the sample's; its predictor materialises only what the sample
// reaches, or nothing where the hierarchy replays its own traversal. (The sample itself:
// test_ray_sample.cpp.)
#include "rtcost/evaluate.hpp"
#include "rtcost/sample.hpp"
#include "test_support.hpp"

namespace rtcost::test {
namespace {

// Every registered hierarchy the model sees into (a new one is covered without touching this
// file), with parameters that make the lazily built ones whole.
std::vector<Variant> modelled_variants(const Scene& s) {
    std::vector<Variant> out;
    for (const HierarchyInfo* info : hierarchies()) {
        std::vector<std::string> set;
        if (info->name == "rc5d") set = {"build=eager", "max_depth=10"};
        if (!build_hierarchy(s, info->name, set)->modelled()) continue;
        out.push_back({info->name, set});
    }
    out.push_back({"bvh-sah", {"order=none"}});
    // bvh-design's own order for occlusion rays (ModelNode::any_order), for each kind of ray
    // its sample holds.
    out.push_back({"bvh-design", {"rays=shadow", "size=24x24", "sample=256", "occlusion=sample"}});
    out.push_back({"bvh-design", {"rays=spd", "size=24x24", "sample=256", "occlusion=sample"}});
    out.push_back({"bsp", {"traversal=recursive"}});
    out.push_back({"octree", {"traversal=recursive", "max_prims=2"}});
    return out;
}

TEST(ModelSegments, ReplayEqualsTheSampledProbeAndTheTraversalForEveryHierarchyAndQuery) {
    Scene s = builtin_scene("balls", 2);
    auto ref = build_hierarchy(s, "bvh-sah");
    const RaySet all = mixed_rays(s);
    const std::size_t n = all.rays.size();
    const RaySample smp = draw_sample_from(s, all, n, 1, *ref);
    // Exactness needs every crossing a traversal may reach: no ray may be cut at the limit.
    for (std::size_t i = 0; i < smp.size(); ++i) ASSERT_LT(smp.crossings_of(i).size(), kMaxCrossings);
    std::vector<std::uint32_t> idx(n);
    for (std::uint32_t i = 0; i < n; ++i) idx[i] = i;
    const auto variants = modelled_variants(s);
    EXPECT_GE(variants.size(), 12u);
    for (const auto& [name, set] : variants) {
        auto h = build_hierarchy(s, name, set);
        const ModelTree t = h->model_tree();
        for (Query q : {Query::Closest, Query::Any, Query::All}) {
            RayCounters total;
            for (const Ray& r : smp.rays.rays) {
                Hit hit;
                if (q == Query::Closest) h->closest(r, hit, total);
                else if (q == Query::Any) h->any(r, hit, total);
                else h->all(r, hit, total);
            }
            const CostVector m = measured_cost(total);
            ModelOptions o;
            o.query = q;
            const Prediction seg = predict_segments(t, s, smp, idx, o);
            const Prediction probe = predict_sampled(t, s, smp.rays.rays, o);
            const std::string what = name + " " + ::testing::PrintToString(set) + " query " +
                                     std::to_string(static_cast<int>(q));
            EXPECT_EQ(seg.estimator, "segments");
            EXPECT_NEAR(seg.scalar, probe.scalar, 1e-9 * probe.scalar) << what;
            auto near = [&](double pred, double meas, const char* kind) {
                EXPECT_NEAR(pred, meas, 1e-3 * meas + 1e-9) << what << " " << kind;
            };
            near(seg.cost.box, m.box, "box");
            near(seg.cost.plane, m.plane, "plane");
            near(seg.cost.hop, m.hop, "hop");
            near(seg.cost.classify, m.classify, "classify");
            near(seg.cost.prim_tests(), m.prim_tests(), "prim");
            near(seg.cost.steps, m.steps, "steps");
            // The floor quad's edges, walked where a ray meets its plane before its hit so far.
            // A search that never ends (All) finds its hits in the order its traversal visits
            // children, which need not be the nearest-first order the probe follows: there the
            // edges walked depend on that order, and only the searches that end are compared.
            EXPECT_GT(m.polygon_edges, 0.05) << what;
            if (q != Query::All) near(seg.cost.polygon_edges, m.polygon_edges, "polygon edges");
        }
    }
}

// The predictor over a hierarchy materialises only what the sample reaches, and predicts
// exactly what the whole tree predicts, for every hierarchy and query; a query that runs its
// segments past the sample's ends (every query but the sample's own) makes it fall back on the
// whole tree.
TEST(ModelSegments, TheReachedTreePredictsWhatTheWholeTreePredicts) {
    Scene s = builtin_scene("balls", 3);
    auto ref = build_hierarchy(s, "bvh-sah");
    const RaySample smp = draw_sample_from(s, mixed_rays(s), 200, 3, *ref);
    const std::vector<std::uint32_t> idx = indices(smp.size());
    std::size_t pruned_trees = 0;
    for (const auto& [name, set] : modelled_variants(s)) {
        auto h = build_hierarchy(s, name, set);
        const ModelTree whole = h->model_tree();
        for (Query q : {Query::Closest, Query::Any, Query::All}) {
            const std::string what = name + " " + ::testing::PrintToString(set) + " query " +
                                     std::to_string(static_cast<int>(q));
            SegmentsPredictor predictor(*h, s, smp, 0, SegmentsPredictor::Via::ModelTree);
            const std::size_t reached = predictor.tree().nodes.size();
            EXPECT_LE(reached, whole.nodes.size()) << what;
            // A 5D tree keeps only the paths of the sample's rays (their 5D points' cells).
            if (whole.one_path) {
                EXPECT_LT(reached, whole.nodes.size() / 2) << what;
            }
            ModelOptions o;
            o.query = q;
            const Prediction a = predictor.predict(idx, o), b = predict_segments(whole, s, smp, idx, o);
            EXPECT_DOUBLE_EQ(a.scalar, b.scalar) << what;
            EXPECT_DOUBLE_EQ(a.cost.steps, b.cost.steps) << what;
            EXPECT_DOUBLE_EQ(a.cost.prim_tests(), b.cost.prim_tests()) << what;
            if (q == Query::Closest && reached < whole.nodes.size()) ++pruned_trees;
            // A BVH's closest-hit search enters overlapping children before it finds its hit,
            // beyond the ray's end: the reached tree holds them, so no replay falls back.
            if (q == Query::Closest && whole.family == ModelFamily::Bvh) {
                EXPECT_EQ(predictor.tree().nodes.size(), reached) << what << ": fell back on the whole tree";
            }
            if (reached < whole.nodes.size() && q == Query::All && whole.cull && !whole.one_path) {
                // The closest-hit sample's ends are not those of a search that never ends.
                EXPECT_EQ(predictor.tree().nodes.size(), whole.nodes.size()) << what << ": fell back on the whole tree";
            }
        }
    }
    // The subdivisions of a 820-sphere scene have far more cells than 200 rays meet.
    EXPECT_GE(pruned_trees, 5u);
}

// The default predictor replays the sample through each hierarchy's own traversal where it
// can, instead of materialising the model tree: the same prediction (kd-trees within rounding,
// their traversal widening each plane crossing by a few ulps) for every hierarchy and query,
// and the model tree's own where the traversal is not the model's (mailboxes) or the query
// never ends (Query::All: a BVH's traversal walks a polygon's
// edges up to the nearest hit so far, its model tree to the segment's end).
TEST(ModelSegments, TheTraversalsReplayPredictsWhatTheModelTreePredicts) {
    Scene s = builtin_scene("balls", 3);
    auto ref = build_hierarchy(s, "bvh-sah");
    const RaySample smp = draw_sample_from(s, mixed_rays(s), 300, 5, *ref);
    const std::vector<std::uint32_t> idx = indices(smp.size());
    std::vector<Variant> variants = modelled_variants(s);
    variants.push_back({"grid", {"mailbox=1"}});
    variants.push_back({"kd-sah", {"mailbox=1"}});
    variants.push_back({"octree", {"mailbox=1"}});
    std::size_t replayed = 0, modelled = 0;
    for (const auto& [name, set] : variants) {
        auto h = build_hierarchy(s, name, set);
        for (Query q : {Query::Closest, Query::Any, Query::All}) {
            const std::string what = name + " " + ::testing::PrintToString(set) + " query " +
                                     std::to_string(static_cast<int>(q));
            ModelOptions o;
            o.query = q;
            SegmentsPredictor traversal(*h, s, smp), tree(*h, s, smp, 0, SegmentsPredictor::Via::ModelTree);
            const Prediction a = traversal.predict(idx, o), b = tree.predict(idx, o);
            const bool by_traversal = a.note.find("the hierarchy's traversal") != std::string::npos;
            RayCounters unused;
            EXPECT_EQ(by_traversal, q != Query::All && h->replay(smp, idx, q, unused)) << what;
            replayed += by_traversal;
            modelled += !by_traversal;
            const bool mailboxed = std::find(set.begin(), set.end(), "mailbox=1") != set.end();
            EXPECT_FALSE(by_traversal && mailboxed) << what << ": a mailboxed traversal is not the model";
            const double tolerance = name.starts_with("kd-") ? 1e-3 : 1e-6;
            EXPECT_NEAR(a.scalar, b.scalar, tolerance * b.scalar) << what;
            EXPECT_NEAR(a.cost.steps, b.cost.steps, tolerance * b.cost.steps) << what;
            EXPECT_NEAR(a.cost.box, b.cost.box, tolerance * b.cost.box + 1e-9) << what;
            EXPECT_NEAR(a.cost.prim_tests(), b.cost.prim_tests(), tolerance * b.cost.prim_tests() + 1e-9) << what;
            EXPECT_NEAR(a.cost.polygon_edges, b.cost.polygon_edges, tolerance * b.cost.polygon_edges + 1e-9) << what;
            // (The model tree's list may end in depths no ray reaches.)
            auto at = [](const std::vector<double>& v, std::size_t d) { return d < v.size() ? v[d] : 0.0; };
            ASSERT_FALSE(a.visits_by_depth.empty()) << what;
            for (std::size_t d = 0; d < std::max(a.visits_by_depth.size(), b.visits_by_depth.size()); ++d)
                EXPECT_NEAR(at(a.visits_by_depth, d), at(b.visits_by_depth, d), tolerance * at(b.visits_by_depth, d) + 1e-9)
                    << what << " depth " << d;
            EXPECT_EQ(traversal.tree_seconds() == 0, by_traversal) << what << ": a replay materialises nothing";
        }
    }
    EXPECT_GE(replayed, 2u * 12);  // the BVHs (bvh-wide too), kd-trees, grids, octrees, BSP trees and rc5d
    EXPECT_GE(modelled, 3u * 3);   // the mailboxed three; every hierarchy's All
}

// A 5D tree has few nodes and many references (each beam lists every primitive it may meet):
// whether to materialise it whole is decided by both, so a small sample copies only the beams
// its rays fall in, and predicts what the whole tree predicts.
TEST(ModelSegments, A5DTreeOfManyReferencesIsMaterialisedOnlyWhereTheSampleReaches) {
    Scene s = builtin_scene("balls", 3);
    auto ref = build_hierarchy(s, "bvh-sah");
    RaySpec spec;
    spec.size = "32x32";
    const RaySample smp = draw_sample_from(s, make_rays(s, spec), 60, 5, *ref);
    const std::vector<std::uint32_t> idx = indices(smp.size());
    auto h = build_hierarchy(s, "rc5d", {"build=eager", "max_depth=6"});
    const StructureStats st = h->structure();
    // Few enough nodes to be taken whole by nodes alone; references far beyond.
    ASSERT_LE(st.interior + st.leaves, SegmentsPredictor::kWholeItemsPerRay * smp.size() / 2);
    ASSERT_GT(st.references, 10 * SegmentsPredictor::kWholeItemsPerRay * smp.size());
    const ModelTree whole = h->model_tree();
    SegmentsPredictor predictor(*h, s, smp, 0, SegmentsPredictor::Via::ModelTree);
    ModelOptions o;
    const Prediction a = predictor.predict(idx, o), b = predict_segments(whole, s, smp, idx, o);
    EXPECT_LT(predictor.tree().prims.size(), whole.prims.size() / 4);
    EXPECT_DOUBLE_EQ(a.scalar, b.scalar);
    EXPECT_DOUBLE_EQ(a.cost.classify, b.cost.classify);
    EXPECT_DOUBLE_EQ(a.cost.prim_tests(), b.cost.prim_tests());
}

// Where a BVH is far larger than its sample, only the part the sample reaches is materialised,
// and that part holds every node a closest-hit replay enters: the overlapping children searched
// before the hit is found, beyond the ray's end. Camera rays of a scene of many small spheres.
TEST(ModelSegments, AReachedBvhHoldsWhatTheReplayEntersBeforeItsHit) {
    Scene s = builtin_scene("balls", 5);
    auto ref = build_hierarchy(s, "bvh-sah");
    RaySpec spec;
    spec.size = "64x64";
    const RaySet cam = make_rays(s, spec);
    const RaySample smp = draw_sample_from(s, cam, 60, 5, *ref);
    const std::vector<std::uint32_t> idx = indices(smp.size());
    for (const char* name : {"bvh-sah", "bvh-median", "bvh-gs", "bvh-wide", "bvh-design"}) {
        auto h = build_hierarchy(s, name);
        const ModelTree whole = h->model_tree();
        SegmentsPredictor predictor(*h, s, smp, 0, SegmentsPredictor::Via::ModelTree);
        const std::size_t reached = predictor.tree().nodes.size();
        EXPECT_LT(reached, whole.nodes.size() / 2) << name;
        ModelOptions o;
        const Prediction a = predictor.predict(idx, o), b = predict_segments(whole, s, smp, idx, o);
        EXPECT_EQ(predictor.tree().nodes.size(), reached) << name << ": fell back on the whole tree";
        EXPECT_DOUBLE_EQ(a.scalar, b.scalar) << name;
        EXPECT_DOUBLE_EQ(a.cost.box, b.cost.box) << name;
        EXPECT_DOUBLE_EQ(a.cost.prim_tests(), b.cost.prim_tests()) << name;
    }
}

// The reached tree finds which BVH nodes hold a ray's hit from the runs of leaf-ordered
// references the emitter offers (ModelSink::leaf_order), with no pass over the whole tree: each
// subtree must hold exactly one run, a leaf's being its primitives, an interior node's its
// children's side by side.
TEST(ModelTree, EveryBvhOffersItsLeafOrderAsOneRunPerSubtree) {
    struct Runs final : ModelSink {
        std::span<const std::uint32_t> refs;
        bool offered = false;
        std::uint32_t lo = 0, hi = 0;
        struct Open {
            std::uint32_t hi, left, next;
        };
        std::vector<Open> open;
        std::size_t nodes = 0, bad = 0;
        bool begin(const ModelFlags&) override { return true; }
        bool leaf_order(std::span<const std::uint32_t> r) override {
            refs = r;
            return offered = true;
        }
        void subtree(std::uint32_t l, std::uint32_t h) override { lo = l, hi = h; }
        void node(const ModelNode& m, std::span<const std::uint32_t> prims) override {
            ++nodes;
            if (nodes == 1) bad += lo != 0 || hi != refs.size();
            if (!open.empty()) {
                bad += lo != open.back().next;
                open.back().next = hi;
                --open.back().left;
            }
            if (m.leaf) {
                bad += prims.data() != refs.data() + lo || prims.size() != hi - lo;
            } else {
                open.push_back({hi, m.count, lo});
                return;
            }
            while (!open.empty() && open.back().left == 0) {
                bad += open.back().next != open.back().hi;
                open.pop_back();
            }
        }
    };
    Scene s = builtin_scene("balls", 3);
    for (const char* name : {"bvh-sah", "bvh-median", "bvh-gs", "bvh-design"}) {
        auto h = build_hierarchy(s, name);
        Runs runs;
        h->emit_model(runs);
        EXPECT_TRUE(runs.offered) << name;
        EXPECT_EQ(runs.nodes, h->structure().interior + h->structure().leaves) << name;
        EXPECT_EQ(runs.bad, 0u) << name;
        EXPECT_TRUE(runs.open.empty()) << name;
    }
}

TEST(ModelSegments, ASampleOfAnotherSceneIsRefused) {
    Scene a = builtin_scene("balls", 3), b = builtin_scene("tetra", 2);
    auto ref = build_hierarchy(a, "bvh-sah");
    const RaySample smp = draw_sample_from(a, mixed_rays(a), 300, 1, *ref);
    const std::vector<std::uint32_t> idx = indices(smp.size());
    auto h = build_hierarchy(b, "bvh-sah");
    EXPECT_THROW(predict_segments(h->model_tree(), b, smp, idx, ModelOptions{}), InputError);
    for (auto via : {SegmentsPredictor::Via::Traversal, SegmentsPredictor::Via::ModelTree}) {
        SegmentsPredictor predictor(*h, b, smp, 0, via);
        EXPECT_THROW(predictor.predict(idx, ModelOptions{}), InputError);
    }
}

// On rays the sample did not see, the prediction errs by the sample's noise only.
TEST(ModelSegments, EvaluatePredictsHeldOutCameraRays) {
    Scene s = builtin_scene("balls", 3);
    EvalOptions opt;
    opt.hierarchies = parse_hierarchy_list("bvh-sah,kd-sah,grid,octree", s.size());
    opt.estimators = {Estimator::Segments};
    opt.segments = 2000;
    RaySpec spec;
    spec.size = "160x160";
    const EvalResult r = evaluate(s, spec, opt);
    EXPECT_EQ(r.sample_rays, 2000u);
    // One camera ray a pixel: the draw took the pixels of twice the sample's rays, and the test
    // rays are every other pixel's.
    EXPECT_EQ(r.test_rays, 160u * 160u - 2u * 2000u);
    EXPECT_EQ(r.distribution_rays, 160u * 160u);  // what a prediction's time is weighed against
    EXPECT_EQ(r.split, "sample");
    ASSERT_EQ(r.rows.size(), 4u);
    for (const EvalRow& row : r.rows) {
        ASSERT_TRUE(row.headline());
        EXPECT_EQ(row.headline()->estimator, "segments");
        EXPECT_LT(std::fabs(row.error), 0.05) << row.name << " predicted " << row.headline()->scalar << " measured "
                                              << row.measured_scalar;
    }
}

}  // namespace
}  // namespace rtcost::test
