#pragma once
// What Kaplan's BSP tree (`bsp`) and Glassner's octree (`octree`) share: regular mid-plane
// subdivision of the scene box, and the way a ray finds its cells by its parameter t.
//
// Cells by ray parameter. A split plane s on an axis the ray moves along is crossed at
// ts = (s - o) * inv, always computed by cross() (the same float expression everywhere). A cell
// holds the ray for a half-open stretch of t: at each ancestor's plane the ray "just after t" is
// on the high side when t >= ts (moving up) or t < ts (moving down), so a t equal to a crossing
// goes to the side the ray moves into. The leaves' stretches thus partition the ray's t range
// exactly, with no gap or overlap, whatever the rounding: locating the leaf at a cell's exit (the
// smallest crossing that bounds it from above) always finds the next cell, t strictly grows, and
// no cell of the partition is skipped. On an axis the ray does not move along (zero or denormal
// direction component) the side is the origin's; a ray lying in a plane is on both sides (both
// closed cells hold every primitive that can meet it there), and both are searched.
//
// Build. The root cell is the scene box; a cell's children are its halves (bsp) or octants
// (octree) at the float midpoint (lo + hi) * 0.5f. A primitive goes to every child that
// spatial::overlaps says (assign=bounds: its box meets the closed child; exact: its surface
// does). When the exact test puts a primitive of the parent in no child (rounding in the
// clipper), it goes to every child its box meets: never fewer cells than it really meets.

#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "spatial.hpp"
#include "impl.hpp"

namespace rtcost::subdiv {

/// Safety net against runaway memory (64 MB of references, 8M nodes): once the structure holds
/// this many leaf references or nodes, every node still to be built becomes a leaf (depth first,
/// so the part of the scene built last gets the shallower tree). The defaults stay far below on
/// every SPD scene (largest: tetra's octree, 2.5M references, 1.3M nodes); one known case reaches
/// it: shells.nff's octree with assign=exact, where hundreds of sphere surfaces cross every cell
/// along the spiral and the surfaces, unlike their boxes, never trip the growth guard.
inline constexpr std::size_t kMaxRefs = std::size_t{1} << 24;
inline constexpr std::size_t kMaxNodes = std::size_t{1} << 23;

/// The midpoint both builders split at, and the model tree's planes.
inline float mid(float lo, float hi) { return (lo + hi) * 0.5f; }

/// The centre both builders split at.
inline Vec3 centre(const Box3& b) { return {mid(b.lo.x, b.hi.x), mid(b.lo.y, b.hi.y), mid(b.lo.z, b.hi.z)}; }

/// The growth guard (kGrowthParam): the octants' reference counts `counts` add up to at least
/// `growth` times the `n` references of their cell, so subdividing would hardly separate them.
inline bool hardly_separates(const std::array<std::size_t, 8>& counts, std::size_t n, double growth) {
    std::size_t sum = 0;
    for (std::size_t c : counts) sum += c;
    return static_cast<double>(sum) >= growth * static_cast<double>(n);
}

using spatial::half;

/// Octant `k` of `b` around `c` (bit 0: high x, bit 1: high y, bit 2: high z).
inline Box3 octant(const Box3& b, Vec3 c, int k) {
    Box3 o = b;
    for (int a = 0; a < 3; ++a) {
        if (k >> a & 1) o.lo[a] = c[a];
        else o.hi[a] = c[a];
    }
    return o;
}

/// A ray prepared for locating cells by its parameter (see the file comment).
struct CellRay {
    RayInv ri;
    bool moving[3];  ///< crosses the planes of this axis (finite reciprocal direction)

