#pragma once
// A binary BVH's references in packs of four triangles (TriPack<4>), reference k in lane k % 4 of
// pack k / 4, tested four at a time in the baseline's lanes by bvh-wide's SIMD watertight test:
// the same hits, counts and order as the scalar loop over LeafPrims. Used where every reference
// is tested as a triangle (meshes); the packs then replace the LeafPrim copies, 48 bytes a
// triangle against 44.

#include <algorithm>
#include <cstdint>
#include <vector>

#include "../common/impl.hpp"
#include "../common/lanes_base.hpp"
#include "../common/leaf_prims.hpp"
#include "../common/tri_pack.hpp"
#include "scene/watertight.hpp"

namespace rtcost::bvh {

namespace packs {

using F4 = lanes::F4;
#include "../common/tri_pack_test.inc"

/// References [first, first + count) of `packs`: tested a pack at a time by test_lanes (a
/// leaf's references may start and end anywhere in a pack). True when an any-hit query ends.
template <class C, Query Q>
bool test_range(const TriPack<4>* packs, std::uint32_t first, std::uint32_t count, const Shear<F4>& shear,
                const Ray& ray, Hit& hit, C& counting, bool& found) {
    for (std::uint32_t k = first, end = first + count; k < end;) {
        const std::uint32_t lo = k % 4, hi = std::min<std::uint32_t>(4, lo + (end - k));
        if (test_lanes<F4, 4, C, Q>(packs[k / 4], lo, hi, shear, ray, hit, counting, found)) return true;
        k += hi - lo;
    }
    return false;
}

}  // namespace packs

/// Every reference of a BVH as a lane of a pack, or none when some reference is not a triangle.
struct LeafPacks {
    std::vector<TriPack<4>> packs;

    /// Packs of `prims` (LeafPrims in leaf order) when every one is tested as a triangle.
    explicit LeafPacks(const std::vector<LeafPrim>& prims) {
        if (prims.empty() || !std::all_of(prims.begin(), prims.end(), [](const LeafPrim& p) { return p.as_triangle; }))
            return;
        packs.resize((prims.size() + 3) / 4);
        for (std::size_t k = 0; k < prims.size(); ++k) {
            TriPack<4>& q = packs[k / 4];
            const std::size_t l = k % 4;
            const LeafPrim& p = prims[k];
            const Vec3 v[3] = {p.tri.v0, p.tri.v1, p.tri.v2};
            for (int i = 0; i < 3; ++i)
                for (int a = 0; a < 3; ++a) q.v[3 * i + a][l] = v[i][a];
            q.id[l] = p.id;
            q.kind[l] = p.kind;
        }
    }
    bool active() const { return !packs.empty(); }
    /// Reference `k` as a LeafPrim (for the tests that take one reference at a time).
    LeafPrim prim(std::uint32_t k) const {
        const TriPack<4>& q = packs[k / 4];
        const std::uint32_t l = k % 4;
        LeafPrim p;
        p.tri = Triangle{{q.v[0][l], q.v[1][l], q.v[2][l]}, {q.v[3][l], q.v[4][l], q.v[5][l]}, {q.v[6][l], q.v[7][l], q.v[8][l]}};
        p.id = q.id[l];
        p.kind = q.kind[l];
        p.as_triangle = true;
        return p;
    }
    std::uint32_t id(std::uint32_t k) const { return packs[k / 4].id[k % 4]; }
    const void* at(std::uint32_t k) const { return packs.data() + k / 4; }
    std::size_t bytes() const { return packs.size() * sizeof(TriPack<4>); }
};

}  // namespace rtcost::bvh
