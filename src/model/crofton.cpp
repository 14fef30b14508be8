// Cauchy-Crofton geometry: what isotropic lines meet, by surface areas.
#include <cmath>
#include <numbers>

#include "model_internal.hpp"

namespace rtcost::model {

Box3 intersect(const Box3& a, const Box3& b) { return Box3{vmax(a.lo, b.lo), vmin(a.hi, b.hi)}; }

/// Area of a box that may be flat (one or two zero extents) or empty.
double surface(const Box3& b) {
    if (b.empty()) return 0;
    Vec3 e = b.extent();
    return 2.0 * (double(e.x) * e.y + double(e.y) * e.z + double(e.z) * e.x);
}

/// The surface a line must cross to meet the primitive, for Cauchy-Crofton: flat primitives
/// count both sides; an open cone or cylinder counts its convex hull (side and both rims' discs).
double crofton_area(const Scene& s, std::uint32_t id, const PrimSummary& p) {
    switch (p.kind) {
        case PrimKind::Triangle:
        case PrimKind::Polygon: return 2.0 * p.area;
        case PrimKind::Sphere: return p.area;
        case PrimKind::Cone: {
            const Cone& c = s.cones[s.prims[id].index];
            double rb = std::fabs(c.base_radius), ra = std::fabs(c.apex_radius);
            return p.area + std::numbers::pi * (rb * rb + ra * ra);
        }
    }
    return 0;
}

/// Share of a primitive's bounding box that lies in `region`, measured in the dimensions where
/// the box has extent (a flat box by area, a line by length).
double share_inside(const Box3& pb, const Box3& region) {
    // Wholly inside (every primitive of a BVH leaf): no divisions.
    if (pb.lo.x >= region.lo.x && pb.lo.y >= region.lo.y && pb.lo.z >= region.lo.z && pb.hi.x <= region.hi.x &&
        pb.hi.y <= region.hi.y && pb.hi.z <= region.hi.z)
        return 1;
    double f = 1;
    for (int k = 0; k < 3; ++k) {
        double ext = double(pb.hi[k]) - pb.lo[k];
        if (ext <= 0) {
            if (pb.lo[k] < region.lo[k] || pb.lo[k] > region.hi[k]) return 0;
            continue;
        }
        double lo = std::max(pb.lo[k], region.lo[k]), hi = std::min(pb.hi[k], region.hi[k]);
        f *= std::max(0.0, hi - lo) / ext;
    }
    return f;
}

}  // namespace rtcost::model
