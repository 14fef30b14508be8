// The kd-trees (`kd-median`, `kd-sah`): exact structure on constructed scenes, exact assignment,
// exact hits against brute force (rays in split planes, along plane intersections, starting
// inside, axis-parallel, max_depth 0), counters, mailboxing and the model's exactness.
#include <random>
#include <set>

#include "../src/hierarchy/kd/float_sort.hpp"
#include "../src/hierarchy/kd/kdtree.hpp"
#include "test_support.hpp"

namespace rtcost::test {
namespace {

// The variants checked here (the lead's cross-check lists the main ones).
const std::vector<std::pair<std::string, std::vector<std::string>>> kKdVariants = {
    {"kd-median", {}},
    {"kd-median", {"max_prims=3", "assign=exact", "mailbox=1"}},
    {"kd-median", {"max_depth=0"}},
    {"kd-sah", {}},
    {"kd-sah", {"assign=exact", "mailbox=1"}},
    {"kd-sah", {"max_prims=4", "empty_bonus=0", "c_trav=1", "c_isect=1.5"}},
    {"kd-sah", {"max_depth=0"}},
};

// A unit triangle spanning x in [x0, x0 + 1], y and z in [0, 1].
Triangle unit_tri(float x0) { return Triangle{{x0, 0, 0}, {x0 + 1, 1, 0}, {x0, 1, 1}}; }

// --- structure -------------------------------------------------------------------------------

TEST(KdBuild, EdgeSortAndNeighbouringFloatsEqualTheStandardLibrarys) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-1000, 1000);
    const float specials[] = {0.0f, -0.0f, 1e-40f, -1e-40f, std::numeric_limits<float>::denorm_min(),
                              -std::numeric_limits<float>::max(), std::numeric_limits<float>::max(), 1.0f, -1.0f};
    std::vector<float> scratch;
    for (std::size_t n : {0u, 1u, 5u, 1023u, 1024u, 5000u, 70000u}) {
        std::vector<float> v(n);
        for (std::size_t i = 0; i < n; ++i) v[i] = i % 7 == 0 ? specials[i % 9] : (i % 3 ? u(rng) : std::round(u(rng)));
        std::vector<float> want = v;
        std::sort(want.begin(), want.end());
        kd::sort_floats(v, scratch);
        ASSERT_EQ(v.size(), n);
        EXPECT_TRUE(std::is_sorted(v.begin(), v.end())) << n;
        // Equal values in the same places (-0 and +0 compare equal).
        EXPECT_TRUE(std::equal(v.begin(), v.end(), want.begin())) << n;
    }
    for (float x : specials) {
        EXPECT_EQ(std::bit_cast<std::uint32_t>(kd::float_below(x)), std::bit_cast<std::uint32_t>(std::nextafter(x, -kInf))) << x;
        EXPECT_EQ(std::bit_cast<std::uint32_t>(kd::float_above(x)), std::bit_cast<std::uint32_t>(std::nextafter(x, kInf))) << x;
    }
    for (int i = 0; i < 1000; ++i) {
        const float x = u(rng);
        EXPECT_EQ(kd::float_below(x), std::nextafter(x, -kInf));
        EXPECT_EQ(kd::float_above(x), std::nextafter(x, kInf));
    }
}

