#pragma once
/// \file stats.hpp
/// Operation counters and the compile-time counting policy.
///
/// Every traversal in rtcost is one function template over a counting policy. `NoCount` has
/// empty inline members, so the instantiation with counting off is the fast path with no trace
/// of the counters; `Count` increments a RayCounters. There is never a runtime branch on
/// whether counting is on.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "rtcost/primitive.hpp"

namespace rtcost {

/// Deepest level for which per-depth visits are kept; deeper visits are folded into the last.
inline constexpr int kMaxStatDepth = 64;

/// Operation counts, summed over one or many rays. Field names follow the cost model's
/// operation kinds and Havran's statistics.
struct RayCounters {
    std::uint64_t rays = 0;
    std::uint64_t box = 0;       ///< ray-box slab tests
    std::uint64_t plane = 0;     ///< separating-plane compares
    std::uint64_t hop = 0;       ///< 3DDDA cell steps
    std::uint64_t classify = 0;  ///< compares while classifying a ray (5D)
    std::array<std::uint64_t, kPrimKinds> prim{};  ///< primitive tests by kind
    /// Edges of the polygons of more than three vertices tested (their crossing test walks each
    /// one): a 144-gon's test took 228 ns here, a quad's 12, which one price per polygon test hides.
    std::uint64_t polygon_edges = 0;
    std::uint64_t steps = 0;         ///< N_TS: traversal steps (interior and leaf visits)
    std::uint64_t leaves = 0;        ///< N_ETS: leaves visited
    std::uint64_t empty_leaves = 0;  ///< N_EETS: empty leaves visited
    std::array<std::uint64_t, kMaxStatDepth> visits{};  ///< node visits per depth

    /// N_IT: primitive tests of all kinds.
    std::uint64_t prim_tests() const { return prim[0] + prim[1] + prim[2] + prim[3]; }

    RayCounters& operator+=(const RayCounters& o) {
        rays += o.rays; box += o.box; plane += o.plane; hop += o.hop; classify += o.classify;
        for (int k = 0; k < kPrimKinds; ++k) prim[k] += o.prim[k];
        polygon_edges += o.polygon_edges;
        steps += o.steps; leaves += o.leaves; empty_leaves += o.empty_leaves;
        for (int d = 0; d < kMaxStatDepth; ++d) visits[d] += o.visits[d];
        return *this;
    }
    bool operator==(const RayCounters&) const = default;
};

/// Counting policy "off": every member is an empty inline function.
struct NoCount {
    static constexpr bool enabled = false;
    void box() {}
    void plane() {}
    void hop() {}
    void classify() {}
    void prim(PrimKind) {}
    /// `n` polygon edges walked by a primitive test (RayCounters::polygon_edges).
    void edges(std::uint32_t) {}
    /// An interior node visited at `depth` (one traversal step).
    void interior(int) {}
    /// A leaf visited at `depth` holding `n` primitive references (one traversal step).
    void leaf(int, std::uint32_t) {}
};

/// Counting policy "on": increments the counters it refers to.
struct Count {
    static constexpr bool enabled = true;
    RayCounters& c;
    void box() { ++c.box; }
    void plane() { ++c.plane; }
    void hop() { ++c.hop; }
    void classify() { ++c.classify; }
    void prim(PrimKind k) { ++c.prim[static_cast<int>(k)]; }
    void edges(std::uint32_t n) { c.polygon_edges += n; }
    void interior(int depth) {
        ++c.steps;
        ++c.visits[depth < kMaxStatDepth ? depth : kMaxStatDepth - 1];
    }
    void leaf(int depth, std::uint32_t n) {
        ++c.steps;
        ++c.leaves;
        c.empty_leaves += (n == 0);
        ++c.visits[depth < kMaxStatDepth ? depth : kMaxStatDepth - 1];
    }
};

/// Structural statistics of a built hierarchy (Havran's names).
struct StructureStats {
    std::uint64_t interior = 0;     ///< N_IN
    std::uint64_t leaves = 0;       ///< N_V
    std::uint64_t empty_leaves = 0; ///< N_EV
    std::uint64_t references = 0;   ///< N_OIV: primitive references in leaves
    int depth = 0;                  ///< deepest leaf (root at depth 0)
    std::uint64_t bytes = 0;        ///< memory of the structure itself (not the scene)
    /// Box tests one SIMD test makes at once in a node visit (bvh-wide: its width; 2: a binary
    /// BVH's two children in one test); 1: one at a time (bvh-gs's n-ary nodes). Counted box
    /// tests are the same either way; the time model prices them apart.
    int box_lanes = 1;
    double seconds = 0;             ///< build time
    /// Bounds on time or memory that stopped the build short of what its parameters asked
    /// ("grid: resolution 46x46x46 reduced to ..."); empty when none did.
    std::vector<std::string> limits;
};

}  // namespace rtcost
