#include "rtcost/trace.hpp"

#include <atomic>
#include <chrono>
#include <mutex>
#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/enumerable_thread_specific.h>
#include <oneapi/tbb/global_control.h>
#include <oneapi/tbb/info.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>

namespace rtcost {

int default_threads() { return tbb::info::default_concurrency(); }

TraceResult trace_rays(const Hierarchy& h, std::span<const Ray> rays, const TraceOptions& opt) {
    TraceResult res;
    res.hits.assign(rays.size(), Hit{});
    res.threads = opt.threads > 0 ? opt.threads : default_threads();
    tbb::task_arena arena(res.threads);
    tbb::enumerable_thread_specific<RayCounters> local;
    std::atomic<std::size_t> done{0};
    std::mutex progress_mutex;
    // Chunks of rays: the per-chunk progress update stays out of the per-ray loop.
    constexpr std::size_t kGrain = 1024;

    // The counting choice is made once per chunk, outside the per-ray loop, so the fast path
    // loop calls the non-counting traversal with no test per ray.
    auto run = [&](const tbb::blocked_range<std::size_t>& range, auto counting) {
        constexpr bool kCount = decltype(counting)::value;
        [[maybe_unused]] RayCounters* counters = kCount ? &local.local() : nullptr;
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
            Hit& hit = res.hits[i];
            if constexpr (kCount) {
                switch (opt.query) {
                    case Query::Closest: h.closest(rays[i], hit, *counters); break;
                    case Query::Any: h.any(rays[i], hit, *counters); break;
                    case Query::All: h.all(rays[i], hit, *counters); break;
                }
            } else {
                switch (opt.query) {
                    case Query::Closest: h.closest(rays[i], hit); break;
                    case Query::Any: h.any(rays[i], hit); break;
                    case Query::All: h.all(rays[i], hit); break;
                }
            }
        }
        if (opt.progress) {
            std::size_t d = done.fetch_add(range.size()) + range.size();
            std::lock_guard lock(progress_mutex);
            opt.progress(d);
        }
    };
    auto body = [&](const tbb::blocked_range<std::size_t>& range) {
        if (opt.count) run(range, std::true_type{});
        else run(range, std::false_type{});
    };
    auto start = std::chrono::steady_clock::now();
    arena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rays.size(), kGrain), body);
    });
    res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    for (auto& c : local) res.counters += c;
    for (const Hit& hit : res.hits) res.hit_count += hit.hit();
    return res;
}

TraceResult trace_ray_set(const Hierarchy& h, const RaySet& set, const TraceOptions& opt, Query occlusion) {
    TraceResult res;
    res.hits.assign(set.rays.size(), Hit{});
    res.threads = opt.threads > 0 ? opt.threads : default_threads();
    // One batch per kind, so each batch runs one query and its counters stay apart.
    std::array<std::vector<std::size_t>, kRayKinds> index;
    for (std::size_t i = 0; i < set.rays.size(); ++i) index[static_cast<int>(set.kinds[i])].push_back(i);
    std::size_t before = 0;
    for (int k = 0; k < kRayKinds; ++k) {
        if (index[k].empty()) continue;
        std::vector<Ray> batch;
        batch.reserve(index[k].size());
        for (std::size_t i : index[k]) batch.push_back(set.rays[i]);
        TraceOptions o = opt;
        if (is_occlusion(static_cast<RayKind>(k))) o.query = occlusion;
        if (opt.progress) o.progress = [&](std::size_t d) { opt.progress(before + d); };
        TraceResult r = trace_rays(h, batch, o);
        for (std::size_t j = 0; j < batch.size(); ++j) res.hits[index[k][j]] = r.hits[j];
        res.seconds += r.seconds;
        res.hit_count += r.hit_count;
        res.counters += r.counters;
        res.rays_by_kind[k] = batch.size();
        res.hits_by_kind[k] = r.hit_count;
        res.counters_by_kind[k] = r.counters;
        before += batch.size();
    }
    return res;
}

}  // namespace rtcost
