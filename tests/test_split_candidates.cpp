// bvh-design's candidate splits (src/hierarchy/bvh-design/split_candidates.hpp): the centroid
// orders stay sorted as nodes split, a sweep finds the split a full-sweep SAH build takes, and
// the kept cuts of the bins and of the sweep are the cheapest, with the boxes and counts of the
// primitives on their sides.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <utility>

#include "hierarchy/bvh-design/split_candidates.hpp"
#include "rtcost/io.hpp"
#include "rtcost/scene.hpp"
#include "test_support.hpp"

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
    std::vector<std::uint32_t> ids = indices(s.size());
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
    std::vector<std::uint32_t> ids = indices(s.size());
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

// Every bin boundary of ids[begin, end) on every axis, made directly from the primitives: the
// cuts binned_cuts chooses from, in its order of generation (axis, then bin).
std::vector<Cut> every_bin_cut(const std::vector<std::uint32_t>& ids, std::uint32_t begin, std::uint32_t end,
                               const PrimInfo& info, const Box3& cb, int nbins) {
    std::vector<Cut> all;
    for (int axis = 0; axis < 3; ++axis) {
        const float ext = cb.hi[axis] - cb.lo[axis];
        if (!(ext > 0)) continue;
        const float scale = nbins / ext;
        for (int at = 1; at < nbins; ++at) {
            Cut c{axis, at, false, 0, Box3{}, Box3{}, 0, 0};
            for (std::uint32_t i = begin; i < end; ++i) {
                const std::uint32_t id = ids[i];
                const int b = std::min(nbins - 1, static_cast<int>((info.centroids[id][axis] - cb.lo[axis]) * scale));
                if (b < at) c.left.extend(info.bounds[id]), ++c.n_left;
                else c.right.extend(info.bounds[id]), ++c.n_right;
            }
            if (c.n_left == 0 || c.n_right == 0) continue;
            c.sah = c.left.area() * c.n_left + c.right.area() * c.n_right;
            all.push_back(c);
        }
    }
    return all;
}

void expect_same_cut(const Cut& got, const Cut& want, const std::string& what) {
    EXPECT_EQ(got.axis, want.axis) << what;
    EXPECT_EQ(got.at, want.at) << what;
    EXPECT_EQ(got.swept, want.swept) << what;
    EXPECT_EQ(got.n_left, want.n_left) << what;
    EXPECT_EQ(got.n_right, want.n_right) << what;
    EXPECT_EQ(got.left.lo, want.left.lo) << what;
    EXPECT_EQ(got.left.hi, want.left.hi) << what;
    EXPECT_EQ(got.right.lo, want.right.lo) << what;
    EXPECT_EQ(got.right.hi, want.right.hi) << what;
    EXPECT_FLOAT_EQ(got.sah, want.sah) << what;
}

// binned_cuts keeps the `keep` cheapest bin boundaries, cheapest first and ties in the order of
// generation, each with the boxes and counts of its sides; a smaller keep keeps a prefix of a
// larger one's (bvh-design's held-out counts compare nested candidate lists). On the root and on
// a small node (most nodes hold a few primitives, and many bins are empty).
TEST(SplitCandidates, BinnedCutsAreTheCheapestBinBoundariesWithTheirSides) {
    const Scene s = builtin_scene("tetra", 4);
    const PrimInfo info(s);
    std::vector<std::uint32_t> ids = indices(s.size());
    const auto n = static_cast<std::uint32_t>(ids.size());
    ASSERT_GT(n, 100u);
    const int nbins = 16;
    CutScratch scratch;
    for (const auto& [begin, end] : {std::pair<std::uint32_t, std::uint32_t>{0, n}, {n / 3, n / 3 + 7}}) {
        Box3 cb;
        for (std::uint32_t i = begin; i < end; ++i) cb.extend(info.centroids[ids[i]]);
        std::vector<Cut> want = every_bin_cut(ids, begin, end, info, cb, nbins);
        ASSERT_GE(want.size(), 3u);
        std::stable_sort(want.begin(), want.end(), [](const Cut& a, const Cut& b) { return a.sah < b.sah; });
        std::vector<Cut> widest;
        for (std::size_t keep : {std::size_t{1}, std::size_t{3}, std::size_t{8}, std::size_t{32}, std::size_t{100}}) {
            std::vector<Cut> cuts;
            bvh::binned_cuts(ids, begin, end, info, cb, nbins, keep, scratch, cuts);
            ASSERT_EQ(cuts.size(), std::min(keep, want.size())) << "keep " << keep;
            for (std::size_t c = 0; c < cuts.size(); ++c)
                expect_same_cut(cuts[c], want[c], "node [" + std::to_string(begin) + ", " + std::to_string(end) +
                                                      "), keep " + std::to_string(keep) + ", cut " + std::to_string(c));
            if (cuts.size() > widest.size()) widest = cuts;
        }
        EXPECT_EQ(widest.size(), want.size());
    }
}

// Every cut swept_cuts keeps, not only the cheapest, has the boxes and counts of the first `at`
// primitives in its axis's centroid order and of the rest, and they are the cheapest splits.
TEST(SplitCandidates, EverySweptCutBoundsItsSides) {
    const Scene s = builtin_scene("balls", 2);
    const PrimInfo info(s);
    std::vector<std::uint32_t> ids = indices(s.size());
    const AxisOrders orders(ids, info);
    const auto n = static_cast<std::uint32_t>(ids.size());
    std::vector<Cut> want;
    for (int axis = 0; axis < 3; ++axis) {
        const auto sorted = orders.of(axis, 0, n);
        for (std::uint32_t at = 1; at < n; ++at) {
            Cut c{axis, static_cast<int>(at), true, 0, Box3{}, Box3{}, at, n - at};
            for (std::uint32_t i = 0; i < n; ++i) (i < at ? c.left : c.right).extend(info.bounds[sorted[i]]);
            c.sah = c.left.area() * c.n_left + c.right.area() * c.n_right;
            want.push_back(c);
        }
    }
    std::stable_sort(want.begin(), want.end(), [](const Cut& a, const Cut& b) { return a.sah < b.sah; });
    CutScratch scratch;
    std::vector<Cut> cuts;
    bvh::swept_cuts(orders, 0, n, info, 5, scratch, cuts);
    ASSERT_EQ(cuts.size(), 5u);
    for (std::size_t c = 0; c < cuts.size(); ++c) expect_same_cut(cuts[c], want[c], "cut " + std::to_string(c));
}

}  // namespace
}  // namespace rtcost::test