TEST(KdStructure, MedianCutOnFourTrianglesInARow) {
    // x ranges [0,1], [2,3], [4,5], [6,7]; y and z span the whole box, so only x can separate.
    // Root: the gap (3, 4) balances 2 / 2 with no straddler: plane 3.5. Then (1, 2) and (5, 6).
    Scene s;
    for (float x : {0.0f, 2.0f, 4.0f, 6.0f}) s.add(unit_tri(x), 0);
    s.finalize();
    auto h = build_hierarchy(s, "kd-median");
    StructureStats st = h->structure();
    EXPECT_EQ(st.interior, 3u);
    EXPECT_EQ(st.leaves, 4u);  // N_V = N_IN + 1
    EXPECT_EQ(st.empty_leaves, 0u);
    EXPECT_EQ(st.references, 4u);
    EXPECT_EQ(st.depth, 2);
    EXPECT_EQ(st.bytes, 7 * sizeof(kd::Node) + 4 * sizeof(std::uint32_t) + 7 * sizeof(Box3));
    ModelTree t = h->model_tree();
    ASSERT_EQ(t.nodes.size(), 7u);
    EXPECT_EQ(t.family, ModelFamily::Kd);
    const ModelNode& root = t.nodes[0];
    EXPECT_EQ(root.axis, 0);
    EXPECT_EQ(root.split, 3.5f);
    EXPECT_TRUE(root.has_bv);
    EXPECT_EQ(root.bv.lo, (Vec3{0, 0, 0}));
    EXPECT_EQ(root.bv.hi, (Vec3{7, 1, 1}));
    EXPECT_EQ(root.box, 1.0f);
    EXPECT_EQ(root.plane, 1.0f);
    const ModelNode& l = t.nodes[root.first];
    const ModelNode& r = t.nodes[root.first + 1];
    EXPECT_EQ(l.split, 1.5f);
    EXPECT_EQ(r.split, 5.5f);
    EXPECT_EQ(l.region.hi.x, 3.5f);
    EXPECT_EQ(r.region.lo.x, 3.5f);
    // The left node's box is its primitives' box within the cell: x in [0, 3].
    EXPECT_EQ(l.bv.hi.x, 3.0f);
    EXPECT_EQ(r.bv.lo.x, 4.0f);
    for (std::uint32_t k = 0; k < 2; ++k) {
        EXPECT_TRUE(t.nodes[l.first + k].leaf);
        EXPECT_EQ(t.nodes[l.first + k].count, 1u);
        EXPECT_FALSE(t.nodes[l.first + k].has_bv);
        EXPECT_EQ(t.nodes[l.first + k].depth, 2);
    }
    // Leaves in x order hold primitives 0, 1, 2, 3.
    EXPECT_EQ(t.prims, (std::vector<std::uint32_t>{0, 1, 2, 3}));
}

TEST(KdStructure, MedianCutKeepsStraddlersFew) {
    // Three triangles: [0,1], [0.5,1.5] and [5,6] on x. The gap (1, 1.5) gives 2 / 2 (one
    // straddler), the gap (1.5, 5) 2 / 1 with none: same larger side, fewer straddlers, plane
    // 3.25. The left pair overlaps on x: every gap leaves one side with both (no progress), and
    // y and z (all spanning [0,1]) have no gap: a leaf of 2. N_IN 1, N_V 2, N_OIV 3.
    Scene s;
    s.add(unit_tri(0), 0);
    s.add(unit_tri(0.5f), 0);
    s.add(unit_tri(5), 0);
    s.finalize();
    auto h = build_hierarchy(s, "kd-median");
    StructureStats st = h->structure();
    EXPECT_EQ(st.interior, 1u);
    EXPECT_EQ(st.leaves, 2u);
    EXPECT_EQ(st.references, 3u);
    EXPECT_EQ(st.depth, 1);
    ModelTree t = h->model_tree();
    EXPECT_EQ(t.nodes[0].axis, 0);
    EXPECT_EQ(t.nodes[0].split, 3.25f);
    EXPECT_EQ(t.nodes[1].count, 2u);
    EXPECT_EQ(t.nodes[2].count, 1u);
}

TEST(KdStructure, MedianCutSplitsOverlappingObjectsWhenFewStraddle) {
    // Four triangles [0,1], [0.5,1.5], [2,3], [2.5,3.5] on x: the gap (1.5, 2) splits 2 / 2. In
    // each overlapping pair every gap ((0, 0.5), (0.5, 1), (1, 1.5)) leaves 2 on one side: no
    // progress, leaves of 2. N_IN 1, N_V 2, N_OIV 4.
    Scene s;
    for (float x : {0.0f, 0.5f, 2.0f, 2.5f}) s.add(unit_tri(x), 0);
    s.finalize();
    auto h = build_hierarchy(s, "kd-median");
    StructureStats st = h->structure();
    EXPECT_EQ(st.interior, 1u);
    EXPECT_EQ(st.leaves, 2u);
    EXPECT_EQ(st.references, 4u);
    EXPECT_EQ(h->model_tree().nodes[0].split, 1.75f);
    // max_prims=2: the same tree; max_prims=4: one leaf.
    EXPECT_EQ(build_hierarchy(s, "kd-median", {"max_prims=2"})->structure().interior, 1u);
    EXPECT_EQ(build_hierarchy(s, "kd-median", {"max_prims=4"})->structure().interior, 0u);
}

