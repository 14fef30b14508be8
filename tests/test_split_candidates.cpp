// bvh-design's candidate splits (src/hierarchy/bvh-design/split_candidates.hpp): the centroid
// orders stay sorted as nodes split, and a sweep finds the split a full-sweep SAH build takes.
#include <gtest/gtest.h>

#include <algorithm>

#include "hierarchy/bvh-design/split_candidates.hpp"
#include "rtcost/io.hpp"
#include "rtcost/scene.hpp"

namespace rtcost::test {
namespace {

using bvh::AxisOrders;
using bvh::Cut;
using bvh::CutScratch;
using bvh::PrimInfo;

// Each axis's order over [begin, end) is sorted by centroid (ties by id) and holds the same
// primitives as ids[begin, end).
void expect_orders_match(const AxisOrders& orders, const PrimInfo& info, std::vector<std::uint32_t> ids,
                         std::uint32_t begin, std::uint32_t end) {
    std::vector<std::uint32_t> want(ids.begin() + begin, ids.begin() + end);
    std::sort(want.begin(), want.end());
    for (int axis = 0; axis < 3; ++axis) {
        const auto got = orders.of(axis, begin, end);
        EXPECT_TRUE(std::is_sorted(got.begin(), got.end(), bvh::by_centroid(info, axis))) << "axis " << axis;
        std::vector<std::uint32_t> set(got.begin(), got.end());
        std::sort(set.begin(), set.end());
        EXPECT_EQ(set, want) << "axis " << axis;
    }
}

TEST(SplitCandidates, AxisOrdersStaySortedAsNodesSplit) {
    const Scene s = builtin_scene("balls", 2);
    const PrimInfo info(s);
    std::vector<std::uint32_t> ids(s.size());
    for (std::uint32_t i = 0; i < s.size(); ++i) ids[i] = i;
    AxisOrders orders(ids, info);
    const auto n = static_cast<std::uint32_t>(ids.size());
    ASSERT_GT(n, 20u);
    expect_orders_match(orders, info, ids, 0, n);
    // Split the root by id parity (not a split along any axis), then its right part by its x order.
    std::stable_partition(ids.begin(), ids.end(), [](std::uint32_t id) { return id % 2 == 0; });
    const std::uint32_t mid = (n + 1) / 2;
    orders.split(ids, 0, mid, n);
    expect_orders_match(orders, info, ids, 0, mid);
    expect_orders_match(orders, info, ids, mid, n);
    const auto x = orders.of(0, mid, n);
    std::copy(x.begin(), x.end(), ids.begin() + mid);
    const std::uint32_t quarter = mid + (n - mid) / 3;
    orders.split(ids, mid, quarter, n);
    expect_orders_match(orders, info, ids, mid, quarter);
    expect_orders_match(orders, info, ids, quarter, n);
    expect_orders_match(orders, info, ids, 0, mid);  // untouched
}

// The cheapest swept cut of the root is the split of bvh-sah with sweep=1, whose root children
// are the primitives on either side of it.
TEST(SplitCandidates, CheapestSweptCutIsTheFullSweepSahSplit) {
    const Scene s = builtin_scene("tetra", 4);
    const PrimInfo info(s);
    std::vector<std::uint32_t> ids(s.size());
    for (std::uint32_t i = 0; i < s.size(); ++i) ids[i] = i;
    const AxisOrders orders(ids, info);
    CutScratch scratch;
    std::vector<Cut> cuts;
    const auto n = static_cast<std::uint32_t>(ids.size());
    bvh::swept_cuts(orders, 0, n, info, 3, scratch, cuts);
    ASSERT_EQ(cuts.size(), 3u);
    for (std::size_t c = 1; c < cuts.size(); ++c) EXPECT_LE(cuts[c - 1].sah, cuts[c].sah);
    const Cut& best = cuts[0];
    EXPECT_TRUE(best.swept);
    EXPECT_EQ(best.n_left + best.n_right, n);
    EXPECT_EQ(best.n_left, static_cast<std::uint32_t>(best.at));
    // The cut's boxes bound its sides exactly.
    const auto sorted = orders.of(best.axis, 0, n);
    Box3 left, right;
    for (std::uint32_t i = 0; i < n; ++i) (i < best.n_left ? left : right).extend(info.bounds[sorted[i]]);
    EXPECT_EQ(best.left.lo, left.lo);
    EXPECT_EQ(best.left.hi, left.hi);
    EXPECT_EQ(best.right.lo, right.lo);
    EXPECT_EQ(best.right.hi, right.hi);
    EXPECT_FLOAT_EQ(best.sah, left.area() * best.n_left + right.area() * best.n_right);
    bvh::SahOptions o;
    o.sweep = true;
    const bvh::BvhData sah = bvh::build_sah(s, o);
    ASSERT_FALSE(sah.nodes[0].leaf);
    const bvh::Node& l = sah.nodes[sah.nodes[0].index];
    EXPECT_EQ(l.box.lo, left.lo);
    EXPECT_EQ(l.box.hi, left.hi);
}

}  // namespace
}  // namespace rtcost::test
