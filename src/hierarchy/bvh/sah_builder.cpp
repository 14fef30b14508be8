// bvh-sah: the surface area heuristic builder. Binned (Wald 2007: centroids binned on each
// axis, every bin boundary evaluated) or, with sweep, every split of the centroid-sorted
// primitives on each axis. A node becomes a leaf when no split beats testing its primitives,
// unless it holds more than max_prims.
#include <algorithm>
#include <array>
#include <numeric>

#include "box4.hpp"
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

// Bin indices of a centroid on the three axes: bin_of lane by lane.
inline std::array<int, 3> bins_of(f4 c, f4 lo, f4 scale, int nbins) {
#if defined(__SSE2__)
    __m128 f = reinterpret_cast<__m128>((c - lo) * scale);
    f = _mm_max_ps(f, _mm_setzero_ps());  // 0 for f <= 0 and for NaN, as bin_of
    f = _mm_min_ps(f, _mm_set1_ps(static_cast<float>(nbins - 1)));
    alignas(16) std::int32_t k[4];
    _mm_store_si128(reinterpret_cast<__m128i*>(k), _mm_cvttps_epi32(f));
    return {k[0], k[1], k[2]};
#else
    return {bin_of(c[0], lo[0], scale[0], nbins), bin_of(c[1], lo[1], scale[1], nbins), bin_of(c[2], lo[2], scale[2], nbins)};
#endif
}

// The binned build works on a copy of each primitive's box with its id, partitioned in place,
// rather than on ids that index the boxes: every pass over a node's primitives (bounds, bins,
// partition) then reads memory in order, four lanes at a time. It makes exactly the tree the
// id-based top-down builder made (same bins, same float expressions, the same partition of the
// same sequence).
class BinnedSah {
public:
    BinnedSah(const Scene& s, const SahOptions& o) : o_(o), bins_(3 * std::size_t(o.bins)), counts_(bins_.size()), right_area_(o.bins), right_n_(o.bins) {
        refs_.resize(s.size());
        for (std::uint32_t i = 0; i < s.size(); ++i) refs_[i] = BoxRef(s.summaries()[i].bounds, i);
    }

    BvhData build() {
        BvhData d = build_nodes(
            static_cast<std::uint32_t>(refs_.size()),
            [&](std::uint32_t begin, std::uint32_t end) {
                // The centroids' box too, kept for the split of this same node, which comes next.
                Box4 box, cb;
                for (std::uint32_t i = begin; i < end; ++i) box.extend(refs_[i].lo, refs_[i].hi), cb.extend(refs_[i].centroid());
                centroid_box_ = cb.box3();
                return box.box3();
            },
            [&](std::uint32_t begin, std::uint32_t end, const Box3& box, int depth) {
                return split(begin, end, box, centroid_box_, depth);
            });
        d.refs.resize(refs_.size());
        for (std::size_t i = 0; i < refs_.size(); ++i) d.refs[i] = refs_[i].id();
        return d;
    }

private:
    // Every bin boundary on each axis (Wald 2007), the three axes binned in one pass.
    Split best(std::uint32_t begin, std::uint32_t end, const Box3& cb) {
        const int nbins = o_.bins;
        f4 lo{0, 0, 0, 0}, scale{0, 0, 0, 0};
        bool binned[3];
        for (int axis = 0; axis < 3; ++axis) {
            const float ext = cb.hi[axis] - cb.lo[axis], sc = nbins / ext;
            binned[axis] = ext > 0 && std::isfinite(sc);  // not flat, nor too thin to bin in float
            if (binned[axis]) lo[axis] = cb.lo[axis], scale[axis] = sc;
        }
        std::fill(bins_.begin(), bins_.end(), Box4{});
        std::fill(counts_.begin(), counts_.end(), 0u);
        for (std::uint32_t i = begin; i < end; ++i) {
            const BoxRef& r = refs_[i];
            const std::array<int, 3> k = bins_of(r.centroid(), lo, scale, nbins);
            for (int axis = 0; axis < 3; ++axis) {  // a flat axis's bins are filled and ignored
                bins_[axis * nbins + k[axis]].extend(r.lo, r.hi);
                ++counts_[axis * nbins + k[axis]];
            }
        }
        Split best;
        for (int axis = 0; axis < 3; ++axis) {
            if (!binned[axis]) continue;
            const Box4* bins = bins_.data() + axis * nbins;
            const std::uint32_t* counts = counts_.data() + axis * nbins;
            Box3 acc;
            std::uint32_t n = 0;
            for (int b = nbins - 1; b > 0; --b) {
                acc.extend(bins[b].box3());
                n += counts[b];
                right_area_[b] = acc.area();
                right_n_[b] = n;
            }
            acc = Box3{};
            n = 0;
            for (int b = 0; b < nbins - 1; ++b) {
                acc.extend(bins[b].box3());
                n += counts[b];
                if (n == 0 || right_n_[b + 1] == 0) continue;
                const float cost = acc.area() * n + right_area_[b + 1] * right_n_[b + 1];
                if (cost < best.cost) best = {axis, cost, static_cast<std::uint32_t>(b + 1)};
            }
        }
        return best;
    }

