// The designed hierarchies: exact hits like every hierarchy (closest and any-hit), the same
// structure for the same seed, the SAH's tree where the sample is given no weight, a grid
// resolution no worse on the sample than the formula's, and `rtcost design`'s rows.
#include <filesystem>
#include <fstream>
#include <random>
#include <type_traits>
#include <unistd.h>

#include "../src/design/sample_reach.hpp"
#include "../src/hierarchy/bvh-design/boxes_met.hpp"
#include "../src/hierarchy/bsp/bsp.hpp"
#include "../src/design/replay.hpp"
#include "../src/hierarchy/octree/octree.hpp"
#include "rtcost/design.hpp"
#include "rtcost/evaluate.hpp"
#include "rtcost/sample.hpp"
#include "test_support.hpp"

namespace rtcost::test {
namespace {

// Small samples of small images keep the designs quick; the structure still follows the rays.
const std::vector<Variant> kDesigned = {
    {"grid-design", {"rays=spd", "size=48x48", "sample=512"}},
    {"grid-design", {"rays=shadow", "size=48x48", "sample=256", "seed=3", "mailbox=1"}},
    {"bvh-design", {"rays=spd", "size=48x48", "sample=512"}},
    {"bvh-design", {"rays=ao", "size=48x48", "sample=512", "max_prims=4", "occlusion=sample"}},
    {"bvh-design", {"rays=shadow", "size=48x48", "sample=512", "occlusion=sample"}},
    {"bvh-design", {"rays=camera", "size=48x48", "sample=256", "trust=0"}},
    {"kd-design", {"rays=spd", "size=48x48", "sample=512"}},
    {"kd-design", {"rays=shadow", "size=48x48", "sample=256", "mailbox=1", "assign=exact"}},
    {"octree-design", {"rays=spd", "size=48x48", "sample=512"}},
    {"octree-design", {"rays=diffuse", "size=48x48", "sample=256", "traversal=recursive"}},
    {"bsp-design", {"rays=spd", "size=48x48", "sample=512"}},
    {"bsp-design", {"rays=ao", "size=48x48", "sample=256", "traversal=recursive", "mailbox=1"}},
};

std::string spec_of(const std::string& name) { return name.rfind("builtin:", 0) == 0 ? name : spd_path(name); }

class DesignScene : public ::testing::TestWithParam<std::string> {};

TEST_P(DesignScene, DesignedHierarchiesMatchBruteForceExactly) {
    const std::string spec = spec_of(GetParam());
    if (spec.rfind("builtin:", 0) != 0 && !std::filesystem::exists(spec)) GTEST_SKIP() << spec << " not present";
    const Scene s = load_scene(spec);
    const std::vector<Ray> rays = hard_rays(s, 3000, 17);
    expect_variants_match_brute(s, rays, GetParam(), kDesigned);
    // Occlusion: an any-hit query hits exactly where brute force's closest query does.
    auto brute = build_hierarchy(s, "brute");
    const std::vector<Hit> want = closest_hits(*brute, rays);
    for (const auto& [name, set] : kDesigned) {
        auto h = build_hierarchy(s, name, set);
        TraceOptions o;
        o.query = Query::Any;
        const TraceResult any = trace_rays(*h, rays, o);
        std::size_t bad = 0;
        for (std::size_t i = 0; i < rays.size(); ++i) bad += any.hits[i].hit() != want[i].hit();
        EXPECT_EQ(bad, 0u) << GetParam() << " " << name << " any-hit";
    }
}

INSTANTIATE_TEST_SUITE_P(Scenes, DesignScene,
                         ::testing::Values("builtin:balls:2", "builtin:tetra:3", "balls", "gears", "lattice", "mount",
                                           "rings", "shells", "sombrero", "teapot", "tetra", "tree"),
                         [](const auto& info) {
                             std::string n = info.param;
                             for (char& c : n)
                                 if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                             return n;
                         });

void expect_same_tree(const ModelTree& a, const ModelTree& b, const std::string& what) {
    EXPECT_EQ(model_tree_differences(a, b), 0u) << what;
}

TEST(Design, SameSeedSameStructure) {
    const Scene s = builtin_scene("balls", 2);
    for (const auto& [name, set] : kDesigned) {
        auto a = build_hierarchy(s, name, set);
        auto b = build_hierarchy(s, name, set);
        expect_same_tree(a->model_tree(), b->model_tree(), name);
    }
}

TEST(Design, DesignSampleIsEvalsOwnDraw) {
    // The hierarchy's sample is the draw `eval --estimator segments` leaves out of its test rays.
    const Scene s = builtin_scene("balls", 2);
    Params p(design_param_specs(), {"rays=spd", "size=32x32", "sample=300", "seed=5"});
    const DesignInput in = draw_design_input(s, p);
    RaySpec spec;
    spec.name = "spd";
    spec.size = "32x32";
    const RaySet all = make_rays(s, spec);
    auto ref = build_hierarchy(s, "bvh-sah");
    const RaySample want = draw_sample_from(s, all, 300, 5, *ref);
    ASSERT_EQ(in.sample.size(), 300u);
    EXPECT_EQ(in.sample.t_end, want.t_end);
    for (std::size_t i = 0; i < want.size(); ++i) ASSERT_EQ(in.sample.rays.rays[i].o, want.rays.rays[i].o) << i;
}

TEST(Design, DesignsMinimiseTypicalTimeUnlessToldOtherwise) {
    const Scene s = builtin_scene("balls", 2);
    const std::vector<std::string> base = {"rays=camera", "size=16x16", "sample=64"};
    const DesignInput typical = draw_design_input(s, Params(design_param_specs(), base));
    EXPECT_TRUE(typical.costs.calibrated);
    EXPECT_EQ(typical.costs.box, UnitCosts::typical().box);
    // A quad's test, with its four edges, costs several box tests, and a step more than a box
    // test: what operation counts alone leave out.
    EXPECT_GT(typical.costs.prim[static_cast<int>(PrimKind::Polygon)] + 4 * typical.costs.polygon_edge,
              3 * typical.costs.box);
    EXPECT_GT(typical.costs.step, typical.costs.box);
    EXPECT_GT(typical.costs.cache, 0);
    std::vector<std::string> unit = base;
    unit.push_back("costs=unit");
    const DesignInput counts = draw_design_input(s, Params(design_param_specs(), unit));
    EXPECT_FALSE(counts.costs.calibrated);
    EXPECT_EQ(counts.costs.box, 1.0);
    EXPECT_EQ(counts.costs.prim[0], 1.0);
    EXPECT_EQ(counts.costs.polygon_edge, 0.0);  // the paper's counts: a polygon test is one operation
    // ops: the same counts, with each edge a polygon's test walks at the share of that test the
    // typical costs give it (gears' 144-gons then cost some 30 operations a test, a quad's 2).
    std::vector<std::string> ops = base;
    ops.push_back("costs=ops");
    const DesignInput with_edges = draw_design_input(s, Params(design_param_specs(), ops));
    EXPECT_FALSE(with_edges.costs.calibrated);
    EXPECT_EQ(with_edges.costs.box, 1.0);
    EXPECT_EQ(with_edges.costs.prim[static_cast<int>(PrimKind::Polygon)], 1.0);
    const UnitCosts t = UnitCosts::typical();
    EXPECT_DOUBLE_EQ(with_edges.costs.polygon_edge, t.polygon_edge / t.prim[static_cast<int>(PrimKind::Polygon)]);
    EXPECT_GT(with_edges.costs.polygon_edge, 0.1);
    EXPECT_LT(with_edges.costs.polygon_edge, 0.5);
    // Each family's default: time where the fitted costs describe its traversal, else counts.
    for (const auto& [name, want] : std::vector<std::pair<std::string, std::string>>{
             {"bvh-design", "typical-bvh"}, {"kd-design", "typical"}, {"grid-design", "ops"},
             {"octree-design", "ops"}, {"bsp-design", "ops"}}) {
        std::string got;
        for (const ParamSpec& p : find_hierarchy(name)->params)
            if (p.name == "costs") got = p.default_value;
        EXPECT_EQ(got, want) << name;
    }
    // A BVH's own margins: a box test carries its step, and a triangle or polygon test costs more
    // than the two box tests of a node visit, a sphere's less.
    std::vector<std::string> bvh = base;
    bvh.push_back("costs=typical-bvh");
    const UnitCosts b = draw_design_input(s, Params(design_param_specs(), bvh)).costs;
    EXPECT_TRUE(b.calibrated);
    EXPECT_EQ(b.box, UnitCosts::typical_bvh().box);
    EXPECT_EQ(b.step, 0.0);
    EXPECT_GT(b.prim[static_cast<int>(PrimKind::Polygon)], 2 * b.box);
    EXPECT_GT(b.prim[static_cast<int>(PrimKind::Triangle)], 2 * b.box);
    EXPECT_LT(b.prim[static_cast<int>(PrimKind::Sphere)], 2 * b.box);
    EXPECT_TRUE(UnitCosts::built_in("typical-bvh"));
    std::vector<std::string> missing = base;
    missing.push_back("costs=/nonexistent/costs.json");
    EXPECT_THROW(draw_design_input(s, Params(design_param_specs(), missing)), InputError);
}

TEST(Design, ACostsFileCalledLikeABuiltInTableIsRefusedWhenAskedForByThatName) {
    // costs=ops would take the built-in table and silently ignore a costs file called ops in the
    // working directory; ./ops names the file. A family's default (ops or typical) is the table
    // whatever the directory holds, and a directory of that name is no costs file.
    namespace fs = std::filesystem;
    struct InTempDir {  // the working directory is restored and the files removed, whatever fails
        fs::path dir, before;
        InTempDir() : dir(fs::temp_directory_path() / ("rtcost_test_costs_" + std::to_string(::getpid()))) {
            fs::create_directories(dir / "typical");  // a directory called like a table
            std::ofstream(dir / "ops") << R"({"unit": "ns", "box": 7.5, "prim": {"triangle": 12}})";
            before = fs::current_path();
            fs::current_path(dir);
        }
        ~InTempDir() {
            std::error_code ec;
            fs::current_path(before, ec);
            fs::remove_all(dir, ec);
        }
    } here;
    const Scene s = builtin_scene("balls", 2);
    auto input = [&](const std::string& costs) {
        std::vector<std::string> set = {"rays=camera", "size=16x16", "sample=32"};
        if (!costs.empty()) set.push_back("costs=" + costs);
        return draw_design_input(s, Params(design_param_specs(), set));
    };
    try {
        input("ops");
        ADD_FAILURE() << "costs=ops with a file called ops here was taken";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("./ops"), std::string::npos) << e.what();
    }
    const DesignInput file = input("./ops");
    EXPECT_EQ(file.costs.box, 7.5);
    EXPECT_EQ(file.costs.prim[static_cast<int>(PrimKind::Triangle)], 12);
    EXPECT_EQ(input("unit").costs.box, 1.0);  // no file called unit: the table
    // The default (typical) beside a directory called typical: the table.
    EXPECT_EQ(input("").costs.box, UnitCosts::typical().box);
    EXPECT_EQ(input("typical").costs.box, UnitCosts::typical().box);
    // grid-design's default is ops: the table, beside the file called ops.
    auto built = build_hierarchy(s, "grid-design", {"rays=camera", "size=16x16", "sample=32"});
    EXPECT_GT(built->structure().leaves, 0u);
}

TEST(Design, BvhDesignWithNoSampleWeightIsTheSahTree) {
    // trust=1e30: the sample weighs nothing, and with unit costs the split cost is the SAH's
    // with a traversal step of two box tests and a primitive test of one: bvh-sah's tree, node
    // for node.
    for (const char* scene : {"builtin:balls:2", "builtin:tetra:3", "gears", "tree"}) {
        const std::string spec = spec_of(scene);
        if (spec.rfind("builtin:", 0) != 0 && !std::filesystem::exists(spec)) continue;
        const Scene s = load_scene(spec);
        auto d = build_hierarchy(s, "bvh-design", {"rays=camera", "size=16x16", "sample=64", "trust=1e30", "max_prims=8", "costs=unit"});
        auto sah = build_hierarchy(s, "bvh-sah", {"c_trav=2"});
        expect_same_tree(d->model_tree(), sah->model_tree(), scene);
    }
}

TEST(Design, GridDesignIsNoWorseOnItsSampleThanTheFormula) {
    for (const char* scene : {"builtin:balls:2", "builtin:tetra:3", "gears", "rings"}) {
        const std::string spec = spec_of(scene);
        if (spec.rfind("builtin:", 0) != 0 && !std::filesystem::exists(spec)) continue;
        const Scene s = load_scene(spec);
        const std::vector<std::string> set{"rays=spd", "size=48x48", "sample=1024"};
        auto d = build_hierarchy(s, "grid-design", set);
        auto hetero = build_hierarchy(s, "grid", {"res=hetero"});
        Params p(design_param_specs(), set);
        const DesignInput in = draw_design_input(s, p);
        const double cd = sample_cost(d->model_tree(), s, in.sample, in.costs);
        const double ch = sample_cost(hetero->model_tree(), s, in.sample, in.costs);
        // hetero at density 1 is the search's first candidate: the choice can only be cheaper.
        EXPECT_LE(cd, ch) << scene;
    }
}

TEST(Design, KdDesignKeepsTheEmptyBonusTheModelPredictsCheaper) {
    // empty_bonus=auto designs the tree with kd-sah's 0.2 and with 0 and keeps the one the model
    // predicts cheaper on the sample: its cost is the smaller of the two fixed bonuses' (or
    // kd-sah's own tree's, when cheaper still). rings: 0 is cheaper there (a sweep's finding).
    for (const char* scene : {"builtin:balls:2", "rings"}) {
        const std::string spec = spec_of(scene);
        if (spec.rfind("builtin:", 0) != 0 && !std::filesystem::exists(spec)) continue;
        const Scene s = load_scene(spec);
        const std::vector<std::string> set{"rays=spd", "size=48x48", "sample=1024"};
        Params p(design_param_specs(), set);
        const DesignInput in = draw_design_input(s, p);
        auto cost = [&](const char* bonus) {
            std::vector<std::string> with = set;
            with.push_back(std::string("empty_bonus=") + bonus);
            return sample_cost(build_hierarchy(s, "kd-design", with)->model_tree(), s, in.sample, in.costs);
        };
        const double chosen = cost("auto"), usual = cost("0.2"), none = cost("0");
        EXPECT_LE(chosen, std::min(usual, none) * (1 + 1e-12)) << scene;
        if (std::string(scene) == "rings") {
            EXPECT_LT(none, usual * 0.95) << scene;
        }
    }
    EXPECT_THROW(build_hierarchy(builtin_scene("balls", 1), "kd-design", {"empty_bonus=2"}), InputError);
}

TEST(Design, EveryDesignIsNoWorseOnItsSampleThanItsYardstick) {
    // The split tests look one level down; where the model predicts the yardstick's termination
    // cheaper on the sample, the designed hierarchy is that tree (design/cheaper.hpp). So on its
    // own sample no design is predicted worse than its yardstick, and on balls' camera rays,
    // where the one-level test stops the BSP and the octree far too early, the design is the
    // yardstick's tree.
    for (const char* scene : {"builtin:balls:2", "builtin:tetra:3"}) {
        const Scene s = load_scene(scene);
        for (const char* rays : {"rays=camera", "rays=shadow"}) {
            const std::vector<std::string> set{rays, "size=32x32", "sample=512"};
            Params p(design_param_specs(), set);
            const DesignInput in = draw_design_input(s, p);
            for (const auto& [designed, yardstick] : std::vector<std::pair<std::string, std::string>>{
                     {"bvh-design", "bvh-sah"}, {"kd-design", "kd-sah"}, {"octree-design", "octree"}, {"bsp-design", "bsp"}}) {
                // In the costs each design minimises (its family's default: typical-bvh for bvh).
                const UnitCosts costs = designed == "bvh-design" ? UnitCosts::named("typical-bvh") : in.costs;
                const double cd = sample_cost(build_hierarchy(s, designed, set)->model_tree(), s, in.sample, costs);
                const double cy = sample_cost(build_hierarchy(s, yardstick)->model_tree(), s, in.sample, costs);
                EXPECT_LE(cd, cy * (1 + 1e-12)) << scene << " " << rays << " " << designed;
            }
        }
    }
    // There the design keeps the yardstick's tree, or one the model predicts cheaper on the
    // sample (above) that also counts no more operations on the rays the sample never saw (a
    // tree stopped far too early counts several times more).
    const Scene balls = builtin_scene("balls", 4);
    DesignOptions o;
    o.rays.name = "camera";
    o.rays.size = "128x128";
    o.families = {"octree", "bsp"};
    for (std::uint64_t seed : {1u, 2u}) {
        o.seed = seed;
        const DesignResult r = design(balls, o);
        ASSERT_EQ(r.rows.size(), 2u);
        for (const DesignRow& row : r.rows) {
            EXPECT_GT(row.yardstick_measured, 300) << row.family;
            EXPECT_LE(row.designed_measured, row.yardstick_measured * (1 + 1e-9)) << row.family << " seed " << seed;
        }
    }
}

// The octree and BSP designs compare themselves with the yardstick's tree built only where the
// sample reaches: it must predict the sample exactly as the whole tree does, and be smaller.
TEST(Design, TheYardstickBuiltWhereTheSampleReachesPredictsAsTheWholeTree) {
    for (const char* scene : {"builtin:balls:2", "builtin:tetra:4"}) {
        const Scene s = load_scene(scene);
        for (const char* rays : {"rays=camera", "rays=shadow", "rays=spd"}) {
            Params p(design_param_specs(), {rays, "size=48x48", "sample=400"});
            const DesignInput in = draw_design_input(s, p);
            auto check = [&](auto tag, int depth, int prims) {
                using H = typename decltype(tag)::type;
                subdiv::CellOptions whole;
                whole.max_depth = depth;
                whole.max_prims = prims;
                designing::SampleReach reach(in.sample, s.bounds());
                subdiv::CellOptions some = whole;
                some.reached = [&reach](const Box3& cell, int d) { return reach(cell, d); };
                const H a(s, whole), b(s, some);
                const std::string what = std::string(scene) + " " + rays + " " + std::string(a.name());
                EXPECT_FALSE(a.partial()) << what;
                EXPECT_TRUE(b.partial()) << what;
                EXPECT_LT(b.structure().leaves, a.structure().leaves) << what;
                EXPECT_EQ(sample_cost(b, s, in.sample, in.costs), sample_cost(a, s, in.sample, in.costs)) << what;
                EXPECT_EQ(sample_cost(b, s, in.sample, UnitCosts{}), sample_cost(a, s, in.sample, UnitCosts{})) << what;
                // The designs price it by its traversal: no ray enters a cell left unbuilt.
                const designing::SampleReplay replay(s, in.sample, in.costs);
                EXPECT_EQ(replay.cost(b), replay.cost(a)) << what;
            };
            check(std::type_identity<octree::Octree>{}, 8, 1);
            check(std::type_identity<bsp::Bsp>{}, 20, 2);
        }
    }
}

TEST(Design, DesignReportsEachFamilyOnDisjointRays) {
    const Scene s = builtin_scene("balls", 2);
    DesignOptions o;
    o.rays.name = "spd";
    o.rays.size = "32x32";
    o.sample = 256;
    const DesignResult r = design(s, o);
    ASSERT_EQ(r.rows.size(), design_families().size());
    EXPECT_EQ(r.sample, 256u);
    // The test rays are those of the pixels the sample's draw did not trace: it traced pixels
    // until they held twice the sample's rays, so it left out that many, plus at most the rays
    // of one pixel more.
    const RaySet all = make_rays(s, o.rays);
    const std::size_t pop = all.rays.size();
    std::size_t most = 0;
    for (std::size_t i = 0; i < pop;) {
        std::size_t j = i;
        while (j < pop && all.pixels[j] == all.pixels[i]) ++j;
        most = std::max(most, j - i);
        i = j;
    }
    EXPECT_EQ(r.test_rays, rays_outside_sample(all, 256, 1).rays.size());
    EXPECT_LE(r.test_rays, pop - 2 * 256);
    EXPECT_GT(r.test_rays, pop - 2 * 256 - most);
    for (const DesignRow& row : r.rows) {
        EXPECT_GT(row.designed_ns, 0) << row.family;
        EXPECT_GT(row.designed_measured, 0) << row.family;
        EXPECT_GT(row.yardstick_predicted, 0) << row.family;
    }
    const nlohmann::json j = to_json(r);
    ASSERT_EQ(j["results"].size(), r.rows.size());
    EXPECT_EQ(j["results"][0]["family"], "grid");
    EXPECT_EQ(j["results"][0]["designed"], "grid-design");
    EXPECT_EQ(j["results"][0]["set"][0], "rays=spd");
    EXPECT_EQ(r.rows[0].control_ns, 0);  // not asked for
    EXPECT_FALSE(j["results"][0]["ns_per_ray"].contains("control"));
}

// --control: the yardstick is timed again in a second evaluation of the three, its figures beside
// the others; the designed, yardstick and Embree rows keep their places.
TEST(Design, ControlTimesTheYardstickInASecondEvaluation) {
    const Scene s = builtin_scene("balls", 2);
    DesignOptions o;
    o.rays.name = "camera";
    o.rays.size = "24x24";
    o.sample = 128;
    o.families = {"grid", "bvh"};
    o.control = true;
    const DesignResult r = design(s, o);
    ASSERT_EQ(r.rows.size(), 2u);
    const nlohmann::json j = to_json(r);
    for (std::size_t i = 0; i < r.rows.size(); ++i) {
        const DesignRow& row = r.rows[i];
        EXPECT_GT(row.control_ns, 0) << row.family;
        EXPECT_GT(row.embree_ns, 0) << row.family;
        EXPECT_EQ(row.designed.substr(0, row.designed.find(':')), row.family + "-design");
        EXPECT_EQ(j["results"][i]["ns_per_ray"]["control"], row.control_ns);
        EXPECT_DOUBLE_EQ(j["results"][i]["control_gain"].get<double>(), 1 - row.control_ns / row.yardstick_ns);
    }
    EXPECT_EQ(r.rows[0].yardstick, "grid:res=hetero");
    EXPECT_NE(design_table(r).find("control: grid:res=hetero"), std::string::npos);
}

TEST(BvhDesign, BoxesMetManyAtATimeAsBoxEntryFindsThem) {
    // Random boxes and segments, and the hard cases: zero direction components, origins in a
    // box's face plane, flat boxes, a box touching the segment's end, segments through the
    // origin and along an axis to infinity (beside the padding's empty boxes). Counted
    // (count_met, with AVX2 where the CPU has it, and on the baseline instructions) as listed.
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(-2, 2);
    std::vector<Box3> boxes;
    for (int i = 0; i < 13; ++i) {
        Box3 b;
        b.extend(Vec3{u(rng), u(rng), u(rng)});
        b.extend(Vec3{u(rng), u(rng), u(rng)});
        if (i % 5 == 0) b.hi.y = b.lo.y;  // flat
        boxes.push_back(b);
    }
    boxes.push_back(Box3{{0, 0, 0}, {1, 1, 1}});
    bvh::BoxColumns columns;
    columns.assign(boxes);
    ASSERT_EQ(columns.padded(), 16u);
    std::vector<bvh::Segment> segments;
    std::vector<Ray> rays;
    std::vector<std::uint32_t> want_counts(columns.padded());
    std::size_t met_total = 0, tested = 0;
    for (int r = 0; r < 4000; ++r) {
        Ray ray{{u(rng), u(rng), u(rng)}, {u(rng), u(rng), u(rng)}, 0, r % 3 ? kInf : std::fabs(u(rng))};
        if (r % 7 == 0) ray.d[r % 3] = 0;
        if (r % 11 == 0) ray.d = Vec3{0, 0, r % 2 ? 1.0f : -1.0f};
        if (r % 13 == 0) ray.o.x = 1;  // in a face plane of the unit box
        if (r % 17 == 0) ray.o = Vec3{0.5f, 0.5f, -1}, ray.d = Vec3{0, 0, 1}, ray.tmax = 1;  // ends at its face
        if (r % 19 == 0) ray.o = Vec3{0, 0, -1}, ray.d = Vec3{0, 0, 1}, ray.tmax = kInf;  // through the origin
        if (r % 23 == 0) ray.d = Vec3{r % 2 ? -0.0f : 0.0f, 0, 1};  // a signed zero, to infinity
        const RayInv ri(ray);
        rays.push_back(ray);
        segments.emplace_back(ri, ray.tmin, ray.tmax);
        std::vector<char> want(boxes.size()), got(boxes.size());
        for (std::size_t j = 0; j < boxes.size(); ++j) want[j] = box_entry(boxes[j], ri, ray.tmin, ray.tmax) != kInf;
        columns.each_met(segments.back(), [&](std::size_t j) {
            ASSERT_LT(j, boxes.size());
            got[j] = 1;
        });
        ASSERT_EQ(got, want) << "ray " << r;
        for (std::size_t j = 0; j < boxes.size(); ++j) want_counts[j] += want[j];
        for (char w : want) met_total += w;
        tested += boxes.size();
    }
    // Every segment, and every third (a sparse list, as a node's).
    std::vector<std::uint32_t> all(segments.size()), thirds, want_thirds(columns.padded());
    for (std::uint32_t r = 0; r < all.size(); ++r) {
        all[r] = r;
        if (r % 3 == 0) thirds.push_back(r);
    }
    for (std::uint32_t r : thirds)
        for (std::size_t j = 0; j < boxes.size(); ++j)
            want_thirds[j] += box_entry(boxes[j], RayInv(rays[r]), rays[r].tmin, rays[r].tmax) != kInf;
    std::vector<std::uint32_t> counts(columns.padded()), baseline(columns.padded()), sparse(columns.padded());
    columns.count_met(all, segments.data(), counts.data());
    columns.count_met_baseline(all, segments.data(), baseline.data());
    columns.count_met(thirds, segments.data(), sparse.data());
    EXPECT_EQ(counts, want_counts);
    EXPECT_EQ(baseline, want_counts);
    EXPECT_EQ(sparse, want_thirds);
    // Both answers are common.
    EXPECT_GT(met_total, tested / 50);
    EXPECT_LT(met_total, tested * 9 / 10);
}

}  // namespace
}  // namespace rtcost::test
