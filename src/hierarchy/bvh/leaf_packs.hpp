#pragma once
// A binary BVH's references in packs of four triangles (TriPack<4>), tested four at a time in the
// baseline's lanes by bvh-wide's SIMD watertight test: the same hits, counts and order as the
// scalar loop over LeafPrims. Used where every reference is tested as a triangle (meshes); the
// packs then replace the LeafPrim copies, 40 bytes a triangle against 44. A leaf's triangles
// follow the last leaf's lanes unless they would then span more packs than their count needs, in
// which case they start the next pack. (Packed end to end, as the references are, leaves spanned
// 24-26% more packs than they needed on bvh-sah's trees of 2CylinderEngine and yxa_1, leaves of
// about 6 triangles; every leaf from a pack of its own took 18-23% more lanes there.)

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "../common/impl.hpp"
#include "../common/lanes_base.hpp"
#include "../common/leaf_prims.hpp"
#include "../common/line_allocator.hpp"
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

/// Every leaf's references as lanes of packs, or none when some reference is not a triangle.
struct LeafPacks {
    /// The array starts a line, so a pack (160 bytes) starts a line or half a line in: a test of
    /// it reads three lines, never four.
    std::vector<TriPack<4>, LineAllocator<TriPack<4>>> packs;

    LeafPacks() = default;
    /// Packs of `prims` (LeafPrims in leaf order, a leaf's from `first` to `first + count`) when
    /// every one is tested as a triangle, leaf by leaf in that order, each leaf in as few packs
    /// as its count needs. Returns each leaf's first lane, in the order of `leaves` (empty when
    /// no packs are made).
    template <class Leaves>
    std::vector<std::uint32_t> pack(const std::vector<LeafPrim>& prims, const Leaves& leaves) {
        packs.clear();
        if (prims.empty() || !std::all_of(prims.begin(), prims.end(), [](const LeafPrim& p) { return p.kind == PrimKind::Triangle; }))
            return {};
        std::vector<std::uint32_t> lanes;
        lanes.reserve(leaves.size());
        std::size_t next = 0;  // the first free lane
        for (const auto& [first, count] : leaves) {
            // A leaf goes on where the last one ended unless that spans a pack more than its count
            // needs; then from the next pack. (An empty leaf needs no pack and moves nothing on.)
            if (count > 0 && (next % 4 + count + 3) / 4 > (count + 3) / 4) next = (next + 3) / 4 * 4;
            lanes.push_back(static_cast<std::uint32_t>(next));
            packs.resize((next + count + 3) / 4);
            for (std::uint32_t k = 0; k < count; ++k) {
                TriPack<4>& q = packs[(next + k) / 4];
                const std::uint32_t l = (next + k) % 4;
                const LeafPrim& p = prims[first + k];
                const Vec3 v[3] = {p.tri.v0, p.tri.v1, p.tri.v2};
                for (int i = 0; i < 3; ++i)
                    for (int a = 0; a < 3; ++a) q.v[3 * i + a][l] = v[i][a];
                q.id[l] = p.id;
            }
            next += count;
        }
        return lanes;
    }
    bool active() const { return !packs.empty(); }
    /// Reference `k` as a LeafPrim (for the tests that take one reference at a time).
    LeafPrim prim(std::uint32_t k) const {
        const TriPack<4>& q = packs[k / 4];
        const std::uint32_t l = k % 4;
        LeafPrim p;
        p.tri = Triangle{{q.v[0][l], q.v[1][l], q.v[2][l]}, {q.v[3][l], q.v[4][l], q.v[5][l]}, {q.v[6][l], q.v[7][l], q.v[8][l]}};
        p.id = q.id[l];
        p.kind = PrimKind::Triangle;
        return p;
    }
    std::uint32_t id(std::uint32_t k) const { return packs[k / 4].id[k % 4]; }
    const void* at(std::uint32_t k) const { return packs.data() + k / 4; }
    std::size_t bytes() const { return packs.size() * sizeof(TriPack<4>); }
};

}  // namespace rtcost::bvh
