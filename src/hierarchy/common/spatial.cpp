#include "spatial.hpp"

#include <array>
#include <cmath>

namespace rtcost::spatial {
namespace {

// Sutherland-Hodgman clipping of a planar polygon (convex or concave) against the six planes of
// a box, in double. The clipped polygon is non-empty exactly when the polygon meets the box:
// clipping by a convex region keeps every point of the intersection (concave inputs may gain
// zero-width bridges, which add no points outside the box).
bool polygon_meets_box(const Vec3* v, std::size_t n, const Box3& b) {
    std::vector<std::array<double, 3>> poly(n), next;
    for (std::size_t i = 0; i < n; ++i) poly[i] = {v[i].x, v[i].y, v[i].z};
    for (int axis = 0; axis < 3; ++axis) {
        for (int side = 0; side < 2; ++side) {
            const double bound = side ? b.hi[axis] : b.lo[axis];
            auto inside = [&](const std::array<double, 3>& p) { return side ? p[axis] <= bound : p[axis] >= bound; };
            next.clear();
            for (std::size_t i = 0; i < poly.size(); ++i) {
                const auto& a = poly[i];
                const auto& c = poly[(i + 1) % poly.size()];
                bool ia = inside(a), ic = inside(c);
                if (ia) next.push_back(a);
                if (ia != ic) {
                    double t = (bound - a[axis]) / (c[axis] - a[axis]);
                    std::array<double, 3> p;
                    for (int k = 0; k < 3; ++k) p[k] = a[k] + t * (c[k] - a[k]);
                    p[axis] = bound;
                    next.push_back(p);
                }
            }
            poly.swap(next);
            if (poly.empty()) return false;
        }
    }
    return true;
}

bool sphere_surface_meets_box(const Sphere& s, const Box3& b) {
    double near2 = 0, far2 = 0;
    for (int k = 0; k < 3; ++k) {
        double c = s.center[k], lo = b.lo[k], hi = b.hi[k];
        double dn = c < lo ? lo - c : (c > hi ? c - hi : 0.0);
        double df = std::max(std::fabs(c - lo), std::fabs(c - hi));
        near2 += dn * dn;
        far2 += df * df;
    }
    double r2 = static_cast<double>(s.radius) * s.radius;
    return near2 <= r2 && far2 >= r2;  // closed: a tangent cell counts
}

}  // namespace

Assign parse_assign(const Params& p) {
    return p.is("assign", "exact") ? Assign::Exact : Assign::Bounds;
}

std::vector<Box3> prim_bounds(const Scene& s) {
    std::vector<Box3> out(s.size());
    for (std::uint32_t id = 0; id < s.size(); ++id) out[id] = s.prim_bounds(id);
    return out;
}

bool overlaps(const Scene& s, std::uint32_t id, const Box3& pb, const Box3& cell, Assign how) {
    if (!pb.overlaps(cell)) return false;
    if (how == Assign::Bounds) return true;
    const PrimRef& p = s.prims[id];
    switch (p.kind) {
        case PrimKind::Triangle: {
            const Triangle& t = s.triangles[p.index];
            Vec3 v[3] = {t.v0, t.v1, t.v2};
            return polygon_meets_box(v, 3, cell);
        }
        case PrimKind::Polygon: {
            const Polygon& poly = s.polygons[p.index];
            return polygon_meets_box(s.polygon_vertices.data() + poly.first, poly.count, cell);
        }
        case PrimKind::Sphere: return sphere_surface_meets_box(s.spheres[p.index], cell);
        case PrimKind::Cone: return true;  // conservative: the bounding box overlaps
    }
    return true;
}

Mailbox& Mailbox::begin_ray(const void* owner, std::size_t n) {
    thread_local Mailbox box;
    if (box.owner_ != owner || box.stamps_.size() != n) {
        box.owner_ = owner;
        box.stamps_.assign(n, 0);
        box.serial_ = 0;
    }
    ++box.serial_;
    return box;
}

}  // namespace rtcost::spatial
