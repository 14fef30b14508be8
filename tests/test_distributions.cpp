// Every registered ray distribution, read from the registry (a new one is tested here without
// touching this file): it makes rays of its kinds, deterministically for a seed, and says what
// it made; `make_rays` names them all when asked for one that does not exist; made for a ray
// sample (another tracer, the rays alone) it makes the same rays.
#include <set>

#include "rtcost/hierarchy.hpp"
#include "rtcost/rays.hpp"
#include "test_support.hpp"

namespace rtcost::test {
namespace {

RaySet make(const Scene& s, const std::string& name, std::uint64_t seed, const RayMaking& making = {}) {
    RaySpec spec;
    spec.name = name;
    spec.size = "12x10";
    spec.count = 300;
    spec.seed = seed;
    return make_rays(s, spec, making);
}

bool same_rays(const RaySet& a, const RaySet& b) {
    if (a.rays.size() != b.rays.size()) return false;
    for (std::size_t i = 0; i < a.rays.size(); ++i) {
        const Ray &x = a.rays[i], &y = b.rays[i];
        if (!(x.o == y.o) || !(x.d == y.d) || x.tmin != y.tmin || x.tmax != y.tmax) return false;
    }
    return a.kinds == b.kinds;
}

TEST(RayDistributions, EveryRegisteredOneMakesDeterministicRaysOfItsKinds) {
    const Scene s = builtin_scene("balls", 1);
    const auto dists = ray_distributions();
    ASSERT_GE(dists.size(), 8u);
    std::set<std::string> names;
    for (const RayDistributionInfo* d : dists) {
        SCOPED_TRACE(d->name);
        EXPECT_TRUE(names.insert(d->name).second) << "registered twice";
        EXPECT_FALSE(d->description.empty());
        EXPECT_EQ(find_ray_distribution(d->name), d);
        const RaySet a = make(s, d->name, 3);
        ASSERT_FALSE(a.rays.empty());
        ASSERT_EQ(a.kinds.size(), a.rays.size());
        EXPECT_NE(a.described.find(d->name), std::string::npos) << a.described;
        std::size_t summed = 0;
        for (const auto& [what, n] : a.summary)
            if (what.find("_hits") == std::string::npos) summed += n;
        EXPECT_GE(summed, a.rays.size()) << "the summary counts every ray";
        for (const Ray& r : a.rays) {
            ASSERT_TRUE(is_finite(r.o) && is_finite(r.d));
            ASSERT_GT(length(r.d), 0.0f);
            ASSERT_LE(r.tmin, r.tmax);
        }
        EXPECT_TRUE(same_rays(a, make(s, d->name, 3))) << "the same seed gives the same rays";
        if (d->seeded_draws) {
            EXPECT_FALSE(same_rays(a, make(s, d->name, 4))) << "another seed is a fresh draw";
        }
    }
    // The listing follows the registry's order.
    std::vector<std::string> in_order;
    for (const RayDistributionInfo* d : dists) in_order.push_back(d->name);
    EXPECT_EQ(distribution_names(), in_order);
    EXPECT_EQ(in_order.front(), "camera");
    EXPECT_EQ(find_ray_distribution("no-such-distribution"), nullptr);
    try {
        make(s, "no-such-distribution", 1);
        ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
        for (const std::string& n : in_order) EXPECT_NE(std::string(e.what()).find(n), std::string::npos) << n;
    }
}

// What a design sample asks for: the rays traced through a given hierarchy, without the tests
// that decide no ray. The rays must be the very same (the sample is drawn by index).
TEST(RayDistributions, RaysAloneThroughAnyTracerAreTheSameRays) {
    const Scene s = builtin_scene("balls", 1);
    auto brute = build_hierarchy(s, "brute");
    RayMaking alone;
    alone.tracer = brute.get();
    alone.rays_only = true;
    for (const RayDistributionInfo* d : ray_distributions()) {
        SCOPED_TRACE(d->name);
        const RaySet full = make(s, d->name, 3), rays = make(s, d->name, 3, alone);
        EXPECT_TRUE(same_rays(full, rays));
        EXPECT_EQ(rays.described, full.described);
    }
}

}  // namespace
}  // namespace rtcost::test