TEST(KdStructure, SahCutsOffTheFarTriangle) {
    // One triangle at x in [0,1], two at [99,100], y and z in [0,1]. K_T 15, K_I 20, leaf 60.
    // Plane just below 99: N_L 1, N_R 2, S_L/S = 398/402, S_R/S = 6/402: 15 + 20 (398 + 12)/402
    // = 35.4; just above 1: 15 + 20 (6 + 796)/402 = 54.9. The pair at [99,100] cannot be
    // separated (same box) and the single triangle is a leaf: N_IN 1, N_V 2, N_OIV 3.
    Scene s;
    s.add(unit_tri(0), 0);
    s.add(unit_tri(99), 0);
    s.add(unit_tri(99), 0);
    s.finalize();
    auto h = build_hierarchy(s, "kd-sah");
    StructureStats st = h->structure();
    EXPECT_EQ(st.interior, 1u);
    EXPECT_EQ(st.leaves, 2u);
    EXPECT_EQ(st.empty_leaves, 0u);
    EXPECT_EQ(st.references, 3u);
    EXPECT_EQ(st.depth, 1);
    EXPECT_EQ(st.bytes, 3 * sizeof(kd::Node) + 3 * sizeof(std::uint32_t));
    ModelTree t = h->model_tree();
    EXPECT_EQ(t.nodes[0].axis, 0);
    EXPECT_EQ(t.nodes[0].split, std::nextafter(99.0f, 0.0f));
    EXPECT_FALSE(t.nodes[0].has_bv);
    EXPECT_EQ(t.nodes[0].box, 0.0f);
    EXPECT_EQ(t.nodes[0].plane, 1.0f);
    EXPECT_EQ(t.nodes[1].count, 1u);
    EXPECT_EQ(t.nodes[2].count, 2u);
    // With a traversal as costly as two tests the split is not worth it: 40 + 20*410/402 > 60.
    EXPECT_EQ(build_hierarchy(s, "kd-sah", {"c_trav=40"})->structure().interior, 0u);
}

TEST(KdStructure, SahPlaneJustAboveAnEdgeKeepsEndingBoxesOnOneSide) {
    // Two coincident triangles at x in [0,1] (y, z in [0,1]) and a point (a sphere of radius 0)
    // at x = 10 that fixes the box. K_T 1, K_I 1.5, leaf 4.5. A plane exactly at x = 1 would
    // reference the triangles on both sides (closed intervals); one float above 1 they are left
    // only: N_L 2, N_R 1, cost 1 + 1.5 (6 * 2 + 38 * 1) / 42 = 2.79 (just below 10: 4.07).
    Scene s;
    s.add(unit_tri(0), 0);
    s.add(unit_tri(0), 0);
    s.add(Sphere{{10, 0.5f, 0.5f}, 0}, 0);
    s.finalize();
    auto h = build_hierarchy(s, "kd-sah", {"c_trav=1", "c_isect=1.5", "max_prims=2"});
    ModelTree t = h->model_tree();
    ASSERT_FALSE(t.nodes[0].leaf);
    EXPECT_EQ(t.nodes[0].axis, 0);
    EXPECT_EQ(t.nodes[0].split, std::nextafter(1.0f, 2.0f));
    EXPECT_EQ(h->structure().references, 3u);
    EXPECT_EQ(t.nodes[1].count, 2u);
    EXPECT_EQ(t.nodes[2].count, 1u);
}

TEST(KdStructure, SahEmptyBonusCutsMoreEmptySpace) {
    Scene s = builtin_scene("balls", 2);
    const StructureStats with = build_hierarchy(s, "kd-sah")->structure();
    const StructureStats without = build_hierarchy(s, "kd-sah", {"empty_bonus=0"})->structure();
    EXPECT_GT(with.empty_leaves, without.empty_leaves);
}

