// Kaplan's BSP tree (`bsp`) and Glassner's octree (`octree`): exact structure on constructed
// scenes, the growth guard, exact assignment, exact hits against brute force for both
// traversals (rays in split planes, from inside the box, axis-parallel, segments, max_depth 0),
// the counters of the locate and recursive traversals, mailboxing, and the model.
#include <random>
#include <set>

#include "../src/hierarchy/bsp/bsp.hpp"
#include "../src/hierarchy/octree/octree.hpp"
#include "test_support.hpp"

namespace rtcost::test {
namespace {

using Set = std::vector<std::string>;

// Three spheres in the box [0,16]^3: A, box [0,3]^3; B, box [13,16]^3; C, box [5,7] x
// [0.5,2.5]^2. No box touches a mid-plane of the first levels (8, then 4).
Scene abc_scene() {
    Scene s;
    s.add(Sphere{{1.5f, 1.5f, 1.5f}, 1.5f}, 0);  // A
    s.add(Sphere{{14.5f, 14.5f, 14.5f}, 1.5f}, 0);  // B
    s.add(Sphere{{6, 1.5f, 1.5f}, 1}, 0);  // C
    s.finalize();
    return s;
}

std::vector<std::uint32_t> leaf_refs_sorted(const ModelTree& t, const ModelNode& m) {
    std::vector<std::uint32_t> r(t.prims.begin() + m.first, t.prims.begin() + m.first + m.count);
    std::sort(r.begin(), r.end());
    return r;
}

void expect_stats(const Hierarchy& h, std::uint64_t in, std::uint64_t v, std::uint64_t ev, std::uint64_t oiv,
                  int depth, const std::string& what) {
    StructureStats s = h.structure();
    EXPECT_EQ(s.interior, in) << what;
    EXPECT_EQ(s.leaves, v) << what;
    EXPECT_EQ(s.empty_leaves, ev) << what;
    EXPECT_EQ(s.references, oiv) << what;
    EXPECT_EQ(s.depth, depth) << what;
    EXPECT_GT(s.bytes, 0u) << what;
}

// --- structure -------------------------------------------------------------------------------

TEST(BspStructure, ExactCountsOnThreeSpheres) {
    Scene s = abc_scene();
    ASSERT_EQ(s.bounds().lo, (Vec3{0, 0, 0}));
    ASSERT_EQ(s.bounds().hi, (Vec3{16, 16, 16}));
    // max_prims 1: x = 8 separates B; y = 8 and z = 8 cut off empty halves; x = 4 separates A
    // from C. Leaves: B (depth 1), two empty (depths 2, 3), A and C (depth 4).
    auto h = build_hierarchy(s, "bsp", {"max_prims=1"});
    expect_stats(*h, 4, 5, 2, 3, 4, "max_prims=1");
    const auto& b = dynamic_cast<const bsp::Bsp&>(*h);
    ASSERT_EQ(b.nodes().size(), 9u);
    EXPECT_EQ(b.nodes()[0].axis, 0u);
    EXPECT_EQ(b.nodes()[0].split, 8.0f);
    // max_prims 2: the root split alone.
    expect_stats(*build_hierarchy(s, "bsp", {"max_prims=2"}), 1, 2, 0, 3, 1, "max_prims=2");
    // max_depth 0: one leaf holding everything; max_depth 2 stops above A and C.
    expect_stats(*build_hierarchy(s, "bsp", {"max_depth=0"}), 0, 1, 0, 3, 0, "max_depth=0");
    expect_stats(*build_hierarchy(s, "bsp", {"max_prims=1", "max_depth=2"}), 2, 3, 1, 3, 2, "max_depth=2");
}

TEST(BspStructure, ModelTreeMirrorsTheNodes) {
    Scene s = abc_scene();
    for (const char* trav : {"traversal=locate", "traversal=recursive"}) {
        auto h = build_hierarchy(s, "bsp", {"max_prims=1", trav});
        ModelTree t = h->model_tree();
        EXPECT_EQ(t.family, ModelFamily::Bsp);
        EXPECT_EQ(t.locate, std::string(trav) == "traversal=locate");
        ASSERT_EQ(t.nodes.size(), 9u);
        EXPECT_EQ(t.nodes[0].region.hi, (Vec3{16, 16, 16}));
        EXPECT_EQ(t.nodes[0].plane, 1.0f);
        EXPECT_EQ(t.nodes[0].axis, 0);
        // The root's children: [0,8] x [0,16]^2 (interior, y = 8) and the leaf holding B.
        const ModelNode& lo = t.nodes[t.nodes[0].first];
        const ModelNode& hi = t.nodes[t.nodes[0].first + 1];
        EXPECT_EQ(lo.region.hi, (Vec3{8, 16, 16}));
        EXPECT_EQ(lo.axis, 1);
        EXPECT_EQ(lo.split, 8.0f);
        EXPECT_TRUE(hi.leaf);
        EXPECT_EQ(hi.region.lo, (Vec3{8, 0, 0}));
        EXPECT_EQ(leaf_refs_sorted(t, hi), (std::vector<std::uint32_t>{1}));
        std::size_t leaves = 0;
        for (const ModelNode& m : t.nodes) {
            leaves += m.leaf;
            EXPECT_TRUE(m.step);
            EXPECT_EQ(m.plane, m.leaf ? 0.0f : 1.0f);
        }
        EXPECT_EQ(leaves, 5u);
    }
}

TEST(OctreeStructure, ExactCountsOnThreeSpheres) {
    Scene s = abc_scene();
    // max_prims 1: the root's octant 0 holds A and C (split again: A in its octant 0, C in its
    // octant 1), octant 7 holds B; 12 empty leaves.
    auto h = build_hierarchy(s, "octree");
    expect_stats(*h, 2, 15, 12, 3, 2, "default");
    const auto& o = dynamic_cast<const octree::Octree&>(*h);
    ASSERT_EQ(o.nodes().size(), 17u);
    EXPECT_EQ(o.nodes()[0].center, (Vec3{8, 8, 8}));
    EXPECT_FALSE(o.nodes()[1].leaf());  // octant 0
    EXPECT_EQ(o.nodes()[1].center, (Vec3{4, 4, 4}));
    EXPECT_EQ(o.nodes()[8].count, 1u);  // octant 7: B
    expect_stats(*build_hierarchy(s, "octree", {"max_prims=2"}), 1, 8, 6, 3, 1, "max_prims=2");
    expect_stats(*build_hierarchy(s, "octree", {"max_depth=0"}), 0, 1, 0, 3, 0, "max_depth=0");
    expect_stats(*build_hierarchy(s, "octree", {"max_depth=1"}), 1, 8, 6, 3, 1, "max_depth=1");
}

TEST(OctreeStructure, ModelTreeIsThreeBinaryLevelsPerNode) {
    Scene s = abc_scene();
    ModelTree t = build_hierarchy(s, "octree")->model_tree();
    EXPECT_EQ(t.family, ModelFamily::Octree);
    EXPECT_TRUE(t.locate);
    // Two octree interior nodes: 2 x (1 + 2 + 4) binary nodes, and 15 leaves.
    ASSERT_EQ(t.nodes.size(), 14u + 15u);
    std::size_t steps = 0, leaves = 0;
    for (std::size_t i = 0; i < t.nodes.size(); ++i) {
        const ModelNode& m = t.nodes[i];
        if (m.leaf) {
            ++leaves;
            EXPECT_TRUE(m.step);
            continue;
        }
        EXPECT_EQ(m.count, 2u);
        EXPECT_GT(m.first, i);  // parents before children
        if (m.step) {
            ++steps;
            EXPECT_EQ(m.axis, 0);
            EXPECT_EQ(m.plane, 3.0f);
        } else {
            EXPECT_NE(m.axis, 0);
            EXPECT_EQ(m.plane + m.box + m.hop + m.classify, 0.0f);
        }
        // Children are the halves of the region at the split.
        const ModelNode& a = t.nodes[m.first];
        const ModelNode& b = t.nodes[m.first + 1];
        EXPECT_EQ(a.region.hi[m.axis], m.split);
        EXPECT_EQ(b.region.lo[m.axis], m.split);
        EXPECT_EQ(a.region.lo, m.region.lo);
        EXPECT_EQ(b.region.hi, m.region.hi);
        EXPECT_EQ(a.depth, m.depth + 1);
    }
    EXPECT_EQ(steps, 2u);
    EXPECT_EQ(leaves, 15u);
    // The leaf of octant 7 ([8,16]^3) holds B alone, at model depth 3.
    bool found = false;
    for (const ModelNode& m : t.nodes)
        if (m.leaf && m.region.lo == Vec3{8, 8, 8} && m.region.hi == Vec3{16, 16, 16}) {
            found = true;
            EXPECT_EQ(m.depth, 3);
            EXPECT_EQ(leaf_refs_sorted(t, m), (std::vector<std::uint32_t>{1}));
        }
    EXPECT_TRUE(found);
}

// Three concentric spheres: every reference straddles every centre, so subdividing separates
// nothing; the guard keeps the root a leaf, growth=9 switches it off.
TEST(OctreeStructure, GrowthGuardStopsWhereNothingSeparates) {
    Scene s;
    s.add(Sphere{{0, 0, 0}, 2}, 0);
    s.add(Sphere{{0, 0, 0}, 1}, 0);
    s.add(Sphere{{0, 0, 0}, 1.5f}, 0);
    s.finalize();
    expect_stats(*build_hierarchy(s, "octree"), 0, 1, 0, 3, 0, "octree guarded");
    expect_stats(*build_hierarchy(s, "bsp"), 0, 1, 0, 3, 0, "bsp guarded");
    // Unguarded to depth 2: every one of the 64 cells touches all three boxes (closed).
    expect_stats(*build_hierarchy(s, "octree", {"growth=9", "max_depth=2"}), 9, 64, 0, 192, 2, "octree unguarded");
    expect_stats(*build_hierarchy(s, "bsp", {"growth=9", "max_depth=3"}), 7, 8, 0, 24, 3, "bsp unguarded");
}

TEST(BspOctreeStructure, TreeInvariantsOnBuiltinAndSpdScenes) {
    std::vector<Scene> scenes;
    scenes.push_back(builtin_scene("balls", 2));
    scenes.push_back(builtin_scene("tetra", 4));
    if (std::filesystem::exists(spd_path("gears"))) scenes.push_back(load_scene(spd_path("gears")));
    for (const Scene& s : scenes) {
        for (const Set& set : {Set{}, Set{"assign=exact"}, Set{"max_prims=4", "max_depth=6"}}) {
            StructureStats b = build_hierarchy(s, "bsp", set)->structure();
            EXPECT_EQ(b.leaves, b.interior + 1) << s.name;
            EXPECT_LE(b.depth, 20);
            StructureStats o = build_hierarchy(s, "octree", set)->structure();
            EXPECT_EQ(o.leaves, 7 * o.interior + 1) << s.name;
            EXPECT_LE(o.depth, 8);
            if (set.empty()) {
                // Bounds assignment: every primitive is in at least one leaf.
                EXPECT_GE(b.references, s.size());
                EXPECT_GE(o.references, s.size());
            }
        }
    }
}

// Every leaf holds exactly the primitives whose boxes meet its cell (bounds), or a subset of
// them that includes every primitive whose surface meets the cell (exact); checked by sampling
// each surface and descending the model tree to every cell holding the sample.
void check_assignment(const Scene& s, const std::string& name, bool exact, std::size_t& tighter) {
    auto h = build_hierarchy(s, name, {exact ? "assign=exact" : "assign=bounds", "max_prims=2"});
    ModelTree t = h->model_tree();
    std::vector<std::set<std::uint32_t>> in_leaf(t.nodes.size());
    for (std::size_t i = 0; i < t.nodes.size(); ++i) {
        const ModelNode& m = t.nodes[i];
        if (!m.leaf) continue;
        for (std::uint32_t k = 0; k < m.count; ++k) in_leaf[i].insert(t.prims[m.first + k]);
        std::size_t meets = 0;
        for (std::uint32_t id = 0; id < s.size(); ++id) {
            const bool box = s.prim_bounds(id).overlaps(m.region);
            if (!exact) {
                EXPECT_EQ(in_leaf[i].count(id), box ? 1u : 0u) << name << " leaf " << i << " prim " << id;
            } else if (in_leaf[i].count(id)) {
                EXPECT_TRUE(box) << name;
            }
            meets += box;
        }
        tighter += meets - in_leaf[i].size();
    }
    if (!exact) return;
    // Surface samples (in double, rounded): each must be referenced by every cell holding it
    // with a margin (a sample a rounding error from a face says nothing about that face).
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(0, 1);
    const float margin = 1e-5f * length(s.bounds().extent());
    std::size_t checked = 0;
    for (std::uint32_t id = 0; id < s.size(); ++id) {
        const PrimRef& p = s.prims[id];
        std::vector<Vec3> pts;
        for (int n = 0; n < 60; ++n) {
            double a = u(rng), b = u(rng);
            if (a + b > 1) { a = 1 - a; b = 1 - b; }
            if (p.kind == PrimKind::Triangle) {
                const Triangle& tr = s.triangles[p.index];
                pts.push_back(tr.v0 + (tr.v1 - tr.v0) * float(a) + (tr.v2 - tr.v0) * float(b));
            } else if (p.kind == PrimKind::Polygon) {
                const Polygon& pg = s.polygons[p.index];
                const Vec3* v = s.polygon_vertices.data() + pg.first;
                const std::uint32_t k = 1 + static_cast<std::uint32_t>(n) % (pg.count - 2);  // fan triangle
                pts.push_back(v[0] + (v[k] - v[0]) * float(a) + (v[k + 1] - v[0]) * float(b));
            } else if (p.kind == PrimKind::Sphere) {
                const Sphere& sp = s.spheres[p.index];
                const double z = 2 * u(rng) - 1, phi = 2 * 3.14159265358979 * u(rng), r = std::sqrt(1 - z * z);
                pts.push_back(sp.center + Vec3{float(r * std::cos(phi)), float(r * std::sin(phi)), float(z)} * sp.radius);
            }
        }
        for (const Vec3& q : pts) {
            std::vector<std::uint32_t> stack{0};
            while (!stack.empty()) {
                const std::uint32_t i = stack.back();
                stack.pop_back();
                const ModelNode& m = t.nodes[i];
                const Box3 inner{m.region.lo + Vec3{margin, margin, margin}, m.region.hi - Vec3{margin, margin, margin}};
                if (!m.region.contains(q)) continue;
                if (!m.leaf) {
                    for (std::uint32_t k = 0; k < m.count; ++k) stack.push_back(m.first + k);
                    continue;
                }
                if (!inner.contains(q)) continue;
                ++checked;
                EXPECT_EQ(in_leaf[i].count(id), 1u) << name << ": prim " << id << " meets leaf " << i;
            }
        }
    }
    EXPECT_GT(checked, s.size() * 30);
}

TEST(BspOctreeAssign, ExactNeverReferencesFewerCellsThanTheSurfaceMeets) {
    for (auto [scene, level] : {std::pair{"balls", 2}, std::pair{"tetra", 3}}) {
        Scene s = builtin_scene(scene, level);
        for (const char* name : {"bsp", "octree"}) {
            std::size_t tighter_bounds = 0, tighter_exact = 0;
            check_assignment(s, name, false, tighter_bounds);
            check_assignment(s, name, true, tighter_exact);
            EXPECT_EQ(tighter_bounds, 0u) << name;
            // Spheres' boxes reach cells their surfaces miss (balls); triangles' boxes likewise.
            EXPECT_GT(tighter_exact, 0u) << name << " " << scene;
        }
    }
}

// --- hits ------------------------------------------------------------------------------------

// Kaplan's and Glassner's own hit checks: the variants bsp and octree declare for them.
std::vector<Variant> subdivision_variants() { return registered_variants(kTestSubdivision); }

void expect_all_match(const Scene& s, const std::vector<Ray>& rays, const std::string& what,
                      const std::vector<Variant>& variants = subdivision_variants()) {
    expect_variants_match_brute(s, rays, what, variants);
}

TEST(BspOctreeHits, BuiltinScenesMatchBruteForceExactly) {
    for (auto [name, level] : {std::pair{"balls", 2}, std::pair{"tetra", 4}}) {
        Scene s = builtin_scene(name, level);
        expect_all_match(s, hard_rays(s, 15000, 5), name);
    }
}

TEST(BspOctreeHits, SpdScenesMatchBruteForceExactly) {
    for (const char* name : {"rings", "gears"}) {
        if (!std::filesystem::exists(spd_path(name))) GTEST_SKIP() << spd_path(name) << " not present";
        Scene s = load_scene(spd_path(name));
        expect_all_match(s, hard_rays(s, 6000, 21), name,
                         {{"bsp", {}}, {"bsp", {"traversal=recursive", "assign=exact", "mailbox=1"}},
                          {"octree", {}}, {"octree", {"traversal=recursive", "max_prims=4"}}});
    }
}

// Every split plane of a tree: (axis, position), from its model tree's planes.
std::vector<std::pair<int, float>> planes_of(const Hierarchy& h) {
    std::vector<std::pair<int, float>> out;
    for (const ModelNode& m : h.model_tree().nodes)
        if (!m.leaf) out.push_back({m.axis, m.split});
    return out;
}

// Rays lying in split planes (parallel to an axis, or any direction within the plane), along
// the line where two planes meet, starting on a plane and crossing it, and aimed at points where
// three planes meet; origins inside and outside the box.
std::vector<Ray> plane_rays(const Hierarchy& h, const Box3& box, std::uint64_t seed) {
    auto planes = planes_of(h);
    std::mt19937 rng(static_cast<std::uint32_t>(seed));
    std::uniform_real_distribution<float> u(0, 1);
    std::array<std::vector<float>, 3> by_axis;
    for (auto [a, s] : planes) by_axis[a].push_back(s);
    for (int a = 0; a < 3; ++a)
        if (by_axis[a].empty()) by_axis[a].push_back(box.center()[a]);
    auto plane = [&](int a) {
        return by_axis[a][std::uniform_int_distribution<std::size_t>(0, by_axis[a].size() - 1)(rng)];
    };
    auto point = [&](float grow) {
        Vec3 lo = box.lo - box.extent() * grow, size = box.extent() * (1 + 2 * grow);
        return lo + Vec3{u(rng) * size.x, u(rng) * size.y, u(rng) * size.z};
    };
    std::vector<Ray> rays;
    for (int n = 0; n < 8000; ++n) {
        const int a = n % 3, b = (a + 1) % 3, c = (a + 2) % 3;
        const float sign = (n / 3) % 2 ? 1.0f : -1.0f;
        Ray r;
        r.o = point(n % 4 == 0 ? 0.0f : 0.3f);  // a quarter start inside the box
        r.o[a] = plane(a);
        switch ((n / 6) % 4) {
            case 0:
                r.d = Vec3{0, 0, 0};
                r.d[b] = sign;
                break;
            case 1:
                r.o[b] = plane(b);
                r.d = Vec3{0, 0, 0};
                r.d[c] = sign;
                break;
            case 2:
                r.d = Vec3{0, 0, 0};
                r.d[b] = u(rng) * 2 - 1;
                r.d[c] = u(rng) * 2 - 1;
                if (r.d == Vec3{0, 0, 0}) r.d[b] = 1;
                break;
            default:
                r.d = Vec3{u(rng) * 2 - 1, u(rng) * 2 - 1, u(rng) * 2 - 1};
                r.d[a] = sign * (0.1f + u(rng));
                break;
        }
        rays.push_back(r);
    }
    for (int n = 0; n < 3000; ++n) {
        Ray r;
        r.o = point(0.5f);
        r.d = Vec3{plane(0), plane(1), plane(2)} - r.o;
        if (r.d == Vec3{0, 0, 0}) continue;
        rays.push_back(r);
    }
    return rays;
}

TEST(BspOctreeHits, RaysInSplitPlanesMatchBruteForce) {
    for (auto [scene, level] : {std::pair{"balls", 2}, std::pair{"tetra", 4}}) {
        Scene s = builtin_scene(scene, level);
        for (const char* name : {"bsp", "octree"}) {
            auto h = build_hierarchy(s, name);
            auto rays = plane_rays(*h, s.bounds(), 99);
            std::vector<std::pair<std::string, Set>> variants;
            for (const auto& v : subdivision_variants())
                if (v.first == name) variants.push_back(v);
            expect_all_match(s, rays, std::string(scene) + " plane rays", variants);
        }
    }
}

// Primitives whose boxes lie exactly on split planes and vertices on plane corners: a cube of
// 12 triangles [4,12]^3 and a unit cube [0,1]^3 (so the box is [0,12]^3, centre 6), triangles in
// the planes x = 6, y = 3 and z = 6, and rays aimed at every vertex and along the planes.
TEST(BspOctreeHits, PrimitivesOnPlanesAndRaysThroughTheirVertices) {
    Scene s;
    auto cube = [&](Vec3 lo, Vec3 hi) {
        Vec3 v[8];
        for (int k = 0; k < 8; ++k) v[k] = {k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z};
        const int f[6][4] = {{0, 1, 3, 2}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 3, 7, 5}};
        for (const auto& q : f) {
            s.add(Triangle{v[q[0]], v[q[1]], v[q[2]]}, 0);
            s.add(Triangle{v[q[0]], v[q[2]], v[q[3]]}, 0);
        }
    };
    cube({4, 4, 4}, {12, 12, 12});
    cube({0, 0, 0}, {1, 1, 1});
    s.add(Triangle{{6, 1, 1}, {6, 5, 2}, {6, 2, 7}}, 0);
    s.add(Triangle{{1, 3, 1}, {9, 3, 2}, {2, 3, 9}}, 0);
    s.add(Triangle{{7, 7, 6}, {11, 8, 6}, {8, 11, 6}}, 0);
    s.finalize();
    ASSERT_EQ(s.bounds().hi, (Vec3{12, 12, 12}));
    std::vector<Ray> rays = hard_rays(s, 4000, 17);
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-2, 14);
    const float coords[] = {0, 1, 1.5f, 2, 3, 4, 6, 7, 8, 9, 10, 12};
    for (int n = 0; n < 6000; ++n) {
        Ray r;
        r.o = {u(rng), u(rng), u(rng)};
        Vec3 target{coords[n % 12], coords[(n / 12) % 12], coords[(n / 144) % 12]};
        if (n % 3 == 0) {
            // Axis-parallel along a plane line.
            const int a = (n / 3) % 3;
            r.o = target;
            r.o[a] = (n / 9) % 2 ? -1.0f : 13.0f;
            r.d = Vec3{0, 0, 0};
            r.d[a] = (n / 9) % 2 ? 1.0f : -1.0f;
        } else {
            r.d = target - r.o;
        }
        if (r.d == Vec3{0, 0, 0}) continue;
        rays.push_back(r);
    }
    expect_all_match(s, rays, "cubes");
    std::vector<std::pair<std::string, Set>> deep = {
        {"bsp", {"max_prims=1"}}, {"bsp", {"max_prims=1", "traversal=recursive"}},
        {"octree", {"max_depth=6"}}, {"octree", {"max_depth=6", "traversal=recursive"}}};
    expect_all_match(s, rays, "cubes deep", deep);
}

