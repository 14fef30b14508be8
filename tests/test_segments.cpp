// The ray sample and the segments estimator: a sample belongs to the scene and the distribution
// (its file round-trips, its ends are brute force's), and replaying it through any hierarchy's
// model tree with no primitive tests gives back exactly what the sampled probe counts with real
// ones, so the estimator's only error is the sample's.
#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "rtcost/evaluate.hpp"
#include "rtcost/sample.hpp"
#include "test_support.hpp"

namespace rtcost::test {
namespace {

RaySet mixed_rays(const Scene& s) {
    RaySet set;
    set.rays = camera_rays(s.camera, 40, 40);
    std::vector<Ray> more = random_rays(s.bounds(), 2500, 31);
    set.rays.insert(set.rays.end(), more.begin(), more.end());
    set.kinds.assign(set.rays.size(), RayKind::Test);
    set.described = "camera 40x40 and random 2500";
    return set;
}

std::string temp_path(const std::string& name) {
    return (std::filesystem::temp_directory_path() / ("rtcost-test-" + std::to_string(::getpid()) + "-" + name)).string();
}

TEST(RaySample, EndsAreTheClosestHitsAndCrossingsAreOrderedAndUnique) {
    Scene s = builtin_scene("balls", 2);
    auto ref = build_hierarchy(s, "bvh-sah");
    auto brute = build_hierarchy(s, "brute");
    const RaySet all = mixed_rays(s);
    const RaySample smp = draw_sample_from(s, all, 500, 7, *ref);
    ASSERT_EQ(smp.size(), 500u);
    EXPECT_EQ(smp.population, all.rays.size());
    std::size_t hits = 0;
    for (std::size_t i = 0; i < smp.size(); ++i) {
        Hit h;
        brute->closest(smp.rays.rays[i], h);
        const auto c = smp.crossings_of(i);
        if (h.hit()) {
            ++hits;
            ASSERT_FALSE(c.empty());
            EXPECT_EQ(smp.t_end[i], h.t);
            EXPECT_EQ(static_cast<std::int32_t>(c[0].prim), h.prim);
        } else {
            EXPECT_TRUE(c.empty());
            EXPECT_EQ(smp.t_end[i], smp.rays.rays[i].tmax);
        }
        for (std::size_t k = 1; k < c.size(); ++k) {
            EXPECT_LT(c[k - 1].t, c[k].t);
            for (std::size_t j = 0; j < k; ++j) EXPECT_NE(c[j].prim, c[k].prim);
        }
    }
    EXPECT_GT(hits, 100u);
}

TEST(RaySample, SameSeedSameSampleAndTheTestRaysAreTheRest) {
    Scene s = builtin_scene("tetra", 3);
    auto ref = build_hierarchy(s, "bvh-sah");
    const RaySet all = mixed_rays(s);
    const RaySample a = draw_sample_from(s, all, 300, 5, *ref), b = draw_sample_from(s, all, 300, 5, *ref);
    const RaySample c = draw_sample_from(s, all, 300, 6, *ref);
    ASSERT_EQ(a.size(), b.size());
    bool differs = false;
    for (std::size_t i = 0; i < a.size(); ++i) {
        EXPECT_EQ(a.rays.rays[i].o, b.rays.rays[i].o);
        EXPECT_EQ(a.t_end[i], b.t_end[i]);
        differs |= !(a.rays.rays[i].o == c.rays.rays[i].o);
    }
    EXPECT_TRUE(differs) << "another seed draws other rays";
    // Sample and test rays partition the distribution.
    const RaySet rest = rays_outside_sample(all, 300, 5);
    ASSERT_EQ(rest.rays.size() + a.size(), all.rays.size());
    std::size_t in = 0, out = 0;
    for (const Ray& r : all.rays) {
        auto same = [&](const Ray& x) { return x.o == r.o && x.d == r.d; };
        in += std::any_of(a.rays.rays.begin(), a.rays.rays.end(), same);
        out += std::any_of(rest.rays.begin(), rest.rays.end(), same);
    }
    EXPECT_EQ(in, a.size());
    EXPECT_EQ(out, rest.rays.size());
}

// The sample is stratified along the distribution's order: one ray from each run of equal
// length, so camera rays cover the image evenly. Its mean then varies less from seed to seed
// than a simple random sample's would (p(1 - p) / n, finite-population corrected); here p is
// the share of pixels that see the sphereflake rather than the floor.
TEST(RaySample, OneRayPerRunOfTheDistributionAndLessVarianceThanARandomDraw) {
    Scene s = builtin_scene("balls", 3);
    auto ref = build_hierarchy(s, "bvh-sah");
    RaySet all;
    all.rays = camera_rays(s.camera, 64, 64);
    all.kinds.assign(all.rays.size(), RayKind::Eye);
    all.described = "camera 64x64";
    const std::size_t n = 128, total = all.rays.size();
    std::vector<char> hit(total);  // the ray's closest hit is a sphere
    for (std::size_t i = 0; i < total; ++i) {
        Hit h;
        ref->closest(all.rays[i], h);
        hit[i] = h.hit() && s.kind(static_cast<std::uint32_t>(h.prim)) == PrimKind::Sphere;
    }
    double p = 0;
    for (char h : hit) p += h;
    p /= double(total);
    ASSERT_GT(p, 0.2);
    ASSERT_LT(p, 0.8);
    std::vector<double> means;
    for (std::uint64_t seed = 1; seed <= 200; ++seed) {
        const RaySample smp = draw_sample_from(s, all, n, seed, *ref);
        ASSERT_EQ(smp.size(), n);
        double m = 0;
        std::size_t run = 0;
        for (std::size_t i = 0; i < n; ++i) {
            // Which ray of the distribution it is: camera rays differ by direction.
            const auto it = std::find_if(all.rays.begin() + std::ptrdiff_t(run * total / n), all.rays.end(),
                                         [&](const Ray& r) { return r.d == smp.rays.rays[i].d; });
            const std::size_t k = std::size_t(it - all.rays.begin());
            EXPECT_GE(k, i * total / n) << "ray " << i << " of seed " << seed;
            EXPECT_LT(k, (i + 1) * total / n) << "ray " << i << " of seed " << seed;
            run = i + 1;
            const auto met = smp.crossings_of(i);  // nearest first
            m += !met.empty() && s.kind(met[0].prim) == PrimKind::Sphere ? 1 : 0;
        }
        means.push_back(m / double(n));
    }
    double mean = 0, var = 0;
    for (double m : means) mean += m / double(means.size());
    for (double m : means) var += (m - mean) * (m - mean) / double(means.size() - 1);
    const double random_draw = p * (1 - p) / double(n) * double(total - n) / double(total - 1);
    EXPECT_NEAR(mean, p, 4 * std::sqrt(random_draw / double(means.size())));
    // Over 200 draws the variance is known to about 10%: a random draw would give 1.0 +- 0.1.
    EXPECT_LT(var, 0.8 * random_draw) << "stratified variance " << var << ", a random draw's " << random_draw;
}

TEST(RaySample, FileRoundTripsAndBadFilesAreRefused) {
    Scene s = builtin_scene("balls", 2);
    auto ref = build_hierarchy(s, "bvh-sah");
    const RaySample a = draw_sample_from(s, mixed_rays(s), 400, 3, *ref, Query::Closest, Query::Any);
    const std::string path = temp_path("sample.bin");
    write_sample(path, a);
    const RaySample b = read_sample(path);
    ASSERT_EQ(b.size(), a.size());
    EXPECT_EQ(b.distribution, a.distribution);
    EXPECT_EQ(b.population, a.population);
    EXPECT_EQ(b.seed, a.seed);
    EXPECT_EQ(a.scene, s.fingerprint());
    EXPECT_EQ(b.scene, a.scene);
    ASSERT_EQ(b.crossings.size(), a.crossings.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
        EXPECT_EQ(b.rays.rays[i].d, a.rays.rays[i].d);
        EXPECT_EQ(b.t_end[i], a.t_end[i]);
        EXPECT_EQ(b.queries[i], a.queries[i]);
        EXPECT_EQ(b.first[i], a.first[i]);
    }
    for (std::size_t i = 0; i < a.crossings.size(); ++i) {
        EXPECT_EQ(b.crossings[i].prim, a.crossings[i].prim);
        EXPECT_EQ(b.crossings[i].t, a.crossings[i].t);
    }
    std::string bytes;
    {
        std::ifstream in(path, std::ios::binary);
        bytes.assign(std::istreambuf_iterator<char>(in), {});
    }
    // A version-1 file (no scene fingerprint after the counts) is read, its scene unknown.
    {
        std::string v1 = bytes;
        ASSERT_EQ(v1[8], 2);
        v1[8] = 1;
        v1.erase(8 + 4 + 4 + 4 * 8, 8);
        std::ofstream(path, std::ios::binary).write(v1.data(), static_cast<std::streamsize>(v1.size()));
        const RaySample c = read_sample(path);
        EXPECT_EQ(c.scene, 0u);
        ASSERT_EQ(c.size(), a.size());
        EXPECT_EQ(c.crossings.size(), a.crossings.size());
        std::string v3 = bytes;
        v3[8] = 3;
        std::ofstream(path, std::ios::binary).write(v3.data(), static_cast<std::streamsize>(v3.size()));
        EXPECT_THROW(read_sample(path), InputError);
    }
    // Truncated, and not a sample at all.
    for (std::size_t cut : {std::size_t(4), std::size_t(40), bytes.size() - 3}) {
        std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(cut));
        EXPECT_THROW(read_sample(path), InputError) << "cut at " << cut;
    }
    std::ofstream(path, std::ios::binary) << "not a sample file at all, just text";
    EXPECT_THROW(read_sample(path), InputError);
    std::filesystem::remove(path);
}

TEST(RaySample, AFileDrawnOnAnotherSceneIsRefusedByEval) {
    // Samples of two scenes whose primitive ids overlap (a sample's ids all exist in the other
    // scene): the fingerprint, not the ids, tells them apart. The same scene built twice agrees.
    Scene balls = builtin_scene("balls", 1), tetra = builtin_scene("tetra", 2);
    ASSERT_LT(balls.size(), tetra.size());
    EXPECT_EQ(builtin_scene("balls", 1).fingerprint(), balls.fingerprint());
    EXPECT_NE(balls.fingerprint(), tetra.fingerprint());
    EXPECT_NE(builtin_scene("balls", 2).fingerprint(), balls.fingerprint());
    RaySpec spec;
    spec.name = "lines";
    spec.count = 2000;
    auto ref = build_hierarchy(balls, "bvh-sah");
    const RaySample smp = draw_sample_from(balls, make_rays(balls, spec), 64, 1, *ref);
    const std::string path = temp_path("balls.sample");
    write_sample(path, smp);
    EvalOptions opt;
    opt.hierarchies = {HierarchyRequest{"bvh-sah", {}}};
    opt.estimators = {Estimator::Segments};
    opt.sample_file = path;
    opt.repeat = 1;
    try {
        evaluate(tetra, spec, opt);
        ADD_FAILURE() << "a sample of another scene was accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("drawn on another scene"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
    EXPECT_EQ(evaluate(balls, spec, opt).rows.size(), 1u);
    std::filesystem::remove(path);
}

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
// and the model tree's own where the traversal is not the model's (mailboxes, bvh-design's
// order bytes, rc5d) or the query never ends (Query::All: a BVH's traversal walks a polygon's
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
