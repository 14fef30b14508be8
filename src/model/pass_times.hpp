#pragma once
// The timed passes of one hierarchy over the test rays, and the figures an evaluation row reports
// from them (evaluate.cpp).

#include <algorithm>
#include <vector>

#include "rtcost/evaluate.hpp"
#include "rtcost/trace.hpp"

namespace rtcost {

/// The timed passes of one hierarchy: how many more to take, and the row's figures from them
/// (medians of wall and CPU time, the spread of CPU time).
struct PassTimes {
    std::vector<double> wall, cpu;
    double total = 0;
    int threads = 1;

    bool more(const EvalOptions& opt) const {
        if (opt.repeat > 0) return static_cast<int>(wall.size()) < opt.repeat;
        return wall.empty() || (total < opt.min_seconds && wall.size() < 1000);
    }
    void add(const TraceResult& r) {
        wall.push_back(r.seconds);
        cpu.push_back(r.cpu_seconds);
        threads = r.threads;
        total += r.seconds;
    }
    void fill(EvalRow& row, std::size_t rays) {
        std::sort(wall.begin(), wall.end());
        std::sort(cpu.begin(), cpu.end());
        const double median = wall[wall.size() / 2], cpu_median = cpu[cpu.size() / 2];
        row.repeats = static_cast<int>(wall.size());
        row.time_spread = cpu_median > 0 ? (cpu.back() - cpu.front()) / cpu_median : 0;
        row.mrays_per_s = median > 0 ? rays / median / 1e6 : 0;
        row.ns_per_ray = cpu_median * 1e9 / rays;
        row.threads = threads;
    }
};

}  // namespace rtcost
