// The geometric estimator under termination: a visibility sample made from the scene alone
// (eye rays through the scene camera's view, rays spawned where they land as the materials
// say, shadow rays to the scene's lights), whose ends are the reference's, and predictions from
// it that rank hierarchies as measured.
#include <algorithm>
#include <cmath>

#include "rtcost/evaluate.hpp"
#include "rtcost/sample.hpp"
#include "rtcost/whitted.hpp"
#include "test_support.hpp"

namespace rtcost::test {
namespace {

TEST(VisibilitySample, EveryKindItsCountItsQueryAndTheReferencesEnds) {
    Scene s = builtin_scene("balls", 2);
    ASSERT_FALSE(s.lights.empty());
    auto ref = build_hierarchy(s, "bvh-sah");
    auto brute = build_hierarchy(s, "brute");
    const std::vector<RayKind> kinds{RayKind::Eye, RayKind::Shadow, RayKind::AO, RayKind::Diffuse};
    const RaySample v = draw_visibility_sample(s, kinds, 300, 5, *ref);
    ASSERT_EQ(v.size(), 4u * 300u);
    EXPECT_EQ(v.population, 0u);
    const Box3 b = s.bounds();
    const float ao = ao_length(s);
    std::array<std::size_t, kRayKinds> count{}, hits{};
    for (std::size_t i = 0; i < v.size(); ++i) {
        const Ray& r = v.rays.rays[i];
        const RayKind k = v.rays.kinds[i];
        ++count[static_cast<int>(k)];
        EXPECT_EQ(v.queries[i], is_occlusion(k) ? Query::Any : Query::Closest);
        if (k == RayKind::Eye) {
            EXPECT_EQ(r.o, s.camera.from) << "eye rays start at the scene's eye";
            EXPECT_GT(dot(r.d, s.camera.at - s.camera.from), 0.0f);
        } else {
            // Spawned on a surface: inside the bounds (up to the spawn offset).
            Box3 grown = b;
            grown.extend(b.lo - Vec3{1e-3f, 1e-3f, 1e-3f} * length(b.extent()));
            grown.extend(b.hi + Vec3{1e-3f, 1e-3f, 1e-3f} * length(b.extent()));
            EXPECT_TRUE(grown.contains(r.o));
        }
        if (k == RayKind::Shadow) {
            EXPECT_EQ(r.tmax, 1.0f);
            const Vec3 end = r.o + r.d;
            const bool at_light = std::any_of(s.lights.begin(), s.lights.end(),
                                              [&](const Light& l) { return length(l.position - end) < 1e-3f; });
            EXPECT_TRUE(at_light) << "shadow ray " << i << " does not end at a light";
        }
        if (k == RayKind::AO) {
            EXPECT_EQ(r.tmax, ao);
        }
        Hit h;
        brute->closest(r, h);
        hits[static_cast<int>(k)] += h.hit();
        if (h.hit()) {
            EXPECT_EQ(v.t_end[i], h.t) << i;
        } else {
            EXPECT_EQ(v.t_end[i], r.tmax) << i;
        }
    }
    for (RayKind k : kinds) EXPECT_EQ(count[static_cast<int>(k)], 300u);
    EXPECT_LT(hits[static_cast<int>(RayKind::Diffuse)], 300u);

    // A view given with another image shape (a distribution's --size) spreads the eye rays to it.
    auto widest = [&](const Camera& cam) {
        const std::vector<RayKind> eye{RayKind::Eye};
        const RaySample e = draw_visibility_sample(s, eye, 300, 5, *ref, Query::Closest, Query::Any, &cam);
        const Vec3 fwd = normalize(cam.at - cam.from), right = normalize(cross(fwd, normalize(cam.up)));
        float most = 0;
        for (const Ray& r : e.rays.rays) most = std::max(most, std::fabs(dot(r.d, right) / dot(r.d, fwd)));
        return most;
    };
    Camera square = s.camera, wide = s.camera;
    square.width = square.height = 64;
    wide.width = 256;
    wide.height = 64;
    EXPECT_GT(widest(wide), 3.5f * widest(square));

    const RaySample again = draw_visibility_sample(s, kinds, 300, 5, *ref);
    ASSERT_EQ(again.size(), v.size());
    for (std::size_t i = 0; i < v.size(); ++i) {
        EXPECT_EQ(again.rays.rays[i].d.x, v.rays.rays[i].d.x);
        EXPECT_EQ(again.t_end[i], v.t_end[i]);
    }
}

// Reflection rays start only where the material reflects, refraction rays only where it
// transmits, bent by its index; shadow rays start also where those rays land, as in the
// Whitted tree. A matte floor, a mirror ball and a glass ball, seen from above.
TEST(VisibilitySample, SecondaryRaysStartWhereTheMaterialSpawnsThem) {
    Scene s;
    s.name = "mirror-and-glass";
    s.materials = {Material{}, Material{{1, 1, 1}, 0.2f, 0.8f, 10, 0, 1}, Material{{1, 1, 1}, 0.1f, 0.1f, 10, 0.9f, 1.5f}};
    s.add(Triangle{{-5, 0, -5}, {5, 0, -5}, {-5, 0, 5}}, 0);
    s.add(Triangle{{5, 0, -5}, {5, 0, 5}, {-5, 0, 5}}, 0);
    const Sphere mirror{{-2, 1.5f, 0}, 1.5f}, glass{{2, 1.5f, 0}, 1.5f};
    s.add(mirror, 1);
    s.add(glass, 2);
    s.camera.from = {0, 12, 8};
    s.camera.at = {0, 0, 0};
    s.has_camera = true;
    s.lights = {Light{{0, 20, 0}, {1, 1, 1}}};
    s.finalize();
    auto ref = build_hierarchy(s, "bvh-sah");
    const std::vector<RayKind> kinds{RayKind::Eye, RayKind::Shadow, RayKind::Reflection, RayKind::Refraction};
    const RaySample v = draw_visibility_sample(s, kinds, 400, 3, *ref);
    const float tol = 1e-3f * length(s.bounds().extent());
    auto on = [&](const Sphere& b, Vec3 p) { return std::fabs(length(p - b.center) - b.radius) < tol; };
    std::size_t reflections = 0, refractions = 0, bent = 0, shadows = 0, shadows_in_glass = 0, eye_hits = 0;
    auto brute = build_hierarchy(s, "brute");
    for (std::size_t i = 0; i < v.size(); ++i) {
        const Ray& r = v.rays.rays[i];
        switch (v.rays.kinds[i]) {
            case RayKind::Eye: {
                EXPECT_EQ(r.o, s.camera.from);
                Hit h;
                brute->closest(r, h);
                eye_hits += h.hit();
                break;
            }
            case RayKind::Reflection:
                ++reflections;
                EXPECT_TRUE(on(mirror, r.o) || on(glass, r.o)) << "reflection ray " << i << " starts on the matte floor";
                break;
            case RayKind::Refraction: {
                ++refractions;
                EXPECT_TRUE(on(glass, r.o)) << "refraction ray " << i << " starts off the glass";
                // Entering glass of index 1.5 bends the ray to within 41.8 degrees of the inward
                // normal (cos 0.745); straight on, rays at grazing incidence would not be.
                const Vec3 inward = normalize(glass.center - r.o);
                bent += dot(normalize(r.d), inward) > 0.74f;
                break;
            }
            case RayKind::Shadow:
                ++shadows;
                // Inside the glass: where a refracted first bounce landed, as the tree spawns them.
                shadows_in_glass += length(r.o - glass.center) < glass.radius - 0.5f * spawn_offset(s);
                break;
            default: break;
        }
    }
    // The floor does not fill the view: eye rays miss as often as the pixels' rays do.
    std::size_t pixel_hits = 0;
    const std::vector<Ray> pixels = camera_rays(s.camera, 40, 40);
    for (const Ray& r : pixels) {
        Hit h;
        brute->closest(r, h);
        pixel_hits += h.hit();
    }
    const double pixel_share = pixel_hits / double(pixels.size());
    EXPECT_GT(pixel_share, 0.2);
    EXPECT_LT(pixel_share, 0.9);
    EXPECT_NEAR(eye_hits / 400.0, pixel_share, 0.08);
    EXPECT_EQ(reflections, 400u);
    EXPECT_EQ(refractions, 400u);
    EXPECT_EQ(bent, refractions);
    EXPECT_EQ(shadows, 400u);
    EXPECT_GT(shadows_in_glass, 0u);
}

// The view keeps the distribution's image shape whichever estimators run beside the geometric
// one (the sampled estimator's split of the rays once dropped it: +137% on a wide image).
TEST(GeometricEstimator, TheViewIsTheDistributionsWhateverElseRuns) {
    Scene s = builtin_scene("balls", 2);
    RaySpec spec;
    spec.name = "camera";
    spec.size = "96x24";
    auto geometric_of = [&](std::vector<Estimator> estimators) {
        EvalOptions opt;
        opt.hierarchies = parse_hierarchy_list("bvh-sah", s.size());
        opt.estimators = std::move(estimators);
        const EvalResult r = evaluate(s, spec, opt);
        for (const Prediction& p : r.rows.at(0).predictions)
            if (p.estimator == "geometric") return p.scalar;
        ADD_FAILURE() << "no geometric prediction";
        return 0.0;
    };
    EXPECT_EQ(geometric_of({Estimator::Geometric}), geometric_of({Estimator::Geometric, Estimator::Sampled}));
}

// With termination the geometric estimate comes from the visibility sample: it ranks the
// hierarchies as their counted operations do and is within a useful distance of them. The
// Poisson form it replaces predicted 4.1 operations for bvh-sah's 21 and 20 for bsp's 227 on
// balls' shadow rays, and ranked them with rho 0.84.
TEST(GeometricEstimator, WithTerminationItLearnsFromTheScenesVisibility) {
    Scene s = builtin_scene("balls", 3);
    EvalOptions opt;
    opt.hierarchies = parse_hierarchy_list("bvh-sah,bvh-median,kd-sah,kd-median,grid,octree,bsp", s.size());
    opt.estimators = {Estimator::Geometric};
    RaySpec spec;
    spec.name = "shadow";
    spec.size = "96x96";
    const EvalResult r = evaluate(s, spec, opt);
    EXPECT_GT(r.visibility_rays, 0u);
    std::vector<double> predicted, measured;
    for (const EvalRow& row : r.rows) {
        ASSERT_TRUE(row.headline());
        EXPECT_EQ(row.headline()->estimator, "geometric");
        EXPECT_NE(row.headline()->note.find("visibility"), std::string::npos) << row.headline()->note;
        EXPECT_LT(std::fabs(row.error), 0.1) << row.name << " predicted " << row.headline()->scalar << " measured "
                                             << row.measured_scalar;
        predicted.push_back(row.headline()->scalar);
        measured.push_back(row.measured_scalar);
    }
    EXPECT_GE(rank_correlation(predicted, measured), 0.9);
}

// Without termination the estimate stays the Cauchy-Crofton one, exact in expectation for lines.
TEST(GeometricEstimator, WithoutTerminationNoVisibilitySampleIsDrawn) {
    Scene s = builtin_scene("balls", 2);
    EvalOptions opt;
    opt.hierarchies = parse_hierarchy_list("bvh-sah", s.size());
    opt.estimators = {Estimator::Geometric};
    opt.query = Query::All;
    RaySpec spec;
    spec.name = "lines";
    spec.count = 2000;
    const EvalResult r = evaluate(s, spec, opt);
    EXPECT_EQ(r.visibility_rays, 0u);
    ASSERT_EQ(r.rows.size(), 1u);
    EXPECT_EQ(r.rows[0].headline()->note.find("visibility"), std::string::npos);
}

}  // namespace
}  // namespace rtcost::test
