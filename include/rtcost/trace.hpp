#pragma once
/// \file trace.hpp
/// Tracing a batch of rays through a hierarchy on many threads (TBB), with or without counting.

#include <array>
#include <functional>
#include <span>
#include <vector>

#include "rtcost/hierarchy.hpp"
#include "rtcost/rays.hpp"

namespace rtcost {

struct TraceOptions {
    Query query = Query::Closest;
    int threads = 0;         ///< 0: all cores
    bool count = false;      ///< run the counting instantiation of the traversal
    /// Called now and then with the number of rays done so far (from any thread, serialised).
    std::function<void(std::size_t)> progress;
};

struct TraceResult {
    std::vector<Hit> hits;    ///< one per ray; for Query::Any, the first hit found
    std::size_t hit_count = 0;
    double seconds = 0;       ///< traversal alone (wall clock)
    /// CPU time the process spent meanwhile (all threads): the work itself, which a busy
    /// machine does not inflate as it inflates the wall clock.
    double cpu_seconds = 0;
    int threads = 1;
    RayCounters counters;     ///< summed over all rays (when counting)
    /// For ray sets: rays, hits and counters by RayKind (indexed by the enum's value).
    std::array<std::size_t, kRayKinds> rays_by_kind{}, hits_by_kind{};
    std::array<RayCounters, kRayKinds> counters_by_kind{};
};

/// Traces every ray. Hits carry `t` and `prim`; call Scene::complete_hit for normals.
TraceResult trace_rays(const Hierarchy& h, std::span<const Ray> rays, const TraceOptions& opt = {});

/// Traces a ray set: shadow and ambient-occlusion rays with `occlusion` (any hit by default),
/// every other kind with `opt.query`; `seconds` is the sum of the traversal times alone.
TraceResult trace_ray_set(const Hierarchy& h, const RaySet& set, const TraceOptions& opt,
                          Query occlusion = Query::Any);

/// Number of hardware threads TBB will use by default.
int default_threads();

}  // namespace rtcost
