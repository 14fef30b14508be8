// Arvo and Kirk's 5D ray classification (`rc5d`): exact structure of a constructed scene, the
// beam test, lazy against eager (hits and counters), the memory cap, and the counters of a
// classification path. (Exact hits against brute force: test_rc5d_hits.cpp.)
#include <unistd.h>

#include "rc5d_test_util.hpp"
#include "rtcost/error.hpp"

namespace rtcost::test {
namespace {

// --- structure -------------------------------------------------------------------------------

TEST(Rc5dStructure, TwoSpheresExactBeams) {
    // max_prims 1, max_depth 1: every cube holds both spheres (origins span the whole box), so
    // every cube is split once, on x at 5.
    //   +x: x in [-1,5] sees A and B; x in [5,11] sees only B (A lies behind every origin).
    //   -x: x in [-1,5] sees only A; x in [5,11] sees B and A.
    //   +-y, +-z: x in [-1,5] sees only A (from x <= 5 a ray with |dx| <= |dy| gets at most
    //   2 further in x inside the 2 of y: 7 < 9), x in [5,11] only B.
    Scene s = two_spheres();
    auto eager = build_hierarchy(s, "rc5d", {"max_prims=1", "max_depth=1", "build=eager"});
    StructureStats st = eager->structure();
    EXPECT_EQ(st.interior, 7u);  // the cube selection and six cubes
    EXPECT_EQ(st.leaves, 12u);
    EXPECT_EQ(st.empty_leaves, 0u);
    EXPECT_EQ(st.references, 14u);  // 3 + 3 + 4 * 2
    EXPECT_EQ(st.depth, 2);
    EXPECT_EQ(st.bytes, as_rc5d(*eager).held_bytes());
    // Tables: padded boxes (24 B) and six start values (4 B) per primitive; 18 nodes; 14 refs.
    EXPECT_EQ(st.bytes, 2u * 24u + 2u * 6u * 4u + 18u * sizeof(rc5d::Node) + 14u * 4u);

    ModelTree t = eager->model_tree();
    EXPECT_EQ(t.family, ModelFamily::Rc5d);
    ASSERT_EQ(t.nodes.size(), 19u);  // root, 6 cubes, 12 beams
    EXPECT_EQ(t.nodes[0].count, 6u);
    EXPECT_EQ(t.nodes[0].classify, 3.0f);
    using V = std::vector<std::uint32_t>;
    auto beam = [&](int cube, int side) {
        const ModelNode& c = t.nodes[1 + cube];
        EXPECT_FALSE(c.leaf);
        EXPECT_EQ(c.classify, 1.0f);
        const ModelNode& l = t.nodes[c.first + side];
        EXPECT_TRUE(l.leaf);
        EXPECT_EQ(l.depth, 2);
        // The region is the beam's origin box: the low or high half in x.
        EXPECT_EQ(l.region.lo.x, side ? 5.0f : -1.0f);
        EXPECT_EQ(l.region.hi.x, side ? 11.0f : 5.0f);
        return V(t.prims.begin() + l.first, t.prims.begin() + l.first + l.count);
    };
    EXPECT_EQ(beam(0, 0), (V{0, 1}));  // +x, sorted by start along +x
    EXPECT_EQ(beam(0, 1), (V{1}));
    EXPECT_EQ(beam(1, 0), (V{0}));     // -x
    EXPECT_EQ(beam(1, 1), (V{1, 0}));  // sorted by start along -x: B first
    for (int cube = 2; cube < 6; ++cube) {
        EXPECT_EQ(beam(cube, 0), (V{0})) << cube;
        EXPECT_EQ(beam(cube, 1), (V{1})) << cube;
    }
}

TEST(Rc5dStructure, LazyBuildGrowsAsRaysArriveUpToTheEagerTree) {
    Scene s = two_spheres();
    auto lazy = build_hierarchy(s, "rc5d", {"max_prims=1", "max_depth=1"});
    StructureStats before = lazy->structure();
    EXPECT_EQ(before.interior, 1u);
    EXPECT_EQ(before.leaves, 6u);  // six pending cubes
    EXPECT_EQ(before.references, 12u);
    EXPECT_EQ(before.depth, 1);
    // One ray into +x expands that cube only.
    Hit hit;
    lazy->closest(Ray{{-5, 0, 0}, {1, 0, 0}}, hit);
    EXPECT_EQ(hit.prim, 0);
    StructureStats one = lazy->structure();
    EXPECT_EQ(one.interior, 2u);
    EXPECT_EQ(one.leaves, 7u);
    EXPECT_EQ(one.references, 10u + 3u);
    EXPECT_EQ(one.bytes, as_rc5d(*lazy).held_bytes());
    // A ray into every cube: the eager tree.
    for (Vec3 d : {Vec3{-1, 0, 0}, Vec3{0, 1, 0}, Vec3{0, -1, 0}, Vec3{0, 0, 1}, Vec3{0, 0, -1}}) {
        Hit h;
        lazy->closest(Ray{{5, 0, 0}, d}, h);
    }
    auto eager = build_hierarchy(s, "rc5d", {"max_prims=1", "max_depth=1", "build=eager"});
    StructureStats a = lazy->structure(), b = eager->structure();
    EXPECT_EQ(a.interior, b.interior);
    EXPECT_EQ(a.leaves, b.leaves);
    EXPECT_EQ(a.references, b.references);
    EXPECT_EQ(a.bytes, b.bytes);
}

TEST(Rc5dStructure, MaxDepthZeroIsOneBeamPerCubeWithEveryPrimitive) {
    // The origin box of a cube is the whole scene box, so every primitive lies in front of some
    // origin of every cube.
    Scene s = builtin_scene("tetra", 3);
    for (const char* build : {"build=lazy", "build=eager"}) {
        auto h = build_hierarchy(s, "rc5d", {"max_depth=0", build});
        StructureStats st = h->structure();
        EXPECT_EQ(st.interior, 1u);
        EXPECT_EQ(st.leaves, 6u);
        EXPECT_EQ(st.references, 6 * s.size());
        EXPECT_EQ(st.depth, 1);
        ModelTree t = h->model_tree();
        ASSERT_EQ(t.nodes.size(), 7u);
        for (int c = 1; c <= 6; ++c) {
            EXPECT_TRUE(t.nodes[c].leaf);
            EXPECT_EQ(t.nodes[c].count, s.size());
        }
        // Tracing does not change it.
        closest_hits(*h, hard_rays(s, 2000, 3));
        EXPECT_EQ(h->structure().leaves, 6u);
    }
}

TEST(Rc5dStructure, ModelTreeIsConsistent) {
    Scene s = builtin_scene("balls", 2);
    auto h = build_hierarchy(s, "rc5d", {"build=eager", "max_depth=8", "max_prims=4"});
    ModelTree t = h->model_tree();
    StructureStats st = h->structure();
    std::uint64_t leaves = 0, interior = 0, refs = 0;
    for (std::size_t i = 0; i < t.nodes.size(); ++i) {
        const ModelNode& m = t.nodes[i];
        if (m.leaf) {
            ++leaves;
            refs += m.count;
            EXPECT_EQ(m.classify, 0.0f);
            // Candidates in ascending start along the cube's direction.
            continue;
        }
        ++interior;
        EXPECT_EQ(m.axis, -1);
        for (std::uint32_t k = 0; k < m.count; ++k) {
            const ModelNode& c = t.nodes[m.first + k];
            EXPECT_EQ(c.depth, m.depth + 1);
            EXPECT_TRUE(m.region.contains(c.region.lo) && m.region.contains(c.region.hi));
        }
    }
    EXPECT_EQ(leaves, st.leaves);
    EXPECT_EQ(interior, st.interior);
    EXPECT_EQ(refs, st.references);
    EXPECT_EQ(refs, t.prims.size());
}

// --- the beam test ---------------------------------------------------------------------------

TEST(Rc5dBeam, IntervalTestIsExactOnConstructedCases) {
    // Cube +x, origins in [0,1]^3, directions u = dy/dx in [0, 0.5], v = dz/dx in [-0.1, 0.1].
    rc5d::Cell c{{0, 0, 0, 0, -0.1f}, {1, 1, 1, 0.5f, 0.1f}};
    const int px = Rc5d::cube_index(0, false), nx = Rc5d::cube_index(0, true);
    // At x in [10, 11] (h in [9, 11]) y reaches up to 1 + 0.5 * 11 = 6.5.
    EXPECT_TRUE(Rc5d::beam_meets(c, px, Box3{{10, 6, 0}, {11, 7, 1}}, 0));
    EXPECT_FALSE(Rc5d::beam_meets(c, px, Box3{{10, 6.6f, 0}, {11, 7, 1}}, 0));
    // y never goes below the origins' 0.
    EXPECT_FALSE(Rc5d::beam_meets(c, px, Box3{{10, -2, 0}, {11, -0.1f, 1}}, 0));
    // z spreads to [-1.1, 2.1] at h = 11, but needs the same h as y: y in [6, 7] needs
    // h >= 10, z >= 2.05 needs h >= 10.5; both fine at h = 11.
    EXPECT_TRUE(Rc5d::beam_meets(c, px, Box3{{10, 6, 2.05f}, {11, 7, 3}}, 0));
    // A box behind every origin, and the same box for the opposite cube.
    EXPECT_FALSE(Rc5d::beam_meets(c, px, Box3{{-3, 0, 0}, {-2, 1, 1}}, 0));
    EXPECT_TRUE(Rc5d::beam_meets(c, nx, Box3{{-3, 0, 0}, {-2, 1, 1}}, 0));
    // A box around the origins is met at h = 0 whatever the directions.
    EXPECT_TRUE(Rc5d::beam_meets(c, px, Box3{{0.5f, 0.5f, 0.5f}, {0.6f, 0.6f, 0.6f}}, 0));
    // A box just beyond the reach is met once the padding covers the gap.
    EXPECT_FALSE(Rc5d::beam_meets(c, px, Box3{{10, 6.501f, 0}, {11, 7, 1}}, 0));
    EXPECT_TRUE(Rc5d::beam_meets(c, px, Box3{{10, 6.501f, 0}, {11, 7, 1}}, 0.001));
}

// --- lazy and eager, memory cap --------------------------------------------------------------

TEST(Rc5dBuild, LazyAndEagerGiveIdenticalHitsAndCounters) {
    Scene s = builtin_scene("balls", 2);
    auto rays = all_test_rays(s, 6000, 61);
    const std::vector<std::string> common = {"max_depth=12", "max_prims=4"};
    auto with = [&](const char* build) {
        std::vector<std::string> set = common;
        set.push_back(build);
        return build_hierarchy(s, "rc5d", set);
    };
    auto lazy = with("build=lazy");
    auto eager = with("build=eager");
    // Ray by ray, one thread.
    std::size_t bad = 0;
    for (const Ray& r : rays) {
        RayCounters a, b;
        Hit ha, hb;
        lazy->closest(r, ha, a);
        eager->closest(r, hb, b);
        bad += !(a == b) || ha.t != hb.t || ha.prim != hb.prim;
    }
    EXPECT_EQ(bad, 0u);
    // A fresh lazy build traced on many threads: the same sums, and the same tree as the
    // single-threaded lazy build over the same rays (expansion never depends on the ray).
    auto lazy_mt = with("build=lazy");
    TraceOptions opt;
    opt.count = true;
    opt.threads = 4;
    TraceResult a = trace_rays(*lazy_mt, rays, opt);
    TraceResult b = trace_rays(*eager, rays, opt);
    EXPECT_TRUE(a.counters == b.counters);
    for (std::size_t i = 0; i < rays.size(); ++i) EXPECT_EQ(a.hits[i].t, b.hits[i].t);
    StructureStats s1 = lazy->structure(), s2 = lazy_mt->structure(), se = eager->structure();
    EXPECT_EQ(s1.interior, s2.interior);
    EXPECT_EQ(s1.leaves, s2.leaves);
    EXPECT_EQ(s1.references, s2.references);
    EXPECT_EQ(s1.bytes, s2.bytes);
    EXPECT_LE(s1.interior, se.interior);
    EXPECT_GT(s1.interior, 1u);
}

TEST(Rc5dBuild, MemoryCapStopsSubdivisionNeverCorrectness) {
    Scene s = builtin_scene("tetra", 4);
    auto rays = all_test_rays(s, 6000, 71);
    auto want = closest_hits(*build_hierarchy(s, "brute"), rays);
    auto full = build_hierarchy(s, "rc5d", {"build=eager", "max_depth=15"});
    const StructureStats f = full->structure();
    // A 1-byte cap: nothing is subdivided (the tables and cube lists are always built).
    for (const char* build : {"build=lazy", "build=eager"}) {
        auto h = build_hierarchy(s, "rc5d", {build, "max_depth=15", "max_bytes=1"});
        std::string first;
        EXPECT_EQ(count_mismatches(want, closest_hits(*h, rays), 0.0f, &first), 0u) << build << ": " << first;
        StructureStats st = h->structure();
        EXPECT_EQ(st.interior, 1u) << build;
        EXPECT_EQ(st.leaves, 6u) << build;
    }
    // A cap between the cube lists and the full tree: held below the cap, fewer nodes.
    const std::uint64_t base = as_rc5d(*build_hierarchy(s, "rc5d", {"max_bytes=1"})).held_bytes();
    const std::uint64_t cap = base + (f.bytes - base) / 4;
    for (const char* build : {"build=lazy", "build=eager"}) {
        auto h = build_hierarchy(s, "rc5d", {build, "max_depth=15", "max_bytes=" + std::to_string(cap)});
        std::string first;
        EXPECT_EQ(count_mismatches(want, closest_hits(*h, rays), 0.0f, &first), 0u) << build << ": " << first;
        StructureStats st = h->structure();
        EXPECT_LE(st.bytes, cap) << build;
        EXPECT_EQ(st.bytes, as_rc5d(*h).held_bytes()) << build;
        EXPECT_GT(st.interior, 1u) << build;
        EXPECT_LT(st.interior, f.interior) << build;
    }
}

TEST(Rc5dBuild, BadParametersAreClearErrors) {
    Scene s = two_spheres();
    for (const char* bad : {"build=sometimes", "max_depth=61", "max_depth=-1", "max_prims=-1", "max_bytes=-5",
                            "max_bytes=lots", "mailbox=1"})
        EXPECT_THROW(build_hierarchy(s, "rc5d", {bad}), InputError) << bad;
    auto h = build_hierarchy(s, "rc5d");
    EXPECT_EQ(as_rc5d(*h).options().max_prims, 8);
    EXPECT_EQ(as_rc5d(*h).options().max_depth, 30);
    EXPECT_TRUE(as_rc5d(*h).options().lazy);
    EXPECT_EQ(as_rc5d(*h).options().max_bytes, std::uint64_t{1} << 30);
    EXPECT_EQ(as_rc5d(*h).options().asked_max_bytes, 0u);
}

// A memory cap beyond the machine's memory would bound nothing (the build would run out of
// memory first): it is lowered to half the physical memory, which the limits name if reached.
TEST(Rc5dBuild, ACapBeyondTheMachinesMemoryIsLowered) {
    const std::uint64_t half = static_cast<std::uint64_t>(::sysconf(_SC_PHYS_PAGES)) *
                               static_cast<std::uint64_t>(::sysconf(_SC_PAGESIZE)) / 2;
    ASSERT_GT(half, 0u);
    ASSERT_LT(half, std::uint64_t{1} << 36) << "a machine of more than 128 GiB: the test's cap is not beyond it";
    auto h = build_hierarchy(two_spheres(), "rc5d", {"max_bytes=68719476736"});
    EXPECT_EQ(as_rc5d(*h).options().max_bytes, half);
    EXPECT_EQ(as_rc5d(*h).options().asked_max_bytes, std::uint64_t{1} << 36);
}

TEST(Rc5dBuild, EmptyAndFlatScenes) {
    Scene empty;
    empty.finalize();
    auto h = build_hierarchy(empty, "rc5d");
    RayCounters c;
    Hit hit;
    h->closest(Ray{{0, 0, -5}, {0, 0, 1}}, hit, c);
    EXPECT_FALSE(hit.hit());
    EXPECT_EQ(c.box, 1u);
    EXPECT_EQ(c.steps, 0u);
    // Triangles in the plane z = 0: a zero-extent origin box on z.
    Scene flat;
    for (int i = 0; i < 50; ++i) {
        const float x = 0.1f * i;
        flat.add(Triangle{{x, 0, 0}, {x + 0.05f, 0, 0}, {x, 1 + 0.02f * i, 0}}, 0);
    }
    flat.finalize();
    auto rays = all_test_rays(flat, 4000, 81);
    auto want = closest_hits(*build_hierarchy(flat, "brute"), rays);
    expect_exact(flat, rays, want, {});
    expect_exact(flat, rays, want, {"max_prims=1", "max_depth=30"});
}

// --- counters --------------------------------------------------------------------------------

TEST(Rc5dCounting, PathsOnTheTwoSpheres) {
    Scene s = two_spheres();
    auto h = build_hierarchy(s, "rc5d", {"max_prims=1", "max_depth=1"});
    auto run = [&](Ray r, RayCounters& c) {
        Hit hit;
        h->closest(r, hit, c);
        return hit;
    };
    {  // Missing the box: the clip and nothing else.
        RayCounters c;
        Hit hit = run(Ray{{-5, 5, 0}, {1, 0, 0}}, c);
        EXPECT_FALSE(hit.hit());
        RayCounters want;
        want.rays = 1;
        want.box = 1;
        EXPECT_TRUE(c == want);
    }
    {  // +x from outside: enters at x = -1, low half {A, B}; A hit at t = 4 ends the search.
        RayCounters c;
        Hit hit = run(Ray{{-5, 0, 0}, {1, 0, 0}}, c);
        EXPECT_EQ(hit.prim, 0);
        EXPECT_EQ(hit.t, 4.0f);
        EXPECT_EQ(c.box, 1u);
        EXPECT_EQ(c.classify, 4u);  // 3 for the cube, 1 for the cube's split
        EXPECT_EQ(c.steps, 3u);     // root, cube, beam
        EXPECT_EQ(c.leaves, 1u);
        EXPECT_EQ(c.prim_tests(), 1u);
        EXPECT_EQ(c.visits[0] + c.visits[1] + c.visits[2], 3u);
        EXPECT_EQ(c.plane + c.hop, 0u);
    }
    {  // -x from outside: high half {B, A}; B hit first.
        RayCounters c;
        Hit hit = run(Ray{{20, 0, 0}, {-1, 0, 0}}, c);
        EXPECT_EQ(hit.prim, 1);
        EXPECT_EQ(hit.t, 9.0f);
        EXPECT_EQ(c.prim_tests(), 1u);
    }
    {  // Starting inside at x = 3: A (behind) is tested and missed, then B.
        RayCounters c;
        Hit hit = run(Ray{{3, 0, 0}, {1, 0, 0}}, c);
        EXPECT_EQ(hit.prim, 1);
        EXPECT_EQ(hit.t, 6.0f);
        EXPECT_EQ(c.prim_tests(), 2u);
    }
    {  // tmin = 7 moves the origin to x = 2 (low half); t stays in the caller's units.
        RayCounters c;
        Hit hit = run(Ray{{-5, 0, 0}, {1, 0, 0}, 7.0f}, c);
        EXPECT_EQ(hit.prim, 1);
        EXPECT_EQ(hit.t, 14.0f);
        EXPECT_EQ(c.prim_tests(), 2u);
    }
    {  // tmax = 10 ends the segment before B starts: only A is tested.
        RayCounters c;
        Hit hit = run(Ray{{-5, 0, 0}, {1, 0, 0}, 7.0f, 10.0f}, c);
        EXPECT_FALSE(hit.hit());
        EXPECT_EQ(c.prim_tests(), 1u);
        EXPECT_EQ(c.classify, 4u);
    }
    {  // A face diagonal (|dx| = |dy|) belongs to the x cube.
        RayCounters c;
        Hit hit = run(Ray{{-3, -2, 0}, {1, 1, 0}}, c);
        EXPECT_EQ(hit.prim, 0);
        EXPECT_EQ(c.classify, 4u);
        EXPECT_EQ(c.leaves, 1u);
    }
}

TEST(Rc5dCounting, ClassifyCountsArePathLengths) {
    Scene s = builtin_scene("balls", 2);
    auto rays = all_test_rays(s, 4000, 91);
    for (const char* depth : {"max_depth=0", "max_depth=13", "max_depth=40"}) {
        auto h = build_hierarchy(s, "rc5d", {depth, "max_prims=2"});
        std::size_t bad = 0, entered = 0;
        for (const Ray& r : rays) {
            RayCounters c;
            Hit hit;
            h->closest(r, hit, c);
            if (c.steps == 0) {  // missed the box: the clip only
                RayCounters want;
                want.rays = 1;
                want.box = 1;
                bad += !(c == want);
                continue;
            }
            ++entered;
            // 3 compares for the cube, then one per 5D node above the beam: root + nodes + beam
            // steps, one visit per depth.
            std::uint64_t path = c.steps - 2;
            bad += c.classify != 3 + path;
            bad += c.box != 1 || c.leaves != 1 || c.plane != 0 || c.hop != 0;
            for (std::uint64_t d = 0; d < c.steps; ++d) bad += c.visits[d] != 1;
        }
        EXPECT_EQ(bad, 0u) << depth;
        EXPECT_GT(entered, rays.size() / 4);
    }
}

}  // namespace
}  // namespace rtcost::test