TEST(BspOctreeHits, SegmentsWithTminAndTmaxMatchBruteForce) {
    Scene s = builtin_scene("balls", 2);
    std::vector<Ray> rays = hard_rays(s, 6000, 8);
    std::mt19937 rng(4);
    std::uniform_real_distribution<float> u(0, 1);
    const float size = length(s.bounds().extent());
    for (Ray& r : rays) {
        r.tmin = u(rng) * size / length(r.d);
        r.tmax = r.tmin + u(rng) * size / length(r.d);
    }
    expect_all_match(s, rays, "segments");
}

TEST(BspOctreeHits, AnyHitAndAllHitsAgreeWithBruteForce) {
    Scene s = builtin_scene("tetra", 4);
    auto rays = hard_rays(s, 4000, 13);
    auto brute = build_hierarchy(s, "brute");
    std::vector<Hit> want = closest_hits(*brute, rays);
    for (const auto& [name, set] : subdivision_variants()) {
        auto h = build_hierarchy(s, name, set);
        std::size_t bad = 0;
        for (std::size_t i = 0; i < rays.size(); ++i) {
            Hit any, all;
            bad += h->any(rays[i], any) != want[i].hit();
            h->all(rays[i], all);
            bad += all.t != want[i].t;
        }
        EXPECT_EQ(bad, 0u) << name << " " << ::testing::PrintToString(set);
    }
}

