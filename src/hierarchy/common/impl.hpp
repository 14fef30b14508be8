#pragma once
// What a hierarchy's author needs and its users do not: the four query overloads made from one
// traversal template, and the primitive test every traversal's leaves share. Internal to the
// library (not installed): the public interface is rtcost/hierarchy.hpp.

#include "rtcost/hierarchy.hpp"
#include "rtcost/stats.hpp"

namespace rtcost {

/// Implements the four query overloads of Hierarchy from one traversal template of `Derived`:
///   template <class C, Query Q> bool trace(const Ray&, Hit&, C& counting) const;
/// which returns true on a hit. This is how counting stays a compile-time policy.
template <class Derived>
class HierarchyImpl : public Hierarchy {
public:
    using Hierarchy::Hierarchy;
    void closest(const Ray& ray, Hit& hit) const final {
        NoCount c;
        self().template trace<NoCount, Query::Closest>(ray, hit, c);
    }
    void closest(const Ray& ray, Hit& hit, RayCounters& counters) const final {
        Count c{counters};
        ++counters.rays;
        self().template trace<Count, Query::Closest>(ray, hit, c);
    }
    bool any(const Ray& ray, Hit& hit) const final {
        NoCount c;
        return self().template trace<NoCount, Query::Any>(ray, hit, c);
    }
    bool any(const Ray& ray, Hit& hit, RayCounters& counters) const final {
        Count c{counters};
        ++counters.rays;
        return self().template trace<Count, Query::Any>(ray, hit, c);
    }

    void all(const Ray& ray, Hit& hit) const final {
        NoCount c;
        self().template trace<NoCount, Query::All>(ray, hit, c);
    }
    void all(const Ray& ray, Hit& hit, RayCounters& counters) const final {
        Count c{counters};
        ++counters.rays;
        self().template trace<Count, Query::All>(ray, hit, c);
    }

private:
    const Derived& self() const { return static_cast<const Derived&>(*this); }
};

/// Tests primitive `id` against `ray` and, when it is hit nearer than `hit.t`, records it.
/// Counts one primitive test of the primitive's kind. Shared by every traversal's leaves.
/// Traversals implement Query::All by never terminating early or culling by `hit.t`
/// (`if constexpr (Q != Query::All)` around every such test).
template <class C>
inline bool test_prim(const Scene& scene, std::uint32_t id, const Ray& ray, Hit& hit, C& counting) {
    counting.prim(scene.kind(id));
    Ray r = ray;
    r.tmax = hit.t < ray.tmax ? hit.t : ray.tmax;
    float t;
    if (scene.intersect(id, r, t)) {
        hit.t = t;
        hit.prim = static_cast<std::int32_t>(id);
        return true;
    }
    return false;
}

/// The primitive test of a real trace (test_prim), for traversals that take the test as a
/// parameter (`trace_with`): a design replays its sample through them with a test that answers
/// from the rays' known crossings instead (design/replay.hpp).
struct RealPrimTest {
    const Scene& scene;
    template <class C>
    bool operator()(std::uint32_t id, const Ray& ray, Hit& hit, C& counting) const {
        return test_prim(scene, id, ray, hit, counting);
    }
};

}  // namespace rtcost