    std::uint32_t split(std::uint32_t begin, std::uint32_t end, const Box3& box, const Box3& cb, int depth) {
        const std::uint32_t n = end - begin;
        if (depth >= o_.max_depth) return begin;
        const Split sp = best(begin, end, cb);
        // SAH in units of the parent's area: c_trav + c_isect * (A_L N_L + A_R N_R) / A.
        const float area = box.area();
        const float split_cost = sp.axis < 0 ? kInf : o_.c_trav + o_.c_isect * (area > 0 ? sp.cost / area : n);
        const float leaf_cost = o_.c_isect * n;
        if (static_cast<int>(n) <= o_.max_prims && leaf_cost <= split_cost) return begin;
        if (sp.axis < 0) {
            // All centroids coincide: no plane separates them, so halve the list.
            const std::uint32_t mid = begin + n / 2;
            std::nth_element(refs_.begin() + begin, refs_.begin() + mid, refs_.begin() + end, [](const BoxRef& a, const BoxRef& b) {
                const float ca = a.centroid()[0], cb2 = b.centroid()[0];
                return ca < cb2 || (ca == cb2 && a.id() < b.id());
            });
            return mid;
        }
        // The same binning expression as best(), so every primitive lands on the side it was
        // counted on.
        const int axis = sp.axis, nbins = o_.bins;
        const float lo = cb.lo[axis], scale = nbins / (cb.hi[axis] - lo);
        auto it = std::partition(refs_.begin() + begin, refs_.begin() + end, [&](const BoxRef& r) {
            return bin_of(r.centroid()[axis], lo, scale, nbins) < static_cast<int>(sp.at);
        });
        return static_cast<std::uint32_t>(it - refs_.begin());
    }

    const SahOptions& o_;
    std::vector<BoxRef> refs_;
    Box3 centroid_box_;
    std::vector<Box4> bins_;
    std::vector<std::uint32_t> counts_;
    std::vector<float> right_area_;
    std::vector<std::uint32_t> right_n_;
};

}  // namespace

BvhData build_sah(const Scene& s, const SahOptions& o) {
    if (!o.sweep) return BinnedSah(s, o).build();
    PrimInfo info(s);
    return build_topdown(s, info, [&](std::vector<std::uint32_t>& ids, std::uint32_t begin, std::uint32_t end,
                                      const Box3& box, int depth) -> std::uint32_t {
        const std::uint32_t n = end - begin;
        if (depth >= o.max_depth) return begin;
        Split sp = best_sweep(ids, begin, end, info);
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
        const std::uint32_t mid = sp.axis < 0 ? begin + n / 2 : begin + sp.at;
        std::nth_element(ids.begin() + begin, ids.begin() + mid, ids.begin() + end, by_axis(sp.axis < 0 ? 0 : sp.axis));
        return mid;
    });
}

bool large_triangle_mesh(const Scene& s) {
    // Every primitive tested as a triangle: the binary BVHs then test their leaves a pack of
    // four at a time (leaf_packs.hpp).
    constexpr std::size_t kLargeMesh = std::size_t{1} << 16;
    return s.size() >= kLargeMesh && s.kind_counts()[static_cast<int>(PrimKind::Triangle)] == s.size();
}

SahOptions sah_leaf_costs(const Scene& s, SahOptions o) {
    if (!large_triangle_mesh(s)) return o;
    o.max_prims = 16;
    o.c_trav = 4;
    return o;
}

}  // namespace rtcost::bvh
