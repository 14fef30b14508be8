// Fitting nanoseconds per operation kind to measured times (rtcost calibrate): synthetic runs
// timed by known costs, exact or with a deterministic scatter, must give the costs back, or where
// the runs cannot fix a price, a price near the others'; and the runs themselves, measured on a
// scene.
#include <cmath>

#include "rtcost/error.hpp"
#include "rtcost/evaluate.hpp"
#include "rtcost/io.hpp"
#include "rtcost/model.hpp"
#include "rtcost/trace.hpp"
#include "test_support.hpp"

namespace rtcost::test {
namespace {

/// `n` synthetic runs, `fill(i, run)` setting run i's operations (and structure), each timed
/// exactly by `truth`'s time model.
template <class Fill>
std::vector<CalibrationSample> timed_runs(const UnitCosts& truth, int n, Fill&& fill) {
    std::vector<CalibrationSample> runs(n);
    for (int i = 0; i < n; ++i) {
        runs[i].label = "run " + std::to_string(i);
        fill(i, runs[i]);
        runs[i].ns_per_ray = truth.scalar(runs[i].ops, runs[i].structure);
    }
    return runs;
}

TEST(Calibrate, RecoversKnownUnitCostsAndKeepsThemNonNegative) {
    // Synthetic runs timed by known costs: the fit must give them back.
    UnitCosts truth;
    truth.box = 3; truth.plane = 0; truth.hop = 7; truth.classify = 2; truth.per_ray = 40;
    truth.prim = {20, 55, 9, 0};
    std::vector<CalibrationSample> runs = timed_runs(truth, 12, [&](int i, CalibrationSample& s) {
        s.ops.box = 5 + 3 * i;
        s.ops.hop = (i % 3) * 4.0;
        s.ops.classify = (i % 4 == 1) ? 30.0 : 0.0;
        s.ops.prim = {1.0 + i % 5, (i % 2) * 2.0, 3.0 + (i * 7) % 4, 0};
    });
    Calibration c = calibrate(runs);
    EXPECT_NEAR(c.costs.box, 3, 1e-6);
    EXPECT_NEAR(c.costs.hop, 7, 1e-6);
    EXPECT_NEAR(c.costs.classify, 2, 1e-6);
    EXPECT_NEAR(c.costs.prim[0], 20, 1e-6);
    EXPECT_NEAR(c.costs.prim[1], 55, 1e-6);
    EXPECT_NEAR(c.costs.prim[2], 9, 1e-6);
    EXPECT_NEAR(c.costs.per_ray, 40, 1e-5);
    EXPECT_FALSE(c.fitted[1]);  // no run performs a plane compare
    EXPECT_NEAR(c.rms_relative, 0, 1e-9);
    // Times that only a negative box cost would fit: the fit stays at zero instead.
    for (auto& s : runs) s.ns_per_ray = 100 - s.ops.box + 20 * s.ops.prim[0] + 9 * s.ops.prim[2];
    Calibration n = calibrate(runs);
    EXPECT_GE(n.costs.box, 0);
    EXPECT_GT(n.rms_relative, 0);
    // Fewer runs than unknowns: an error, not a guess.
    EXPECT_THROW(calibrate(std::span(runs).first(3)), InputError);
}

TEST(Calibrate, FitsTheTimeModelsStepSimdAndCacheTerms) {
    // Runs timed by a known time model: per step, SIMD box tests and binary nodes' pairs priced
    // apart, and a cache term for structures beyond 1 MiB. The fit must give every term back.
    UnitCosts truth;
    truth.box = 3; truth.plane = 5; truth.hop = 0; truth.classify = 0; truth.per_ray = 20;
    truth.prim = {12, 30, 0, 0};
    truth.step = 6; truth.box_simd = 0.5; truth.box_pair = 1.5; truth.cache = 2; truth.cache_bytes = 1 << 20;
    std::vector<CalibrationSample> runs = timed_runs(truth, 16, [&](int i, CalibrationSample& s) {
        s.ops.box = 4 + 5 * (i % 7);
        s.ops.plane = (i % 3) * 6.0;
        s.ops.steps = 3 + (i * 5) % 11;
        s.ops.prim = {1.0 + i % 4, (i % 2) * 3.0, 0, 0};
        s.structure.box_lanes = i % 4 == 3 ? 8 : i % 4 == 1 ? 2 : 1;
        s.structure.bytes = std::uint64_t(1) << (16 + i % 9);  // 64 KiB .. 16 MiB
    });
    Calibration c = calibrate(runs, {}, 1 << 20);
    EXPECT_NEAR(c.costs.box, 3, 1e-6);
    EXPECT_NEAR(c.costs.plane, 5, 1e-6);
    EXPECT_NEAR(c.costs.step, 6, 1e-6);
    EXPECT_NEAR(c.costs.box_simd, 0.5, 1e-6);
    EXPECT_NEAR(c.costs.box_pair, 1.5, 1e-6);
    EXPECT_NEAR(c.costs.cache, 2, 1e-6);
    EXPECT_NEAR(c.costs.per_ray, 20, 1e-5);
    EXPECT_NEAR(c.rms_relative, 0, 1e-9);
    // The same runs fitted by operations alone cannot explain them.
    Calibration ops = calibrate(runs, {false, false, false, false}, 1 << 20);
    EXPECT_GT(ops.rms_relative, 0.01);
    EXPECT_EQ(ops.costs.step, 0);
    EXPECT_LT(ops.costs.box_simd, 0);  // not fitted: priced as box
    EXPECT_LT(ops.costs.box_pair, 0);
    EXPECT_FALSE(ops.fitted[ops.fitted.size() - 5]);  // step
    EXPECT_FALSE(ops.fitted.back());                  // polygon_edge
    // Every box test in pairs (binary BVHs alone): box_pair is fitted, and a box test priced
    // without its structure costs the same, not the 0 of an unexercised kind.
    for (auto& s : runs) s.structure.box_lanes = 2;
    for (auto& s : runs) s.ns_per_ray = truth.scalar(s.ops, s.structure);
    Calibration pairs = calibrate(runs, {}, 1 << 20);
    EXPECT_NEAR(pairs.costs.box_pair, 1.5, 1e-6);
    EXPECT_NEAR(pairs.costs.box, 1.5, 1e-6);
    EXPECT_FALSE(pairs.fitted[0]);
    // No SIMD structure among the runs: box_simd and box_pair stay unfitted.
    for (auto& s : runs) s.structure.box_lanes = 1;
    for (auto& s : runs) s.ns_per_ray = truth.scalar(s.ops, s.structure);
    const Calibration scalar = calibrate(runs, {}, 1 << 20);
    EXPECT_LT(scalar.costs.box_simd, 0);
    EXPECT_LT(scalar.costs.box_pair, 0);
    EXPECT_NEAR(scalar.costs.box, 3, 1e-6);
}

TEST(Calibrate, AKindTheRunsCannotTellFromAnotherIsNotPricedAtZero) {
    // Spheres only ever tested beside as many cones (as in tree.nff): the runs fix their sum, not
    // each. NNLS alone may price one of them at 0; the fit then pulls the kinds toward their mean.
    UnitCosts truth;
    truth.box = 4; truth.plane = 0; truth.hop = 0; truth.classify = 0; truth.per_ray = 10;
    truth.prim = {10, 0, 6, 20};
    std::vector<CalibrationSample> runs = timed_runs(truth, 12, [&](int i, CalibrationSample& s) {
        s.ops.box = 6 + 5 * (i % 4);
        const double paired = (i * 3) % 5;
        s.ops.prim = {1.0 + i % 3, 0, paired, paired};
    });
    TimeTerms ops_only;
    ops_only.steps = ops_only.simd = ops_only.cache = ops_only.edges = false;
    const Calibration c = calibrate(runs, ops_only);
    const double sphere = c.costs.prim[2], cone = c.costs.prim[3];
    EXPECT_GT(sphere, 1);
    EXPECT_GT(cone, 1);
    EXPECT_NEAR(sphere + cone, 26, 0.05);  // what the runs do fix
    EXPECT_NEAR(c.costs.prim[0], 10, 0.3);  // a kind the runs fix moves by a few percent at most
    EXPECT_LT(c.rms_relative, 0.01);
}

TEST(Calibrate, PricesPolygonEdgesAtTheirTimedCostAndFitsTheRest) {
    // Runs with polygons of many vertices (gears' 144-gons): their time is their tests' price plus
    // an edge price the fit is handed (timed on the machine by default). The rest comes back
    // exactly; a fit without the edges' term cannot explain the runs.
    UnitCosts truth;
    truth.box = 4; truth.plane = 0; truth.hop = 0; truth.classify = 0; truth.per_ray = 10;
    truth.prim = {15, 11, 0, 0};
    truth.polygon_edge = 1.5;
    std::vector<CalibrationSample> runs = timed_runs(truth, 12, [&](int i, CalibrationSample& s) {
        s.ops.box = 10 + 3 * (i % 5);
        s.ops.prim = {1.0 + i % 3, 2.0 + (i * 3) % 4, 0, 0};
        // Some runs walk quads' edges only, others 144-gons' too.
        s.ops.polygon_edges = 4 * s.ops.prim[1] + (i % 2) * 144.0 * (1 + i % 3);
    });
    TimeTerms edges{false, false, false, true};
    Calibration c = calibrate(runs, edges, 1 << 20, 1.5);
    EXPECT_DOUBLE_EQ(c.costs.polygon_edge, 1.5);
    EXPECT_TRUE(c.fitted.back());
    EXPECT_NEAR(c.costs.box, 4, 1e-6);
    EXPECT_NEAR(c.costs.prim[0], 15, 1e-6);
    EXPECT_NEAR(c.costs.prim[1], 11, 1e-6);
    EXPECT_NEAR(c.costs.per_ray, 10, 1e-5);
    EXPECT_NEAR(c.rms_relative, 0, 1e-9);
    // Priced back: a run's fitted time holds its edges.
    EXPECT_NEAR(c.predicted[1], runs[1].ns_per_ray, 1e-6 * runs[1].ns_per_ray);
    Calibration without = calibrate(runs, {false, false, false, false}, 1 << 20);
    EXPECT_EQ(without.costs.polygon_edge, 0);
    EXPECT_GT(without.rms_relative, 0.05);
}

TEST(Calibrate, APriceNoisyRunsFixPoorlyStaysNearTheOtherKinds) {
    // Spheres tested nearly only beside as many cones (lattice and tree), with the scatter of real
    // timings: the runs fix the sum of the two prices and little else. Unpulled, where the sum
    // falls between them moves with the noise (for these patterns, spheres anywhere from 0 to 21
    // ns). Pulled toward the kinds' mean by the runs' own scatter, each stays near the mean
    // whatever the noise, and the sum stays what the runs fix.
    UnitCosts truth;
    truth.box = 4; truth.plane = 0; truth.hop = 0; truth.classify = 0; truth.per_ray = 10;
    truth.prim = {10, 0, 8, 20};
    TimeTerms ops_only;
    ops_only.steps = ops_only.simd = ops_only.cache = ops_only.edges = false;
    for (int pattern = 0; pattern < 8; ++pattern) {
        std::vector<CalibrationSample> runs = timed_runs(truth, 16, [&](int i, CalibrationSample& s) {
            s.ops.box = 6 + 5 * (i % 4);
            const double paired = 1 + (i * 3) % 5;
            s.ops.prim = {1.0 + i % 3, 0, paired, paired + 0.25 * (i % 2)};
        });
        // A deterministic scatter of +-15%, its phase set by the pattern.
        for (int i = 0; i < 16; ++i) runs[i].ns_per_ray *= (1 + 0.15 * std::sin(12.9898 * i + 0.8 * pattern));
        const Calibration c = calibrate(runs, ops_only);
        const double sphere = c.costs.prim[2], cone = c.costs.prim[3];
        SCOPED_TRACE("pattern " + std::to_string(pattern) + ": sphere " + std::to_string(sphere) + ", cone " +
                     std::to_string(cone));
        EXPECT_NEAR(sphere + cone, 28, 2.8);
        EXPECT_GT(sphere, 10);
        EXPECT_LT(sphere, 17);
        EXPECT_GT(cone, 10);
        EXPECT_LT(cone, 17);
        EXPECT_GT(c.rms_relative, 0.05);  // the scatter is there: the fit does not hide it
    }
}

TEST(CalibrationRuns, EachCountedHierarchyCountedOnceAndTimedInRounds) {
    // Embree counts nothing and is left out; the others are counted as a counted trace counts
    // them, timed (ns per ray > 0), and the passes add up to hierarchies x (1 + repeat),
    // interleaved or one after the other.
    const Scene s = load_scene("builtin:balls:2");
    RaySpec spec;
    spec.name = "camera";
    spec.size = "16x16";
    const RaySet rays = make_rays(s, spec);
    const std::vector<HierarchyRequest> hs = parse_hierarchy_list("bvh-sah,embree,grid:res=2x2x2", s.size());
    for (bool sequential : {false, true}) {
        std::size_t passes = 0;
        const std::vector<CalibrationSample> runs =
            measure_for_calibration(s, rays, hs, 3, sequential, [&](std::size_t n) { passes += n; });
        EXPECT_EQ(passes, 3u * 4u);
        ASSERT_EQ(runs.size(), 2u);
        EXPECT_EQ(runs[0].label, "bvh-sah on " + s.name);
        EXPECT_EQ(runs[1].label, "grid:res=2x2x2 on " + s.name);
        for (std::size_t i = 0; i < runs.size(); ++i) {
            auto h = build_hierarchy(s, hs[i == 0 ? 0 : 2].name, hs[i == 0 ? 0 : 2].params);
            TraceOptions o;
            o.count = true;
            o.threads = 1;
            const CostVector want = measured_cost(trace_ray_set(*h, rays, o).counters);
            EXPECT_DOUBLE_EQ(runs[i].ops.box, want.box) << i;
            EXPECT_DOUBLE_EQ(runs[i].ops.hop, want.hop) << i;
            EXPECT_DOUBLE_EQ(runs[i].ops.prim[static_cast<int>(PrimKind::Sphere)],
                             want.prim[static_cast<int>(PrimKind::Sphere)]) << i;
            EXPECT_GT(runs[i].ns_per_ray, 0.0) << i;
            EXPECT_GT(runs[i].structure.bytes, 0u) << i;
        }
        EXPECT_GT(runs[0].ops.box, 0.0);
        EXPECT_GT(runs[1].ops.hop, 0.0);
    }
}

}  // namespace
}  // namespace rtcost::test
