// Per-pixel cost heat maps: the pixels' counters sum to those of the same rays traced as a batch
// (camera rays, and the Whitted trees of the spd procedure), each pixel is its own rays, the
// colour map's ends and clipping, the legend's text, and `render --heatmap`.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <set>

#include "report_test_util.hpp"
#include "rtcost/error.hpp"
#include "rtcost/heatmap.hpp"
#include "rtcost/io.hpp"
#include "rtcost/trace.hpp"

using namespace rtcost;
using namespace rtcost::report_test;

namespace {

constexpr std::array<int, 3> kLow{68, 1, 84}, kHigh{253, 231, 37};  // viridis' ends

TEST(PixelCosts, CameraPixelsSumToTheBatchAndEachIsItsRay) {
    Scene s = load_scene("builtin:balls:2");
    for (const char* name : {"bvh-sah", "grid", "kd-sah"}) {
        auto h = build_hierarchy(s, name);
        PixelCostOptions opt;
        opt.width = 24;
        opt.height = 18;
        PixelCosts pc = pixel_costs(*h, opt);
        ASSERT_EQ(pc.pixels.size(), 24u * 18u);
        std::vector<Ray> rays = camera_rays(s.camera, 24, 18);
        TraceOptions to;
        to.count = true;
        TraceResult batch = trace_rays(*h, rays, to);
        EXPECT_EQ(pc.total, batch.counters) << name;
        std::uint64_t box = 0, steps = 0;
        for (const PixelCost& p : pc.pixels) {
            EXPECT_EQ(p.rays, 1u);
            box += p.box;
            steps += p.steps;
        }
        EXPECT_EQ(box, batch.counters.box) << name;
        EXPECT_EQ(steps, batch.counters.steps) << name;
        // One pixel alone: its camera ray traced by itself.
        const std::size_t k = 9 * 24 + 13;
        RayCounters one;
        Hit hit;
        h->closest(rays[k], hit, one);
        EXPECT_EQ(pc.pixels[k].box, one.box) << name;
        EXPECT_EQ(pc.pixels[k].hop, one.hop) << name;
        EXPECT_EQ(pc.pixels[k].prim[0] + pc.pixels[k].prim[1] + pc.pixels[k].prim[2] + pc.pixels[k].prim[3],
                  one.prim_tests())
            << name;
    }
}

TEST(PixelCosts, WhittedTreesSumToTheSpdRaysOfThePixelCentres) {
    Scene s = load_scene("builtin:balls:2");
    auto h = build_hierarchy(s, "bvh-sah");
    PixelCostOptions opt;
    opt.width = 20;
    opt.height = 16;
    opt.tree = true;
    PixelCosts pc = pixel_costs(*h, opt);
    WhittedOptions wo;
    wo.width = 20;
    wo.height = 16;
    RayTree tree = whitted_tree(*h, wo);
    RaySet set;
    set.rays = tree.rays;
    set.kinds = tree.kinds;
    TraceOptions to;
    to.count = true;
    TraceResult batch = trace_ray_set(*h, set, to, Query::Any);
    EXPECT_EQ(pc.total, batch.counters);
    std::uint64_t rays = 0;
    std::uint32_t most = 0;
    for (const PixelCost& p : pc.pixels) {
        rays += p.rays;
        most = std::max(most, p.rays);
    }
    EXPECT_EQ(rays, tree.rays.size());
    EXPECT_GT(most, 2u);  // the sphereflake reflects: some trees have more than eye and shadow rays
}

TEST(HeatValues, OpsAreUnitCostsOfEveryOperationAndTimeNeedsTiming) {
    Scene s = load_scene("builtin:balls:2");
    auto h = build_hierarchy(s, "kd-sah");
    PixelCostOptions opt;
    opt.width = opt.height = 12;
    PixelCosts pc = pixel_costs(*h, opt);
    std::vector<double> ops = heat_values(pc, HeatKind::Ops);
    double sum = 0;
    for (double v : ops) sum += v;
    const RayCounters& t = pc.total;
    EXPECT_DOUBLE_EQ(sum, static_cast<double>(t.box + t.plane + t.hop + t.classify + t.prim_tests()));
    EXPECT_GT(t.plane, 0u);
    UnitCosts ns;
    ns.box = 2;
    ns.plane = 0.5;
    ns.prim = {3, 3, 3, 3};
    ns.per_ray = 10;
    ns.calibrated = true;
    std::vector<double> timed = heat_values(pc, HeatKind::Ops, ns);
    const PixelCost& p = pc.pixels[70];
    EXPECT_DOUBLE_EQ(timed[70], 10.0 + 2.0 * p.box + 0.5 * p.plane + p.hop + p.classify +
                                    3.0 * (p.prim[0] + p.prim[1] + p.prim[2] + p.prim[3]));
    EXPECT_EQ(heat_units(HeatKind::Ops, ns), "ns per pixel (operations x calibrated costs)");
    // A structure's box tests at its own price: a binary BVH's pairs at box_pair.
    ns.box_pair = 0.25;
    PixelCosts paired = pc;
    paired.box_lanes = 2;
    EXPECT_DOUBLE_EQ(heat_values(paired, HeatKind::Ops, ns)[70], timed[70] - 1.75 * p.box);
    EXPECT_DOUBLE_EQ(heat_values(pc, HeatKind::Ops, ns)[70], timed[70]);
    EXPECT_GT(p.box, 0u);  // the kd-tree's clip to the root box
    EXPECT_EQ(pc.box_lanes, 1);
    EXPECT_EQ(pixel_costs(*build_hierarchy(s, "bvh-sah"), opt).box_lanes, 2);
    EXPECT_THROW(heat_values(pc, HeatKind::Time), InputError);
    opt.time = true;
    PixelCosts tpc = pixel_costs(*h, opt);
    std::vector<double> ns_px = heat_values(tpc, HeatKind::Time);
    double total_ns = 0;
    for (double v : ns_px) {
        EXPECT_GE(v, 0);
        total_ns += v;
    }
    EXPECT_GT(total_ns, 0);
    EXPECT_EQ(heat_kind_name(parse_heat_kind("classify")), "classify");
    EXPECT_THROW(parse_heat_kind("boxes"), InputError);
}

// The map starts at (10, 10); 2 x 1 values are enlarged to 96-pixel squares.
TEST(DrawHeatmap, ViridisEndsClippingAndLegendText) {
    HeatStyle style;
    style.title = "a title";
    style.units = "box tests per pixel";
    Image img = draw_heatmap({0.0, 10.0}, 2, 1, style);
    EXPECT_EQ(pixel(img, 10 + 40, 10 + 40), kLow);
    EXPECT_EQ(pixel(img, 10 + 96 + 40, 10 + 40), kHigh);
    style.scale_max = 20;  // the larger value is now at mid scale
    Image half = draw_heatmap({0.0, 10.0}, 2, 1, style);
    auto mid = pixel(half, 10 + 96 + 40, 10 + 40);
    EXPECT_NEAR(mid[0], 33, 1);
    EXPECT_NEAR(mid[1], 145, 1);
    EXPECT_NEAR(mid[2], 140, 1);
    style.scale_max = 99;  // log scale: 9 is half way, log(10) / log(100)
    style.log = true;
    auto logmid = pixel(draw_heatmap({0.0, 9.0}, 2, 1, style), 10 + 96 + 40, 10 + 40);
    EXPECT_NEAR(logmid[0], 33, 1);
    EXPECT_NEAR(logmid[1], 145, 1);
    EXPECT_NEAR(logmid[2], 140, 1);
    style.log = false;
    style.scale_max = 5;  // above the scale: the top colour, and counted
    Image clipped = draw_heatmap({0.0, 10.0}, 2, 1, style);
    EXPECT_EQ(pixel(clipped, 10 + 96 + 40, 10 + 40), kHigh);
    EXPECT_EQ(summarize({0.0, 10.0}, 5).clipped, 1u);
    // Text: dark pixels below the map (title, units, range) and right of the colour bar (ticks).
    auto dark = [&](const Image& im, int x0, int y0, int x1, int y1) {
        int n = 0;
        for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) {
                auto c = pixel(im, x, y);
                n += c[0] + c[1] + c[2] < 300;
            }
        return n;
    };
    EXPECT_GT(dark(img, 0, 10 + 96 + 5, img.width, img.height), 200);
    const int bar_end = 10 + 192 + 14 + 18;
    EXPECT_GT(dark(img, bar_end + 2, 0, img.width, 10 + 96), 20);
    // Wide enough for the title, whatever the map's size.
    style.title = std::string(120, 'x');
    EXPECT_GT(draw_heatmap({1.0}, 1, 1, style).width, 500);
    EXPECT_THROW(draw_heatmap({1.0, 2.0}, 3, 1, style), InputError);
}

