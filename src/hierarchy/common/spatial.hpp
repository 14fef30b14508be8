#pragma once
// What every space-subdividing hierarchy (bsp, octree, kd-trees, grid) shares: which cells a
// primitive is referenced by, the `assign` and `mailbox` parameters, and the per-ray mailbox.

#include <cstdint>
#include <vector>

#include "rtcost/hierarchy.hpp"

namespace rtcost::spatial {

/// Half `side` (0 low, 1 high) of `b` cut at `s` on `axis`.
inline Box3 half(const Box3& b, int axis, float s, int side) {
    Box3 c = b;
    if (side) c.lo[axis] = s;
    else c.hi[axis] = s;
    return c;
}

/// How primitives are assigned to cells.
enum class Assign {
    Bounds,  ///< every cell the primitive's bounding box overlaps (closed intervals)
    Exact,   ///< every cell its surface really meets (conservative where exactness is not cheap)
};

inline const ParamSpec kAssignParam = ParamSpec::choice(
    "assign", "bounds", {"bounds", "exact"}, "bounds: cells the primitive's box overlaps; exact: cells its surface meets");
inline const ParamSpec kMailboxParam = ParamSpec::flag("mailbox", "0", "1: each primitive tested at most once per ray");

Assign parse_assign(const Params& p);

/// Every primitive's bounding box, by id (Scene::prim_bounds): what cell assignment reads for
/// each primitive at every node or grid built.
std::vector<Box3> prim_bounds(const Scene& s);

/// True when primitive `id`, whose bounding box is `pb`, is to be referenced by `cell`.
/// Exact tests: triangles and polygons by clipping against the cell (separating axes for
/// triangles), spheres by the cell meeting the sphere's surface (not lying wholly inside or
/// outside it); cones fall back to their bounding box (conservative: never fewer cells).
bool overlaps(const Scene& s, std::uint32_t id, const Box3& pb, const Box3& cell, Assign how);

/// Per-thread, per-ray record of the primitives already tested ("mailbox"). A ray takes a new
/// serial; a primitive whose stamp equals the serial was tested by this ray already.
class Mailbox {
public:
    /// The calling thread's mailbox for a hierarchy over `n` primitives, reset for a new ray.
    static Mailbox& begin_ray(const void* owner, std::size_t n);
    /// True the first time `id` is seen during the current ray.
    bool first_visit(std::uint32_t id) {
        if (stamps_[id] == serial_) return false;
        stamps_[id] = serial_;
        return true;
    }

private:
    const void* owner_ = nullptr;
    std::uint64_t serial_ = 0;
    std::vector<std::uint64_t> stamps_;
};

}  // namespace rtcost::spatial
