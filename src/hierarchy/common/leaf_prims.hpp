#pragma once
// Leaf references as their test needs them, copied in leaf order: a traversal that reads a
// leaf's triangles from here reads them contiguously, instead of through the scene's id tables
// (three dependent loads per primitive, which incoherent rays pay as cache misses).

#include <vector>

#include "impl.hpp"
#include "scene/watertight.hpp"

namespace rtcost {

/// One reference: the id, the kind counted and, for a triangle, its vertices (tested from
/// here; any other kind through the scene).
struct LeafPrim {
    Triangle tri;
    std::uint32_t id = 0;
    PrimKind kind = PrimKind::Triangle;
};

/// `refs` (primitive ids in leaf order) as LeafPrims.
inline std::vector<LeafPrim> leaf_prims(const Scene& s, const std::vector<std::uint32_t>& refs) {
    std::vector<LeafPrim> out(refs.size());
    for (std::size_t k = 0; k < refs.size(); ++k) {
        LeafPrim& p = out[k];
        const PrimRef& r = s.prims[refs[k]];
        p.id = refs[k];
        p.kind = r.kind;
        if (r.kind == PrimKind::Triangle) p.tri = s.triangles[r.index];
    }
    return out;
}

/// test_prim for a LeafPrim: the same steps and count, on the copy of the same triangle, with
/// the ray's shear `sh` (RayShear(ray.d)) computed once per ray by the traversal.
template <class C>
inline bool test_prim(const Scene& scene, const LeafPrim& p, const Ray& ray, const RayShear& sh, Hit& hit,
                      C& counting) {
    if (p.kind != PrimKind::Triangle) return test_prim(scene, p.id, ray, hit, counting);
    counting.prim(p.kind);
    Ray r = ray;
    r.tmax = hit.t < ray.tmax ? hit.t : ray.tmax;
    float t;
    if (intersect(p.tri, r, sh, t)) {
        hit.t = t;
        hit.prim = static_cast<std::int32_t>(p.id);
        return true;
    }
    return false;
}

}  // namespace rtcost
