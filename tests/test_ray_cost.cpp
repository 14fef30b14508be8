// The model's cost of single rays (RayCostModel) and the predicted heat map built on it.
// Without termination the model is exact, so each ray's prediction must be its traversal's
// counts, operation by operation, in every hierarchy; with termination it is an estimate whose
// mean must stay near the measured mean.
#include <nlohmann/json.hpp>

#include "rtcost/heatmap.hpp"
#include "rtcost/model.hpp"
#include "rtcost/sample.hpp"
#include "test_support.hpp"

namespace rtcost::test {
namespace {

RaySample camera_sample(const Scene& s, std::size_t n) {
    RaySpec spec;
    spec.size = "32x32";
    auto ref = build_hierarchy(s, "bvh-sah");
    return draw_sample(s, spec, n, 3, *ref);
}

std::vector<std::uint32_t> all_of(const RaySample& sample) {
    std::vector<std::uint32_t> idx(sample.size());
    for (std::uint32_t i = 0; i < idx.size(); ++i) idx[i] = i;
    return idx;
}

TEST(RayCostModel, WithoutTerminationEachRayCostsExactlyWhatItsTraversalCounts) {
    Scene s = builtin_scene("balls", 2);
    std::vector<Ray> rays = camera_rays(s.camera, 24, 24);
    std::vector<Ray> more = random_rays(s.bounds(), 600, 5);
    rays.insert(rays.end(), more.begin(), more.end());
    const RaySample sample = camera_sample(s, 64);
    ModelOptions all;
    all.query = Query::All;
    std::size_t checked = 0;
    for (const auto& [name, set] : registered_variants(kTestSampled)) {
        auto h = build_hierarchy(s, name, set);
        ModelTree t = h->model_tree();
        if (t.one_path) continue;  // 5D classification: no per-ray model
        const RayCostModel model(std::move(t), s, sample, all_of(sample), all);
        for (std::size_t i = 0; i < rays.size(); ++i) {
            RayCounters c;
            Hit hit;
            h->all(rays[i], hit, c);
            const CostVector m = measured_cost(c);
            const CostVector p = model.predict(rays[i]);
            const std::string what = name + " " + ::testing::PrintToString(set) + " ray " + std::to_string(i);
            ASSERT_NEAR(p.box, m.box, 1e-9) << what;
            ASSERT_NEAR(p.plane, m.plane, 1e-9) << what;
            ASSERT_NEAR(p.hop, m.hop, 1e-9) << what;
            ASSERT_NEAR(p.classify, m.classify, 1e-9) << what;
            ASSERT_NEAR(p.steps, m.steps, 1e-9) << what;
            ASSERT_NEAR(p.prim_tests(), m.prim_tests(), 1e-9) << what;
        }
        ++checked;
    }
    EXPECT_GE(checked, 8u);
}

TEST(RayCostModel, WithTerminationTheMeanIsNearTheMeasuredMean) {
    // Learned from 256 of the camera rays, predicting all 64x64: the mean within 10% (the
    // per-ray walk is exact in geometry; only where the search ends is estimated).
    Scene s = builtin_scene("balls", 3);
    const RaySample sample = camera_sample(s, 256);
    const std::vector<Ray> rays = camera_rays(s.camera, 64, 64);
    for (const char* name : {"bvh-sah", "kd-sah", "grid"}) {
        auto h = build_hierarchy(s, name);
        const RayCostModel model(h->model_tree(), s, sample, all_of(sample), ModelOptions{});
        double predicted = 0, measured = 0;
        for (const Ray& r : rays) {
            RayCounters c;
            Hit hit;
            h->closest(r, hit, c);
            measured += UnitCosts{}.scalar(measured_cost(c));
            predicted += UnitCosts{}.scalar(model.predict(r));
        }
        EXPECT_NEAR(predicted, measured, 0.10 * measured) << name;
        // Termination counts: the prediction is well below what visiting everything costs.
        ModelOptions all;
        all.query = Query::All;
        const RayCostModel exhaustive(h->model_tree(), s, sample, all_of(sample), all);
        double everything = 0;
        for (const Ray& r : rays) everything += UnitCosts{}.scalar(exhaustive.predict(r));
        EXPECT_LT(predicted, 0.9 * everything) << name;
    }
    auto rc5d = build_hierarchy(s, "rc5d", {"build=eager", "max_depth=8"});
    EXPECT_THROW(RayCostModel(rc5d->model_tree(), s, sample, all_of(sample), ModelOptions{}), InputError);
}

TEST(RenderHeatmapCli, PredictedMapIsComparedWithTheMeasuredOne) {
    const std::filesystem::path out = std::filesystem::temp_directory_path() / "predicted.png";
    CliRun r = run_cli("render builtin:balls:3 -H bvh-sah --heatmap predicted --size 64x64 -o " + out.string() +
                       " --json");
    ASSERT_EQ(r.code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["units"], "operations per pixel (predicted by the model, unit costs)");
    const double measured = j["against_measured"]["measured_mean"];
    EXPECT_GT(measured, 5.0);
    EXPECT_NEAR(j["mean"].get<double>(), measured, 0.10 * measured);
    EXPECT_GT(j["against_measured"]["pixel_correlation"].get<double>(), 0.7);
    EXPECT_TRUE(std::filesystem::exists(out));
    // Whitted trees: shadow rays get the any-hit model.
    r = run_cli("render builtin:balls:2 -H kd-sah --heatmap predicted --rays spd --size 32x32 -o " + out.string() +
                " --json");
    ASSERT_EQ(r.code, 0) << r.err;
    const auto k = nlohmann::json::parse(r.out);
    EXPECT_NEAR(k["mean"].get<double>(), k["against_measured"]["measured_mean"].get<double>(),
                0.25 * k["against_measured"]["measured_mean"].get<double>());
    // A hierarchy the model cannot follow ray by ray says so.
    const std::filesystem::path never = std::filesystem::temp_directory_path() / "never-predicted.png";
    r = run_cli("render builtin:balls:2 -H rc5d --heatmap predicted --size 16x16 -o " + never.string());
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("5D ray classification has no per-ray prediction"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(never));
}

}  // namespace
}  // namespace rtcost::test
