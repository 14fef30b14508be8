#pragma once
// bvh-design's candidate splits of a node: the surface-area-cheapest of the bin boundaries on
// each axis (binned_cuts) and of a sweep over the centroid-sorted primitives (swept_cuts), which
// the design then weighs again with the sample (bvh_design.cpp).

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <span>
#include <vector>

#include "../bvh/box4.hpp"
#include "../bvh/bvh.hpp"

namespace rtcost::bvh {

struct Cut {
    int axis = -1;
    int at = 0;           // binned: first bin on the right; swept: primitives on the left
    bool swept = false;
    float sah = kInf;     // A_L N_L + A_R N_R
    Box3 left, right;
    std::uint32_t n_left = 0, n_right = 0;
};

// Buffers of binned_cuts and swept_cuts, reused from node to node.
struct CutScratch {
    struct Bin {
        Box4 box;
        std::uint32_t n = 0;
    };
    std::vector<Bin> bins;
    std::vector<float> suffix_area;
    std::vector<std::uint32_t> suffix_n;
    std::vector<Box4> prefix_box, suffix_box;  // per axis: bins [0, b] and [b, nbins)
    // A bin boundary's cut without boxes: a node's bins give 45 cuts, of which a few are kept.
    struct BinCut {
        float sah;
        int axis, at;
        std::uint32_t n_left, n_right;
    };
    std::vector<BinCut> all;
    std::vector<std::uint64_t> keys;
    std::vector<float> right_area;
    std::vector<Box4> right_box;
};

// A float's bits as an unsigned integer that orders as the float does (-0 taken as 0, which
// compares equal to it; a NaN after +inf): cuts and centroid orders sort as single integers
// with their tie-breaking index in the low word, rather than through a comparison of two fields.
inline std::uint32_t sortable_bits(float f) {
    f += 0.0f;  // -0 to 0
    std::uint32_t u;
    std::memcpy(&u, &f, sizeof u);
    return u ^ (static_cast<std::uint32_t>(static_cast<std::int32_t>(u) >> 31) | 0x80000000u);
}

// The `keep` cheapest of `sc.all` by surface-area cost, cheapest first (ties in the order of
// generation), appended to `cuts` with their boxes (`sc`'s prefix and suffix boxes of `nbins` bins).
inline void keep_cheapest(std::size_t keep, int nbins, CutScratch& sc, std::vector<Cut>& cuts) {
    keep = std::min(keep, sc.all.size());
    // Sorted as one integer each, the cost above the index (comparing the cuts through their
    // indices was a sixth of the cuts' time at 32 kept).
    sc.keys.resize(sc.all.size());
    for (std::uint32_t i = 0; i < sc.all.size(); ++i) sc.keys[i] = std::uint64_t{sortable_bits(sc.all[i].sah)} << 32 | i;
    if (keep == 1)  // a node no sample segment reaches (most nodes)
        std::iter_swap(sc.keys.begin(), std::min_element(sc.keys.begin(), sc.keys.end()));
    else if (2 * keep >= sc.keys.size())
        std::sort(sc.keys.begin(), sc.keys.end());
    else
        std::partial_sort(sc.keys.begin(), sc.keys.begin() + static_cast<std::ptrdiff_t>(keep), sc.keys.end());
    for (std::size_t i = 0; i < keep; ++i) {
        const CutScratch::BinCut& c = sc.all[static_cast<std::uint32_t>(sc.keys[i])];
        cuts.push_back(Cut{c.axis, c.at, false, c.sah, sc.prefix_box[c.axis * nbins + c.at - 1].box3(),
                           sc.suffix_box[c.axis * nbins + c.at].box3(), c.n_left, c.n_right});
    }
}

// `b`'s bounds extended by `box` (Box3::extend's results, in four lanes). The spare lane holds
// whatever follows in memory and is never read.
inline void extend(Box4& b, const Box3& box) {
    const float* f = &box.lo.x;
    f4 lo, hi;
    std::memcpy(&lo, f, sizeof lo);                   // lo.x, lo.y, lo.z, hi.x
    std::memcpy(&hi, f + 2, sizeof hi);               // lo.z, hi.x, hi.y, hi.z
    hi = __builtin_shufflevector(hi, hi, 1, 2, 3, 3);  // hi.x, hi.y, hi.z, hi.z
    b.extend(lo, hi);
}

// Box3::area() of a box that is not empty, the same expression.
inline float area_of(const Box4& b) {
    const float ex = b.hi[0] - b.lo[0], ey = b.hi[1] - b.lo[1], ez = b.hi[2] - b.lo[2];
    return 2 * (ex * ey + ey * ez + ez * ex);
}

// Centroid order on `axis`, ties by id: a swept cut's left side is its first `at` primitives.
inline auto by_centroid(const PrimInfo& info, int axis) {
    return [&info, axis](std::uint32_t a, std::uint32_t b) {
        const float ca = info.centroids[a][axis], cb = info.centroids[b][axis];
        return ca < cb || (ca == cb && a < b);
    };
}

/// Every node's primitives sorted by centroid on each axis (by_centroid), kept sorted as nodes
/// split by a stable partition of each axis's order: a sweep then costs no sort at a node, and
/// the build O(N log N) rather than O(N log^2 N).
class AxisOrders {
public:
    /// The root's primitives, `ids` (all primitives, any order).
    AxisOrders(const std::vector<std::uint32_t>& ids, const PrimInfo& info) : left_(info.centroids.size(), 0) {
        // by_centroid's order, sorted as one integer per primitive, the coordinate above the id:
        // three times faster than comparing through the ids.
        std::vector<std::uint64_t> keys(ids.size());
        for (int axis = 0; axis < 3; ++axis) {
            for (std::size_t i = 0; i < ids.size(); ++i)
                keys[i] = std::uint64_t{sortable_bits(info.centroids[ids[i]][axis])} << 32 | ids[i];
            std::sort(keys.begin(), keys.end());
            order_[axis].resize(ids.size());
            for (std::size_t i = 0; i < ids.size(); ++i) order_[axis][i] = static_cast<std::uint32_t>(keys[i]);
        }
    }
    /// The node [begin, end)'s primitives in centroid order on `axis`.
    std::span<const std::uint32_t> of(int axis, std::uint32_t begin, std::uint32_t end) const {
        return std::span<const std::uint32_t>(order_[axis]).subspan(begin, end - begin);
    }
    /// The node [begin, end) became ids[begin, mid) and ids[mid, end).
    void split(const std::vector<std::uint32_t>& ids, std::uint32_t begin, std::uint32_t mid, std::uint32_t end) {
        for (std::uint32_t i = begin; i < end; ++i) left_[ids[i]] = i < mid;
        for (auto& order : order_) {
            right_.clear();
            std::uint32_t l = begin;
            for (std::uint32_t i = begin; i < end; ++i) {
                if (left_[order[i]]) order[l++] = order[i];
                else right_.push_back(order[i]);
            }
            std::copy(right_.begin(), right_.end(), order.begin() + l);
        }
    }

private:
    std::array<std::vector<std::uint32_t>, 3> order_;
    std::vector<std::uint8_t> left_;
    std::vector<std::uint32_t> right_;
};

/// The `keep` cheapest by surface-area cost of every split of the node [begin, end)'s primitives
/// sorted by centroid on each axis (bvh-sah's sweep), appended to `cuts`. Sixteen bins lose good
/// splits of patch meshes: bvh-sah with sweep=1 tests 15% fewer operations on teapot's spd rays
/// than with its bins. (Only a few: the cheapest splits of a sweep are neighbours, and the sample
/// then has fewer different cuts to choose from than the bins give it: 8 swept instead of 8
/// binned tested 10% more operations on gears' and mount's spd rays.)
inline void swept_cuts(const AxisOrders& orders, std::uint32_t begin, std::uint32_t end, const PrimInfo& info,
                       std::size_t keep, CutScratch& sc, std::vector<Cut>& cuts) {
    const std::uint32_t n = end - begin;
    if (keep == 0 || n < 2) return;
    sc.right_area.resize(n + 1);
    // The cheapest `keep` so far, cheapest first; a tie keeps the earlier (axis, then position),
    // as binned_cuts orders its ties. Only they are stored, and their boxes made at the end: a
    // node has 3 (n - 1) splits.
    const std::size_t first = cuts.size();
    sc.right_box.resize(n + 1);
    for (int axis = 0; axis < 3; ++axis) {
        const std::span<const std::uint32_t> sorted = orders.of(axis, begin, end);
        // Four-lane boxes (Box4 keeps Box3::extend's results), each running box stored for the
        // cut that may keep it rather than made again from the primitives at the end.
        Box4 right;
        for (std::uint32_t i = n; i-- > 1;) {
            extend(right, info.bounds[sorted[i]]);
            sc.right_box[i] = right;
            sc.right_area[i] = area_of(right);
        }
        Box4 left;
        for (std::uint32_t i = 1; i < n; ++i) {
            extend(left, info.bounds[sorted[i - 1]]);
            const float sah = area_of(left) * i + sc.right_area[i] * (n - i);
            const std::size_t kept = cuts.size() - first;
            if (kept == keep && !(sah < cuts.back().sah)) continue;
            if (kept == keep) cuts.pop_back();
            auto at = cuts.end();
            while (at != cuts.begin() + first && sah < (at - 1)->sah) --at;
            cuts.insert(at, Cut{axis, static_cast<int>(i), true, sah, left.box3(), sc.right_box[i].box3(), i, n - i});
        }
    }
}

// The largest node binned_cuts chooses its one cut for by the primitives rather than the bins.
inline constexpr std::uint32_t kFewPrims = 16;

// binned_cuts' one cheapest cut (keep = 1) of a node of at most kFewPrims primitives, found from
// the primitives in bin order rather than from every bin: a boundary between two occupied bins
// splits them as every boundary of the empty bins between does, at the same cost, and the first
// of them comes first in the order of generation; one outside them leaves a side empty. The same
// cut, then, for a few operations per primitive instead of a pass over the 3 x 16 bins (nodes
// that no sample segment reaches, most of a design's nodes, hold four primitives on average).
inline void cheapest_few(const std::vector<std::uint32_t>& ids, std::uint32_t begin, std::uint32_t end,
                         const PrimInfo& info, const Box3& cb, int nbins, std::vector<Cut>& cuts) {
    const std::uint32_t n = end - begin;
    struct Ref {
        int bin;
        std::uint32_t id;
    };
    Ref refs[kFewPrims];
    Box4 right_of[kFewPrims];  // right_of[i]: the box of refs[i, n)
    std::uint64_t best_key = ~std::uint64_t{0};
    Cut best;
    for (int axis = 0; axis < 3; ++axis) {
        const float lo = cb.lo[axis], ext = cb.hi[axis] - lo;
        if (!(ext > 0)) continue;
        const float scale = nbins / ext;
        for (std::uint32_t i = 0; i < n; ++i) {
            const std::uint32_t id = ids[begin + i];
            const int b = std::min(nbins - 1, static_cast<int>((info.centroids[id][axis] - lo) * scale));
            std::uint32_t at = i;  // insertion sort by bin
            for (; at > 0 && refs[at - 1].bin > b; --at) refs[at] = refs[at - 1];
            refs[at] = {b, id};
        }
        Box4 right;
        for (std::uint32_t i = n; i-- > 0;) {
            extend(right, info.bounds[refs[i].id]);
            right_of[i] = right;
        }
        Box4 left;
        for (std::uint32_t i = 0; i + 1 < n; ++i) {
            extend(left, info.bounds[refs[i].id]);
            if (refs[i + 1].bin == refs[i].bin) continue;
            const std::uint32_t n_left = i + 1, n_right = n - n_left;
            const float sah = area_of(left) * n_left + area_of(right_of[i + 1]) * n_right;
            // Ties in the order of generation, axis then boundary, as keep_cheapest breaks them.
            const int at = refs[i].bin + 1;
            const std::uint64_t key = std::uint64_t{sortable_bits(sah)} << 32 | static_cast<std::uint32_t>(axis * nbins + at);
            if (key < best_key)
                best_key = key, best = Cut{axis, at, false, sah, left.box3(), right_of[i + 1].box3(), n_left, n_right};
        }
    }
    cuts.clear();
    if (best.axis >= 0) cuts.push_back(best);
}

// The `keep` cheapest of every bin boundary on every axis by surface-area cost, cheapest first
// (ties in the order of generation: axis, then bin), into `cuts`.
inline void binned_cuts(const std::vector<std::uint32_t>& ids, std::uint32_t begin, std::uint32_t end,
                        const PrimInfo& info, const Box3& cb, int nbins, std::size_t keep, CutScratch& sc,
                        std::vector<Cut>& cuts) {
    if (keep == 1 && end - begin <= kFewPrims) return cheapest_few(ids, begin, end, info, cb, nbins, cuts);
    sc.all.clear();
    sc.bins.assign(3 * nbins, CutScratch::Bin{});
    sc.suffix_area.resize(nbins + 1);
    sc.suffix_n.resize(nbins + 1);
    sc.prefix_box.resize(3 * nbins);
    sc.suffix_box.resize(3 * nbins);
    // One pass over the primitives fills the three axes' bins.
    float lo[3], scale[3];
    for (int axis = 0; axis < 3; ++axis) {
        lo[axis] = cb.lo[axis];
        const float ext = cb.hi[axis] - lo[axis];
        scale[axis] = ext > 0 ? nbins / ext : 0;
    }
    for (std::uint32_t i = begin; i < end; ++i) {
        const Vec3& c = info.centroids[ids[i]];
        const Box3& bounds = info.bounds[ids[i]];
        for (int axis = 0; axis < 3; ++axis) {
            const int b = std::min(nbins - 1, static_cast<int>((c[axis] - lo[axis]) * scale[axis]));
            CutScratch::Bin& bin = sc.bins[axis * nbins + b];
            extend(bin.box, bounds);
            ++bin.n;
        }
    }
    for (int axis = 0; axis < 3; ++axis) {
        if (!(cb.hi[axis] - lo[axis] > 0)) continue;
        const CutScratch::Bin* bins = sc.bins.data() + axis * nbins;
        Box4* prefix_box = sc.prefix_box.data() + axis * nbins;
        Box4* suffix_box = sc.suffix_box.data() + axis * nbins;
        // The running boxes in locals, only stored (read back from the array they had just gone
        // to, they waited on the store every bin): a kept cut's boxes are then two lookups
        // rather than a pass over the bins each (32 kept cuts took 512 box unions a node).
        Box4 suffix;
        std::uint32_t suffix_n = 0;
        sc.suffix_area[nbins] = 0;
        sc.suffix_n[nbins] = 0;
        for (int b = nbins - 1; b >= 0; --b) {
            suffix.extend(bins[b].box.lo, bins[b].box.hi);
            suffix_n += bins[b].n;
            suffix_box[b] = suffix;
            sc.suffix_area[b] = suffix_n ? area_of(suffix) : 0;  // Box3::area(): 0 when empty
            sc.suffix_n[b] = suffix_n;
        }
        Box4 prefix;
        std::uint32_t n = 0;
        for (int b = 0; b + 1 < nbins; ++b) {
            prefix.extend(bins[b].box.lo, bins[b].box.hi);
            prefix_box[b] = prefix;
            n += bins[b].n;
            if (n == 0 || sc.suffix_n[b + 1] == 0) continue;
            sc.all.push_back({area_of(prefix) * n + sc.suffix_area[b + 1] * sc.suffix_n[b + 1], axis, b + 1, n, sc.suffix_n[b + 1]});
        }
    }
    cuts.clear();
    keep_cheapest(keep, nbins, sc, cuts);
}

}  // namespace rtcost::bvh