    explicit CellRay(const Ray& r) : ri(r) {
        for (int a = 0; a < 3; ++a) moving[a] = std::fabs(ri.inv[a]) < kInf;
    }
    /// Where the ray crosses plane `s` of a moving axis `a`.
    float cross(int a, float s) const { return (s - ri.o[a]) * ri.inv[a]; }
    /// On a moving axis: the ray just after `t` lies on the high side of the plane crossed at `ts`.
    bool high_after(int a, float ts, float t) const { return ri.neg[a] ? t < ts : t >= ts; }
    /// On a moving axis: the crossing bounds the side `high` from above (the ray leaves it there).
    bool leaves(int a, bool high) const { return high == static_cast<bool>(ri.neg[a]); }
};

/// The root clip: box_entry (the RayInv form, with its conservative factor on the exit) that
/// also returns the exit. False when the ray misses the box within (tmin, tmax).
inline bool clip_root(const Box3& b, const RayInv& r, float tmin, float tmax, float& t0, float& t1) {
    const Vec3* f = &b.lo;
    t0 = tmin;
    t1 = tmax;
    for (int a = 0; a < 3; ++a) {
        const float tn = (f[r.neg[a]][a] - r.o[a]) * r.inv[a];
        const float tf = (f[1 - r.neg[a]][a] - r.o[a]) * r.inv[a] * 1.0000004f;
        // NaN (0 * inf: a ray in a face's plane) fails both compares and is ignored.
        t0 = tn > t0 ? tn : t0;
        t1 = tf < t1 ? tf : t1;
    }
    return t0 <= t1;
}

/// Reference assignment shared by the builders.
class Assigner {
public:
    Assigner(const Scene& s, spatial::Assign how);

    /// Every primitive with a non-empty bounding box, ascending.
    std::vector<std::uint32_t> all() const;

    /// For each of `refs`, the mask of the `n` (<= 8) `cells` it goes to; `counts[k]` the number
    /// of references cell k gets.
    void masks(const std::vector<std::uint32_t>& refs, const Box3* cells, int n, std::vector<std::uint8_t>& mask,
               std::array<std::size_t, 8>& counts) const;

    /// The references of cell `k` by the masks.
    static std::vector<std::uint32_t> select(const std::vector<std::uint32_t>& refs,
                                             const std::vector<std::uint8_t>& mask, int k, std::size_t count);

private:
    const Scene& s_;
    spatial::Assign how_;
    std::vector<Box3> bounds_;
};

/// Tests the `count` references `refs` of a leaf at `depth` (bsp and octree leaves alike) with
/// `test` (RealPrimTest, or a replay's); true when an any-hit query may stop. With kMailbox, a primitive already tested in this ray is skipped.
template <class C, Query Q, bool kMailbox, class PrimTest>
bool test_leaf(const std::uint32_t* refs, std::uint32_t count, int depth, const Ray& ray, Hit& hit, C& counting,
               spatial::Mailbox* mb, bool& found, PrimTest& test) {
    counting.leaf(depth, count);
    for (std::uint32_t k = 0; k < count; ++k) {
        const std::uint32_t id = refs[k];
        if constexpr (kMailbox) {
            if (!mb->first_visit(id)) continue;
        }
        if (test(id, ray, hit, counting)) {
            found = true;
            if constexpr (Q == Query::Any) return true;
        }
    }
    return false;
}

inline const ParamSpec kTraversalParam = ParamSpec::choice(
    "traversal", "locate", {"locate", "recursive"},
    "locate: each next cell found by a descent from the root at the current cell's exit (the original); "
    "recursive: front-to-back recursion over the children");

/// Guard against subdivision that separates nothing (cells around a vertex shared by a fan of
/// triangles; spheres overlapping by the hundred, as in shells.nff): a node stays a leaf when its
/// eight octants would hold at least `growth` times its references together, i.e. when on average
/// a reference would straddle into `growth` of the eight. Measured with the defaults (camera
/// rays): on teapot and tetra the octree keeps 60% of the references of the unguarded build
/// (growth=9) and costs fewer tests and steps per ray (teapot N_IT 5.1 vs 6.1); on shells the
/// unguarded build runs into kMaxRefs (33M references), the guarded one holds 1.4M (bsp) and 3.2M
/// (octree).
inline const ParamSpec kGrowthParam = ParamSpec::real(
    "growth", "6", 1, 9,
    "a node stays a leaf when its eight octants (a BSP node: those of its next three planes) would hold at least "
    "growth x its references together (8: only when no octant loses one; 9: never)");

/// An optional termination test both builders call with a cell about to be split: its box, its
/// reference count, and the `k` children it would get with their reference counts; false keeps
/// the cell a leaf (the designed hierarchies' cost model decides there).
using SplitTest = std::function<bool(const Box3& cell, std::size_t n, const Box3* children, const std::size_t* counts, int k)>;

/// The parameters `bsp` and `octree` share, with each one's defaults for depth and leaf size
/// (read by cell_tree.hpp's read_options).
std::vector<ParamSpec> param_specs(int default_depth, int max_depth, int default_prims);

}  // namespace rtcost::subdiv