// --- counters --------------------------------------------------------------------------------

TEST(BspCounters, LocateDescendsFromTheRootForEveryCell) {
    Scene s = abc_scene();
    auto loc = build_hierarchy(s, "bsp", {"max_prims=1"});
    auto rec = build_hierarchy(s, "bsp", {"max_prims=1", "traversal=recursive"});
    Hit hit;
    // Along x at y = z = 1.5: the first cell ([0,4] x [0,8]^2, depth 4) holds A, hit at x = 0.
    const Ray first{{-1, 1.5f, 1.5f}, {1, 0, 0}, 0, kInf};
    for (const Hierarchy* h : {loc.get(), rec.get()}) {
        RayCounters c = count_one(*h, first, hit);
        EXPECT_EQ(hit.prim, 0);
        EXPECT_FLOAT_EQ(hit.t, 1.0f);
        EXPECT_EQ(c.box, 1u);
        EXPECT_EQ(c.plane, 4u);
        EXPECT_EQ(c.steps, 5u);
        EXPECT_EQ(c.leaves, 1u);
        EXPECT_EQ(c.prim_tests(), 1u);
        EXPECT_EQ(c.visits[4], 1u);
    }
    // At y = 12, z = 1.5: the empty cell [0,8] x [8,16] x [0,16] (depth 2), then B's cell
    // (depth 1), missing B. locate: two descents (root, y-node; root); recursive: each node once.
    const Ray miss{{-1, 12, 1.5f}, {1, 0, 0}, 0, kInf};
    RayCounters c = count_one(*loc, miss, hit);
    EXPECT_FALSE(hit.hit());
    EXPECT_EQ(c.plane, 3u);
    EXPECT_EQ(c.steps, 5u);
    EXPECT_EQ(c.leaves, 2u);
    EXPECT_EQ(c.empty_leaves, 1u);
    EXPECT_EQ(c.prim_tests(), 1u);
    EXPECT_EQ(c.visits[0], 2u);
    c = count_one(*rec, miss, hit);
    EXPECT_EQ(c.plane, 2u);
    EXPECT_EQ(c.steps, 4u);
    EXPECT_EQ(c.leaves, 2u);
    EXPECT_EQ(c.visits[0], 1u);
    // The same ray backwards visits B's cell first: it ends in the empty one, the same counts.
    const Ray back{{17, 12, 1.5f}, {-1, 0, 0}, 0, kInf};
    EXPECT_EQ(count_one(*loc, back, hit).steps, 5u);
    EXPECT_EQ(count_one(*rec, back, hit).steps, 4u);
}