TEST(KdStructure, MaxDepthZeroIsOneLeaf) {
    Scene s = builtin_scene("tetra", 3);
    for (const char* name : {"kd-median", "kd-sah"}) {
        auto h = build_hierarchy(s, name, {"max_depth=0"});
        StructureStats st = h->structure();
        EXPECT_EQ(st.interior, 0u) << name;
        EXPECT_EQ(st.leaves, 1u) << name;
        EXPECT_EQ(st.references, s.size()) << name;
        EXPECT_EQ(st.depth, 0) << name;
        ModelTree t = h->model_tree();
        ASSERT_EQ(t.nodes.size(), 1u);
        EXPECT_TRUE(t.nodes[0].leaf);
        EXPECT_EQ(t.nodes[0].region.lo, s.bounds().lo);
        EXPECT_EQ(t.nodes[0].region.hi, s.bounds().hi);
    }
}

TEST(KdStructure, InvariantsOnBuiltinScenes) {
    for (const char* scene : {"balls", "tetra"}) {
        Scene s = builtin_scene(scene, scene == std::string("balls") ? 2 : 4);
        for (const auto& [name, set] : kKdVariants) {
            auto h = build_hierarchy(s, name, set);
            StructureStats st = h->structure();
            EXPECT_EQ(st.leaves, st.interior + 1) << name;  // binary
            EXPECT_GE(st.references, s.size()) << name;     // every primitive in some leaf
            EXPECT_LE(st.depth, kd::default_max_depth(s.size())) << name;
            ModelTree t = h->model_tree();
            ASSERT_EQ(t.nodes.size(), st.leaves + st.interior);
            std::set<std::uint32_t> seen(t.prims.begin(), t.prims.end());
            EXPECT_EQ(seen.size(), s.size()) << name;
            for (const ModelNode& m : t.nodes) {
                if (m.leaf) continue;
                // Children tile the parent cell at the plane; the node box lies in the cell.
                const ModelNode& l = t.nodes[m.first];
                const ModelNode& r = t.nodes[m.first + 1];
                EXPECT_EQ(l.region.hi[m.axis], m.split);
                EXPECT_EQ(r.region.lo[m.axis], m.split);
                EXPECT_GT(m.split, m.region.lo[m.axis]);
                EXPECT_LT(m.split, m.region.hi[m.axis]);
                if (m.has_bv) {
                    EXPECT_TRUE(m.region.contains(m.bv.lo) && m.region.contains(m.bv.hi));
                }
            }
        }
        // Auto depth: 8 + 1.3 log2 N.
        EXPECT_EQ(kd::default_max_depth(1024), 21);
    }
}

// Leaves holding point `p` (on a plane, both sides), skipping planes within `eps` of p: those
// leaves contain p without doubt.
void leaves_clearly_containing(const ModelTree& t, std::uint32_t node, Vec3 p, float eps,
                               std::vector<std::uint32_t>& out) {
    const ModelNode& m = t.nodes[node];
    if (m.leaf) {
        out.push_back(node);
        return;
    }
    const float d = p[m.axis] - m.split;
    if (std::fabs(d) <= eps) return;
    leaves_clearly_containing(t, m.first + (d > 0 ? 1 : 0), p, eps, out);
}

