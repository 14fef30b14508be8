// The binary BVH walk's two-box slab test (hierarchy/bvh/pair_entry.hpp) against box_entry.
#include <random>

#include "../src/hierarchy/bvh/bvh.hpp"
#include "test_support.hpp"

namespace rtcost::test {
namespace {

/// Boxes whose faces lie on a few planes (so that rays start in them, run along them and pass
/// through their edges and corners), flat and point boxes among them.
std::vector<Box3> planar_boxes() {
    const float c[] = {-1.0f, 0.0f, 0.5f, 1.0f};
    std::vector<Box3> boxes;
    for (float lx : c)
        for (float hx : c)
            for (float ly : c)
                for (float hy : c) {
                    if (hx < lx || hy < ly) continue;
                    boxes.push_back({{lx, ly, -1.0f}, {hx, hy, lx < 0 ? 0.0f : 1.0f}});
                }
    boxes.push_back({{0, 0, 0}, {0, 0, 0}});
    boxes.push_back({{1e-30f, -1e30f, 3}, {2e-30f, 1e30f, 3}});
    return boxes;
}

/// Rays from points on those planes and inside and outside the boxes, along the axes, with
/// components of +0 and -0, through corners and at random.
std::vector<Ray> planar_rays() {
    std::vector<Ray> rays;
    const float c[] = {-2.0f, -1.0f, 0.0f, 0.25f, 0.5f, 1.0f, 3.0f};
    const float dc[] = {-1.0f, -0.0f, 0.0f, 0.5f, 1.0f};
    for (float ox : c)
        for (float oy : c)
            for (float oz : {-1.0f, 0.0f, 2.0f})
                for (float dx : dc)
                    for (float dy : dc)
                        for (float dz : dc) {
                            if (dx == 0 && dy == 0 && dz == 0) continue;
                            Ray r;
                            r.o = {ox, oy, oz};
                            r.d = {dx, dy, dz};
                            rays.push_back(r);
                        }
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-2.0f, 2.0f);
    for (int i = 0; i < 20000; ++i) {
        Ray r;
        r.o = {u(rng), u(rng), u(rng)};
        // Aimed at a corner of the planes' lattice: through boxes' edges and vertices.
        r.d = Vec3{c[i % 7], c[(i / 7) % 7], c[(i / 49) % 7]} - r.o;
        if (r.d == Vec3{0, 0, 0}) continue;
        rays.push_back(r);
    }
    return rays;
}

TEST(BvhPairEntry, EntersEveryPairOfBoxesWhereBoxEntryDoesAtTheSameDistance) {
    const std::vector<Box3> boxes = planar_boxes();
    const std::vector<Ray> rays = planar_rays();
    // Each box as a node's, followed by what a node's box is (its index), as the walk reads them.
    std::vector<bvh::Node> nodes(boxes.size());
    for (std::size_t i = 0; i < boxes.size(); ++i) nodes[i].box = boxes[i], nodes[i].index = 0xffffffffu;
    std::size_t met = 0, missed = 0, mismatched = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const Ray& ray = rays[i];
        const RayInv ri(ray);
        const bvh::PairRay pr(ri);
        const float limits[] = {kInf, 1.0f, 0.5f};
        const float tmins[] = {0.0f, -0.0f, 0.25f};
        const float limit = limits[i % 3], tmin = tmins[(i / 3) % 3];
        for (std::size_t a = 0; a < nodes.size(); ++a) {
            const std::size_t b = (a * 7 + i) % nodes.size();
            float ta, tb;
            bvh::pair_entry(nodes[a].box, nodes[b].box, pr, tmin, limit, ta, tb);
            const float ea = box_entry(nodes[a].box, ri, tmin, limit), eb = box_entry(nodes[b].box, ri, tmin, limit);
            // Equal as values (a zero's sign may differ; every use of an entry compares it).
            if (!(ta == ea) || !(tb == eb)) {
                if (++mismatched <= 5)
                    ADD_FAILURE() << "ray " << i << " boxes " << a << ", " << b << ": " << ta << " " << tb
                                  << " against box_entry's " << ea << " " << eb;
            }
            (ea == kInf ? missed : met) += 1;
        }
    }
    EXPECT_EQ(mismatched, 0u);
    // Both answers occur in quantity, so the comparison is not one-sided.
    EXPECT_GT(met, 100000u);
    EXPECT_GT(missed, 100000u);
}

}  // namespace
}  // namespace rtcost::test

namespace rtcost::test {
namespace {

// Every binary node's two children lie in one 64-byte cache line (bvh.hpp's NodeArray): the
// walk reads both boxes and prefetches a child's pair as one line.
TEST(BvhPairEntry, SiblingPairsShareOneCacheLine) {
    const Scene s = builtin_scene("tetra", 5);
    for (const char* name : {"bvh-sah", "bvh-median"}) {
        auto h = build_hierarchy(s, name);
        const auto* bvh = dynamic_cast<const bvh::Bvh*>(h.get());
        ASSERT_NE(bvh, nullptr) << name;
        ASSERT_NE(&bvh->walk_nodes(), &bvh->data().nodes) << name << ": a mesh's walk reads its own copy";
        for (const bvh::NodeArray* nodes : {&bvh->data().nodes, &bvh->walk_nodes()}) {
            std::size_t pairs = 0;
            for (const bvh::Node& n : *nodes) {
                if (n.leaf || n.count != 2) continue;
                const auto first = reinterpret_cast<std::uintptr_t>(&(*nodes)[n.index]);
                EXPECT_EQ(first % 64, 0u) << name << ": children at " << n.index;
                ++pairs;
            }
            EXPECT_GT(pairs, 100u) << name;
        }
    }
}

}  // namespace
}  // namespace rtcost::test
