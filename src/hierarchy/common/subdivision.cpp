// Reference assignment shared by `bsp` and `octree`.
#include "subdivision.hpp"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace rtcost::subdiv {

Assigner::Assigner(const Scene& s, spatial::Assign how) : s_(s), how_(how), bounds_(spatial::prim_bounds(s)) {}

std::vector<std::uint32_t> Assigner::all() const {
    std::vector<std::uint32_t> r;
    r.reserve(bounds_.size());
    for (std::uint32_t i = 0; i < bounds_.size(); ++i)
        if (!bounds_[i].empty()) r.push_back(i);
    return r;
}

void Assigner::masks(const std::vector<std::uint32_t>& refs, const Box3* cells, int n, std::vector<std::uint8_t>& mask,
                     std::array<std::size_t, 8>& counts) const {
    mask.assign(refs.size(), 0);
    counts.fill(0);
    // The cells' faces in columns, eight of them (past n: empty, lo +inf and hi -inf, which no
    // box overlaps), so that one reference's box meets all the cells in a few SIMD compares: the
    // box tests were a third of bsp-design's time. The same compares as Box3::overlaps.
    alignas(16) float lo[3][8], hi[3][8];
    for (int a = 0; a < 3; ++a)
        for (int k = 0; k < 8; ++k) {
            lo[a][k] = k < n ? cells[k].lo[a] : kInf;
            hi[a][k] = k < n ? cells[k].hi[a] : -kInf;
        }
    const int halves = n > 4 ? 2 : 1;  // columns of four holding the n cells
    for (std::size_t i = 0; i < refs.size(); ++i) {
        const std::uint32_t id = refs[i];
        const Box3& pb = bounds_[id];
        unsigned box_m = 0;
#if defined(__SSE2__)
        for (int half = 0; half < halves; ++half) {
            __m128 in = _mm_castsi128_ps(_mm_set1_epi32(-1));
            for (int a = 0; a < 3; ++a) {
                // pb.lo <= cell.hi && cell.lo <= pb.hi
                in = _mm_and_ps(in, _mm_cmple_ps(_mm_set1_ps(pb.lo[a]), _mm_load_ps(hi[a] + 4 * half)));
                in = _mm_and_ps(in, _mm_cmple_ps(_mm_load_ps(lo[a] + 4 * half), _mm_set1_ps(pb.hi[a])));
            }
            box_m |= static_cast<unsigned>(_mm_movemask_ps(in)) << (4 * half);
        }
#else
        (void)halves;
        for (int k = 0; k < n; ++k)
            if (pb.overlaps(cells[k])) box_m |= 1u << k;
#endif
        unsigned m = box_m;
        if (how_ != spatial::Assign::Bounds) {
            m = 0;
            for (unsigned b = box_m; b; b &= b - 1) {
                const int k = __builtin_ctz(b);
                if (spatial::overlaps(s_, id, pb, cells[k], how_)) m |= 1u << k;
            }
            if (m == 0) m = box_m;  // rounding in the exact test: stay conservative
        }
        mask[i] = static_cast<std::uint8_t>(m);
        for (; m; m &= m - 1) ++counts[__builtin_ctz(m)];
    }
}

std::vector<std::uint32_t> Assigner::select(const std::vector<std::uint32_t>& refs,
                                            const std::vector<std::uint8_t>& mask, int k, std::size_t count) {
    std::vector<std::uint32_t> out;
    out.reserve(count);
    for (std::size_t i = 0; i < refs.size(); ++i)
        if (mask[i] >> k & 1) out.push_back(refs[i]);
    return out;
}

std::vector<ParamSpec> param_specs(int default_depth, int max_depth, int default_prims) {
    return {ParamSpec::integer("max_depth", std::to_string(default_depth), 0, max_depth, "deepest leaf (root at 0)"),
            ParamSpec::integer("max_prims", std::to_string(default_prims), 1, 1 << 20,
                               "a node with at most this many references is a leaf"),
            kTraversalParam,
            spatial::kAssignParam,
            kGrowthParam,
            spatial::kMailboxParam};
}

}  // namespace rtcost::subdiv
