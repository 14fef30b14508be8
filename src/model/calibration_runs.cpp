// The runs `rtcost calibrate` fits: each hierarchy's counted operations and single-thread time on a scene.
#include <algorithm>
#include <memory>

#include "rtcost/evaluate.hpp"
#include "rtcost/trace.hpp"

namespace rtcost {

std::vector<CalibrationSample> measure_for_calibration(const Scene& scene, const RaySet& rays,
                                                       const std::vector<HierarchyRequest>& hierarchies, int repeat,
                                                       bool sequential,
                                                       const std::function<void(std::size_t n)>& on_passes) {
    auto done = [&](std::size_t n) {
        if (on_passes) on_passes(n);
    };
    TraceOptions opt;
    opt.threads = 1;  // unit costs are single-thread figures
    struct Timed {
        std::unique_ptr<Hierarchy> h;
        CalibrationSample s;
        double best = kInf;
    };
    std::vector<Timed> timed;
    auto time_once = [&](Timed& t) {
        t.best = std::min(t.best, trace_ray_set(*t.h, rays, opt).cpu_seconds);
        done(1);
    };
    for (const HierarchyRequest& req : hierarchies) {
        auto h = build_hierarchy(scene, req.name, req.params);
        if (!h->counted()) {
            done(1 + static_cast<std::size_t>(std::max(repeat, 0)));
            continue;
        }
        Timed t{std::move(h), {}, kInf};
        TraceOptions counting = opt;
        counting.count = true;
        const TraceResult counted = trace_ray_set(*t.h, rays, counting);
        done(1);
        t.s.label = req.label() + " on " + scene.name;
        t.s.ops = measured_cost(counted.counters);
        if (sequential) {
            for (int r = 0; r < repeat; ++r) time_once(t);
            t.s.structure = t.h->structure();
            t.h.reset();
        }
        timed.push_back(std::move(t));
    }
    if (!sequential)
        for (int r = 0; r < repeat; ++r)
            for (std::size_t i : timing_order(timed.size(), r)) time_once(timed[i]);
    std::vector<CalibrationSample> out;
    for (Timed& t : timed) {
        if (t.h) t.s.structure = t.h->structure();
        t.s.ns_per_ray = rays.rays.empty() || t.best == kInf ? 0.0 : t.best * 1e9 / rays.rays.size();
        out.push_back(std::move(t.s));
    }
    return out;
}

}  // namespace rtcost
