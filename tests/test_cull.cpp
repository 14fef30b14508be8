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

// Rays from hard_rays through a vertex of tetra's triangles that lies in a kd-sah plane: the
// cell before the plane holds a triangle met at 0.99999994, the cell after it one met a float
// nearer. kd-trees ended the search at the first cell, its hit inside the (widened) plane
// crossing, until a leaf ended it only when cull_bound(hit) lies inside (kd::KdTree).
TEST(Cull, EveryHierarchyFindsTheNearerHitJustBeyondAKdPlane) {
    struct Case {
        int level;
        float r[6];
    };
    const Case cases[] = {
        {4, {0x1.ecc1ep+0f, -0x1.d851ecp-1f, -0x1.a2b272p+0f, -0x1.3660fp+1f, 0x1.6c28f6p+0f, 0x1.4564e4p-1f}},
        {3, {-0x1.78077p-2f, 0x1.f12898p-1f, -0x1.312a1p-3f, 0x1.bc03b8p-1f, 0x1.daedp-6f, 0x1.4c4a84p-1f}},
        {5, {0x1.403a98p+0f, 0x1.311158p-1f, -0x1.ed738p-6f, -0x1.203a98p+0f, -0x1.7888acp+0f, 0x1.ed738p-6f}},
        {5, {0x1.6e03f8p-1f, 0x1.d4e548p+0f, 0x1.a18168p+0f, -0x1.9701fcp+0f, -0x1.a9ca9p-1f, -0x1.40c0b4p+1f}},
        {5, {-0x1.e4db6p-4f, 0x1.b020cp-1f, 0x1.5ff828p-1f, 0x1.e4db6p-4f, -0x1.7020cp-1f, -0x1.8ffc14p+0f}},
        {5, {-0x1.c35d98p-2f, 0x1.82d384p+0f, -0x1.3af226p+0f, 0x1.a1aeccp-1f, -0x1.a2d384p+0f, 0x1.ebc898p-2f}},
    };
    for (const Case& c : cases) {
        const Scene s = builtin_scene("tetra", c.level);
        const std::vector<Ray> rays{Ray{{c.r[0], c.r[1], c.r[2]}, {c.r[3], c.r[4], c.r[5]}, 0.0f, kInf}};
        const Hit want = closest_hits(*build_hierarchy(s, "brute"), rays)[0];
        ASSERT_TRUE(want.hit());
        EXPECT_EQ(want.t, 0.999999881f);  // a float before 0.99999994
        for (const auto& [name, set] : registered_variants(kTestHits)) {
            if (name == "embree") continue;  // as above
            const Hit got = closest_hits(*build_hierarchy(s, name, set), rays)[0];
            EXPECT_EQ(got.t, want.t) << name << " " << ::testing::PrintToString(set) << " tetra:" << c.level;
            EXPECT_EQ(got.prim, want.prim) << name << " " << ::testing::PrintToString(set) << " tetra:" << c.level;
        }
    }
}

}  // namespace
}  // namespace rtcost::test
