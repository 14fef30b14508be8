// bvh-design's occlusion order (occlusion=sample): an order per node and direction from the sample,
// on the designed tree or on bvh-sah's, and of those trees with their orders or in stored order the one its
// own walk of the sample prices cheapest; and the model's estimators taking that order from the
// model tree (ModelNode::any_order), or a whole tree's stored order (OcclusionOrder::Stored).
#include <gtest/gtest.h>

#include <algorithm>

#include "../src/design/replay.hpp"
#include "../src/hierarchy/bvh-design/occlusion_order.hpp"
#include "rtcost/design.hpp"
#include "rtcost/hierarchy.hpp"
#include "rtcost/model.hpp"
#include "rtcost/sample.hpp"
#include "rtcost/trace.hpp"
#include "test_support.hpp"

namespace rtcost::test {
namespace {

// Operations per ray of `h` on the sample's rays, each traced with its own query, counted.
double ops_on_sample(const Hierarchy& h, const RaySample& smp) {
    RayCounters sum;
    for (Query q : {Query::Closest, Query::Any}) {
        std::vector<Ray> rays;
        for (std::size_t i = 0; i < smp.size(); ++i)
            if (smp.queries[i] == q) rays.push_back(smp.rays.rays[i]);
        if (rays.empty()) continue;
        TraceOptions o;
        o.query = q;
        o.count = true;
        o.threads = 1;
        const TraceResult r = trace_rays(h, rays, o);
        sum += r.counters;
    }
    return UnitCosts{}.scalar(measured_cost(sum));  // unit costs, per ray: sum.rays of them
}

// Each of the sample's rays costs, box tests and primitive tests, the same by the per-ray models
// `a` and `b`.
void expect_same_per_ray(const RayCostModel& a, const RayCostModel& b, const RaySample& smp) {
    for (std::size_t i = 0; i < smp.size(); ++i) {
        const CostVector x = a.predict(smp.rays.rays[i]), y = b.predict(smp.rays.rays[i]);
        ASSERT_NEAR(x.box, y.box, 1e-9 * (1 + y.box)) << "ray " << i;
        ASSERT_NEAR(x.prim_tests(), y.prim_tests(), 1e-9 * (1 + y.prim_tests())) << "ray " << i;
    }
}

TEST(DesignOcclusion, TheOrderChosenCountsNoMoreOnItsSampleThanFrontToBack) {
    // With unit costs the price of a walk of the sample is its operation count: the tree and order
    // chosen count no more on the sample than bvh-sah's front-to-back walk, and fewer where an
    // order bit pays.
    int fewer = 0;
    for (const char* scene : {"builtin:balls:2", "builtin:tetra:3"}) {
        const Scene s = load_scene(scene);
        for (const char* rays : {"rays=shadow", "rays=ao"}) {
            std::vector<std::string> set{rays, "size=32x32", "sample=512", "costs=unit"};
            const DesignInput in = draw_design_input(s, Params(design_param_specs(), set));
            set.push_back("occlusion=sample");
            const double designed = ops_on_sample(*build_hierarchy(s, "bvh-design", set), in.sample);
            const double sah = ops_on_sample(*build_hierarchy(s, "bvh-sah"), in.sample);
            EXPECT_LE(designed, sah * (1 + 1e-9)) << scene << " " << rays;
            fewer += designed < sah * 0.99;
            std::printf("%s %s: bvh-design %.3f, bvh-sah %.3f operations per sample ray\n", scene, rays, designed, sah);
        }
    }
    EXPECT_GE(fewer, 2);
}

// The priced order bytes (each subtree's cheapest orders for the sample's rays that enter it):
// their walk of the sample's occlusion rays, priced in the design's costs, costs no more than
// the guessed bytes' (ends per primitive), and less on balls' (on tetra's they agree). Every ray
// that meets the root gets to it, so there the subtree's optimum is the whole walk's: turning
// either of the root's bits never makes the sample cheaper (the pricing counts what the walk
// counts).
TEST(DesignOcclusion, PricedOrdersCostTheSampleNoMoreThanGuessedOnesAndTheRootsAreOptimal) {
    using Rays = designing::SampleReplay::Rays;
    int fewer = 0, dearer = 0;
    for (const char* scene : {"builtin:balls:3", "builtin:tetra:4"}) {
        const Scene s = load_scene(scene);
        for (const char* rays : {"rays=shadow", "rays=ao"}) {
            const DesignInput in = draw_design_input(s, Params(design_param_specs(), {rays, "size=32x32", "sample=600"}));
            const designing::SampleReplay replay(s, in.sample, in.costs);
            auto sah = build_hierarchy(s, "bvh-sah");
            const bvh::BvhData& d = dynamic_cast<const bvh::Bvh&>(*sah).data();
            const std::vector<std::uint8_t> guess = bvh::occlusion_bits(d, s, in.sample);
            std::vector<std::uint8_t> priced = guess;
            bvh::price_occlusion_bits(d, s, in.sample, in.costs, priced);
            auto cost = [&](const std::vector<std::uint8_t>& bits) {
                const bvh::DesignedBvh h(s, d, bits);
                return replay.time(h, replay.counters(h, Rays::Occlusion));
            };
            const double best = cost(priced), guessed = cost(guess);
            const std::string what = std::string(scene) + " " + rays;
            std::printf("%s: priced %.1f, guessed %.1f\n", what.c_str(), best, guessed);
            EXPECT_LE(best, guessed * (1 + 1e-12)) << what;
            fewer += best < guessed * (1 - 1e-3);
            ASSERT_FALSE(d.nodes[0].leaf);
            for (int sign = 0; sign < 2; ++sign) {
                std::vector<std::uint8_t> turned = priced;
                turned[0] ^= static_cast<std::uint8_t>(1u << (2 + sign));
                const double c = cost(turned);
                EXPECT_GE(c, best * (1 - 1e-12)) << what << ": the root's bit for sign " << sign;
                dearer += c > best * (1 + 1e-12);
            }
        }
    }
    EXPECT_GE(fewer, 2);
    EXPECT_GE(dearer, 2);  // the root's order matters somewhere
}

// A node's own order (ModelNode::any_order) is modelled as that order stored: a tree whose binary
// nodes all enter their second child first predicts, for every occlusion ray and for the sample,
// what the same tree with each node's two children swapped predicts when walked in stored order.
TEST(DesignOcclusion, ANodesOwnOrderIsModelledAsThatOrderStored) {
    const Scene s = load_scene("builtin:balls:3");
    RaySpec spec;
    spec.name = "shadow";
    spec.size = "32x32";
    auto ref = build_hierarchy(s, "bvh-sah");
    const ModelTree plain = ref->model_tree();
    ModelTree second = plain, swapped = plain;
    std::size_t binary = 0;
    for (std::size_t i = 0; i < plain.nodes.size(); ++i) {
        const ModelNode& m = plain.nodes[i];
        if (m.leaf || m.count != 2) continue;
        ++binary;
        second.nodes[i].any_order = kAnyOrderSet | 0b1100;  // second child first, either way
        std::swap(swapped.nodes[m.first], swapped.nodes[m.first + 1]);  // the subtrees move with them
    }
    ASSERT_GT(binary, 100u);
    swapped.cull = false;  // stored order (an any-hit query cuts nothing by distance either way)
    const RaySample smp = draw_sample(s, spec, 512, 7, *ref);
    ModelOptions any;
    any.query = Query::Any;
    const auto idx = indices(smp.size());
    const Prediction a = predict_segments(second, s, smp, idx, any), b = predict_segments(swapped, s, smp, idx, any),
                     nearest = predict_segments(plain, s, smp, idx, any);
    EXPECT_NEAR(a.scalar, b.scalar, 1e-9 * b.scalar);
    EXPECT_NEAR(a.cost.box, b.cost.box, 1e-9 * b.cost.box);
    EXPECT_NEAR(a.cost.prim_tests(), b.cost.prim_tests(), 1e-9 * b.cost.prim_tests());
    EXPECT_GT(std::fabs(a.scalar - nearest.scalar), 1e-3 * nearest.scalar);  // the order matters here
    expect_same_per_ray(RayCostModel(second, s, smp, idx, any), RayCostModel(swapped, s, smp, idx, any), smp);
}

// A tree walked in stored order by its occlusion rays (OcclusionOrder::Stored: bvh-sah's default
// any_order=stored) is modelled, for an any-hit query, as the same tree walked unordered, by every
// estimator and by the per-ray model; and that is not what the tree walked nearest first predicts.
// Traced, the ray counts what the probe of the tree says.
TEST(DesignOcclusion, AStoredOrderIsModelledAsTheUnorderedWalkOfTheSameTree) {
    const Scene s = load_scene("builtin:balls:3");
    RaySpec spec;
    spec.name = "shadow";
    spec.size = "32x32";
    auto ref = build_hierarchy(s, "bvh-sah", {"any_order=nearest"});
    auto stored_bvh = build_hierarchy(s, "bvh-sah", {"any_order=stored"});
    const ModelTree nearest = ref->model_tree();
    ModelTree stored = nearest, unordered = nearest;
    ASSERT_EQ(nearest.occlusion_order, OcclusionOrder::AsClosest);
    stored.occlusion_order = OcclusionOrder::Stored;
    unordered.cull = false;
    EXPECT_EQ(stored_bvh->model_tree().occlusion_order, OcclusionOrder::Stored);
    const RaySample smp = draw_sample(s, spec, 512, 11, *ref);
    ModelOptions any;
    any.query = Query::Any;
    const auto idx = indices(smp.size());
    const Prediction a = predict_segments(stored, s, smp, idx, any), b = predict_segments(unordered, s, smp, idx, any),
                     n = predict_segments(nearest, s, smp, idx, any);
    EXPECT_NEAR(a.scalar, b.scalar, 1e-9 * b.scalar);
    EXPECT_GT(std::fabs(a.scalar - n.scalar), 1e-3 * n.scalar);
    const Prediction g = predict_geometric(stored, s, any), gu = predict_geometric(unordered, s, any);
    EXPECT_NEAR(g.scalar, gu.scalar, 1e-9 * gu.scalar);
    const RayCostModel ra(stored, s, smp, idx, any), rn(nearest, s, smp, idx, any);
    expect_same_per_ray(ra, RayCostModel(unordered, s, smp, idx, any), smp);
    std::size_t differ = 0;
    for (const Ray& r : smp.rays.rays) {
        const double x = ra.predict(r).box, z = rn.predict(r).box;
        differ += std::fabs(x - z) > 1e-6 * (1 + z);
    }
    EXPECT_GT(differ, smp.size() / 20);
    // The probe of the stored tree with real tests is what tracing its rays counts (every ray of
    // the sample is a shadow ray, traced with its own query).
    ASSERT_EQ(std::count(smp.queries.begin(), smp.queries.end(), Query::Any), static_cast<std::ptrdiff_t>(smp.size()));
    const double per_ray = ops_on_sample(*stored_bvh, smp);
    EXPECT_NEAR(predict_sampled(stored, s, smp.rays.rays, any).scalar, per_ray, 1e-6 * per_ray);
}

// Without rays (isotropic lines, half going each way along any axis) the prediction is linear in
// the share of lines a node enters first child first: a root entered first child first by every
// line and one entered second child first by every line average to the random order of a root
// without its own, as does a root whose order turns with the direction's sign.
TEST(DesignOcclusion, TheGeometricModelTakesTheNodesOwnOrderAsTheShareOfLinesItOrders) {
    const Scene s = load_scene("builtin:balls:3");
    const ModelTree plain = build_hierarchy(s, "bvh-sah")->model_tree();
    ASSERT_TRUE(!plain.nodes[0].leaf && plain.nodes[0].count == 2);
    auto with_order = [&](std::uint8_t bits) {
        ModelTree t = plain;
        t.nodes[0].any_order = kAnyOrderSet | bits;
        return t;
    };
    ModelOptions any;
    any.query = Query::Any;
    const double none = predict_geometric(plain, s, any).scalar;
    const double first = predict_geometric(with_order(0), s, any).scalar;            // first child first
    const double second = predict_geometric(with_order(0b1100), s, any).scalar;      // second child first
    const double by_sign = predict_geometric(with_order(0b0100 | 1), s, any).scalar;  // half each way
    EXPECT_GT(std::fabs(first - second), 1e-3 * none);
    EXPECT_NEAR(first + second, 2 * none, 1e-9 * none);
    EXPECT_NEAR(by_sign, none, 1e-9 * none);
    // Closest-hit queries keep the nearest child first.
    ModelOptions closest;
    EXPECT_DOUBLE_EQ(predict_geometric(with_order(0), s, closest).scalar, predict_geometric(plain, s, closest).scalar);
}

}  // namespace
}  // namespace rtcost::test
