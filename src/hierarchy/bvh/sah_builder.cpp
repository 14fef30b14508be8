// bvh-sah: the surface area heuristic builder. Binned (Wald 2007: centroids binned on each
// axis, every bin boundary evaluated) or, with sweep, every split of the centroid-sorted
// primitives on each axis. A node becomes a leaf when no split beats testing its primitives,
// unless it holds more than max_prims.
#include <algorithm>
#include <numeric>

#include "topdown.hpp"

namespace rtcost::bvh {
namespace {

struct Split {
    int axis = -1;
    float cost = kInf;
    std::uint32_t at = 0;  // binned: first bin on the right; sweep: primitives on the left
};

// The bin of centroid coordinate `c`: clamped to [0, nbins - 1], and 0 for a NaN (a scale that
// overflowed), so that no float-to-int conversion is ever out of range.
inline int bin_of(float c, float lo, float scale, int nbins) {
    const float f = (c - lo) * scale;
    if (!(f > 0)) return 0;
    return f >= static_cast<float>(nbins - 1) ? nbins - 1 : static_cast<int>(f);
}

Split best_binned(const std::vector<std::uint32_t>& ids, std::uint32_t begin, std::uint32_t end,
                  const PrimInfo& info, const Box3& cb, int nbins) {
    Split best;
    struct Bin { Box3 box; std::uint32_t n = 0; };
    std::vector<Bin> bins(nbins);
    std::vector<float> right_area(nbins);
    std::vector<std::uint32_t> right_n(nbins);
    for (int axis = 0; axis < 3; ++axis) {
        float lo = cb.lo[axis], ext = cb.hi[axis] - lo;
        float scale = nbins / ext;
        if (!(ext > 0) || !std::isfinite(scale)) continue;  // flat, or too thin to bin in float
        std::fill(bins.begin(), bins.end(), Bin{});
        for (std::uint32_t i = begin; i < end; ++i) {
            const int b = bin_of(info.centroids[ids[i]][axis], lo, scale, nbins);
            bins[b].box.extend(info.bounds[ids[i]]);
            ++bins[b].n;
        }
        Box3 acc;
        std::uint32_t n = 0;
        for (int b = nbins - 1; b > 0; --b) {
            acc.extend(bins[b].box);
            n += bins[b].n;
            right_area[b] = acc.area();
            right_n[b] = n;
        }
        acc = Box3{};
        n = 0;
        for (int b = 0; b < nbins - 1; ++b) {
            acc.extend(bins[b].box);
            n += bins[b].n;
            if (n == 0 || right_n[b + 1] == 0) continue;
            float cost = acc.area() * n + right_area[b + 1] * right_n[b + 1];
            if (cost < best.cost) best = {axis, cost, static_cast<std::uint32_t>(b + 1)};
        }
    }
    return best;
}

Split best_sweep(std::vector<std::uint32_t>& ids, std::uint32_t begin, std::uint32_t end, const PrimInfo& info) {
    Split best;
    const std::uint32_t n = end - begin;
    std::vector<std::uint32_t> sorted(ids.begin() + begin, ids.begin() + end);
    std::vector<float> right_area(n);
    for (int axis = 0; axis < 3; ++axis) {
        std::sort(sorted.begin(), sorted.end(), [&](std::uint32_t a, std::uint32_t b) {
            float ca = info.centroids[a][axis], cb = info.centroids[b][axis];
            return ca < cb || (ca == cb && a < b);
        });
        Box3 acc;
        for (std::uint32_t i = n; i-- > 1;) {
            acc.extend(info.bounds[sorted[i]]);
            right_area[i] = acc.area();
        }
        acc = Box3{};
        for (std::uint32_t i = 0; i + 1 < n; ++i) {
            acc.extend(info.bounds[sorted[i]]);
            float cost = acc.area() * (i + 1) + right_area[i + 1] * (n - i - 1);
            if (cost < best.cost) best = {axis, cost, i + 1};
        }
    }
    return best;
}

}  // namespace

BvhData build_sah(const Scene& s, const SahOptions& o) {
    PrimInfo info(s);
    return build_topdown(s, info, [&](std::vector<std::uint32_t>& ids, std::uint32_t begin, std::uint32_t end,
                                      const Box3& box, int depth) -> std::uint32_t {
        const std::uint32_t n = end - begin;
        if (depth >= o.max_depth) return begin;
        Box3 cb;
        for (std::uint32_t i = begin; i < end; ++i) cb.extend(info.centroids[ids[i]]);
        Split sp = o.sweep ? best_sweep(ids, begin, end, info) : best_binned(ids, begin, end, info, cb, o.bins);
        // SAH in units of the parent's area: c_trav + c_isect * (A_L N_L + A_R N_R) / A.
        float area = box.area();
        float split_cost = sp.axis < 0 ? kInf : o.c_trav + o.c_isect * (area > 0 ? sp.cost / area : n);
        float leaf_cost = o.c_isect * n;
        if (static_cast<int>(n) <= o.max_prims && leaf_cost <= split_cost) return begin;
        auto by_axis = [&](int axis) {
            return [&info, axis](std::uint32_t a, std::uint32_t b) {
                float ca = info.centroids[a][axis], cb2 = info.centroids[b][axis];
                return ca < cb2 || (ca == cb2 && a < b);
            };
        };
        if (sp.axis < 0) {
            // All centroids coincide: no plane separates them, so halve the list.
            std::uint32_t mid = begin + n / 2;
            std::nth_element(ids.begin() + begin, ids.begin() + mid, ids.begin() + end, by_axis(0));
            return mid;
        }
        if (o.sweep) {
            std::uint32_t mid = begin + sp.at;
            std::nth_element(ids.begin() + begin, ids.begin() + mid, ids.begin() + end, by_axis(sp.axis));
            return mid;
        }
        // The same binning expression as best_binned, so every primitive lands on the side it was
        // counted on.
        const float lo = cb.lo[sp.axis], scale = o.bins / (cb.hi[sp.axis] - lo);
        auto it = std::partition(ids.begin() + begin, ids.begin() + end, [&](std::uint32_t id) {
            const int b = bin_of(info.centroids[id][sp.axis], lo, scale, o.bins);
            return b < static_cast<int>(sp.at);
        });
        return static_cast<std::uint32_t>(it - ids.begin());
    });
}

}  // namespace rtcost::bvh
