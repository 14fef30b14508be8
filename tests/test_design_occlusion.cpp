// bvh-design's occlusion order (occlusion=sample): an order per node and direction from the sample,
// on the designed tree or on bvh-sah's, and of those and bvh-sah walked front to back the one its
// own walk of the sample prices cheapest.
#include <gtest/gtest.h>

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

}  // namespace
}  // namespace rtcost::test
