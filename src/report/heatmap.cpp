// Per-pixel costs: each pixel's rays (its camera ray, or the Whitted tree `render` shades)
// traced through a hierarchy with counting, and optionally timed, summed per pixel.
#include "rtcost/heatmap.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "rays/whitted_tracer.hpp"
#include "rtcost/error.hpp"
#include "rtcost/rays.hpp"
#include "rtcost/trace.hpp"

namespace rtcost {
namespace {

constexpr std::string_view kNames[] = {"box", "plane", "hop", "classify", "prim", "steps", "ops", "time", "predicted"};

using Clock = std::chrono::steady_clock;

// What reading the clock twice costs, so that a pixel's time is that of its rays alone: the
// median of many back-to-back readings.
double timer_overhead_ns() {
    std::vector<double> d(1001);
    for (double& x : d) {
        auto a = Clock::now();
        auto b = Clock::now();
        x = std::chrono::duration<double, std::nano>(b - a).count();
    }
    std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
    return d[d.size() / 2];
}

std::uint32_t narrow(std::uint64_t v) { return static_cast<std::uint32_t>(std::min<std::uint64_t>(v, UINT32_MAX)); }

}  // namespace

std::string_view heat_kind_name(HeatKind k) { return kNames[static_cast<int>(k)]; }

std::vector<std::string> heat_kind_names() { return {std::begin(kNames), std::end(kNames)}; }

HeatKind parse_heat_kind(std::string_view name, const std::string& what) {
    for (int k = 0; k < static_cast<int>(std::size(kNames)); ++k)
        if (kNames[k] == name) return static_cast<HeatKind>(k);
    throw InputError(what, 0,
                     fmt::format("unknown heat map kind '{}' (box, plane, hop, classify, prim, steps, ops, time, predicted)", name));
}

PixelCosts pixel_costs(const Hierarchy& h, const PixelCostOptions& opt) {
    if (opt.width <= 0 || opt.height <= 0) throw InputError("--size", 0, "the image has no pixels");
    const Scene& scene = h.scene();
    const std::vector<Ray> eye = camera_rays(scene.camera, opt.width, opt.height);
    const detail::WhittedTracer tracer(h, opt.max_depth);
    const double overhead = opt.time ? timer_overhead_ns() : 0;
    PixelCosts pc;
    pc.width = opt.width;
    pc.height = opt.height;
    pc.timed = opt.time;
    pc.box_lanes = h.structure().box_lanes;
    pc.pixels.resize(eye.size());
    if (opt.predict) pc.predicted.resize(eye.size());
    std::vector<RayCounters> rows(static_cast<std::size_t>(opt.height));
    auto occluded = [&](RayKind k) {
        return is_occlusion(k) && opt.occlusion == Query::Any;
    };
    detail::run_rows(
        opt.height, opt.threads,
        [&](int j) {
            detail::Recorder rec;
            for (int i = 0; i < opt.width; ++i) {
                const std::size_t pixel = static_cast<std::size_t>(j) * opt.width + i;
                rec.rays.clear();
                rec.kinds.clear();
                if (opt.tree) {
                    tracer.trace(eye[pixel], RayKind::Eye, 1, &rec);
                } else {
                    rec.rays.push_back(eye[pixel]);
                    rec.kinds.push_back(RayKind::Eye);
                }
                RayCounters c;
                for (std::size_t r = 0; r < rec.rays.size(); ++r) {
                    Hit hit;
                    if (occluded(rec.kinds[r])) h.any(rec.rays[r], hit, c);
                    else h.closest(rec.rays[r], hit, c);
                }
                PixelCost& p = pc.pixels[pixel];
                p.rays = narrow(c.rays);
                p.box = narrow(c.box);
                p.plane = narrow(c.plane);
                p.hop = narrow(c.hop);
                p.classify = narrow(c.classify);
                p.steps = narrow(c.steps);
                for (int k = 0; k < kPrimKinds; ++k) p.prim[k] = narrow(c.prim[k]);
                p.polygon_edges = narrow(c.polygon_edges);
                rows[j] += c;
                if (opt.predict)
                    for (std::size_t r = 0; r < rec.rays.size(); ++r)
                        add_scaled(pc.predicted[pixel], opt.predict(rec.rays[r], rec.kinds[r]), 1.0);
                if (!opt.time) continue;
                // The fast path, as `trace` times it; the rays were just traced, so they are warm.
                // The lesser of two timings: an interruption inflates one, rarely both.
                double best = kInf;
                for (int run = 0; run < 2; ++run) {
                    auto start = Clock::now();
                    for (std::size_t r = 0; r < rec.rays.size(); ++r) {
                        Hit hit;
                        if (occluded(rec.kinds[r])) h.any(rec.rays[r], hit);
                        else h.closest(rec.rays[r], hit);
                    }
                    best = std::min(best, std::chrono::duration<double, std::nano>(Clock::now() - start).count());
                }
                p.ns = static_cast<float>(std::max(0.0, best - overhead));
            }
        },
        opt.progress);
    for (const RayCounters& r : rows) pc.total += r;
    return pc;
}

std::vector<double> heat_values(const PixelCosts& pc, HeatKind kind, const UnitCosts& costs) {
    if (kind == HeatKind::Time && !pc.timed) throw InputError("--heatmap", 0, "time: the pixels were not timed");
    if (kind == HeatKind::Predicted && pc.predicted.size() != pc.pixels.size())
        throw InputError("--heatmap", 0, "predicted: the pixels were not predicted");
    std::vector<double> out(pc.pixels.size());
    const double box = costs.box_price(pc.box_lanes);
    for (std::size_t i = 0; i < out.size(); ++i) {
        const PixelCost& p = pc.pixels[i];
        const double prims = static_cast<double>(p.prim[0]) + p.prim[1] + p.prim[2] + p.prim[3];
        switch (kind) {
            case HeatKind::Box: out[i] = p.box; break;
            case HeatKind::Plane: out[i] = p.plane; break;
            case HeatKind::Hop: out[i] = p.hop; break;
            case HeatKind::Classify: out[i] = p.classify; break;
            case HeatKind::Prim: out[i] = prims; break;
            case HeatKind::Steps: out[i] = p.steps; break;
            case HeatKind::Time: out[i] = p.ns; break;
            case HeatKind::Predicted: {
                const CostVector& c = pc.predicted[i];
                double s = costs.per_ray * p.rays + box * c.box + costs.plane * c.plane + costs.hop * c.hop +
                           costs.classify * c.classify + costs.step * c.steps + costs.polygon_edge * c.polygon_edges;
                for (int k = 0; k < kPrimKinds; ++k) s += costs.prim[k] * c.prim[k];
                out[i] = s;
                break;
            }
            case HeatKind::Ops: {
                // UnitCosts::scalar of the summed operations plus the fixed cost of every ray, its
                // box tests at the structure's price (the cache term aside: one structure per map).
                double s = costs.per_ray * p.rays + box * p.box + costs.plane * p.plane + costs.hop * p.hop +
                           costs.classify * p.classify + costs.step * p.steps + costs.polygon_edge * p.polygon_edges;
                for (int k = 0; k < kPrimKinds; ++k) s += costs.prim[k] * p.prim[k];
                out[i] = s;
                break;
            }
        }
    }
    return out;
}

std::string heat_units(HeatKind kind, const UnitCosts& costs) {
    switch (kind) {
        case HeatKind::Box: return "box tests per pixel";
        case HeatKind::Plane: return "plane compares per pixel";
        case HeatKind::Hop: return "grid steps per pixel";
        case HeatKind::Classify: return "classify compares per pixel";
        case HeatKind::Prim: return "primitive tests per pixel";
        case HeatKind::Steps: return "traversal steps per pixel";
        case HeatKind::Ops:
            return costs.calibrated ? "ns per pixel (operations x calibrated costs)" : "operations per pixel (unit costs)";
        case HeatKind::Time: return "ns per pixel (measured)";
        case HeatKind::Predicted:
            return costs.calibrated ? "ns per pixel (predicted operations x calibrated costs)"
                                    : "operations per pixel (predicted by the model, unit costs)";
    }
    return "";
}

HeatSummary summarize(const std::vector<double>& values, double scale_max) {
    HeatSummary s;
    if (values.empty()) return s;
    s.min = *std::min_element(values.begin(), values.end());
    s.max = *std::max_element(values.begin(), values.end());
    double sum = 0;
    for (double v : values) sum += v;
    s.mean = sum / values.size();
    s.scale_max = scale_max > 0 ? scale_max : s.max;
    for (double v : values) s.clipped += v > s.scale_max;
    return s;
}

}  // namespace rtcost
