// Single-thread traversal and build benchmarks of rtcost's hierarchies against Embree on the same
// scenes and the same rays, and the geometric estimator against tracing the `spd` rays. Run: build/bench/rtcost_bench [--benchmark_filter=...]
// Scenes come from ../shared/scenes/spd when present (RTCOST_SHARED overrides), else built-ins.
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>

#include "rtcost/hierarchy.hpp"
#include "rtcost/io.hpp"
#include "rtcost/model.hpp"
#include "rtcost/rays.hpp"
#include "rtcost/trace.hpp"

using namespace rtcost;

namespace {

struct Workload {
    Scene scene;
    std::map<std::string, std::vector<Ray>> rays;  // "random", "camera"
    std::unique_ptr<RaySet> spd;                   // made on first use: a Whitted ray tree
};

std::string shared_dir() {
    if (const char* env = std::getenv("RTCOST_SHARED")) return env;
    return RTCOST_SHARED_DIR;
}

Workload& workload(const std::string& name) {
    static std::map<std::string, std::unique_ptr<Workload>> cache;
    auto& w = cache[name];
    if (!w) {
        w = std::make_unique<Workload>();
        std::string path = shared_dir() + "/scenes/spd/" + name + ".nff";
        w->scene = std::filesystem::exists(path) ? load_scene(path) : load_scene("builtin:" + name);
        w->rays["random"] = random_rays(w->scene.bounds(), 1 << 16, 1);
        w->rays["camera"] = camera_rays(w->scene.camera, 256, 256);
    }
    return *w;
}

void trace_bench(benchmark::State& state, std::string scene, std::string hierarchy, std::string dist) {
    Workload& w = workload(scene);
    auto h = build_hierarchy(w.scene, hierarchy);
    const auto& rays = w.rays.at(dist);
    std::size_t hits = 0;
    if (h->lazy()) {
        // A lazily built structure grows during its first pass: time that pass as its build,
        // then the traversal of what the rays built.
        auto start = std::chrono::steady_clock::now();
        for (const Ray& r : rays) {
            Hit hit;
            h->closest(r, hit);
        }
        state.counters["lazy_build_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
    for (auto _ : state) {
        for (const Ray& r : rays) {
            Hit hit;
            h->closest(r, hit);
            hits += hit.hit();
        }
    }
    benchmark::DoNotOptimize(hits);
    state.counters["Mrays/s"] = benchmark::Counter(static_cast<double>(rays.size()) * state.iterations() / 1e6,
                                                   benchmark::Counter::kIsRate);
    state.counters["bytes"] = static_cast<double>(h->structure().bytes);
}

void build_bench(benchmark::State& state, std::string scene, std::string hierarchy) {
    Workload& w = workload(scene);
    // rtcost's builders run on one thread; Embree's is held to one thread too for a fair ratio.
    std::vector<std::string> set;
    if (hierarchy == "embree") set.push_back("threads=1");
    for (auto _ : state) {
        auto h = build_hierarchy(w.scene, hierarchy, set);
        benchmark::DoNotOptimize(h.get());
    }
    state.counters["prims"] = static_cast<double>(w.scene.size());
}

/// The geometric estimator alone (one pass over the hierarchy's nodes), after the build: the cost
/// of predicting instead of measuring. Counters: the single-thread time to trace the scene's
/// `spd` rays through the same hierarchy in the same process (`spd_trace_ms`, traversal alone, as
/// `rtcost trace --rays spd -j 1 --no-count`) and the estimate's share of it (`share_pct`).
void model_bench(benchmark::State& state, std::string scene, std::string hierarchy) {
    Workload& w = workload(scene);
    auto h = build_hierarchy(w.scene, hierarchy);
    if (!w.spd) {
        RaySpec spec;
        spec.name = "spd";
        w.spd = std::make_unique<RaySet>(make_rays(w.scene, spec));
    }
    TraceOptions t;
    t.threads = 1;
    if (h->lazy()) trace_ray_set(*h, *w.spd, t);  // the first pass builds what the rays need
    const double trace = trace_ray_set(*h, *w.spd, t).seconds;
    ModelOptions opt;
    double seconds = 0;
    for (auto _ : state) {
        const auto start = std::chrono::steady_clock::now();
        Prediction p = predict_geometric(*h, opt);
        seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        benchmark::DoNotOptimize(p.scalar);
    }
    const double estimate = state.iterations() > 0 ? seconds / state.iterations() : 0;
    state.counters["spd_trace_ms"] = trace * 1e3;
    state.counters["share_pct"] = trace > 0 ? 100 * estimate / trace : 0;
}

}  // namespace

int main(int argc, char** argv) {
    const std::vector<std::string> scenes = {"tetra", "balls", "mount-s8"};
    std::vector<std::string> hier;
    for (const char* h : {"embree", "bvh-sah", "bvh-median", "bvh-gs", "kd-sah", "kd-median", "bsp", "octree", "grid",
                          "rc5d"})
        if (find_hierarchy(h)) hier.push_back(h);
    for (const auto& s : scenes) {
        for (const auto& h : hier) {
            if (h != "embree")
                benchmark::RegisterBenchmark(("model/" + s + "/" + h).c_str(), model_bench, s, h)
                    ->Unit(benchmark::kMillisecond)
                    ->MinTime(0.2);
            for (const char* d : {"random", "camera"}) {
                benchmark::RegisterBenchmark(("trace/" + s + "/" + d + "/" + h).c_str(), trace_bench, s, h, d)
                    ->Unit(benchmark::kMillisecond)
                    ->MinTime(0.5);
            }
            benchmark::RegisterBenchmark(("build/" + s + "/" + h).c_str(), build_bench, s, h)
                ->Unit(benchmark::kMillisecond)
                ->MinTime(0.5);
        }
    }
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 2;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