TEST(OctreeCounters, OneStepAndThreeComparesPerNodeVisit) {
    Scene s = abc_scene();
    auto loc = build_hierarchy(s, "octree");
    auto rec = build_hierarchy(s, "octree", {"traversal=recursive"});
    Hit hit;
    // At y = 12, z = 1.5: octants 2 and 3 of the root, both empty leaves.
    const Ray miss{{-1, 12, 1.5f}, {1, 0, 0}, 0, kInf};
    RayCounters c = count_one(*loc, miss, hit);
    EXPECT_FALSE(hit.hit());
    EXPECT_EQ(c.box, 1u);
    EXPECT_EQ(c.steps, 4u);  // root, leaf, root, leaf
    EXPECT_EQ(c.plane, 6u);
    EXPECT_EQ(c.leaves, 2u);
    EXPECT_EQ(c.empty_leaves, 2u);
    EXPECT_EQ(c.prim_tests(), 0u);
    c = count_one(*rec, miss, hit);
    EXPECT_EQ(c.steps, 3u);
    EXPECT_EQ(c.plane, 3u);
    EXPECT_EQ(c.leaves, 2u);
    // At y = z = 1.5 from x = 17 backwards: octant 1 (empty), then octant 0 of the root, in it
    // octant 1 (C, hit at x = 7) -- and the search ends there.
    const Ray back{{17, 1.5f, 1.5f}, {-1, 0, 0}, 0, kInf};
    c = count_one(*loc, back, hit);
    EXPECT_EQ(hit.prim, 2);
    EXPECT_FLOAT_EQ(hit.t, 10.0f);
    EXPECT_EQ(c.steps, 5u);  // root, leaf; root, node, leaf
    EXPECT_EQ(c.plane, 9u);
    EXPECT_EQ(c.leaves, 2u);
    EXPECT_EQ(c.prim_tests(), 1u);
    EXPECT_EQ(c.visits[2], 1u);
    c = count_one(*rec, back, hit);
    EXPECT_FLOAT_EQ(hit.t, 10.0f);
    EXPECT_EQ(c.steps, 4u);
    EXPECT_EQ(c.plane, 6u);
}

