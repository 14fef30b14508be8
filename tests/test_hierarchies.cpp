// Every hierarchy against brute force (exactly the same t) and brute force against Embree, on
// real scenes and hard rays; plus the structural and counting invariants of the shared interface.
#include <cmath>
#include <map>
#include <numbers>
#include <optional>
#include <random>

#include "rtcost/model.hpp"
#include "test_support.hpp"

namespace rtcost::test {
namespace {

// The hierarchies checked here are the kTestHits variants each registration declares
// (registered_variants): the parameter sets that change traversal or build.

struct Reference {
    Scene scene;
    std::vector<Ray> rays;
    std::optional<std::vector<Hit>> brute_hits;
    /// Brute force's closest hits, computed on first use (the counting test needs none).
    const std::vector<Hit>& brute() {
        if (!brute_hits) brute_hits = closest_hits(*build_hierarchy(scene, "brute"), rays);
        return *brute_hits;
    }
};

// Brute force is the slow part: ctest runs each test in a process of its own, so the checks
// that need it share two tests per scene, and each scene's reference is computed once per process.
Reference& reference(const std::string& spec) {
    static std::map<std::string, Reference> cache;
    auto it = cache.find(spec);
    if (it != cache.end()) return it->second;
    Reference r{load_scene(spec), {}, {}};
    r.rays = hard_rays(r.scene, 100000, 42);
    return cache.emplace(spec, std::move(r)).first->second;
}

std::string scene_spec(const std::string& name) {
    return name.rfind("builtin:", 0) == 0 || name.find('/') != std::string::npos ? name : spd_path(name);
}

class SceneCheck : public ::testing::TestWithParam<std::string> {
protected:
    void SetUp() override {
        std::string spec = scene_spec(GetParam());
        if (!std::filesystem::exists(spec) && spec.rfind("builtin:", 0) != 0)
            GTEST_SKIP() << spec << " not present";
    }
    Reference& ref() { return reference(scene_spec(GetParam())); }
};

TEST_P(SceneCheck, BruteForceHitsSomethingAndEmbreeAgrees) {
    Reference& r = ref();
    const std::vector<Hit>& brute = r.brute();
    std::size_t hits = 0;
    for (const Hit& h : brute) hits += h.hit();
    // Every scene is hit by a real share of the test rays, and missed by some.
    EXPECT_GT(hits, r.rays.size() / 50);
    EXPECT_LT(hits, r.rays.size());

    auto embree = build_hierarchy(r.scene, "embree");
    // Random rays only: the vertex- and edge-aimed rays are where a non-watertight peer may
    // legitimately differ.
    std::size_t n = 100000;
    std::vector<Hit> got = closest_hits(*embree, std::span(r.rays).first(n));
    std::string first;
    // Embree intersects spheres in float: for hits a hair from the origin its t is off by up to
    // ~1e-5 of the scene's size in absolute terms, so that is the floor of the tolerance.
    float abs_tol = 1e-5f * length(r.scene.bounds().extent());
    std::size_t bad = count_mismatches(std::span(brute).first(n), got, 1e-4f, &first, abs_tol);
    EXPECT_EQ(bad, 0u) << "embree: " << first;
}

TEST_P(SceneCheck, EveryHierarchyMatchesBruteForceExactlyAndAnyHitAgrees) {
    Reference& r = ref();
    const std::vector<Hit>& brute = r.brute();
    for (const auto& [name, set] : registered_variants(kTestHits)) {
        auto h = build_hierarchy(r.scene, name, set);
        std::vector<Hit> got = closest_hits(*h, r.rays);
        std::string first;
        EXPECT_EQ(count_mismatches(brute, got, 0.0f, &first), 0u)
            << name << " " << ::testing::PrintToString(set) << ": " << first;
        // Any-hit queries: a hit exactly where brute force has one, and a real hit within the segment.
        TraceOptions opt;
        opt.query = Query::Any;
        TraceResult any = trace_rays(*h, r.rays, opt);
        std::size_t bad = 0;
        for (std::size_t i = 0; i < r.rays.size(); ++i) {
            bad += any.hits[i].hit() != brute[i].hit();
            if (any.hits[i].hit()) {
                float t;
                Ray ray = r.rays[i];
                bad += !r.scene.intersect(static_cast<std::uint32_t>(any.hits[i].prim), ray, t);
            }
        }
        EXPECT_EQ(bad, 0u) << name << " " << ::testing::PrintToString(set) << " (any hit)";
    }
}

TEST_P(SceneCheck, CountingDoesNotChangeHitsAndInvariantsHold) {
    Reference& r = ref();
    std::span<const Ray> rays = std::span(r.rays).first(20000);
    for (const auto& [name, set] : registered_variants(kTestHits)) {
        auto h = build_hierarchy(r.scene, name, set);
        StructureStats s = h->structure();
        const ModelFamily family = h->model_tree().family;
        if (family == ModelFamily::Bvh) {
            // Binary trees: N_V = N_IN + 1; n-ary ones (Goldsmith-Salmon): more leaves than that.
            if (name == "bvh-gs" || name == "bvh-wide") EXPECT_GE(s.leaves, s.interior + 1) << name;
            else EXPECT_EQ(s.leaves, s.interior + 1) << name;
            EXPECT_EQ(s.references, r.scene.size()) << name;  // every primitive in exactly one leaf
        } else if (family == ModelFamily::Grid) {
            EXPECT_EQ(s.interior, 1u) << name;
            EXPECT_GE(s.references, r.scene.size()) << name;  // every primitive in at least one cell
        }
        EXPECT_GT(s.bytes, 0u);
        TraceOptions opt;
        TraceResult fast = trace_rays(*h, rays, opt);
        opt.count = true;
        TraceResult counted = trace_rays(*h, rays, opt);
        std::string first;
        EXPECT_EQ(count_mismatches(fast.hits, counted.hits, 0.0f, &first), 0u) << name << ": " << first;
        for (std::size_t i = 0; i < rays.size(); ++i) EXPECT_EQ(fast.hits[i].prim, counted.hits[i].prim);
        const RayCounters& c = counted.counters;
        EXPECT_EQ(c.rays, rays.size());

        if (family == ModelFamily::Bvh) {
            EXPECT_GT(c.box, c.rays);  // the root box per ray, and more for rays that enter
            EXPECT_EQ(c.plane + c.hop + c.classify, 0u);
        } else if (family == ModelFamily::Grid) {
            EXPECT_EQ(c.box, c.rays);  // the clip to the grid box, nothing else
            EXPECT_GT(c.hop, 0u);
            EXPECT_EQ(c.plane + c.classify, 0u);
        } else if (family == ModelFamily::Rc5d) {
            EXPECT_EQ(c.box, c.rays);
            EXPECT_GT(c.classify, c.rays / 2);
            EXPECT_EQ(c.plane + c.hop, 0u);
        }
        EXPECT_LT(c.leaves, c.steps);  // a leaf is reached through interior nodes
        std::uint64_t visits = 0;
        for (auto v : c.visits) visits += v;
        EXPECT_EQ(visits, c.steps) << name;
    }
}

INSTANTIATE_TEST_SUITE_P(Spd, SceneCheck,
                         ::testing::Values("balls", "gears", "mount", "rings", "teapot", "tetra", "tree", "lattice",
                                           "shells", "sombrero"));
INSTANTIATE_TEST_SUITE_P(Builtin, SceneCheck, ::testing::Values("builtin:balls:2", "builtin:tetra:4"));
INSTANTIATE_TEST_SUITE_P(Mesh, SceneCheck,
                         ::testing::Values("/usr/share/assimp/models/OBJ/spider.obj",
                                           "/usr/share/assimp/models/PLY/Wuson.ply"),
                         [](const auto& info) { return std::filesystem::path(info.param).stem().string(); });

// Binary BVHs: N_V = N_IN + 1 exactly.
TEST(BvhStructure, BinaryTreesHaveOneMoreLeafThanInteriorNodes) {
    Scene s = builtin_scene("tetra", 4);
    for (const char* name : {"bvh-median", "bvh-sah"}) {
        auto h = build_hierarchy(s, name);
        StructureStats st = h->structure();
        EXPECT_EQ(st.leaves, st.interior + 1) << name;
        EXPECT_EQ(st.references, s.size()) << name;
    }
    // Kay-Kajiya with one object per leaf: exactly one leaf per primitive.
    auto m = build_hierarchy(s, "bvh-median", {"max_prims=1"});
    EXPECT_EQ(m->structure().leaves, s.size());
    EXPECT_EQ(m->structure().interior, s.size() - 1);
    // Median cut halves the list: depth is ceil(log2 N).
    EXPECT_EQ(m->structure().depth, 8);  // 256 triangles
}

// bvh-sah's max_prims=auto and c_trav=auto: leaves of up to 16 triangles, a step priced as four
// tests, on a mesh of 2^16 triangles or more (tested four at a time); 8 and 1 otherwise.
TEST(BvhStructure, SahLeafCostsFollowTheMeshSize) {
    auto same_tree = [](const Hierarchy& a, const Hierarchy& b) {
        const StructureStats x = a.structure(), y = b.structure();
        return x.leaves == y.leaves && x.interior == y.interior && x.depth == y.depth && x.bytes == y.bytes;
    };
    // Small triangles scattered through a cube: 2^16 of them.
    auto scattered = [](std::uint32_t n) {
        Scene s;
        std::mt19937 rng(3);
        std::uniform_real_distribution<float> u(0.0f, 1.0f);
        for (std::uint32_t i = 0; i < n; ++i) {
            const Vec3 c{u(rng), u(rng), u(rng)};
            s.add(Triangle{c, c + Vec3{0.01f * u(rng), 0.01f, 0}, c + Vec3{0, 0.01f * u(rng), 0.01f}}, 0);
        }
        s.finalize();
        return s;
    };
    Scene large = scattered(65536);
    auto automatic = build_hierarchy(large, "bvh-sah");
    auto big = build_hierarchy(large, "bvh-sah", {"max_prims=16", "c_trav=4"});
    auto usual = build_hierarchy(large, "bvh-sah", {"max_prims=8", "c_trav=1"});
    EXPECT_TRUE(same_tree(*automatic, *big));
    EXPECT_LT(automatic->structure().leaves, usual->structure().leaves * 3 / 4);
    // Same closest hits as brute force with the larger leaves.
    const std::vector<Ray> rays = random_rays(large.bounds(), 500, 5);
    std::string first;
    EXPECT_EQ(count_mismatches(closest_hits(*build_hierarchy(large, "brute"), rays), closest_hits(*automatic, rays),
                               0.0f, &first),
              0u)
        << first;
    // One primitive short of the bound, or one that is not a triangle: bvh-sah's usual costs.
    Scene smaller = scattered(65535);
    EXPECT_TRUE(same_tree(*build_hierarchy(smaller, "bvh-sah"),
                          *build_hierarchy(smaller, "bvh-sah", {"max_prims=8", "c_trav=1"})));
    large.add(Sphere{{0, 0, 0}, 0.01f}, 0);
    large.finalize();
    EXPECT_TRUE(same_tree(*build_hierarchy(large, "bvh-sah"),
                          *build_hierarchy(large, "bvh-sah", {"max_prims=8", "c_trav=1"})));
}

TEST(BvhStructure, MaxDepthZeroIsOneLeaf) {
    Scene s = builtin_scene("tetra", 3);
    for (const char* name : {"bvh-median", "bvh-sah"}) {
        auto h = build_hierarchy(s, name, {"max_depth=0"});
        StructureStats st = h->structure();
        EXPECT_EQ(st.interior, 0u) << name;
        EXPECT_EQ(st.leaves, 1u) << name;
        EXPECT_EQ(st.references, s.size()) << name;
    }
}

TEST(BvhStructure, GoldsmithSalmonRespectsFanoutAndLeafSize) {
    Scene s = builtin_scene("balls", 2);
    auto h = build_hierarchy(s, "bvh-gs", {"max_children=3", "max_prims=2"});
    ModelTree t = h->model_tree();
    ASSERT_FALSE(t.nodes.empty());
    std::size_t refs = 0;
    for (const ModelNode& n : t.nodes) {
        if (n.leaf) {
            EXPECT_LE(n.count, 2u);
            refs += n.count;
        } else {
            EXPECT_GE(n.count, 2u);
            EXPECT_LE(n.count, 3u);
        }
    }
    EXPECT_EQ(refs, s.size());
    // Every child lies inside its parent's box.
    for (const ModelNode& n : t.nodes) {
        if (n.leaf) continue;
        for (std::uint32_t k = 0; k < n.count; ++k) {
            const Box3& c = t.nodes[n.first + k].region;
            EXPECT_TRUE(n.region.contains(c.lo) && n.region.contains(c.hi));
        }
    }
}

TEST(BvhStructure, InsertionOrderChangesTheTreeButNotTheHits) {
    Scene s = builtin_scene("balls", 2);
    auto a = build_hierarchy(s, "bvh-gs");
    auto b = build_hierarchy(s, "bvh-gs", {"seed=3"});
    EXPECT_NE(a->structure().depth * 1000 + a->structure().interior, b->structure().depth * 1000 + b->structure().interior);
    auto rays = random_rays(s.bounds(), 5000, 9);
    EXPECT_EQ(count_mismatches(closest_hits(*a, rays), closest_hits(*b, rays), 0.0f), 0u);
}

TEST(BvhCounting, RayMissingTheRootBoxCostsOneBoxTest) {
    Scene s = builtin_scene("tetra", 3);
    Ray miss{{100, 100, 100}, {1, 0, 0}, 0, kInf};
    for (const char* name : {"bvh-median", "bvh-gs", "bvh-sah"}) {
        auto h = build_hierarchy(s, name);
        RayCounters c;
        Hit hit;
        h->closest(miss, hit, c);
        EXPECT_FALSE(hit.hit());
        EXPECT_EQ(c.box, 1u) << name;
        EXPECT_EQ(c.steps, 0u) << name;
        EXPECT_EQ(c.prim_tests(), 0u) << name;
    }
}

TEST(BvhCounting, UnorderedVisitsEverythingTheRayMeets) {
    // order=none visits at least as many nodes as ordered traversal, for every ray, and the same
    // hits; on a ray through the whole scene it tests strictly more.
    Scene s = builtin_scene("tetra", 4);
    auto near = build_hierarchy(s, "bvh-sah");
    auto none = build_hierarchy(s, "bvh-sah", {"order=none"});
    auto rays = random_rays(s.bounds(), 2000, 5);
    std::uint64_t more = 0;
    for (const Ray& r : rays) {
        RayCounters a, b;
        Hit ha, hb;
        near->closest(r, ha, a);
        none->closest(r, hb, b);
        EXPECT_EQ(ha.t, hb.t);
        EXPECT_LE(a.steps, b.steps);
        EXPECT_LE(a.prim_tests(), b.prim_tests());
        more += b.steps > a.steps;
    }
    EXPECT_GT(more, 100u);
}

TEST(BruteCounting, TestsEveryPrimitiveOnce) {
    Scene s = builtin_scene("balls", 1);  // 10 spheres + 1 polygon
    auto h = build_hierarchy(s, "brute");
    RayCounters c;
    Hit hit;
    h->closest(Ray{{0, 0, 5}, {0, 0, -1}, 0, kInf}, hit, c);
    EXPECT_EQ(c.prim[static_cast<int>(PrimKind::Sphere)], 10u);
    EXPECT_EQ(c.prim[static_cast<int>(PrimKind::Polygon)], 1u);
    EXPECT_EQ(c.leaves, 1u);
    EXPECT_TRUE(hit.hit());
}

// A hexagon over a parallel quad and a triangle beside them: a polygon test walks every edge of
// a polygon of more than three vertices whose plane the ray meets before its nearest hit so far.
Scene hexagon_over_quad() {
    Scene s;
    std::vector<Vec3> hex;
    for (int i = 0; i < 6; ++i) {
        const double a = i * std::numbers::pi / 3;
        hex.push_back({float(std::cos(a)), float(std::sin(a)), 0});
    }
    const std::vector<Vec3> quad{{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1}};
    const std::vector<Vec3> tri{{3, 0, 0}, {4, 0, 0}, {3, 1, 0}};
    s.add_polygon(hex, 0);
    s.add_polygon(quad, 0);
    s.add_polygon(tri, 0);
    s.finalize();
    return s;
}

TEST(PolygonEdges, CountedWhereThePolygonTestWalksThem) {
    const Scene s = hexagon_over_quad();
    ASSERT_EQ(s.size(), 3u);
    EXPECT_EQ(s.edges_walked(0), 6u);
    EXPECT_EQ(s.edges_walked(1), 4u);
    EXPECT_EQ(s.edges_walked(2), 0u);  // a triangle: the watertight test, no edge walk
    auto brute = build_hierarchy(s, "brute");
    auto edges = [&](const Hierarchy& h, const Ray& r) {
        RayCounters c;
        Hit hit;
        h.closest(r, hit, c);
        return c.polygon_edges;
    };
    // Down through both: brute force tests in id order, the hexagon first (its plane at t = 1,
    // 6 edges), then the quad, whose plane at t = 2 lies beyond that hit (none).
    const Ray down{{0.1f, 0.2f, 1}, {0, 0, -1}, 0, kInf};
    EXPECT_EQ(edges(*brute, down), 6u);
    // Up, away from both planes; and along them (no plane met): no edge walked.
    EXPECT_EQ(edges(*brute, Ray{{0.1f, 0.2f, 1}, {0, 0, 1}, 0, kInf}), 0u);
    EXPECT_EQ(edges(*brute, Ray{{-5, 0.2f, 0.5f}, {1, 0, 0}, 0, kInf}), 0u);
    // A ray that stops short of the quad's plane walks the hexagon's edges only.
    EXPECT_EQ(edges(*brute, Ray{{2, 2, 1}, {0, 0, -1}, 0, 1.5f}), 6u);
    // Every counted hierarchy tests the hexagon the ray hits (6 edges), and the quad before it
    // at most (4 more); its hit is the hexagon.
    for (const auto& [name, set] : registered_variants(kTestHits)) {
        auto h = build_hierarchy(s, name, set);
        if (!h->counted()) continue;
        const std::uint64_t e = edges(*h, down);
        EXPECT_TRUE(e == 6 || e == 10) << name << ": " << e << " edges";
    }
    // Counted per ray in the measured cost.
    RayCounters c;
    Hit hit;
    c.rays = 0;
    brute->closest(down, hit, c);
    c.rays = 1;
    EXPECT_DOUBLE_EQ(measured_cost(c).polygon_edges, 6.0);
}

TEST(Registry, UnknownHierarchyAndParametersAreClearErrors) {
    Scene s = builtin_scene("tetra", 2);
    try {
        build_hierarchy(s, "no-such-tree");
        FAIL();
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("unknown hierarchy 'no-such-tree'"), std::string::npos);
        EXPECT_NE(std::string(e.what()).find("bvh-sah"), std::string::npos);
    }
    EXPECT_THROW(build_hierarchy(s, "bvh-sah", {"max_leaf=3"}), InputError);
    EXPECT_THROW(build_hierarchy(s, "bvh-sah", {"max_prims=zero"}), InputError);
    EXPECT_THROW(build_hierarchy(s, "bvh-sah", {"max_prims=0"}), InputError);
    EXPECT_THROW(build_hierarchy(s, "bvh-sah", {"order=sideways"}), InputError);
    EXPECT_THROW(build_hierarchy(s, "bvh-sah", {"noequals"}), InputError);
    EXPECT_NO_THROW(build_hierarchy(s, "bvh-sah", {"max_prims=2", "bins=8"}));
}

}  // namespace
}  // namespace rtcost::test
