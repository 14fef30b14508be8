#pragma once
// What a hierarchy's author needs and its users do not: the four query overloads made from one
// traversal template, and the primitive test every traversal's leaves share. Internal to the
// library (not installed): the public interface is rtcost/hierarchy.hpp.

#include "../../model/model_internal.hpp"
#include "rtcost/hierarchy.hpp"
#include "rtcost/sample.hpp"
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

    /// One closest-hit traversal whose primitive test collects the crossings (CrossingCollector)
    /// where the traversal takes its test (`trace_with`); restarted queries otherwise.
    std::size_t crossings(const Ray& ray, std::span<Crossing> out) const final;

    /// Each sample ray through `trace_with` with KnownTest, where the hierarchy has it and its
    /// replay is the model tree's prediction (`Derived::replay_is_model()`, true if absent).
    bool replay(const RaySample& sample, std::span<const std::uint32_t> rays, Query query,
                RayCounters& counters) const final;

private:
    const Derived& self() const { return static_cast<const Derived&>(*this); }
};

/// The ray as a primitive test sees it: cut at the nearest hit so far, which decides whether the
/// test finds a hit and whether it meets a polygon's plane and walks its edges.
inline Ray up_to_hit(const Ray& ray, const Hit& hit) {
    Ray r = ray;
    r.tmax = hit.t < ray.tmax ? hit.t : ray.tmax;
    return r;
}

/// Tests primitive `id` against `ray` and, when it is hit nearer than `hit.t`, records it.
/// Counts one primitive test of the primitive's kind, and the edges a polygon's test walks.
/// Shared by every traversal's leaves.
/// Traversals implement Query::All by never terminating early or culling by `hit.t`
/// (`if constexpr (Q != Query::All)` around every such test).
template <class C>
inline bool test_prim(const Scene& scene, std::uint32_t id, const Ray& ray, Hit& hit, C& counting) {
    counting.prim(scene.kind(id));
    const Ray r = up_to_hit(ray, hit);
    if constexpr (C::enabled) counting.edges(scene.edges_walked(id, r));
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

/// The primitive test of a search for a ray's first crossings (Hierarchy::crossings): a
/// closest-hit traversal with it ends at the last of the `out.size()` nearest primitives met,
/// which it keeps in `out`, nearest first (a tie after the earlier found). Until `out` is full no
/// hit is reported, so the traversal cuts nothing; then the hit is the farthest kept, and
/// everything beyond it is cut. A primitive kept is not tested again (it may be referenced by
/// several cells); one dropped lies beyond the hit and fails its test again.
struct CrossingCollector {
    const Scene& scene;
    std::span<Crossing> out;  ///< not empty
    std::size_t& n;
    template <class C>
    bool operator()(std::uint32_t id, const Ray& ray, Hit& hit, C&) const {
        if (kept(id)) return false;
        float t;
        return scene.intersect(id, up_to_hit(ray, hit), t) && insert(id, t, hit);
    }
    /// Keeps primitive `id`, met at `t` (nearer than `hit.t`) by a traversal's own exact test
    /// (bvh: its triangle copies), unless kept already; true when `hit` then holds the
    /// farthest kept of a full `out`.
    bool keep(std::uint32_t id, float t, Hit& hit) const { return !kept(id) && insert(id, t, hit); }

private:
    bool kept(std::uint32_t id) const {
        for (std::size_t i = 0; i < n; ++i)
            if (out[i].prim == id) return true;
        return false;
    }
    bool insert(std::uint32_t id, float t, Hit& hit) const {
        std::size_t at = n < out.size() ? n++ : n - 1;  // full: the farthest is dropped
        for (; at > 0 && out[at - 1].t > t; --at) out[at] = out[at - 1];
        out[at] = {id, t};
        if (n < out.size()) return false;
        hit.t = out[n - 1].t;
        hit.prim = static_cast<std::int32_t>(out[n - 1].prim);
        return true;
    }
};

/// The segments estimator's primitive test: answered from the ray's known crossings (where the
/// ray sample found it meets each primitive) instead of intersecting, and counted as test_prim
/// counts a real test. A traversal that takes it replays a sample ray as the model's probe
/// replays it through the hierarchy's model tree (tests/test_replay.cpp).
struct KnownTest {
    model::KnownCrossings known;
    /// Each primitive's PrimKind as a byte, or null to read the scene's (its records are far
    /// larger, and a replay looks up a kind for every reference of every leaf it visits).
    const std::uint8_t* kinds;
    const Scene& scene;
    bool operator()(std::uint32_t id, const Ray& ray, Hit& hit, Count& c) const {
        const auto kind = kinds ? static_cast<PrimKind>(kinds[id]) : scene.kind(id);
        c.prim(kind);
        if (kind == PrimKind::Polygon) c.edges(scene.edges_walked(id, up_to_hit(ray, hit)));
        return known.hit(id, ray, hit);
    }
    /// A traversal of a tree built only where the sample reaches (subdiv::CellOptions::reached)
    /// entered a cell left unbuilt: its count would be wrong.
    [[noreturn]] void unbuilt() const { throw model::PrunedNodeReached{}; }
};

template <class Derived>
bool HierarchyImpl<Derived>::replay(const RaySample& sample, std::span<const std::uint32_t> rays, Query query,
                                    RayCounters& counters) const {
    const Ray probe{};
    if constexpr (requires(Hit& hit, Count& c, const KnownTest& test) {
                      self().template trace_with<Count, Query::Closest>(probe, hit, c, test);
                  }) {
        if constexpr (requires { self().replay_is_model(); })
            if (!self().replay_is_model()) return false;
        Count counting{counters};
        for (std::uint32_t i : rays) {
            const Ray& ray = sample.rays.rays.at(i);  // (a bad index throws before its crossings are read)
            const KnownTest test{model::KnownCrossings(sample.crossings_of(i)), nullptr, *scene_};
            Hit hit;
            ++counters.rays;
            switch (query) {
                case Query::Closest: self().template trace_with<Count, Query::Closest>(ray, hit, counting, test); break;
                case Query::Any: self().template trace_with<Count, Query::Any>(ray, hit, counting, test); break;
                case Query::All: self().template trace_with<Count, Query::All>(ray, hit, counting, test); break;
            }
        }
        return true;
    } else {
        (void)sample, (void)rays, (void)query, (void)counters, (void)probe;
        return false;
    }
}

template <class Derived>
std::size_t HierarchyImpl<Derived>::crossings(const Ray& ray, std::span<Crossing> out) const {
    if (out.empty()) return 0;
    std::size_t n = 0;
    const CrossingCollector collect{*scene_, out, n};
    if constexpr (requires(Hit& hit, NoCount& c) {
                      self().template trace_with<NoCount, Query::Closest>(ray, hit, c, collect);
                  }) {
        Hit hit;
        NoCount c;
        self().template trace_with<NoCount, Query::Closest>(ray, hit, c, collect);
        return n;
    } else {
        return Hierarchy::crossings(ray, out);
    }
}

}  // namespace rtcost