TEST(BspOctreeCounters, RayMissingTheBoxCostsOneBoxTestAndEmptySceneToo) {
    Scene s = abc_scene();
    Scene empty;
    empty.finalize();
    for (const auto& [name, set] : subdivision_variants()) {
        for (const Scene* sc : {&s, &empty}) {
            auto h = build_hierarchy(*sc, name, set);
            Hit hit;
            RayCounters c = count_one(*h, Ray{{100, 100, 100}, {1, 0, 0}, 0, kInf}, hit);
            EXPECT_FALSE(hit.hit());
            EXPECT_EQ(c.box, 1u);
            EXPECT_EQ(c.steps + c.plane + c.prim_tests(), 0u);
        }
    }
}

TEST(BspOctreeCounters, CountingDoesNotChangeHitsAndInvariantsHold) {
    Scene s = builtin_scene("balls", 2);
    auto rays = hard_rays(s, 5000, 3);
    for (const auto& [name, set] : subdivision_variants()) {
        auto h = build_hierarchy(s, name, set);
        TraceOptions opt;
        TraceResult fast = trace_rays(*h, rays, opt);
        opt.count = true;
        TraceResult counted = trace_rays(*h, rays, opt);
        std::string first;
        EXPECT_EQ(count_mismatches(fast.hits, counted.hits, 0.0f, &first), 0u) << name << ": " << first;
        const RayCounters& c = counted.counters;
        EXPECT_EQ(c.box, rays.size());
        EXPECT_EQ(c.hop + c.classify, 0u);
        const std::uint64_t interior = c.steps - c.leaves;
        EXPECT_EQ(c.plane, (name == "octree" ? 3 : 1) * interior) << name;
        std::uint64_t visits = 0;
        for (auto v : c.visits) visits += v;
        EXPECT_EQ(visits, c.steps);
        if (h->structure().interior > 0) {
            EXPECT_LT(c.leaves, c.steps);
        }
    }
}

