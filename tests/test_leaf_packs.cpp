// A binary BVH's leaf packs (hierarchy/bvh/leaf_packs.hpp): every leaf of a mesh in as few packs
// as its count needs, its lanes holding its references in order, and the walk's nodes saying
// where.
#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "../src/hierarchy/bvh/bvh.hpp"
#include "test_support.hpp"

namespace rtcost::test {
namespace {

TEST(BvhLeafPacks, EveryLeafSpansTheFewestPacksAndHoldsItsReferences) {
    const Scene s = builtin_scene("tetra", 5);
    const std::vector<std::pair<std::string, std::vector<std::string>>> variants = {
        {"bvh-sah", {}}, {"bvh-sah", {"max_prims=7"}}, {"bvh-median", {"max_prims=3"}}, {"bvh-gs", {"max_prims=5"}}};
    std::size_t spanning_more = 0;
    for (const auto& [hname, set] : variants) {
        const std::string name = hname + (set.empty() ? "" : " " + set[0]);
        auto h = build_hierarchy(s, hname, set);
        const auto* bvh = dynamic_cast<const bvh::Bvh*>(h.get());
        ASSERT_NE(bvh, nullptr) << name;
        ASSERT_TRUE(bvh->packs().active()) << name << ": a scene of triangles is tested from packs";
        // Each pack (two and a half lines) on three cache lines, never four: the array starts a line.
        EXPECT_EQ(reinterpret_cast<std::uintptr_t>(bvh->packs().packs.data()) % 64, 0u) << name;
        for (const TriPack<4>& q : bvh->packs().packs) {
            const std::uintptr_t a = reinterpret_cast<std::uintptr_t>(&q);
            EXPECT_EQ((a + sizeof q - 1) / 64 - a / 64 + 1, 3u) << name << ": a pack at " << a % 64 << " into a line";
        }
        const bvh::NodeArray& built = bvh->data().nodes;
        const bvh::NodeArray& walked = bvh->walk_nodes();
        ASSERT_EQ(built.size(), walked.size()) << name;
        ASSERT_NE(&built, &walked) << name;
        std::vector<std::pair<std::uint32_t, std::uint32_t>> lanes;  // first lane, end, per leaf
        std::size_t leaves = 0;
        for (std::size_t i = 0; i < built.size(); ++i) {
            const bvh::Node &b = built[i], &w = walked[i];
            EXPECT_EQ(b.leaf, w.leaf);
            EXPECT_EQ(b.count, w.count);
            EXPECT_EQ(b.box.lo.x, w.box.lo.x);
            EXPECT_EQ(b.box.hi.z, w.box.hi.z);
            if (!b.leaf) {
                EXPECT_EQ(b.index, w.index) << name << ": interior node " << i;
                continue;
            }
            ++leaves;
            const std::uint32_t count = static_cast<std::uint32_t>(b.count);
            spanning_more += (b.index % 4 + count + 3) / 4 > (count + 3) / 4;
            EXPECT_EQ((w.index % 4 + count + 3) / 4, (count + 3) / 4)
                << name << ": leaf " << i << " of " << b.count << " from lane " << w.index;
            for (std::uint32_t k = 0; k < b.count; ++k)
                EXPECT_EQ(bvh->packs().id(w.index + k), bvh->data().refs[b.index + k]) << name << ": leaf " << i;
            lanes.push_back({w.index, w.index + b.count});
        }
        // The leaves' lanes do not overlap, and the packs hold no pack no leaf uses.
        std::sort(lanes.begin(), lanes.end());
        for (std::size_t k = 1; k < lanes.size(); ++k) EXPECT_LE(lanes[k - 1].second, lanes[k].first) << name;
        ASSERT_FALSE(lanes.empty());
        EXPECT_EQ(bvh->packs().packs.size(), (lanes.back().second + 3) / 4) << name;
        EXPECT_GT(leaves, 100u) << name;
    }
    // Packed end to end as the references are, many of these leaves would span a pack more.
    EXPECT_GT(spanning_more, 30u);
}

TEST(BvhLeafPacks, AnEmptyLeafTakesNoLaneAndMovesNoLeafOn) {
    std::vector<LeafPrim> prims(5);
    for (std::uint32_t i = 0; i < prims.size(); ++i) {
        prims[i].id = 10 + i;
        prims[i].tri = Triangle{{0, 0, float(i)}, {1, 0, float(i)}, {0, 1, float(i)}};
    }
    // Leaves of 2, 0, 2 and 1 references: the second of two fits the first pack after the first
    // leaf, the empty one between them changing nothing; the last goes on from lane 4.
    const std::vector<std::pair<std::uint32_t, std::uint32_t>> leaves = {{0, 2}, {2, 0}, {2, 2}, {4, 1}};
    bvh::LeafPacks lp;
    const std::vector<std::uint32_t> lanes = lp.pack(prims, leaves);
    EXPECT_EQ(lanes, (std::vector<std::uint32_t>{0, 2, 2, 4}));
    ASSERT_EQ(lp.packs.size(), 2u);
    for (std::uint32_t k = 0; k < prims.size(); ++k) {
        EXPECT_EQ(lp.id(k), 10 + k);
        EXPECT_EQ(lp.prim(k).tri.v0.z, float(k));
    }
}

TEST(BvhLeafPacks, NoneWhereAReferenceIsNotATriangle) {
    const Scene s = builtin_scene("balls", 2);  // spheres and a polygon
    auto h = build_hierarchy(s, "bvh-sah");
    const auto* bvh = dynamic_cast<const bvh::Bvh*>(h.get());
    ASSERT_NE(bvh, nullptr);
    EXPECT_FALSE(bvh->packs().active());
    EXPECT_EQ(&bvh->walk_nodes(), &bvh->data().nodes);
}

}  // namespace
}  // namespace rtcost::test