TEST(KdAssign, ExactNeverReferencesFewerCellsThanTheSurfaceMeets) {
    // Points sampled on each triangle: every leaf clearly containing one must reference it.
    Scene s = builtin_scene("tetra", 4);
    for (const char* name : {"kd-median", "kd-sah"}) {
        auto exact = build_hierarchy(s, name, {"assign=exact"});
        auto bounds = build_hierarchy(s, name);
        const ModelTree t = exact->model_tree();
        std::vector<std::set<std::uint32_t>> refs(t.nodes.size());
        for (std::size_t i = 0; i < t.nodes.size(); ++i)
            if (t.nodes[i].leaf)
                for (std::uint32_t k = 0; k < t.nodes[i].count; ++k) refs[i].insert(t.prims[t.nodes[i].first + k]);
        const float eps = 1e-5f * length(s.bounds().extent());
        std::size_t checked = 0, missing = 0;
        std::vector<std::uint32_t> leaves;
        for (std::uint32_t id = 0; id < s.size(); ++id) {
            const Triangle& tri = s.triangles[s.prims[id].index];
            for (int i = 0; i <= 12; ++i)
                for (int j = 0; i + j <= 12; ++j) {
                    const float u = i / 12.0f, v = j / 12.0f;
                    const Vec3 p = tri.v0 + (tri.v1 - tri.v0) * u + (tri.v2 - tri.v0) * v;
                    leaves.clear();
                    leaves_clearly_containing(t, 0, p, eps, leaves);
                    for (std::uint32_t leaf : leaves) {
                        ++checked;
                        missing += !refs[leaf].count(id);
                    }
                }
        }
        EXPECT_GT(checked, 10 * s.size()) << name;
        EXPECT_EQ(missing, 0u) << name;
        // Exact drops the cells that only the bounding box reaches: strictly fewer references.
        EXPECT_LT(exact->structure().references, bounds->structure().references) << name;
    }
}

// --- hits against brute force ----------------------------------------------------------------

// Rays lying in split planes (direction component 0 on the plane's axis, origin on the plane),
// along the intersection of two planes (axis-parallel), and crossing planes exactly at a cell
// corner, taken from the tree's own planes.
std::vector<Ray> plane_rays(const Hierarchy& h, std::size_t n, std::uint64_t seed) {
    const ModelTree t = h.model_tree();
    std::vector<const ModelNode*> inner;
    for (const ModelNode& m : t.nodes)
        if (!m.leaf) inner.push_back(&m);
    std::vector<Ray> rays;
    if (inner.empty()) return rays;
    std::mt19937_64 rng(seed);
    const Box3 b = h.scene().bounds();
    auto uni = [&](float lo, float hi) { return std::uniform_real_distribution<float>(lo, hi)(rng); };
    auto pick = [&] { return inner[rng() % inner.size()]; };
    for (std::size_t i = 0; i < n; ++i) {
        const ModelNode& m = *pick();
        const int a = m.axis;
        Vec3 o{uni(b.lo.x - 1, b.hi.x + 1), uni(b.lo.y - 1, b.hi.y + 1), uni(b.lo.z - 1, b.hi.z + 1)};
        if (i % 4 == 3) o = m.region.center();  // starting inside the cell
        o[a] = m.split;
        Vec3 target{uni(m.region.lo.x, m.region.hi.x), uni(m.region.lo.y, m.region.hi.y), uni(m.region.lo.z, m.region.hi.z)};
        target[a] = m.split;
        Vec3 d = target - o;
        if (i % 3 == 1) {
            // Along the line where this plane meets a descendant's plane on another axis.
            const ModelNode* c = &t.nodes[m.first + (i & 1)];
            while (!c->leaf && c->axis == a) c = &t.nodes[c->first + (rng() & 1)];
            if (!c->leaf) {
                o[c->axis] = c->split;
                d = Vec3{0, 0, 0};
                d[3 - a - c->axis] = (i & 2) ? 1.0f : -1.0f;
            }
        }
        d[a] = 0;
        if (d == Vec3{0, 0, 0}) d[(a + 1) % 3] = 1;
        rays.push_back(Ray{o, d, 0, kInf});
        // And a ray through the target, a point of the plane inside the node's cell.
        const Vec3 off{uni(-3, 3), uni(-3, 3), uni(-3, 3)};
        if (!(off == Vec3{0, 0, 0})) rays.push_back(Ray{target - off, off, 0, kInf});
    }
    return rays;
}

