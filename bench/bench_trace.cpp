// Traversal (one thread and all cores) and build benchmarks of rtcost's hierarchies against
// Embree on the same scenes and the same rays, and the geometric estimator against tracing the
// `spd` rays. Run: build/bench/rtcost_bench [--benchmark_filter=...]; docs/benchmarks.md says how.
// Scenes come from ../shared/scenes/spd when present (RTCOST_SHARED overrides), else built-ins;
// meshes from RTCOST_BENCH_MESHES (default build/meshes), written by scripts/tessellate.py and
// viewed with their SPD scene's camera and lights; RTCOST_BENCH_VIEW sets one scene's camera and
// light instead (an earlier run's view, below).
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>

#include "rtcost/hierarchy.hpp"
#include "rtcost/io.hpp"
#include "rtcost/model.hpp"
#include "rtcost/rays.hpp"
#include "rtcost/sample.hpp"
#include "rtcost/trace.hpp"

using namespace rtcost;

namespace {

struct Workload {
    Scene scene;
    std::map<std::string, RaySet> rays;  // by distribution, made on first use
    std::unique_ptr<RaySet> spd;         // the model benchmark's: the scene's own camera size
};

std::string shared_dir() {
    if (const char* env = std::getenv("RTCOST_SHARED")) return env;
    return RTCOST_SHARED_DIR;
}

/// Tessellated meshes written by scripts/tessellate.py (see docs/benchmarks.md) live here.
std::string mesh_dir() {
    if (const char* env = std::getenv("RTCOST_BENCH_MESHES")) return env;
    return RTCOST_MESH_DIR;
}

std::string scene_path(const std::string& name) {
    if (name.ends_with(".obj")) return mesh_dir() + "/" + name;
    std::string path = shared_dir() + "/scenes/spd/" + name + ".nff";
    return std::filesystem::exists(path) ? path : "builtin:" + name;
}

Workload& workload(const std::string& name) {
    static std::map<std::string, std::unique_ptr<Workload>> cache;
    auto& w = cache[name];
    if (!w) {
        w = std::make_unique<Workload>();
        w->scene = load_scene(scene_path(name));
        // A mesh tessellated from an SPD scene (scripts/tessellate.py keeps its coordinates) is
        // viewed with that scene's camera and lights, not the default mesh camera: the same eye,
        // and shadow rays that the scene's own occluders block.
        if (name.ends_with("-mesh.obj")) {
            const std::string nff = shared_dir() + "/scenes/spd/" + name.substr(0, name.size() - 9) + ".nff";
            if (std::filesystem::exists(nff)) {
                const Scene source = load_scene(nff);
                w->scene.camera = source.camera;
                w->scene.has_camera = source.has_camera;
                w->scene.lights = source.lights;
            }
        }
        // RTCOST_BENCH_VIEW="SCENE|fx,fy,fz,ax,ay,az,ux,uy,uz,fov|x,y,z": another camera and light for
        // one scene (as rtcost's --camera and --light), e.g. the mesh camera of an earlier run.
        if (const char* env = std::getenv("RTCOST_BENCH_VIEW")) {
            const std::string v = env;
            const std::size_t a = v.find('|'), b = v.find('|', a + 1);
            if (a != std::string::npos && b != std::string::npos && v.substr(0, a) == name) {
                ViewSpec view;
                view.camera = v.substr(a + 1, b - a - 1);
                view.lights.push_back(v.substr(b + 1));
                try {
                    apply_view(w->scene, view);
                } catch (const std::exception& e) {
                    std::fprintf(stderr, "rtcost_bench: error: RTCOST_BENCH_VIEW: %s\n", e.what());
                    std::exit(2);
                }
            }
        }
    }
    return *w;
}

/// "name" or "name+key=value+key=value" (the variants RTCOST_BENCH_EXTRA adds, for tuning).
std::unique_ptr<Hierarchy> build_variant(const Scene& s, const std::string& spec) {
    std::vector<std::string> parts;
    for (std::size_t a = 0, b; a <= spec.size(); a = b + 1) {
        b = spec.find('+', a);
        if (b == std::string::npos) b = spec.size();
        parts.push_back(spec.substr(a, b - a));
    }
    return build_hierarchy(s, parts[0], std::vector<std::string>(parts.begin() + 1, parts.end()));
}

/// The rays of distribution `dist` over the workload's scene: camera-based sets at 256 x 256
/// (the tree distributions trace through their own BVH to make them), 65,536 random and aimed rays.
const RaySet& rays_of(Workload& w, const std::string& dist) {
    auto it = w.rays.find(dist);
    if (it != w.rays.end()) return it->second;
    RaySpec spec;
    spec.name = dist;
    spec.size = "256x256";
    spec.count = 1 << 16;
    return w.rays.emplace(dist, make_rays(w.scene, spec)).first->second;
}

/// Closest hits, occlusion for shadow rays. One thread (`threads` 1): a plain loop on the
/// benchmark's thread, rays per second of its CPU time (so that other processes on a shared
/// machine do not count). All cores (`threads` 0): the threaded runner, traversal alone, rays
/// per second of wall time.
void trace_bench(benchmark::State& state, std::string scene, std::string hierarchy, std::string dist, int threads) {
    Workload& w = workload(scene);
    auto h = build_variant(w.scene, hierarchy);
    const RaySet& set = rays_of(w, dist);
    TraceOptions opt;
    opt.threads = threads;
    if (h->lazy()) {
        // A lazily built structure grows during its first pass: time that pass as its build,
        // then the traversal of what the rays built.
        state.counters["lazy_build_s"] = trace_ray_set(*h, set, opt).seconds;
    }
    std::size_t hits = 0;
    for (auto _ : state) {
        if (threads == 1) {
            hits = 0;
            for (std::size_t i = 0; i < set.rays.size(); ++i) {
                Hit hit;
                const RayKind k = set.kinds[i];
                if (k == RayKind::Shadow || k == RayKind::AO) hits += h->any(set.rays[i], hit);
                else {
                    h->closest(set.rays[i], hit);
                    hits += hit.hit();
                }
            }
        } else {
            TraceResult r = trace_ray_set(*h, set, opt);
            state.SetIterationTime(r.seconds);
            hits = r.hit_count;
        }
    }
    const double n = static_cast<double>(set.rays.size()) * state.iterations() / 1e6;
    // kIsRate divides by the CPU time of the benchmark's thread; the all-core rate is by wall time.
    state.counters["Mrays/s"] = threads == 1 ? benchmark::Counter(n, benchmark::Counter::kIsRate) : benchmark::Counter(0);
    state.counters["wall_Mrays"] = n;
    state.counters["hit_pct"] = set.rays.empty() ? 0 : 100.0 * static_cast<double>(hits) / set.rays.size();
    state.counters["rays"] = static_cast<double>(set.rays.size());
    state.counters["bytes"] = static_cast<double>(h->structure().bytes);
}

void build_bench(benchmark::State& state, std::string scene, std::string hierarchy) {
    Workload& w = workload(scene);
    // rtcost's builders run on one thread; Embree's is held to one thread too for a fair ratio.
    std::vector<std::string> set;
    if (hierarchy == "embree") set.push_back("threads=1");
    for (auto _ : state) {
        auto h = build_variant(w.scene, hierarchy + (set.empty() ? "" : "+" + set[0]));
        benchmark::DoNotOptimize(h.get());
    }
    state.counters["prims"] = static_cast<double>(w.scene.size());
}

/// Single-thread seconds of tracing the scene's `spd` rays (the scene's own camera size, as
/// `rtcost trace --rays spd -j 1 --no-count`) through `h`, after a first pass that grows a lazy
/// hierarchy; the rays are made once per workload.
double spd_trace_seconds(Workload& w, const Hierarchy& h) {
    if (!w.spd) {
        RaySpec spec;
        spec.name = "spd";
        w.spd = std::make_unique<RaySet>(make_rays(w.scene, spec));
    }
    TraceOptions t;
    t.threads = 1;
    if (h.lazy()) trace_ray_set(h, *w.spd, t);
    return trace_ray_set(h, *w.spd, t).seconds;
}

/// The geometric estimator alone (one pass over the hierarchy's nodes), after the build: the cost
/// of predicting instead of measuring. Counters: the single-thread time to trace the scene's
/// `spd` rays through the same hierarchy in the same process (`spd_trace_ms`, traversal alone, as
/// `rtcost trace --rays spd -j 1 --no-count`) and the estimate's share of it (`share_pct`).
void model_bench(benchmark::State& state, std::string scene, std::string hierarchy) {
    Workload& w = workload(scene);
    auto h = build_hierarchy(w.scene, hierarchy);
    const double trace = spd_trace_seconds(w, *h);
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

/// The segments estimator for one hierarchy: materialising what its sample reaches and the
/// replay, from a sample of 2% of the scene's `spd` rays (at most 4,096, as `rtcost eval` draws
/// it), after the build and the draw. Counters as model_bench's: the traversal of every `spd` ray
/// (`spd_trace_ms`) and the prediction's share of it (`share_pct`; the target is 2%).
void segments_bench(benchmark::State& state, std::string scene, std::string hierarchy) {
    Workload& w = workload(scene);
    auto h = build_hierarchy(w.scene, hierarchy);
    const double trace = spd_trace_seconds(w, *h);
    auto reference = build_hierarchy(w.scene, "bvh-sah");
    const std::size_t n = std::clamp<std::size_t>(w.spd->rays.size() / 50, 1, 4096);
    const RaySample sample = draw_sample_from(w.scene, *w.spd, n, 1, *reference);
    std::vector<std::uint32_t> all(sample.size());
    for (std::uint32_t i = 0; i < all.size(); ++i) all[i] = i;
    double seconds = 0;
    for (auto _ : state) {
        const auto start = std::chrono::steady_clock::now();
        SegmentsPredictor p(*h, w.scene, sample);
        Prediction pr = p.predict(all, ModelOptions{});
        seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        benchmark::DoNotOptimize(pr.scalar);
    }
    const double estimate = state.iterations() > 0 ? seconds / state.iterations() : 0;
    state.counters["spd_trace_ms"] = trace * 1e3;
    state.counters["share_pct"] = trace > 0 ? 100 * estimate / trace : 0;
    state.counters["sample"] = static_cast<double>(n);
}

}  // namespace

int main(int argc, char** argv) {
    // The model benchmarks: every modelled hierarchy on three SPD scenes.
    const std::vector<std::string> model_scenes = {"tetra", "balls", "mount-s8"};
    std::vector<std::string> all;
    for (const HierarchyInfo* info : hierarchies()) all.push_back(info->name);
    for (const auto& s : model_scenes)
        for (const auto& h : all)
            if (h != "embree" && h != "brute") {
                benchmark::RegisterBenchmark(("model/" + s + "/" + h).c_str(), model_bench, s, h)
                    ->Unit(benchmark::kMillisecond)
                    ->MinTime(0.2);
                benchmark::RegisterBenchmark(("segments/" + s + "/" + h).c_str(), segments_bench, s, h)
                    ->Unit(benchmark::kMillisecond)
                    ->MinTime(0.2);
            }
    // Traversal against Embree on the rays that matter, one thread and all cores (names end in
    // /1t and /mt: run the /1t ones pinned to one core), on mount-s8 and two tessellated meshes;
    // `random` rays (most miss) once per scene. Builds on one thread.
    std::vector<std::string> scenes = {"mount-s8"};
    for (const char* m : {"balls-mesh.obj", "rings-mesh.obj"})
        if (std::filesystem::exists(mesh_dir() + "/" + m)) scenes.push_back(m);
    std::vector<std::string> hier = {"embree", "bvh-wide", "bvh-sah", "kd-sah"};
    if (const char* extra = std::getenv("RTCOST_BENCH_EXTRA")) {
        std::string e = extra;
        for (std::size_t a = 0, b; a < e.size(); a = b + 1) {
            b = e.find(',', a);
            if (b == std::string::npos) b = e.size();
            hier.push_back(e.substr(a, b - a));
        }
    }
    for (const auto& s : scenes) {
        for (const auto& h : hier) {
            for (const RayDistributionInfo* dist : ray_distributions()) {
                if (!dist->benchmarked) continue;
                const std::string& d = dist->name;
                for (int threads : {1, 0}) {
                    auto* b = benchmark::RegisterBenchmark(
                        ("trace/" + s + "/" + d + "/" + h + (threads == 1 ? "/1t" : "/mt")).c_str(), trace_bench, s,
                        h, d, threads);
                    b->Unit(benchmark::kMillisecond)->MinTime(0.5);
                    // All cores: wall time of the traversal, and the process's CPU time over all its
                    // threads (which a shared machine's other load does not inflate).
                    if (threads != 1) b->UseManualTime()->MeasureProcessCPUTime();
                }
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
