// Rays through a shared vertex of tetra's triangles, from hard_rays: each meets one triangle a
// float or two before 1 and others at exactly 1. A traversal that skips a box whose entry
// distance rounds to the hit found so far (1) loses the nearer triangle inside it; the BVHs
// did, until they culled by cull_bound (math.hpp).
#include <gtest/gtest.h>

#include "rtcost/hierarchy.hpp"
#include "rtcost/scene.hpp"
#include "test_support.hpp"

namespace rtcost::test {
namespace {

std::vector<Ray> vertex_rays() {
    const float r[][6] = {
        {0x1.bdf308p+0f, 0x1.3722ccp+0f, -0x1.9f2998p-2f, -0x1.fbe61p-1f, -0x1.7722ccp+0f, -0x1.8359a0p-4f},
        {0x1.c9f8acp+0f, 0x1.b32ad0p-2f, 0x1.a06408p-1f, -0x1.09f8acp+0f, -0x1.d99568p-1f, -0x1.903204p+0f},
        {-0x1.bd15b8p-2f, 0x1.b92490p-2f, 0x1.08ef84p+0f, 0x1.bd15b8p-2f, 0x1.46db70p-2f, -0x1.91df08p-1f},
        {0x1.6c29b8p+0f, 0x1.1a5364p+0f, 0x1.2aab70p-1f, -0x1.b0a6e0p-2f, -0x1.5a5364p+0f, -0x1.aaab70p-1f},
        {-0x1.0f8f0ep+0f, 0x1.2cb58cp+0f, -0x1.0cdae6p+0f, 0x1.3e3c38p-2f, -0x1.65ac60p-3f, 0x1.336b98p-2f},
    };
    std::vector<Ray> rays;
    for (const auto& v : r) rays.push_back(Ray{{v[0], v[1], v[2]}, {v[3], v[4], v[5]}, 0.0f, kInf});
    return rays;
}

TEST(Cull, EveryHierarchyFindsTheNearestOfHitsAFloatApartAtASharedVertex) {
    const Scene s = builtin_scene("tetra", 4);
    const std::vector<Ray> rays = vertex_rays();
    auto brute = build_hierarchy(s, "brute");
    const std::vector<Hit> want = closest_hits(*brute, rays);
    for (const Hit& h : want) {
        ASSERT_TRUE(h.hit());
        EXPECT_LT(h.t, 1.0f);  // the nearest triangle is met just before the vertex
        EXPECT_GT(h.t, 0.9999997f);
    }
    for (const auto& [name, set] : registered_variants(kTestHits)) {
        if (name == "embree") continue;  // Embree's test is not watertight: another triangle at the vertex
        auto h = build_hierarchy(s, name, set);
        const std::vector<Hit> got = closest_hits(*h, rays);
        for (std::size_t i = 0; i < rays.size(); ++i) {
            EXPECT_EQ(got[i].t, want[i].t) << name << " " << ::testing::PrintToString(set) << " ray " << i;
            EXPECT_EQ(got[i].prim, want[i].prim) << name << " " << ::testing::PrintToString(set) << " ray " << i;
        }
    }
}

}  // namespace
}  // namespace rtcost::test