TEST(BspOctreeCounters, LocateCostsMoreStepsThanRecursiveWithTheSameLeavesAndTests) {
    Scene s = builtin_scene("tetra", 4);
    auto rays = hard_rays(s, 3000, 6);
    for (const char* name : {"bsp", "octree"}) {
        auto loc = build_hierarchy(s, name);
        auto rec = build_hierarchy(s, name, {"traversal=recursive"});
        std::size_t more = 0;
        for (const Ray& r : rays) {
            RayCounters a, b;
            Hit ha, hb;
            loc->closest(r, ha, a);
            rec->closest(r, hb, b);
            EXPECT_EQ(ha.t, hb.t);
            // The same cells in the same order (a ray in a plane may differ by a repeated cell).
            if (a.leaves != b.leaves) continue;
            EXPECT_EQ(a.prim_tests(), b.prim_tests());
            EXPECT_GE(a.steps, b.steps);
            more += a.steps > b.steps;
        }
        EXPECT_GT(more, rays.size() / 10) << name;
    }
}

// A long thin triangle referenced by every cell of a row of small spheres; a ray along the row
// inside every box but hitting nothing tests each primitive once with mailbox=1.
TEST(BspOctreeMailbox, EachPrimitiveTestedOnceAlongARow) {
    Scene s;
    s.add(Triangle{{0, 0, 0}, {16, 0, 0}, {16, 0.5f, 0.5f}}, 0);
    s.add(Sphere{{15, 15, 15}, 1}, 0);
    for (int k = 0; k < 8; ++k) s.add(Sphere{{1.0f + 2 * k, 0.25f, 0.25f}, 0.2f}, 0);
    s.finalize();
    // (y, z) = (0.44, 0.40): inside every box, off the triangle's plane y = z, 0.24 from the spheres' axis.
    const Ray r{{-1, 0.44f, 0.40f}, {1, 0, 0}, 0, kInf};
    for (const char* name : {"bsp", "octree"}) {
        for (const char* trav : {"traversal=locate", "traversal=recursive"}) {
            auto with = build_hierarchy(s, name, {"mailbox=1", "max_prims=1", trav});
            auto without = build_hierarchy(s, name, {"max_prims=1", trav});
            Hit a, b;
            RayCounters ca = count_one(*with, r, a), cb = count_one(*without, r, b);
            EXPECT_FALSE(a.hit());
            EXPECT_FALSE(b.hit());
            EXPECT_EQ(ca.prim[static_cast<int>(PrimKind::Triangle)], 1u) << name << " " << trav;
            EXPECT_EQ(ca.prim[static_cast<int>(PrimKind::Sphere)], 8u) << name << " " << trav;
            EXPECT_GT(cb.prim[static_cast<int>(PrimKind::Triangle)], 4u) << name << " " << trav;
            EXPECT_EQ(ca.leaves, cb.leaves);
        }
    }
}