void expect_exact_hits(const Scene& s, const std::vector<std::pair<std::string, std::vector<std::string>>>& variants,
                       std::size_t n_random, std::size_t n_plane) {
    auto brute = build_hierarchy(s, "brute");
    std::vector<Ray> rays = hard_rays(s, n_random, 5);
    for (const auto& [name, set] : variants) {
        auto h = build_hierarchy(s, name, set);
        std::vector<Ray> all = rays;
        std::vector<Ray> extra = plane_rays(*h, n_plane, 17);
        all.insert(all.end(), extra.begin(), extra.end());
        std::vector<Hit> want = closest_hits(*brute, all);
        std::vector<Hit> got = closest_hits(*h, all);
        std::string first;
        EXPECT_EQ(count_mismatches(want, got, 0.0f, &first), 0u)
            << s.name << " " << name << " " << ::testing::PrintToString(set) << ": " << first;
        // Any-hit finds a hit exactly when there is one; all-hits finds the closest as well.
        std::size_t bad = 0;
        std::vector<Hit> every(all.size());
        for (std::size_t i = 0; i < all.size(); ++i) {
            Hit any;
            bad += h->any(all[i], any) != want[i].hit();
            h->all(all[i], every[i]);
        }
        EXPECT_EQ(bad, 0u) << s.name << " " << name << " " << ::testing::PrintToString(set);
        EXPECT_EQ(count_mismatches(want, every, 0.0f, &first), 0u)
            << s.name << " " << name << " " << ::testing::PrintToString(set) << " all: " << first;
    }
}

TEST(KdHits, BuiltinScenesMatchBruteForceExactly) {
    expect_exact_hits(builtin_scene("balls", 2), kKdVariants, 20000, 10000);
    expect_exact_hits(builtin_scene("tetra", 4), kKdVariants, 20000, 10000);
}

TEST(KdHits, ConstructedScenesWithPlanesOnFaces) {
    // Axis-aligned squares exactly on the split planes the builders choose (x = 1, 2, 3 faces),
    // and a ray segment with tmin > 0 and finite tmax.
    Scene s;
    for (int k = 0; k < 4; ++k) {
        const float x = static_cast<float>(k);
        const Vec3 sq[4] = {{x, 0, 0}, {x, 1, 0}, {x, 1, 1}, {x, 0, 1}};
        s.add_polygon(sq, 0);
        s.add(unit_tri(x), 0);
    }
    s.add(Sphere{{2, 0.5f, 0.5f}, 0.25f}, 0);
    s.finalize();
    expect_exact_hits(s, kKdVariants, 20000, 20000);
    auto brute = build_hierarchy(s, "brute");
    for (const auto& [name, set] : kKdVariants) {
        auto h = build_hierarchy(s, name, set);
        for (float tmin : {0.0f, 0.5f, 1.0f, 1.5f, 2.25f}) {
            for (float tmax : {1.0f, 2.0f, 2.75f, kInf}) {
                Ray r{{-0.5f, 0.5f, 0.5f}, {1, 0, 0}, tmin, tmax};
                Hit a, b;
                brute->closest(r, a);
                h->closest(r, b);
                EXPECT_EQ(a.t, b.t) << name << " tmin " << tmin << " tmax " << tmax;
                // In the plane y = 0 (a face of every triangle's box and the squares' edges).
                Ray e{{-0.5f, 0, 0.5f}, {1, 0, 0}, tmin, tmax};
                brute->closest(e, a);
                h->closest(e, b);
                EXPECT_EQ(a.t, b.t) << name << " edge ray tmin " << tmin;
            }
        }
    }
}

TEST(KdHits, SpdRingsMatchesBruteForceExactly) {
    RTCOST_REQUIRE_SPD("rings");
    Scene s = load_scene(spd_path("rings"));
    expect_exact_hits(s, {{"kd-median", {}}, {"kd-sah", {}}, {"kd-sah", {"assign=exact", "mailbox=1"}}}, 15000, 5000);
}

TEST(KdHits, EmptySceneCostsOneBoxTest) {
    Scene s;
    s.finalize();
    for (const char* name : {"kd-median", "kd-sah"}) {
        auto h = build_hierarchy(s, name);
        EXPECT_EQ(h->structure().leaves, 1u);
        EXPECT_EQ(h->structure().references, 0u);
        RayCounters c;
        Hit hit;
        h->closest(Ray{{0, 0, 0}, {1, 0, 0}, 0, kInf}, hit, c);
        EXPECT_FALSE(hit.hit());
        EXPECT_EQ(c.box, 1u);
        EXPECT_EQ(c.steps, 0u);
    }
}

// --- counters --------------------------------------------------------------------------------

