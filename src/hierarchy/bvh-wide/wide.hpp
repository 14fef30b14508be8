#pragma once
// bvh-wide: a 4- or 8-wide BVH collapsed from the binned SAH tree, its children's boxes stored
// as arrays (one lane per child) so that one SIMD slab test meets all of them at once.
//
// The traversals live in per-instruction-set files (walk_sse.cpp, walk_avx2.cpp), each compiled
// for its own target inside its own namespace, and are chosen once per build by what the CPU
// runs: the library itself is built for the baseline x86-64, not -march=native. Hand-written
// intrinsics rather than a SIMD library (Highway, xsimd): the traversal needs five operations
// (sub, mul, min, max, compare-to-mask) on two fixed widths, and runtime dispatch among the
// two targets is two function tables; a library would add a dependency for that.

#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "../common/impl.hpp"
#include "../common/tri_pack.hpp"
#include "scene/watertight.hpp"
#include "util/cpu.hpp"

namespace rtcost::wide {

/// One wide node of `W` lanes (a lane per child): 32 W bytes, a multiple of the cache line.
/// `b[2 a]` holds the children's lower bounds on axis a, `b[2 a + 1]` the upper ones. An unused
/// lane has an empty box (+inf, -inf), which no slab test accepts, and `child == kEmpty`.
template <int W>
struct alignas(64) Node {
    float b[6][W];
    /// Interior child: its node index. Leaf child: kLeaf | first primitive slot.
    std::uint32_t child[W];
    /// Leaf child: its number of primitives; interior child: its number of used lanes.
    std::uint32_t count[W];
};

inline constexpr std::uint32_t kLeaf = 0x80000000u;
inline constexpr std::uint32_t kEmpty = 0xffffffffu;
/// Bound on depth (the collapsed tree is never deeper than the binary one).
inline constexpr int kMaxDepth = 100;

/// A leaf's primitive other than a triangle: tested through
/// Scene::intersect, as test_prim does.
struct Other {
    std::uint32_t id = 0;
    PrimKind kind = PrimKind::Sphere;
};

/// The pack width of a leaf of `ntri` triangles in a tree of `tri_lanes`-lane packs: a leaf of
/// at most four is one pack of four (eight lanes would be mostly empty and twice the bytes to
/// read). The builder stores and the traversals read leaves by it.
constexpr int pack_lanes(int tri_lanes, std::uint32_t ntri) { return tri_lanes > 4 && ntri <= 4 ? 4 : tri_lanes; }

/// A leaf's storage begins at a multiple of this many bytes in the leaf arena.
inline constexpr std::size_t kLeafAlign = 32;

/// What a traversal reads: the nodes of one width, and the leaves in leaf order. A leaf lane's
/// `child` is kLeaf | (its offset in `leaves` / kLeafAlign) and its `count` packs the
/// triangles (low 16 bits) and the other primitives (high 16 bits). At that offset lie
/// ceil(triangles / K) TriPack<K>, then the other primitives as Other records, where K is
/// pack_lanes(tri_lanes, triangles).
struct View {
    const void* nodes = nullptr;
    int width = 8;
    Box3 root_box;
    std::uint32_t root_count = 0;       ///< lanes used in the root
    const std::byte* leaves = nullptr;
    int tri_lanes = 4;  ///< 4 for the baseline traversal, 4 or 8 for AVX2
    const Scene* scene = nullptr;
    /// Order in which an any-hit query visits the children a node's slab test met. AsClosest:
    /// nearest first. LeavesFirst: leaf children first (only a leaf can end the query), nearest
    /// first within leaves and within interior nodes: occlusion by a large primitive held high in
    /// the tree (a wall or floor over the whole scene) is then found at the top instead of after
    /// everything nearer along the ray. Stored: in the node's order, first child first, with no
    /// sort at all (as Embree's occlusion traversal): any occluder ends the query, so ordering
    /// buys little, and the sort was 6-9% of a mesh's shadow rays.
    OcclusionOrder any_order = OcclusionOrder::AsClosest;
};

/// One traversal instantiation: closest, any or all, with or without counting. The last
/// argument is null but in a replay, which answers every primitive test from the ray's known
/// crossings (KnownTest) instead of intersecting.
template <class C>
using WalkFn = bool (*)(const View&, const Ray&, Hit&, C&, const KnownTest*);
struct Walks {
    WalkFn<NoCount> fast[3] = {};  ///< indexed by Query
    WalkFn<Count> counted[3] = {};
    WalkFn<Count> replay[3] = {};  ///< counted, each primitive test a KnownTest
};

/// The traversals compiled for the baseline (SSE2 on x86-64, plain loops elsewhere; triangle
/// packs of 4) and, on x86-64, for AVX2 (packs of `tri_lanes`, 4 or 8); `width` is 4 or 8.
Walks walks_baseline(int width);
Walks walks_avx2(int width, int tri_lanes);

class BvhWide final : public HierarchyImpl<BvhWide> {
public:
    struct Data;
    BvhWide(const Scene& s, std::unique_ptr<Data> d, Walks walks);
    ~BvhWide() override;

    std::string_view name() const override { return "bvh-wide"; }
    bool emit_model(ModelSink& sink) const override;

    template <class C, Query Q>
    bool trace(const Ray& ray, Hit& hit, C& counting) const {
        if constexpr (C::enabled) return walks_.counted[static_cast<int>(Q)](view_, ray, hit, counting, nullptr);
        else return walks_.fast[static_cast<int>(Q)](view_, ray, hit, counting, nullptr);
    }
    /// The same walk with every primitive test answered from the ray's known crossings: what
    /// Hierarchy::replay needs (the model tree's prediction, without materialising the tree).
    /// Only KnownTest: a leaf's triangles are otherwise tested a pack at a time.
    template <class C, Query Q, class PrimTest>
        requires std::is_same_v<C, Count> && std::is_same_v<PrimTest, KnownTest>
    bool trace_with(const Ray& ray, Hit& hit, C& counting, const PrimTest& test) const {
        return walks_.replay[static_cast<int>(Q)](view_, ray, hit, counting, &test);
    }

protected:
    StructureStats compute_structure() const override;

private:
    std::unique_ptr<Data> d_;
    View view_;
    Walks walks_;
};

}  // namespace rtcost::wide
