// Multi-threaded tracing gives one thread's answers, in every hierarchy. Built a second time,
// with test_rc5d.cpp, as rtcost_thread_tests: the small target scripts/sanitize.sh builds under
// ThreadSanitizer (a build of the whole suite does not fit CI's time beside the ASan one).
#include "test_support.hpp"

namespace rtcost::test {
namespace {

TEST(Reliability, ThreadedTracingGivesOneThreadsHitsAndCountersInEveryHierarchy) {
    // Run under ThreadSanitizer by scripts/sanitize.sh: every hierarchy, the lazily grown rc5d
    // included (its beams are subdivided by whichever thread reaches them first).
    Scene s = builtin_scene("balls", 2);
    std::vector<Ray> rays = random_rays(s.bounds(), 6000, 21);
    for (const HierarchyInfo* info : hierarchies()) {
        SCOPED_TRACE(info->name);
        TraceOptions one, many;
        one.threads = 1;
        one.count = info->name != "embree";
        many = one;
        many.threads = 0;  // every core
        auto a = build_hierarchy(s, info->name), b = build_hierarchy(s, info->name);
        TraceResult r1 = trace_rays(*a, rays, one), rn = trace_rays(*b, rays, many);
        ASSERT_EQ(r1.hits.size(), rn.hits.size());
        std::size_t differ = 0;
        for (std::size_t i = 0; i < rays.size(); ++i)
            differ += r1.hits[i].prim != rn.hits[i].prim || r1.hits[i].t != rn.hits[i].t;
        EXPECT_EQ(differ, 0u);
        if (one.count) {
            EXPECT_EQ(r1.counters.prim_tests(), rn.counters.prim_tests());
            EXPECT_EQ(r1.counters.steps, rn.counters.steps);
        }
        EXPECT_LE(rn.threads, default_threads());
    }
    TraceOptions lots;
    lots.threads = 1000;
    auto h = build_hierarchy(s, "bvh-sah");
    EXPECT_EQ(trace_rays(*h, rays, lots).threads, default_threads());
}

}  // namespace
}  // namespace rtcost::test