TEST(KdCounters, WalkThroughTheMedianRow) {
    // The four-triangle row of MedianCutOnFourTrianglesInARow. Triangle k lies in the plane
    // x - x0 = y - z; a ray along x at y = 0.999, z = 0.001 hits each at x = x0 + 0.998.
    Scene s;
    for (float x : {0.0f, 2.0f, 4.0f, 6.0f}) s.add(unit_tri(x), 0);
    s.finalize();
    auto h = build_hierarchy(s, "kd-median");
    Hit hit;
    // A ray missing the root box: one box test and nothing else.
    RayCounters c = count_one(*h, Ray{{-1, 5, 5}, {1, 0, 0}, 0, kInf}, hit);
    EXPECT_EQ(c.box, 1u);
    EXPECT_EQ(c.steps + c.plane + c.prim_tests(), 0u);
    c = count_one(*h, Ray{{-1, 0.999f, 0.001f}, {1, 0, 0}, 0, kInf}, hit);
    ASSERT_TRUE(hit.hit());
    EXPECT_EQ(hit.prim, 0);
    // Root (box, plane), left node (box, plane), first leaf: terminated there.
    EXPECT_EQ(c.box, 3u);  // root clip + two node boxes
    EXPECT_EQ(c.plane, 2u);
    EXPECT_EQ(c.steps, 3u);
    EXPECT_EQ(c.leaves, 1u);
    EXPECT_EQ(c.visits[0], 1u);
    EXPECT_EQ(c.visits[1], 1u);
    EXPECT_EQ(c.visits[2], 1u);
    EXPECT_EQ(c.prim_tests(), 1u);
    // The all-hits query visits all seven nodes and tests all four triangles.
    c = RayCounters{};
    hit = Hit{};
    h->all(Ray{{-1, 0.999f, 0.001f}, {1, 0, 0}, 0, kInf}, hit, c);
    EXPECT_EQ(c.steps, 7u);
    EXPECT_EQ(c.box, 4u);
    EXPECT_EQ(c.plane, 3u);
    EXPECT_EQ(c.prim_tests(), 4u);
    // A ray through the left node's cell outside its node box (x in (3, 3.5)): root, then the
    // left node's box test fails: no plane test there and no leaf.
    hit = Hit{};
    c = count_one(*h, Ray{{3.25f, 0.5f, -1}, {0, 0, 1}, 0, kInf}, hit);
    EXPECT_FALSE(hit.hit());
    EXPECT_EQ(c.box, 3u);
    EXPECT_EQ(c.plane, 1u);
    EXPECT_EQ(c.steps, 2u);
    EXPECT_EQ(c.leaves, 0u);
}

TEST(KdCounters, CountingDoesNotChangeHitsAndInvariantsHold) {
    Scene s = builtin_scene("balls", 2);
    auto rays = hard_rays(s, 10000, 77);
    for (const auto& [name, set] : kKdVariants) {
        auto h = build_hierarchy(s, name, set);
        TraceOptions opt;
        TraceResult fast = trace_rays(*h, rays, opt);
        opt.count = true;
        TraceResult counted = trace_rays(*h, rays, opt);
        std::string first;
        EXPECT_EQ(count_mismatches(fast.hits, counted.hits, 0.0f, &first), 0u) << first;
        for (std::size_t i = 0; i < rays.size(); ++i) ASSERT_EQ(fast.hits[i].prim, counted.hits[i].prim);
        const RayCounters& c = counted.counters;
        EXPECT_EQ(c.rays, rays.size());
        const std::uint64_t interior = c.steps - c.leaves;
        if (name == "kd-median") {
            EXPECT_EQ(c.box, c.rays + interior);  // root clip + one node box per interior visit
            EXPECT_LE(c.plane, interior);          // a plane only when the node box is met
        } else {
            EXPECT_EQ(c.box, c.rays);
            EXPECT_EQ(c.plane, interior);
        }
        EXPECT_EQ(c.hop + c.classify, 0u);
        EXPECT_LE(c.empty_leaves, c.leaves);
        std::uint64_t visits = 0;
        for (auto v : c.visits) visits += v;
        EXPECT_EQ(visits, c.steps);
        if (set.empty()) {
            EXPECT_LT(c.leaves, c.steps);
        }
    }
}

