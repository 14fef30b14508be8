// The `aimed` ray distribution: incoherent rays from around the scene that nearly all hit.
#include "test_support.hpp"

namespace rtcost::test {
namespace {

TEST(AimedRays, NearlyAllHitAndStartOutsideTheScene) {
    for (const char* spec : {"balls", "tetra"}) {
        Scene s = builtin_scene(spec, 2);
        auto rays = aimed_rays(s, 5000, 3);
        ASSERT_EQ(rays.size(), 5000u);
        const Vec3 c = s.bounds().center();
        const float r = 0.5f * length(s.bounds().extent());
        for (const Ray& ray : rays) {
            EXPECT_NEAR(length(ray.d), 1.0f, 1e-5f);
            EXPECT_NEAR(length(ray.o - c), 2 * r, 1e-3f * r);  // on the sphere twice the bounding one
            EXPECT_FALSE(s.bounds().contains(ray.o));
        }
        auto brute = build_hierarchy(s, "brute");
        std::size_t hits = 0;
        for (const Hit& h : closest_hits(*brute, rays)) hits += h.hit();
        EXPECT_GT(hits, rays.size() * 99 / 100) << spec;
    }
}

TEST(AimedRays, AreDeterministicAndNamedByMakeRays) {
    Scene s = builtin_scene("balls", 1);
    auto a = aimed_rays(s, 100, 7), b = aimed_rays(s, 100, 7), c = aimed_rays(s, 100, 8);
    for (std::size_t i = 0; i < a.size(); ++i) {
        EXPECT_EQ(a[i].o, b[i].o);
        EXPECT_EQ(a[i].d, b[i].d);
    }
    EXPECT_NE(a[0].o, c[0].o);
    RaySpec spec;
    spec.name = "aimed";
    spec.count = 100;
    spec.seed = 7;
    RaySet set = make_rays(s, spec);
    ASSERT_EQ(set.rays.size(), 100u);
    EXPECT_EQ(set.rays[5].d, a[5].d);
    EXPECT_EQ(set.kinds[0], RayKind::Test);
    const auto names = distribution_names();
    EXPECT_NE(std::find(names.begin(), names.end(), "aimed"), names.end());
}

TEST(AimedRays, EmptySceneGivesNone) {
    Scene s;
    s.finalize();
    EXPECT_TRUE(aimed_rays(s, 10, 1).empty());
}

}  // namespace
}  // namespace rtcost::test