TEST(RenderHeatmapCli, WritesTheMapAndRejectsBadKinds) {
    fs::path out = temp_dir() / "heat.png";
    CliRun r = run_cli("render builtin:balls:2 -H grid --heatmap prim --rays spd --size 30x20 --scale-max 400 -o " +
                       out.string() + " --json");
    ASSERT_EQ(r.code, 0) << r.err;
    auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["heatmap"], "prim");
    EXPECT_EQ(j["units"], "primitive tests per pixel");
    EXPECT_EQ(j["scale_max"], 400.0);
    EXPECT_GT(j["traced_rays"].get<int>(), 30 * 20);
    Image img = decode_png(slurp(out));
    EXPECT_GT(img.width, 192);  // map enlarged, legend beside it
    std::set<std::array<int, 3>> colours;
    for (int y = 10; y < 10 + 128; ++y)
        for (int x = 10; x < 10 + 192; ++x) colours.insert(pixel(img, x, y));
    EXPECT_GT(colours.size(), 10u);
    fs::path bad = temp_dir() / "never.png";
    fs::remove(bad);
    r = run_cli("render builtin:balls:2 --heatmap boxes -o " + bad.string());
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("boxes"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(bad));
    r = run_cli("render builtin:balls:2 --scale-max 5 -o " + bad.string());
    EXPECT_EQ(r.code, 2);
    EXPECT_FALSE(fs::exists(bad));
}

}  // namespace