TEST(KdCounters, MailboxTestsEachPrimitiveAtMostOnce) {
    Scene s = builtin_scene("tetra", 4);
    auto rays = random_rays(s.bounds(), 3000, 3);
    for (const char* name : {"kd-median", "kd-sah"}) {
        auto plain = build_hierarchy(s, name, {"max_prims=4"});
        auto mailbox = build_hierarchy(s, name, {"max_prims=4", "mailbox=1"});
        std::uint64_t repeated = 0, sum_plain = 0, sum_mailbox = 0;
        for (const Ray& r : rays) {
            Hit ha, hb;
            RayCounters a, b;
            plain->all(r, ha, a);
            mailbox->all(r, hb, b);
            ASSERT_EQ(ha.t, hb.t);
            // Distinct primitives in the leaves the ray visits bound the mailboxed tests.
            EXPECT_LE(b.prim_tests(), s.size());
            EXPECT_LE(b.prim_tests(), a.prim_tests());
            EXPECT_EQ(a.leaves, b.leaves);
            repeated += a.prim_tests() > b.prim_tests();
            sum_plain += a.prim_tests();
            sum_mailbox += b.prim_tests();
            Hit hc, hd;
            RayCounters c, d;
            plain->closest(r, hc, c);
            mailbox->closest(r, hd, d);
            ASSERT_EQ(hc.t, hd.t);
            EXPECT_LE(d.prim_tests(), c.prim_tests());
        }
        EXPECT_GT(repeated, 100u) << name;  // without the mailbox many rays repeat a test
        EXPECT_LT(sum_mailbox, sum_plain) << name;
    }
    // A ray along a row of cells through one long triangle: tested once with the mailbox.
    Scene row;
    row.add(Triangle{{0, 0.1f, 0}, {8, 0.1f, 0}, {8, 0.1f, 1}}, 0);
    for (float x : {0.0f, 2.0f, 4.0f, 6.0f}) row.add(unit_tri(x), 0);
    row.finalize();
    auto mb = build_hierarchy(row, "kd-median", {"mailbox=1"});
    auto pl = build_hierarchy(row, "kd-median");
    RayCounters a, b;
    Hit ha, hb;
    const Ray r{{-1, 0.05f, 0.99f}, {1, 0, 0}, 0, kInf};  // misses everything
    pl->all(r, ha, a);
    mb->all(r, hb, b);
    EXPECT_FALSE(hb.hit());
    EXPECT_EQ(a.leaves, b.leaves);
    EXPECT_GT(a.prim_tests(), b.prim_tests());
    EXPECT_LE(b.prim_tests(), row.size());
}

TEST(KdCounters, ParametersAreValidated) {
    Scene s = builtin_scene("tetra", 2);
    EXPECT_THROW(build_hierarchy(s, "kd-sah", {"max_depth=65"}), InputError);
    EXPECT_THROW(build_hierarchy(s, "kd-sah", {"max_depth=deep"}), InputError);
    EXPECT_THROW(build_hierarchy(s, "kd-sah", {"empty_bonus=2"}), InputError);
    EXPECT_THROW(build_hierarchy(s, "kd-sah", {"assign=tight"}), InputError);
    EXPECT_THROW(build_hierarchy(s, "kd-median", {"mailbox=2"}), InputError);
    EXPECT_THROW(build_hierarchy(s, "kd-median", {"max_prims=0"}), InputError);
    EXPECT_NO_THROW(build_hierarchy(s, "kd-median", {"max_depth=64", "max_prims=2"}));
}

// --- the model -------------------------------------------------------------------------------

TEST(KdModel, ExactForQueryAllOnBuiltinScenes) {
    Scene balls = builtin_scene("balls", 2);
    Scene tetra = builtin_scene("tetra", 4);
    for (const auto& set : std::vector<std::vector<std::string>>{{}, {"assign=exact"}, {"max_depth=0"}}) {
        expect_model_exact(balls, "kd-median", set);
        expect_model_exact(tetra, "kd-median", set);
        expect_model_exact(balls, "kd-sah", set);
        expect_model_exact(tetra, "kd-sah", set);
    }
}

}  // namespace
}  // namespace rtcost::test