TEST(BspOctreeMailbox, SameHitsAndNeverMoreTests) {
    Scene s = builtin_scene("balls", 2);
    auto rays = hard_rays(s, 4000, 12);
    for (const char* name : {"bsp", "octree"}) {
        for (const char* trav : {"traversal=locate", "traversal=recursive"}) {
            auto with = build_hierarchy(s, name, {"mailbox=1", trav});
            auto without = build_hierarchy(s, name, {trav});
            std::uint64_t fewer = 0;
            for (const Ray& r : rays) {
                Hit a, b;
                RayCounters ca, cb;
                with->all(r, a, ca);
                without->all(r, b, cb);
                EXPECT_EQ(a.t, b.t);
                EXPECT_LE(ca.prim_tests(), cb.prim_tests());
                EXPECT_LE(ca.prim_tests(), s.size());
                EXPECT_EQ(ca.steps, cb.steps);
                fewer += ca.prim_tests() < cb.prim_tests();
            }
            EXPECT_GT(fewer, 100u) << name << " " << trav;
        }
    }
}

TEST(BspOctreeParams, AreValidated) {
    Scene s = abc_scene();
    for (const char* name : {"bsp", "octree"}) {
        EXPECT_THROW(build_hierarchy(s, name, {"traversal=sideways"}), InputError);
        EXPECT_THROW(build_hierarchy(s, name, {"max_depth=-1"}), InputError);
        EXPECT_THROW(build_hierarchy(s, name, {"max_depth=99"}), InputError);
        EXPECT_THROW(build_hierarchy(s, name, {"max_prims=0"}), InputError);
        EXPECT_THROW(build_hierarchy(s, name, {"growth=0.5"}), InputError);
        EXPECT_THROW(build_hierarchy(s, name, {"assign=maybe"}), InputError);
        EXPECT_NO_THROW(build_hierarchy(s, name, {"traversal=recursive", "assign=exact", "mailbox=1"}));
    }
}

// --- model -----------------------------------------------------------------------------------

TEST(BspOctreeModel, ExactForQueryAllOnBuiltinScenes) {
    Scene balls = builtin_scene("balls", 2), tetra = builtin_scene("tetra", 4);
    for (const char* name : {"bsp", "octree"}) {
        for (const Set& set : {Set{}, Set{"traversal=recursive"}}) {
            expect_model_exact(balls, name, set);
            expect_model_exact(tetra, name, set);
        }
    }
}

}  // namespace
}  // namespace rtcost::test
