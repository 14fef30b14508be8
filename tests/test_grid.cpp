// The uniform grid (`grid`): resolution formulas, exact structure on constructed scenes, exact
// assignment, exact hits against brute force (including rays along cell boundaries), mailboxing
// and the 3DDDA counters.
#include <map>
#include <random>
#include <set>

#include "../src/hierarchy/grid/grid.hpp"
#include "test_support.hpp"

namespace rtcost::test {
namespace {

using grid::Grid;

const Grid& as_grid(const Hierarchy& h) {
    const Grid* g = dynamic_cast<const Grid*>(&h);
    if (!g) throw std::runtime_error("not a grid");
    return *g;
}

std::array<int, 3> res_of(const Hierarchy& h) { return as_grid(h).res(); }

// N = 1000 triangles whose bounds are exactly [0,2] x [0,1] x [0,1]: one triangle spanning the
// box diagonal and 999 small ones inside.
Scene box_2x1x1_with_1000() {
    Scene s;
    s.add(Triangle{{0, 0, 0}, {2, 0, 0}, {2, 1, 1}}, 0);
    for (int k = 0; k < 999; ++k) {
        Vec3 v0{0.5f + 0.001f * k, 0.5f, 0.5f};
        s.add(Triangle{v0, v0 + Vec3{0.001f, 0, 0}, v0 + Vec3{0, 0.001f, 0}}, 0);
    }
    s.finalize();
    return s;
}

TEST(GridResolution, FormulasOnA2x1x1BoxWith1000Primitives) {
    Scene s = box_2x1x1_with_1000();
    ASSERT_EQ(s.size(), 1000u);
    ASSERT_EQ(s.bounds().lo, (Vec3{0, 0, 0}));
    ASSERT_EQ(s.bounds().hi, (Vec3{2, 1, 1}));
    // regular: round(1 * 1000^(1/3)) = 10 on every axis.
    auto regular = build_hierarchy(s, "grid", {"res=regular"});
    EXPECT_EQ(res_of(*regular), (std::array<int, 3>{10, 10, 10}));
    EXPECT_EQ(regular->structure().leaves, 1000u);
    // woo: L = 1000^(1/3) = 10; floor(2/2*10) = 10, floor(1/2*10) = 5, 5.
    auto woo = build_hierarchy(s, "grid", {"res=woo"});
    EXPECT_EQ(res_of(*woo), (std::array<int, 3>{10, 5, 5}));
    EXPECT_EQ(woo->structure().leaves, 250u);
    // hetero: x = round((1000 * 4 / 1)^(1/3)) = round(15.874) = 16;
    //         y = round((1000 * 1 / (16 * 1))^(1/2)) = round(7.906) = 8;
    //         z = round(1000 / (16 * 8)) = round(7.8125) = 8.
    auto hetero = build_hierarchy(s, "grid", {"res=hetero"});
    EXPECT_EQ(res_of(*hetero), (std::array<int, 3>{16, 8, 8}));
    EXPECT_EQ(hetero->structure().leaves, 1024u);
    // The default is hetero.
    EXPECT_EQ(res_of(*build_hierarchy(s, "grid")), (std::array<int, 3>{16, 8, 8}));
}

TEST(GridResolution, DensityEntersEachFormula) {
    Scene s = box_2x1x1_with_1000();
    // regular, D = 2: round(2 * 10) = 20 per axis.
    EXPECT_EQ(res_of(*build_hierarchy(s, "grid", {"res=regular", "density=2"})), (std::array<int, 3>{20, 20, 20}));
    // woo, D = 8: L = 8000^(1/3) = 20; floor(20) = 20, floor(10) = 10, 10.
    EXPECT_EQ(res_of(*build_hierarchy(s, "grid", {"res=woo", "density=8"})), (std::array<int, 3>{20, 10, 10}));
    // hetero, D = 8: x = round(32000^(1/3)) = round(31.748) = 32; y = round((8000/32)^(1/2)) =
    // round(15.811) = 16; z = round(8000 / 512) = round(15.625) = 16.
    EXPECT_EQ(res_of(*build_hierarchy(s, "grid", {"res=hetero", "density=8"})), (std::array<int, 3>{32, 16, 16}));
    // woo, D = 0.125: L = 125^(1/3) = 5; floor(5) = 5, floor(2.5) = 2, 2.
    EXPECT_EQ(res_of(*build_hierarchy(s, "grid", {"res=woo", "density=0.125"})), (std::array<int, 3>{5, 2, 2}));
}

TEST(GridResolution, ExplicitResolutionAndCellCount) {
    Scene s = box_2x1x1_with_1000();
    auto g = build_hierarchy(s, "grid", {"res=3x4x5"});
    EXPECT_EQ(res_of(*g), (std::array<int, 3>{3, 4, 5}));
    StructureStats st = g->structure();
    EXPECT_EQ(st.leaves, 60u);  // N_V = 3 * 4 * 5
    EXPECT_EQ(st.interior, 1u);
    EXPECT_EQ(st.depth, 1);
    // Boundaries split the box evenly, the last exactly on the box face.
    auto px = as_grid(*g).planes(0);
    ASSERT_EQ(px.size(), 4u);
    EXPECT_EQ(px[0], 0.0f);
    EXPECT_FLOAT_EQ(px[1], 2.0f / 3.0f);
    EXPECT_EQ(px[3], 2.0f);
    EXPECT_EQ(as_grid(*g).planes(2)[5], 1.0f);
    EXPECT_EQ(res_of(*build_hierarchy(s, "grid", {"res=1x1x1"})), (std::array<int, 3>{1, 1, 1}));
    EXPECT_EQ(res_of(*build_hierarchy(s, "grid", {"res=1024x1x7"})), (std::array<int, 3>{1024, 1, 7}));
}

TEST(GridResolution, BadParametersAreClearErrors) {
    Scene s = box_2x1x1_with_1000();
    for (const char* bad : {"res=cubic", "res=3x4", "res=3x4x", "res=0x4x4", "res=1025x1x1", "res=3x4x5x6",
                            "res=-2x2x2", "res=2.5x2x2", "res=1024x1024x1024", "density=0", "density=x",
                            "assign=tight", "mailbox=2"}) {
        EXPECT_THROW(build_hierarchy(s, "grid", {bad}), InputError) << bad;
    }
    try {
        build_hierarchy(s, "grid", {"res=cubic"});
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("res=cubic"), std::string::npos) << e.what();
    }
}

TEST(GridResolution, CapsAxesAndTotalCells) {
    const Box3 cube{{0, 0, 0}, {1, 1, 1}};
    // regular, N = 1000, D = 1000: 10000 per axis, clamped to 1024, then 2^30 cells scaled by
    // (2^24 / 2^30)^(1/3) = 1/4 to 256 per axis.
    EXPECT_EQ(grid::resolution("regular", 1000, 1000, cube), (std::array<int, 3>{256, 256, 256}));
    // Within the cap nothing changes: 200^3 = 8e6 < 2^24.
    EXPECT_EQ(grid::resolution("regular", 200, 1, cube), (std::array<int, 3>{200, 200, 200}));
    // Woo never goes below one cell on a short axis: L = 10, floor(0.01 * 10) = 0 -> 1.
    EXPECT_EQ(grid::resolution("woo", 1, 1000, Box3{{0, 0, 0}, {100, 1, 100}}), (std::array<int, 3>{10, 1, 10}));
    // No primitives: one cell.
    EXPECT_EQ(grid::resolution("hetero", 1, 0, Box3{}), (std::array<int, 3>{1, 1, 1}));
}

TEST(GridResolution, FlatSceneGetsOneCellOnTheFlatAxis) {
    // 100 triangles in the plane z = 0 spanning [0,4] x [0,1].
    Scene s;
    s.add(Triangle{{0, 0, 0}, {4, 0, 0}, {4, 1, 0}}, 0);
    for (int k = 0; k < 99; ++k) s.add(Triangle{{0.01f * k, 0.5f, 0}, {0.01f * k + 0.01f, 0.5f, 0}, {0.01f * k, 0.6f, 0}}, 0);
    s.finalize();
    ASSERT_EQ(s.bounds().extent().z, 0.0f);
    // hetero: the flat axis gets one cell and, in the formulas, the extent of a cubic cell of the
    // 2D problem, c = (4 * 1 / 100)^(1/2) = 0.2; then x = round((100*16/(1*0.2))^(1/3)) = 20,
    // y = round((100*1/(20*0.2))^(1/2)) = 5, z = 1 (20 * 5 = 100 square cells of side 0.2).
    EXPECT_EQ(res_of(*build_hierarchy(s, "grid", {"res=hetero"})), (std::array<int, 3>{20, 5, 1}));
    // woo: L = 100^(1/3) = 4.64; floor(4.64) = 4, floor(1.16) = 1, flat 1.
    EXPECT_EQ(res_of(*build_hierarchy(s, "grid", {"res=woo"})), (std::array<int, 3>{4, 1, 1}));
    // regular: round(4.64) = 5, flat axis 1.
    EXPECT_EQ(res_of(*build_hierarchy(s, "grid", {"res=regular"})), (std::array<int, 3>{5, 5, 1}));
    // Explicit: a zero-extent axis has nothing to subdivide.
    EXPECT_EQ(res_of(*build_hierarchy(s, "grid", {"res=4x4x4"})), (std::array<int, 3>{4, 4, 1}));
    // Rays through the flat grid get brute force's hits.
    for (const char* res : {"res=hetero", "res=woo", "res=4x4x4"}) {
        auto g = build_hierarchy(s, "grid", {res});
        auto brute = build_hierarchy(s, "brute");
        auto rays = hard_rays(s, 3000, 17);
        std::string first;
        EXPECT_EQ(count_mismatches(closest_hits(*brute, rays), closest_hits(*g, rays), 0.0f, &first), 0u)
            << res << ": " << first;
    }
}

// --- structure on constructed scenes ---------------------------------------------------------

// Box [0,4]^3 cut 4x4x4 into unit cells. Radius-0 spheres are points.
Scene known_cells_scene() {
    Scene s;
    s.add(Sphere{{0, 0, 0}, 0}, 0);           // box corner: cell (0,0,0)
    s.add(Sphere{{4, 4, 4}, 0}, 0);           // box corner: cell (3,3,3)
    s.add(Sphere{{1.5f, 0.5f, 0.5f}, 0.25f}, 0);  // inside cell (1,0,0)
    s.add(Sphere{{2, 2.5f, 2.5f}, 0.25f}, 0);     // straddles x = 2: cells (1,2,2), (2,2,2)
    s.add(Sphere{{3, 1, 1}, 0}, 0);           // point on a grid vertex: x {2,3} y {0,1} z {0,1}, 8 cells
    s.add(Sphere{{2, 3, 0.5f}, 0}, 0);        // point on a grid edge: x {1,2} y {2,3} z {0}, 4 cells
    s.add(Sphere{{0.5f, 3.5f, 2}, 0}, 0);     // point on a face: (0,3,1), (0,3,2)
    s.finalize();
    return s;
}

TEST(GridStructure, ReferencesGoToEveryCellTheBoundsTouch) {
    Scene s = known_cells_scene();
    for (const char* assign : {"assign=bounds", "assign=exact"}) {
        auto h = build_hierarchy(s, "grid", {"res=4x4x4", assign});
        const Grid& g = as_grid(*h);
        StructureStats st = h->structure();
        EXPECT_EQ(st.interior, 1u);
        EXPECT_EQ(st.leaves, 64u);
        EXPECT_EQ(st.references, 19u) << assign;    // 1 + 1 + 1 + 2 + 8 + 4 + 2
        EXPECT_EQ(st.empty_leaves, 45u) << assign;  // the 19 references fall in 19 distinct cells
        EXPECT_EQ(st.depth, 1);
        // Offsets (65) + references (19) + boundaries (3 x 5), 4 bytes each.
        EXPECT_EQ(st.bytes, (65u + 19u + 15u) * 4u);
        using V = std::vector<std::uint32_t>;
        auto ids = [&](int i, int j, int k) { auto c = g.cell(i, j, k); return V(c.begin(), c.end()); };
        EXPECT_EQ(ids(0, 0, 0), V{0});
        EXPECT_EQ(ids(3, 3, 3), V{1});
        EXPECT_EQ(ids(1, 0, 0), V{2});
        EXPECT_EQ(ids(1, 2, 2), V{3});
        EXPECT_EQ(ids(2, 2, 2), V{3});
        for (int i : {2, 3})
            for (int j : {0, 1})
                for (int k : {0, 1}) EXPECT_EQ(ids(i, j, k), V{4}) << i << j << k;
        for (int i : {1, 2})
            for (int j : {2, 3}) EXPECT_EQ(ids(i, j, 0), V{5});
        EXPECT_EQ(ids(0, 3, 1), V{6});
        EXPECT_EQ(ids(0, 3, 2), V{6});
        EXPECT_TRUE(ids(0, 1, 0).empty());
        EXPECT_TRUE(ids(1, 1, 1).empty());
    }
}

TEST(GridStructure, CellsOfAPrimitiveAreThoseItsBoundsReachOnThePlanes) {
    // Odd resolutions (boundaries rounded from double), and triangles whose box faces lie exactly
    // on a boundary, just either side of it, or flat: every cell lists exactly the primitives whose
    // box reaches it by the planes themselves, as the binary searches over them decide (the
    // first cell whose upper boundary is >= the box's lo, through the last whose lower boundary
    // is <= its hi).
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(-3.7f, 5.3f);
    Scene s;
    s.add(Triangle{{-3.7f, -3.7f, -3.7f}, {5.3f, -3.7f, -3.7f}, {5.3f, 5.3f, 5.3f}}, 0);  // the scene's box
    s.finalize();
    const std::array<int, 3> res{7, 5, 9};
    std::vector<std::vector<float>> on_planes;  // each axis's boundaries, from a first grid
    {
        const Grid first(s, res, spatial::Assign::Bounds, false);
        for (int a = 0; a < 3; ++a) on_planes.emplace_back(first.planes(a).begin(), first.planes(a).end());
    }
    auto plane = [&](int a, int n) { return on_planes[a][static_cast<std::size_t>(n) % on_planes[a].size()]; };
    for (int n = 0; n < 800; ++n) {
        Vec3 p[3];
        const Vec3 c{u(rng), u(rng), u(rng)};
        // Inside the first triangle's box, so that every grid here has the same planes.
        auto in_box = [](float x) { return std::clamp(x, -3.7f, 5.3f); };
        for (Vec3& v : p) v = Vec3{c.x + 0.2f * u(rng), c.y + 0.2f * u(rng), c.z + 0.2f * u(rng)};
        if (n % 3 == 0) p[0].x = plane(0, n), p[1].x = std::nextafter(p[0].x, 10.0f);
        if (n % 5 == 0) p[1].y = plane(1, n), p[2].y = std::nextafter(p[1].y, -10.0f);
        if (n % 7 == 0) p[0].z = p[1].z = p[2].z = plane(2, n);  // flat, on a boundary
        if (n % 11 == 0) p[0].x = p[1].x = p[2].x = std::nextafter(plane(0, n), -10.0f);  // flat, just below one
        if (n % 13 == 0) {  // lowest just above a boundary, on every axis
            for (int a = 0; a < 3; ++a) {
                const float lo = std::nextafter(plane(a, n + a), 10.0f);
                p[0][a] = lo, p[1][a] = lo + 0.1f, p[2][a] = lo + 0.05f;
            }
        }
        for (Vec3& v : p) v = Vec3{in_box(v.x), in_box(v.y), in_box(v.z)};
        s.add(Triangle{p[0], p[1], p[2]}, 0);
    }
    s.finalize();
    const Grid g(s, res, spatial::Assign::Bounds, false);
    ASSERT_EQ(g.res(), res);
    for (int a = 0; a < 3; ++a) ASSERT_EQ(std::vector<float>(g.planes(a).begin(), g.planes(a).end()), on_planes[a]);
    std::size_t listed = 0;
    for (std::uint32_t id = 0; id < s.size(); ++id) {
        const Box3 b = s.prim_bounds(id);
        int lo[3], hi[3];
        for (int a = 0; a < 3; ++a) {
            const std::span<const float> pl = g.planes(a);
            lo[a] = std::min(static_cast<int>(std::lower_bound(pl.begin() + 1, pl.end(), b.lo[a]) - (pl.begin() + 1)), res[a] - 1);
            hi[a] = std::max(static_cast<int>(std::upper_bound(pl.begin(), pl.end() - 1, b.hi[a]) - pl.begin()) - 1, 0);
        }
        for (int k = 0; k < res[2]; ++k)
            for (int j = 0; j < res[1]; ++j)
                for (int i = 0; i < res[0]; ++i) {
                    const auto c = g.cell(i, j, k);
                    const bool in = std::binary_search(c.begin(), c.end(), id);
                    const bool want = lo[0] <= i && i <= hi[0] && lo[1] <= j && j <= hi[1] && lo[2] <= k && k <= hi[2];
                    ASSERT_EQ(in, want) << "primitive " << id << " cell " << i << "," << j << "," << k;
                    listed += in;
                }
    }
    EXPECT_EQ(listed, g.structure().references);
    EXPECT_GT(listed, 2 * s.size());  // many primitives span cells
}

TEST(GridStructure, ExactAssignmentSkipsCellsInsideABigSphere) {
    // A sphere of radius 2 centred in [0,4]^3: its box touches all 64 cells, its surface misses
    // the 8 central cells [1,3]^3 (their farthest corner is sqrt(3) < 2 from the centre) and
    // meets every other cell (nearest point closer than 2, farthest corner beyond 2).
    Scene s;
    s.add(Sphere{{2, 2, 2}, 2}, 0);
    s.finalize();
    auto bounds = build_hierarchy(s, "grid", {"res=4x4x4"});
    auto exact = build_hierarchy(s, "grid", {"res=4x4x4", "assign=exact"});
    EXPECT_EQ(bounds->structure().references, 64u);
    EXPECT_EQ(exact->structure().references, 56u);
    EXPECT_EQ(exact->structure().empty_leaves, 8u);
    for (int i : {1, 2})
        for (int j : {1, 2})
            for (int k : {1, 2}) EXPECT_TRUE(as_grid(*exact).cell(i, j, k).empty());
    EXPECT_EQ(as_grid(*exact).cell(0, 0, 0).size(), 1u);
    // Same hits either way (the ray from the centre leaves through the surface).
    auto rays = hard_rays(s, 3000, 3);
    rays.push_back(Ray{{2, 2, 2}, {1, 0, 0}, 0, kInf});
    rays.push_back(Ray{{2, 2, 2}, {1, 1, 1}, 0, kInf});
    auto brute = build_hierarchy(s, "brute");
    std::vector<Hit> want = closest_hits(*brute, rays);
    EXPECT_EQ(count_mismatches(want, closest_hits(*exact, rays), 0.0f), 0u);
    EXPECT_EQ(count_mismatches(want, closest_hits(*bounds, rays), 0.0f), 0u);
}

TEST(GridStructure, ExactAssignmentNeverMissesACellTheSurfaceMeets) {
    // Random triangles; every cell holding a sampled point of a triangle (well inside the cell,
    // away from rounding at its faces) must reference it, and exact references are a subset of
    // bounds references.
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(0, 1);
    Scene s;
    for (int k = 0; k < 60; ++k) {
        Vec3 c{u(rng) * 10, u(rng) * 10, u(rng) * 10};
        auto jitter = [&] { return Vec3{u(rng) * 6 - 3, u(rng) * 6 - 3, u(rng) * 6 - 3}; };
        s.add(Triangle{c + jitter(), c + jitter(), c + jitter()}, 0);
    }
    // A polygon too (exact assignment clips polygons as well).
    std::vector<Vec3> quad{{1, 1, 2}, {9, 2, 3}, {8, 9, 7}, {2, 8, 6}};
    std::uint32_t quad_id = 0;
    ASSERT_TRUE(s.add_polygon(quad, 0, &quad_id));
    s.finalize();
    auto hb = build_hierarchy(s, "grid", {"res=9x8x7"});
    auto he = build_hierarchy(s, "grid", {"res=9x8x7", "assign=exact"});
    const Grid& gb = as_grid(*hb);
    const Grid& ge = as_grid(*he);
    EXPECT_LT(he->structure().references, hb->structure().references);
    std::size_t checked = 0;
    for (int k = 0; k < 7; ++k)
        for (int j = 0; j < 8; ++j)
            for (int i = 0; i < 9; ++i) {
                auto e = ge.cell(i, j, k);
                auto b = gb.cell(i, j, k);
                EXPECT_TRUE(std::includes(b.begin(), b.end(), e.begin(), e.end()));
            }
    auto cell_of = [&](Vec3 p, int c[3]) {
        for (int a = 0; a < 3; ++a) {
            auto pl = ge.planes(a);
            int i = static_cast<int>(std::upper_bound(pl.begin(), pl.end(), p[a]) - pl.begin()) - 1;
            i = std::clamp(i, 0, static_cast<int>(pl.size()) - 2);
            float margin = 1e-4f * (pl.back() - pl.front());
            if (p[a] < pl[i] + margin || p[a] > pl[i + 1] - margin) return false;
            c[a] = i;
        }
        return true;
    };
    auto check = [&](std::uint32_t id, Vec3 p) {
        int c[3];
        if (!cell_of(p, c)) return;
        auto refs = ge.cell(c[0], c[1], c[2]);
        EXPECT_TRUE(std::binary_search(refs.begin(), refs.end(), id)) << "prim " << id << " cell " << c[0] << "," << c[1] << "," << c[2];
        ++checked;
    };
    for (std::uint32_t id = 0; id + 1 < s.size(); ++id) {
        const Triangle& t = s.triangles[s.prims[id].index];
        for (int n = 0; n < 400; ++n) {
            float a = u(rng), b = u(rng);
            if (a + b > 1) { a = 1 - a; b = 1 - b; }
            check(id, t.v0 + (t.v1 - t.v0) * a + (t.v2 - t.v0) * b);
        }
        check(id, t.v0);
        check(id, t.v1);
        check(id, t.v2);
    }
    for (int n = 0; n < 2000; ++n) {  // the quad as two triangles
        float a = u(rng), b = u(rng);
        if (a + b > 1) { a = 1 - a; b = 1 - b; }
        const Vec3& o = quad[0];
        Vec3 p = (n % 2) ? o + (quad[1] - o) * a + (quad[2] - o) * b : o + (quad[2] - o) * a + (quad[3] - o) * b;
        check(quad_id, p);
    }
    EXPECT_GT(checked, 10000u);
}

TEST(GridStructure, ModelTreeIsTheBalancedSplitOfTheCells) {
    Scene s = known_cells_scene();
    auto h = build_hierarchy(s, "grid", {"res=4x2x1"});
    const Grid& g = as_grid(*h);
    ModelTree t = h->model_tree();
    EXPECT_EQ(t.family, ModelFamily::Grid);
    EXPECT_EQ(t.per_ray_box, 1.0f);
    EXPECT_EQ(t.per_entry_hop, -1.0f);
    ASSERT_EQ(t.nodes.size(), 15u);  // 8 cells, 7 binary nodes
    const ModelNode& root = t.nodes[0];
    EXPECT_FALSE(root.leaf);
    EXPECT_EQ(root.axis, 0);   // x has the longest index range (4)
    EXPECT_EQ(root.split, 2.0f);
    EXPECT_TRUE(root.step);    // the grid itself: interior(0) in the traversal
    EXPECT_EQ(root.hop, 0.0f);
    EXPECT_EQ(root.region.lo, s.bounds().lo);
    EXPECT_EQ(root.region.hi, s.bounds().hi);
    // Children 2x2x1: the tie goes to x, split at 1 and 3; then y at 2.
    EXPECT_EQ(t.nodes[root.first].axis, 0);
    EXPECT_EQ(t.nodes[root.first].split, 1.0f);
    EXPECT_EQ(t.nodes[root.first + 1].split, 3.0f);
    std::size_t leaves = 0, refs = 0;
    for (std::size_t i = 0; i < t.nodes.size(); ++i) {
        const ModelNode& m = t.nodes[i];
        if (m.leaf) {
            ++leaves;
            refs += m.count;
            EXPECT_EQ(m.hop, 1.0f);
            EXPECT_TRUE(m.step);
            EXPECT_EQ(m.depth, 3);
            // Each leaf is one cell: its region is a cell box and its primitives the cell's.
            int c[3];
            for (int a = 0; a < 3; ++a) {
                auto pl = g.planes(a);
                c[a] = static_cast<int>(std::find(pl.begin(), pl.end(), m.region.lo[a]) - pl.begin());
            }
            Box3 cb = g.cell_box(c[0], c[1], c[2]);
            EXPECT_EQ(cb.lo, m.region.lo);
            EXPECT_EQ(cb.hi, m.region.hi);
            auto ids = g.cell(c[0], c[1], c[2]);
            EXPECT_EQ(std::vector<std::uint32_t>(ids.begin(), ids.end()),
                      std::vector<std::uint32_t>(t.prims.begin() + m.first, t.prims.begin() + m.first + m.count));
        } else {
            EXPECT_EQ(m.count, 2u);
            EXPECT_EQ(m.hop, 0.0f);
            EXPECT_EQ(m.step, i == 0);
            EXPECT_EQ(m.box, 0.0f);
            EXPECT_FALSE(m.has_bv);
            // The children share the split plane and tile the parent.
            const ModelNode& l = t.nodes[m.first];
            const ModelNode& r = t.nodes[m.first + 1];
            EXPECT_EQ(l.region.hi[m.axis], m.split);
            EXPECT_EQ(r.region.lo[m.axis], m.split);
            EXPECT_EQ(l.region.lo, m.region.lo);
            EXPECT_EQ(r.region.hi, m.region.hi);
        }
    }
    EXPECT_EQ(leaves, 8u);
    EXPECT_EQ(refs, h->structure().references);

    // One cell: the grid node above the single leaf.
    ModelTree one = build_hierarchy(s, "grid", {"res=1x1x1"})->model_tree();
    ASSERT_EQ(one.nodes.size(), 2u);
    EXPECT_FALSE(one.nodes[0].leaf);
    EXPECT_EQ(one.nodes[0].count, 1u);
    EXPECT_TRUE(one.nodes[1].leaf);
    EXPECT_EQ(one.nodes[1].count, s.size());
}

// --- exact hits ------------------------------------------------------------------------------

const std::vector<std::vector<std::string>> kGridVariants = {
    {},
    {"res=regular"},
    {"res=woo"},
    {"res=7x3x5"},
    {"res=1x1x1"},
    {"assign=exact"},
    {"mailbox=1"},
    {"res=hetero", "density=8", "assign=exact", "mailbox=1"},
};

void expect_matches_brute(const Scene& s, const std::vector<Ray>& rays, const std::string& what) {
    std::vector<Variant> variants;
    for (const auto& set : kGridVariants) variants.emplace_back("grid", set);
    expect_variants_match_brute(s, rays, what, variants);
}

TEST(GridTrace, MatchesBruteForceOnBuiltinScenes) {
    for (auto [name, level] : {std::pair{"balls", 2}, std::pair{"tetra", 4}}) {
        Scene s = builtin_scene(name, level);
        expect_matches_brute(s, hard_rays(s, 20000, 5), name);
    }
}

TEST(GridTrace, MatchesBruteForceOnSpdScenes) {
    RTCOST_REQUIRE_SPD("rings");
    RTCOST_REQUIRE_SPD("mount");
    for (const char* name : {"rings", "mount"}) {
        Scene s = load_scene(spd_path(name));
        auto rays = hard_rays(s, 8000, 21);
        auto brute = build_hierarchy(s, "brute");
        std::vector<Hit> want = closest_hits(*brute, rays);
        for (const std::vector<std::string>& set :
             {std::vector<std::string>{}, {"res=woo", "assign=exact", "mailbox=1"}, {"res=regular", "density=3"}}) {
            auto g = build_hierarchy(s, "grid", set);
            std::string first;
            EXPECT_EQ(count_mismatches(want, closest_hits(*g, rays), 0.0f, &first), 0u)
                << name << " " << ::testing::PrintToString(set) << ": " << first;
        }
    }
}

// Rays lying in cell boundary planes or along grid lines (axis-parallel, origins on the planes,
// inside and outside the box), rays starting on a plane and crossing it, and rays aimed at grid
// vertices.
std::vector<Ray> boundary_rays(const Grid& g, const Box3& box, std::uint64_t seed) {
    std::mt19937 rng(static_cast<std::uint32_t>(seed));
    std::uniform_real_distribution<float> u(0, 1);
    auto plane = [&](int a) {
        auto pl = g.planes(a);
        return pl[std::uniform_int_distribution<std::size_t>(0, pl.size() - 1)(rng)];
    };
    auto point = [&](float grow) {
        Vec3 lo = box.lo - box.extent() * grow, size = box.extent() * (1 + 2 * grow);
        return lo + Vec3{u(rng) * size.x, u(rng) * size.y, u(rng) * size.z};
    };
    std::vector<Ray> rays;
    for (int n = 0; n < 6000; ++n) {
        const int a = n % 3, b = (a + 1) % 3, c = (a + 2) % 3;
        const float sign = (n / 3) % 2 ? 1.0f : -1.0f;
        Ray r;
        r.o = point(n % 4 == 0 ? 0.0f : 0.3f);  // a quarter start inside the box
        r.o[a] = plane(a);
        switch ((n / 6) % 4) {
            case 0:  // in plane a, parallel to axis b
                r.d = Vec3{0, 0, 0};
                r.d[b] = sign;
                break;
            case 1:  // along a grid line (planes a and b), parallel to axis c
                r.o[b] = plane(b);
                r.d = Vec3{0, 0, 0};
                r.d[c] = sign;
                break;
            case 2:  // in plane a, any direction within it
                r.d = Vec3{0, 0, 0};
                r.d[b] = u(rng) * 2 - 1;
                r.d[c] = u(rng) * 2 - 1;
                if (r.d == Vec3{0, 0, 0}) r.d[b] = 1;
                break;
            default:  // starting on plane a, crossing it
                r.d = Vec3{u(rng) * 2 - 1, u(rng) * 2 - 1, u(rng) * 2 - 1};
                r.d[a] = sign * (0.1f + u(rng));
                break;
        }
        rays.push_back(r);
    }
    for (int n = 0; n < 3000; ++n) {  // aimed at grid vertices
        Ray r;
        r.o = point(0.5f);
        r.d = Vec3{plane(0), plane(1), plane(2)} - r.o;
        if (r.d == Vec3{0, 0, 0}) continue;
        rays.push_back(r);
    }
    return rays;
}

TEST(GridTrace, RaysAlongCellBoundariesMatchBruteForce) {
    for (auto [name, level] : {std::pair{"balls", 2}, std::pair{"tetra", 4}}) {
        Scene s = builtin_scene(name, level);
        auto brute = build_hierarchy(s, "brute");
        for (const std::vector<std::string>& set :
             {std::vector<std::string>{}, {"res=hetero", "density=4"}, {"res=6x5x4", "assign=exact", "mailbox=1"}}) {
            auto g = build_hierarchy(s, "grid", set);
            auto rays = boundary_rays(as_grid(*g), s.bounds(), 99);
            std::string first;
            EXPECT_EQ(count_mismatches(closest_hits(*brute, rays), closest_hits(*g, rays), 0.0f, &first), 0u)
                << name << " " << ::testing::PrintToString(set) << ": " << first;
        }
    }
}

TEST(GridTrace, SegmentsWithTminAndTmaxMatchBruteForce) {
    Scene s = builtin_scene("balls", 2);
    std::vector<Ray> rays = hard_rays(s, 6000, 8);
    std::mt19937 rng(4);
    std::uniform_real_distribution<float> u(0, 1);
    const float size = length(s.bounds().extent());
    for (Ray& r : rays) {
        r.tmin = u(rng) * size / length(r.d);
        r.tmax = r.tmin + u(rng) * size / length(r.d);
    }
    expect_matches_brute(s, rays, "segments");
}

TEST(GridTrace, AnyHitAndAllHitsAgreeWithBruteForce) {
    Scene s = builtin_scene("tetra", 4);
    auto rays = hard_rays(s, 5000, 13);
    auto brute = build_hierarchy(s, "brute");
    std::vector<Hit> want = closest_hits(*brute, rays);
    for (const auto& set : kGridVariants) {
        auto g = build_hierarchy(s, "grid", set);
        std::size_t bad = 0;
        for (std::size_t i = 0; i < rays.size(); ++i) {
            Hit any, all;
            bad += g->any(rays[i], any) != want[i].hit();
            g->all(rays[i], all);
            bad += all.t != want[i].t;
        }
        EXPECT_EQ(bad, 0u) << ::testing::PrintToString(set);
    }
}

// --- counters and mailboxing -----------------------------------------------------------------

// A row of 8 unit cells, box [0,8] x [0,1] x [0,1] fixed by two points at its corners, a small
// sphere in cell 5 (y, z in [0.25, 0.75]) and a long thin triangle in the plane y = 0.1 spanning
// every cell.
Scene row_scene(bool with_triangle) {
    Scene s;
    s.add(Sphere{{0, 0, 0}, 0}, 0);
    s.add(Sphere{{8, 1, 1}, 0}, 0);
    s.add(Sphere{{5.5f, 0.5f, 0.5f}, 0.25f}, 0);
    if (with_triangle) s.add(Triangle{{0, 0.1f, 0}, {8, 0.1f, 0}, {8, 0.1f, 1}}, 0);
    s.finalize();
    return s;
}

TEST(GridCounters, AxisParallelRayHopsCellsMinusOne) {
    Scene s = row_scene(false);
    auto h = build_hierarchy(s, "grid", {"res=8x1x1"});
    Hit hit;
    // Through the whole row, missing everything (y = z = 0.9): 8 cells, 7 hops.
    RayCounters c = count_one(*h, Ray{{-1, 0.9f, 0.9f}, {1, 0, 0}, 0, kInf}, hit);
    EXPECT_FALSE(hit.hit());
    EXPECT_EQ(c.box, 1u);
    EXPECT_EQ(c.leaves, 8u);
    EXPECT_EQ(c.hop, 7u);
    EXPECT_EQ(c.steps, 9u);  // the grid (interior, depth 0) and 8 cells (depth 1)
    EXPECT_EQ(c.visits[0], 1u);
    EXPECT_EQ(c.visits[1], 8u);
    EXPECT_EQ(c.empty_leaves, 5u);  // cells 0, 5 and 7 hold a primitive
    EXPECT_EQ(c.prim_tests(), 3u);
    EXPECT_EQ(c.plane + c.classify, 0u);
    // Backwards: the same cells.
    c = count_one(*h, Ray{{9, 0.9f, 0.9f}, {-1, 0, 0}, 0, kInf}, hit);
    EXPECT_EQ(c.leaves, 8u);
    EXPECT_EQ(c.hop, 7u);
    // Starting inside cell 2: cells 2..7.
    c = count_one(*h, Ray{{2.5f, 0.9f, 0.9f}, {1, 0, 0}, 0, kInf}, hit);
    EXPECT_EQ(c.leaves, 6u);
    EXPECT_EQ(c.hop, 5u);
    // Starting exactly on the plane x = 3: forwards cells 3..7, backwards cells 2..0.
    c = count_one(*h, Ray{{3, 0.9f, 0.9f}, {1, 0, 0}, 0, kInf}, hit);
    EXPECT_EQ(c.leaves, 5u);
    EXPECT_EQ(c.hop, 4u);
    c = count_one(*h, Ray{{3, 0.9f, 0.9f}, {-1, 0, 0}, 0, kInf}, hit);
    EXPECT_EQ(c.leaves, 3u);
    EXPECT_EQ(c.hop, 2u);
    // A segment ending in cell 3 (x = 3.5).
    c = count_one(*h, Ray{{-1, 0.9f, 0.9f}, {1, 0, 0}, 0, 4.5f}, hit);
    EXPECT_EQ(c.leaves, 4u);
    EXPECT_EQ(c.hop, 3u);
    // tmin past the start: the segment (4.5, inf) starts in cell 3.
    c = count_one(*h, Ray{{-1, 0.9f, 0.9f}, {1, 0, 0}, 4.5f, kInf}, hit);
    EXPECT_EQ(c.leaves, 5u);
    EXPECT_EQ(c.hop, 4u);
    // Hitting the sphere in cell 5 (at x = 5.25, inside the cell): cells 0..5, then stop.
    c = count_one(*h, Ray{{-1, 0.5f, 0.5f}, {1, 0, 0}, 0, kInf}, hit);
    ASSERT_TRUE(hit.hit());
    EXPECT_EQ(hit.prim, 2);
    EXPECT_FLOAT_EQ(hit.t, 6.25f);
    EXPECT_EQ(c.leaves, 6u);
    EXPECT_EQ(c.hop, 5u);
    EXPECT_EQ(c.prim_tests(), 2u);  // the corner point in cell 0, the sphere in cell 5
    EXPECT_EQ(c.empty_leaves, 4u);
    // Along the box's top face (y = 1): still inside (closed box), 8 cells.
    hit = Hit{};
    c = count_one(*h, Ray{{-1, 1, 0.5f}, {1, 0, 0}, 0, kInf}, hit);
    EXPECT_EQ(c.leaves, 8u);
    // Missing the box: one box test and nothing else.
    c = count_one(*h, Ray{{-1, 2, 0.5f}, {1, 0, 0}, 0, kInf}, hit);
    EXPECT_EQ(c.box, 1u);
    EXPECT_EQ(c.steps, 0u);
    EXPECT_EQ(c.hop, 0u);
}

TEST(GridCounters, DiagonalRayVisitsOneCellPerPlaneCrossed) {
    // 4x4x4 unit cells; a ray through the box crossing 3 x-planes, 2 y-planes and 1 z-plane
    // (none at a common point) visits 1 + 3 + 2 + 1 = 7 cells.
    Scene s = known_cells_scene();
    auto h = build_hierarchy(s, "grid", {"res=4x4x4"});
    Hit hit;
    // From (-1, 0.3, 0.2) along (1, 0.5, 0.3): at x = 0 y = 0.8, z = 0.5; at x = 4 y = 2.8, z = 1.7.
    // Crossings at t = 2, 3, 4 (x), 1.4, 3.4 (y), 2.67 (z): all distinct.
    Ray r{{-1, 0.3f, 0.2f}, {1, 0.5f, 0.3f}, 0, kInf};
    RayCounters c;
    h->all(r, hit, c);
    EXPECT_EQ(c.leaves, 7u);
    EXPECT_EQ(c.hop, 6u);
}

TEST(GridMailbox, EachPrimitiveTestedOnceOnAKnownRow) {
    Scene s = row_scene(true);  // the triangle is referenced by all 8 cells
    auto plain = build_hierarchy(s, "grid", {"res=8x1x1"});
    auto mailbox = build_hierarchy(s, "grid", {"res=8x1x1", "mailbox=1"});
    ASSERT_EQ(plain->structure().references, 11u);  // 2 points, the sphere, the triangle x 8
    const Ray r{{-1, 0.9f, 0.9f}, {1, 0, 0}, 0, kInf};  // parallel to the triangle, misses all
    Hit h1, h2;
    RayCounters a = count_one(*plain, r, h1);
    RayCounters b = count_one(*mailbox, r, h2);
    EXPECT_EQ(a.prim_tests(), 11u);
    EXPECT_EQ(b.prim_tests(), 4u);  // every primitive once
    EXPECT_EQ(b.prim[static_cast<int>(PrimKind::Triangle)], 1u);
    EXPECT_EQ(a.leaves, b.leaves);
    EXPECT_EQ(a.hop, b.hop);
    // The same ray twice: the mailbox starts afresh for each ray.
    b = count_one(*mailbox, r, h2);
    EXPECT_EQ(b.prim_tests(), 4u);
}

TEST(GridMailbox, SameHitsFewerTestsAndNoPrimitiveTestedTwice) {
    Scene s = builtin_scene("balls", 2);
    auto plain = build_hierarchy(s, "grid", {"res=hetero", "density=4"});
    auto mailbox = build_hierarchy(s, "grid", {"res=hetero", "density=4", "mailbox=1"});
    const Grid& g = as_grid(*plain);
    auto rays = random_rays(s.bounds(), 3000, 31);
    // Independent cell enumeration: every cell whose (slightly grown) box the segment meets.
    const auto res = g.res();
    const float grow = 1e-4f * length(s.bounds().extent());
    std::uint64_t fewer = 0, repeated = 0, sum_plain = 0, sum_mailbox = 0;
    for (const Ray& r : rays) {
        Hit ha, hb;
        RayCounters a, b;
        plain->all(r, ha, a);
        mailbox->all(r, hb, b);
        ASSERT_EQ(ha.t, hb.t);
        ASSERT_EQ(ha.prim, hb.prim);
        EXPECT_LE(b.prim_tests(), a.prim_tests());
        EXPECT_EQ(a.leaves, b.leaves);
        std::set<std::uint32_t> met;
        const RayInv ri(r);
        for (int k = 0; k < res[2]; ++k)
            for (int j = 0; j < res[1]; ++j)
                for (int i = 0; i < res[0]; ++i) {
                    Box3 cb = g.cell_box(i, j, k);
                    cb.lo = cb.lo - Vec3{grow, grow, grow};
                    cb.hi = cb.hi + Vec3{grow, grow, grow};
                    if (box_entry(cb, ri.o, ri.inv, r.tmin, r.tmax) == kInf) continue;
                    for (std::uint32_t id : g.cell(i, j, k)) met.insert(id);
                }
        // With the mailbox no primitive is tested twice: at most one test per distinct primitive.
        EXPECT_LE(b.prim_tests(), met.size());
        repeated += a.prim_tests() > met.size();
        fewer += b.prim_tests() < a.prim_tests();
        sum_plain += a.prim_tests();
        sum_mailbox += b.prim_tests();
    }
    // The check has teeth: without the mailbox many rays test some primitive twice.
    EXPECT_GT(repeated, 100u);
    EXPECT_GT(fewer, 100u);
    EXPECT_LT(sum_mailbox, sum_plain);
    // Closest-hit queries too: same hits, never more tests.
    for (const Ray& r : rays) {
        Hit ha, hb;
        RayCounters a, b;
        plain->closest(r, ha, a);
        mailbox->closest(r, hb, b);
        ASSERT_EQ(ha.t, hb.t);
        EXPECT_LE(b.prim_tests(), a.prim_tests());
    }
}

TEST(GridCounters, CountingDoesNotChangeHitsAndInvariantsHold) {
    Scene s = builtin_scene("balls", 2);
    auto rays = hard_rays(s, 10000, 77);
    for (const auto& set : kGridVariants) {
        auto g = build_hierarchy(s, "grid", set);
        TraceOptions opt;
        TraceResult fast = trace_rays(*g, rays, opt);
        opt.count = true;
        TraceResult counted = trace_rays(*g, rays, opt);
        std::string first;
        EXPECT_EQ(count_mismatches(fast.hits, counted.hits, 0.0f, &first), 0u) << first;
        for (std::size_t i = 0; i < rays.size(); ++i) ASSERT_EQ(fast.hits[i].prim, counted.hits[i].prim);
        const RayCounters& c = counted.counters;
        const std::uint64_t entered = c.visits[0];
        EXPECT_EQ(c.rays, rays.size());
        EXPECT_EQ(c.box, c.rays);           // one clip per ray
        EXPECT_GT(entered, 0u);
        EXPECT_LE(entered, c.rays);
        EXPECT_EQ(c.visits[1], c.leaves);   // cells at depth 1
        EXPECT_EQ(c.steps, entered + c.leaves);
        EXPECT_EQ(c.hop, c.leaves - entered);  // one hop between consecutive cells of a ray
        EXPECT_EQ(c.plane + c.classify, 0u);
        EXPECT_LE(c.empty_leaves, c.leaves);
        std::uint64_t visits = 0;
        for (auto v : c.visits) visits += v;
        EXPECT_EQ(visits, c.steps);
    }
}

TEST(GridCounters, EmptySceneCostsOneBoxTest) {
    Scene s;
    s.finalize();
    auto g = build_hierarchy(s, "grid");
    EXPECT_EQ(g->structure().leaves, 1u);
    EXPECT_EQ(g->structure().references, 0u);
    Hit hit;
    RayCounters c = count_one(*g, Ray{{0, 0, 0}, {1, 0, 0}, 0, kInf}, hit);
    EXPECT_FALSE(hit.hit());
    EXPECT_EQ(c.box, 1u);
    EXPECT_EQ(c.steps, 0u);
}

}  // namespace
}  // namespace rtcost::test
