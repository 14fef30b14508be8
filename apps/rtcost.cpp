// The rtcost command line: info, build, trace and list over the library's public API.
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <cstdio>
#include <iostream>
#include <optional>
#include <unistd.h>

#include "rtcost/error.hpp"
#include "rtcost/hierarchy.hpp"
#include "rtcost/io.hpp"
#include "rtcost/model.hpp"
#include "rtcost/rays.hpp"
#include "rtcost/report.hpp"
#include "rtcost/trace.hpp"

using namespace rtcost;
using nlohmann::json;

namespace {

constexpr int kExitBadInput = 2;

struct Common {
    bool json = false;
    bool quiet = false;
};

/// Warnings gathered while loading (degenerate primitives skipped), to stderr unless quiet.
void print_warnings(const Scene& scene, bool quiet) {
    if (quiet || scene.warnings.empty()) return;
    constexpr std::size_t kShown = 5;
    for (std::size_t i = 0; i < scene.warnings.size() && i < kShown; ++i)
        fmt::print(stderr, "rtcost: warning: {}\n", scene.warnings[i]);
    if (scene.warnings.size() > kShown)
        fmt::print(stderr, "rtcost: warning: ... and {} more\n", scene.warnings.size() - kShown);
}

Scene load(const std::string& spec, const Common& common) {
    Scene scene = load_scene(spec);
    print_warnings(scene, common.quiet || common.json);
    return scene;
}

std::string kind_summary(const Scene& s) {
    std::string out;
    auto counts = s.kind_counts();
    for (int k = 0; k < kPrimKinds; ++k) {
        if (!counts[k]) continue;
        out += fmt::format("{}{} {}{}", out.empty() ? "" : ", ", counts[k],
                           prim_kind_name(static_cast<PrimKind>(k)), counts[k] == 1 ? "" : "s");
    }
    return out;
}

/// Text listing of every hierarchy and its parameters with defaults; shown by `--help`.
std::string hierarchy_help() {
    std::string out = "Hierarchies (--hierarchy NAME, parameters with --set key=value):\n";
    for (const HierarchyInfo* h : hierarchies()) {
        out += fmt::format("  {:<12} {}\n", h->name, h->description);
        for (const ParamSpec& p : h->params)
            out += fmt::format("      {}={:<10} {}\n", p.name, p.default_value, p.help);
    }
    return out;
}

struct BuildArgs {
    std::string scene;
    std::string hierarchy = "brute";
    std::vector<std::string> set;
};

void add_build_args(CLI::App* cmd, BuildArgs& a) {
    cmd->add_option("SCENE", a.scene, "scene file (.nff, or any mesh assimp reads) or builtin:NAME[:level]")
        ->required();
    cmd->add_option("-H,--hierarchy", a.hierarchy, "hierarchy to build (see the list below)")
        ->capture_default_str();
    cmd->add_option("--set", a.set, "hierarchy parameter key=value (repeatable)");
}

std::unique_ptr<Hierarchy> build(const Scene& scene, const BuildArgs& a, const Common& common) {
    // A build reports no fraction done, so the terminal shows what is being built while it runs.
    bool tty = !common.quiet && ::isatty(STDERR_FILENO);
    if (tty) fmt::print(stderr, "building {} over {} primitives...", a.hierarchy, scene.size());
    std::fflush(stderr);
    auto h = build_hierarchy(scene, a.hierarchy, a.set);
    if (tty) fmt::print(stderr, "\r\033[K");
    return h;
}

int cmd_info(const std::string& spec, const Common& common) {
    Scene scene = load(spec, common);
    if (common.json) {
        std::cout << to_json(scene).dump(2) << "\n";
        return 0;
    }
    const Box3& b = scene.bounds();
    const Camera& c = scene.camera;
    fmt::print("scene      {}\n", scene.name);
    fmt::print("primitives {} ({})\n", scene.size(), kind_summary(scene));
    fmt::print("bounds     ({:g}, {:g}, {:g}) - ({:g}, {:g}, {:g})\n", b.lo.x, b.lo.y, b.lo.z, b.hi.x, b.hi.y, b.hi.z);
    fmt::print("lights     {}\n", scene.lights.size());
    for (const Light& l : scene.lights) fmt::print("           at ({:g}, {:g}, {:g})\n", l.position.x, l.position.y, l.position.z);
    fmt::print("camera     from ({:g}, {:g}, {:g}) at ({:g}, {:g}, {:g}) angle {:g} hither {:g} {}x{}{}\n", c.from.x,
               c.from.y, c.from.z, c.at.x, c.at.y, c.at.z, c.angle, c.hither, c.width, c.height,
               scene.has_camera ? "" : " (default framing)");
    fmt::print("materials  {}\n", scene.materials.size());
    fmt::print("memory     {}\n", human_bytes(scene.bytes()));
    if (!scene.warnings.empty()) fmt::print("warnings   {} (skipped input)\n", scene.warnings.size());
    return 0;
}

int cmd_build(const BuildArgs& a, const Common& common) {
    Scene scene = load(a.scene, common);
    auto h = build(scene, a, common);
    StructureStats s = h->structure();
    if (common.json) {
        json j = {{"scene", scene.name},
                  {"primitives", scene.size()},
                  {"hierarchy", h->name()},
                  {"params", Params(find_hierarchy(h->name())->params, a.set).values()},
                  {"build", to_json(s)}};
        std::cout << j.dump(2) << "\n";
        return 0;
    }
    fmt::print("{} over {} ({} primitives)\n", h->name(), scene.name, scene.size());
    fmt::print("  build     {:.4f} s\n", s.seconds);
    fmt::print("  N_IN      {}   interior nodes\n", s.interior);
    fmt::print("  N_V       {}   leaves\n", s.leaves);
    fmt::print("  N_EV      {}   empty leaves\n", s.empty_leaves);
    fmt::print("  N_OIV     {}   primitive references in leaves\n", s.references);
    fmt::print("  depth     {}\n", s.depth);
    fmt::print("  memory    {}\n", human_bytes(s.bytes));
    return 0;
}

struct TraceArgs {
    BuildArgs b;
    std::string rays = "camera";
    std::string size;
    std::size_t count = 100000;
    std::uint64_t seed = 1;
    std::string query = "closest";
    std::string hits_out;
    int threads = 0;
    bool no_count = false;
};

std::vector<Ray> make_rays(const Scene& scene, const TraceArgs& a, std::string& described) {
    if (a.rays == "camera") {
        int w = scene.camera.width, h = scene.camera.height;
        if (!a.size.empty()) parse_size(a.size, "--size", w, h);
        described = fmt::format("camera {}x{}", w, h);
        return camera_rays(scene.camera, w, h);
    }
    if (a.rays == "lines") {
        described = fmt::format("lines {} seed {}", a.count, a.seed);
        return line_rays(scene.bounds(), a.count, a.seed);
    }
    if (a.rays == "random") {
        described = fmt::format("random {} seed {}", a.count, a.seed);
        return random_rays(scene.bounds(), a.count, a.seed);
    }
    described = a.rays;
    return read_rays(a.rays);
}

int cmd_trace(const TraceArgs& a, const Common& common) {
    Scene scene = load(a.b.scene, common);
    std::string described;
    std::vector<Ray> rays = make_rays(scene, a, described);
    auto h = build(scene, a.b, common);
    StructureStats s = h->structure();

    TraceOptions opt;
    opt.query = a.query == "any" ? Query::Any : a.query == "all" ? Query::All : Query::Closest;
    opt.threads = a.threads;
    TraceResult timed;
    {
        Progress progress(fmt::format("trace {}", h->name()), rays.size(), common.quiet);
        opt.progress = [&](std::size_t done) { progress.update(done); };
        timed = trace_rays(*h, rays, opt);
    }
    std::optional<TraceResult> counted;
    if (!a.no_count) {
        // Counting is a second pass through the counting instantiation of the same traversal, so
        // the timing above is of the fast path alone.
        Progress progress(fmt::format("count {}", h->name()), rays.size(), common.quiet);
        opt.progress = [&](std::size_t done) { progress.update(done); };
        opt.count = true;
        counted = trace_rays(*h, rays, opt);
    }
    if (!a.hits_out.empty()) write_hits(a.hits_out, timed.hits);

    double mrays = timed.seconds > 0 ? rays.size() / timed.seconds / 1e6 : 0;
    if (common.json) {
        json trace = {{"rays", rays.size()},       {"hits", timed.hit_count},  {"seconds", timed.seconds},
                      {"threads", timed.threads},  {"mrays_per_s", mrays},     {"query", a.query},
                      {"distribution", described}};
        if (counted) trace["per_ray"] = per_ray_json(counted->counters);
        json j = {{"scene", scene.name}, {"primitives", scene.size()}, {"hierarchy", h->name()},
                  {"build", to_json(s)},  {"trace", trace}};
        std::cout << j.dump(2) << "\n";
        return 0;
    }
    fmt::print("scene      {} ({} primitives: {})\n", scene.name, scene.size(), kind_summary(scene));
    fmt::print("hierarchy  {}: built in {:.4f} s, {} interior, {} leaves, depth {}, {}\n", h->name(), s.seconds,
               s.interior, s.leaves, s.depth, human_bytes(s.bytes));
    fmt::print("rays       {} ({}), {} query, {} hits\n", rays.size(), described, a.query, timed.hit_count);
    fmt::print("trace      {:.4f} s on {} thread{}: {:.3f} Mrays/s\n", timed.seconds, timed.threads,
               timed.threads == 1 ? "" : "s", mrays);
    if (counted) {
        const RayCounters& c = counted->counters;
        double n = c.rays ? static_cast<double>(c.rays) : 1;
        fmt::print("per ray    N_IT {:.2f}  N_TS {:.2f}  N_ETS {:.2f}  N_EETS {:.2f}\n", c.prim_tests() / n, c.steps / n,
                   c.leaves / n, c.empty_leaves / n);
        fmt::print("           box {:.2f}  plane {:.2f}  hop {:.2f}  classify {:.2f}  prim {:.2f}\n", c.box / n,
                   c.plane / n, c.hop / n, c.classify / n, c.prim_tests() / n);
    }
    if (!a.hits_out.empty()) fmt::print("hits       written to {}\n", a.hits_out);
    return 0;
}

struct EvalArgs {
    std::string scene;
    std::string hierarchies = "all";
    std::vector<std::string> set;
    TraceArgs rays;  // distribution options (rays, size, count, seed, query, threads)
    std::string estimator = "geometric";
    std::string preset = "exact";
    std::size_t sample = 20000;
    std::string costs;
    bool by_depth = false;
};

std::vector<std::string> split_list(const std::string& list) {
    std::vector<std::string> out;
    if (list == "all") {
        for (const HierarchyInfo* h : hierarchies())
            if (h->name != "embree") out.push_back(h->name);
        return out;
    }
    std::size_t start = 0;
    while (start <= list.size()) {
        std::size_t comma = list.find(',', start);
        if (comma == std::string::npos) comma = list.size();
        if (comma > start) out.push_back(list.substr(start, comma - start));
        start = comma + 1;
    }
    return out;
}

struct EvalRow {
    std::string name;
    StructureStats s;
    bool modelled = false;
    Prediction pred;
    CostVector meas;
    std::vector<double> meas_visits;
    double meas_scalar = 0, error = 0, mrays = 0;
    int rank_pred = 0, rank_meas = 0;
};

json cost_json(const CostVector& c, double scalar) {
    json by_kind = json::object();
    for (int k = 0; k < kPrimKinds; ++k) by_kind[std::string(prim_kind_name(static_cast<PrimKind>(k)))] = c.prim[k];
    return {{"cost", scalar}, {"box", c.box},       {"plane", c.plane},   {"hop", c.hop},
            {"classify", c.classify}, {"prim", c.prim_tests()}, {"prim_by_kind", by_kind},
            {"N_TS", c.steps}, {"N_ETS", c.leaves}, {"N_EETS", c.empty_leaves}};
}

/// Ranks 1..n by ascending value.
template <class F>
void rank(std::vector<EvalRow>& rows, F value, int EvalRow::*out) {
    std::vector<std::size_t> idx(rows.size());
    for (std::size_t i = 0; i < idx.size(); ++i) idx[i] = i;
    std::stable_sort(idx.begin(), idx.end(), [&](auto x, auto y) { return value(rows[x]) < value(rows[y]); });
    for (std::size_t r = 0; r < idx.size(); ++r) rows[idx[r]].*out = static_cast<int>(r + 1);
}

int cmd_eval(EvalArgs& a, const Common& common) {
    Scene scene = load(a.scene, common);
    UnitCosts costs = a.costs.empty() ? UnitCosts{} : UnitCosts::read(a.costs);
    std::vector<std::string> names = split_list(a.hierarchies);
    if (names.empty()) throw InputError("--hierarchy", 0, "no hierarchy named");
    for (const auto& n : names)
        if (!find_hierarchy(n)) build_hierarchy(scene, n);  // throws the unknown-hierarchy error
    if (names.size() > 1 && !a.set.empty())
        throw InputError("--set", 0, "parameters apply to one hierarchy: name a single one with --hierarchy");
    std::string described;
    std::vector<Ray> test = make_rays(scene, a.rays, described);
    const bool sampled = a.estimator == "sampled";
    std::vector<Ray> train;
    if (sampled) {
        // A training sample disjoint from the test rays: a fresh draw for generated
        // distributions, every other ray for camera rays and ray files.
        if (a.rays.rays == "lines" || a.rays.rays == "random") {
            TraceArgs t = a.rays;
            t.seed = a.rays.seed + 7919;
            t.count = a.sample;
            std::string unused;
            train = make_rays(scene, t, unused);
        } else {
            std::vector<Ray> keep;
            for (std::size_t i = 0; i < test.size(); ++i) (i % 2 ? train : keep).push_back(test[i]);
            test.swap(keep);
            if (train.size() > a.sample) train.resize(a.sample);
        }
    }
    ModelOptions mo;
    mo.preset = a.preset == "paper" ? Preset::Paper : Preset::Exact;
    mo.query = a.rays.query == "any" ? Query::Any : a.rays.query == "all" ? Query::All : Query::Closest;

    std::vector<EvalRow> rows;
    std::vector<Hit> train_hits;
    Progress progress("eval", names.size(), common.quiet || common.json);
    for (const auto& name : names) {
        auto h = build(scene, BuildArgs{a.scene, name, a.set}, common);
        EvalRow row;
        row.name = name;
        row.s = h->structure();
        ModelTree tree = h->model_tree();
        row.modelled = !tree.nodes.empty();
        if (row.modelled) {
            if (sampled) {
                if (train_hits.empty()) train_hits = trace_rays(*h, train).hits;  // hits are exact in every hierarchy
                row.pred = predict_sampled(tree, scene, train, train_hits, mo, costs);
            } else {
                row.pred = predict_geometric(tree, scene, mo, costs);
            }
        }
        TraceOptions opt;
        opt.query = mo.query;
        opt.threads = a.rays.threads;
        TraceResult timed = trace_rays(*h, test, opt);
        opt.count = true;
        TraceResult counted = trace_rays(*h, test, opt);
        row.meas = measured_cost(counted.counters);
        row.meas_scalar = costs.scalar(row.meas);
        row.error = row.modelled && row.meas_scalar > 0 ? (row.pred.scalar - row.meas_scalar) / row.meas_scalar : 0;
        row.mrays = timed.seconds > 0 ? test.size() / timed.seconds / 1e6 : 0;
        double n = counted.counters.rays ? static_cast<double>(counted.counters.rays) : 1;
        for (int d = 0; d < kMaxStatDepth; ++d) row.meas_visits.push_back(counted.counters.visits[d] / n);
        while (!row.meas_visits.empty() && row.meas_visits.back() == 0) row.meas_visits.pop_back();
        rows.push_back(std::move(row));
        progress.update(rows.size());
    }
    progress.finish();
    rank(rows, [](const EvalRow& r) { return r.modelled ? r.pred.scalar : kInf; }, &EvalRow::rank_pred);
    rank(rows, [](const EvalRow& r) { return r.meas_scalar; }, &EvalRow::rank_meas);

    if (common.json) {
        json results = json::array();
        for (const auto& r : rows) {
            json j = {{"hierarchy", r.name}, {"build", to_json(r.s)}, {"measured", cost_json(r.meas, r.meas_scalar)},
                      {"mrays_per_s", r.mrays}, {"rank_measured", r.rank_meas}};
            if (r.modelled) {
                j["predicted"] = cost_json(r.pred.cost, r.pred.scalar);
                j["error"] = r.error;
                j["rank_predicted"] = r.rank_pred;
                j["note"] = r.pred.note;
            } else {
                j["predicted"] = nullptr;
            }
            if (a.by_depth) {
                j["visits_by_depth"] = {{"predicted", r.modelled ? json(r.pred.visits_by_depth) : json(nullptr)},
                                        {"measured", r.meas_visits}};
            }
            results.push_back(j);
        }
        json out = {{"scene", scene.name},       {"primitives", scene.size()}, {"rays", test.size()},
                    {"distribution", described}, {"query", a.rays.query},     {"estimator", a.estimator},
                    {"preset", a.preset},        {"training_rays", train.size()},
                    {"unit_costs", costs.calibrated ? "ns" : "operations"}, {"results", results}};
        std::cout << out.dump(2) << "\n";
        return 0;
    }
    fmt::print("scene {} ({} primitives), {} test rays ({}), {} query\n", scene.name, scene.size(), test.size(),
               described, a.rays.query);
    fmt::print("model: {} estimator{}, {} preset, costs in {}\n", a.estimator,
               sampled ? fmt::format(" ({} training rays)", train.size()) : std::string(), a.preset,
               costs.calibrated ? "ns" : "operations");
    fmt::print("{:<12} {:>9} {:>9} {:>10} {:>11} {:>11} {:>8} {:>9} {:>5} {:>5}\n", "hierarchy", "build s", "nodes",
               "bytes", "predicted", "measured", "error", "Mrays/s", "rk-p", "rk-m");
    for (const auto& r : rows) {
        fmt::print("{:<12} {:>9.4f} {:>9} {:>10} {:>11} {:>11.2f} {:>8} {:>9.3f} {:>5} {:>5}\n", r.name, r.s.seconds,
                   r.s.interior + r.s.leaves, human_bytes(r.s.bytes),
                   r.modelled ? fmt::format("{:.2f}", r.pred.scalar) : "-", r.meas_scalar,
                   r.modelled ? fmt::format("{:+.1f}%", 100 * r.error) : "-", r.mrays,
                   r.modelled ? std::to_string(r.rank_pred) : "-", r.rank_meas);
    }
    fmt::print("\nby kind (predicted / measured per ray):\n");
    for (const auto& r : rows) {
        if (!r.modelled) continue;
        const CostVector &p = r.pred.cost, &m = r.meas;
        fmt::print("{:<12} box {:.2f}/{:.2f}  plane {:.2f}/{:.2f}  hop {:.2f}/{:.2f}  classify {:.2f}/{:.2f}  prim "
                   "{:.2f}/{:.2f}  N_TS {:.2f}/{:.2f}\n",
                   r.name, p.box, m.box, p.plane, m.plane, p.hop, m.hop, p.classify, m.classify, p.prim_tests(),
                   m.prim_tests(), p.steps, m.steps);
    }
    if (a.by_depth) {
        fmt::print("\nvisits per depth (predicted / measured per ray):\n");
        for (const auto& r : rows) {
            if (!r.modelled) continue;
            fmt::print("{}\n", r.name);
            std::size_t depth = std::max(r.pred.visits_by_depth.size(), r.meas_visits.size());
            for (std::size_t d = 0; d < depth; ++d) {
                double p = d < r.pred.visits_by_depth.size() ? r.pred.visits_by_depth[d] : 0;
                double m = d < r.meas_visits.size() ? r.meas_visits[d] : 0;
                fmt::print("  depth {:>3}  {:10.4f} {:10.4f}\n", d, p, m);
            }
        }
    }
    return 0;
}

int cmd_list() {
    fmt::print("{}", hierarchy_help());
    fmt::print("Built-in scenes (SCENE = builtin:NAME[:level]):\n");
    for (const auto& n : builtin_scene_names()) fmt::print("  {}\n", n);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"rtcost: build, trace, count and model ray tracing acceleration structures"};
    app.require_subcommand(1);
    app.set_help_all_flag("--help-all", "help for every subcommand");
    Common common;
    auto add_common = [&](CLI::App* cmd, bool with_json = true) {
        if (with_json) cmd->add_flag("--json", common.json, "machine-readable JSON on stdout");
        cmd->add_flag("-q,--quiet", common.quiet, "no progress and no warnings on stderr");
    };

    std::string info_scene;
    auto* info = app.add_subcommand("info", "summarise a scene: primitives by kind, bounds, lights, camera, memory");
    info->add_option("SCENE", info_scene, "scene file or builtin:NAME[:level]")->required();
    add_common(info);

    BuildArgs build_args;
    auto* buildc = app.add_subcommand("build", "build a hierarchy and print its structural statistics");
    add_build_args(buildc, build_args);
    add_common(buildc);
    buildc->footer(hierarchy_help());

    TraceArgs trace_args;
    auto* trace = app.add_subcommand("trace", "trace rays through a hierarchy; time and count every operation");
    add_build_args(trace, trace_args.b);
    trace->add_option("-r,--rays", trace_args.rays,
                      "rays: a ray file (8 float32 per ray), or camera (pixel centres), lines (isotropic "
                      "random lines), random (test rays)")
        ->capture_default_str();
    trace->add_option("--size", trace_args.size, "image size WxH for --rays camera (default: the scene's)");
    trace->add_option("--count", trace_args.count, "number of rays for lines and random")->capture_default_str();
    trace->add_option("--seed", trace_args.seed, "seed for lines and random")->capture_default_str();
    trace->add_option("--query", trace_args.query,
                      "closest hit, any hit (occlusion), or all (visit everything the ray meets, no early exit)")
        ->check(CLI::IsMember({"closest", "any", "all"}))
        ->capture_default_str();
    trace->add_option("--hits", trace_args.hits_out, "write hits (int32 id, float32 t per ray) to this file");
    trace->add_option("-j,--threads", trace_args.threads, "threads (0: all cores)")
        ->check(CLI::Range(0, 1024))
        ->capture_default_str();
    trace->add_flag("--no-count", trace_args.no_count, "skip the counting pass (timing only)");
    add_common(trace);
    trace->footer(hierarchy_help());

    EvalArgs eval_args;
    auto* eval = app.add_subcommand("eval", "predict each hierarchy's cost with the model and measure it");
    eval->add_option("SCENE", eval_args.scene, "scene file or builtin:NAME[:level]")->required();
    eval->add_option("-H,--hierarchy", eval_args.hierarchies, "comma-separated hierarchies, or all")
        ->capture_default_str();
    eval->add_option("--set", eval_args.set, "parameter key=value for a single hierarchy (repeatable)");
    eval->add_option("-r,--rays", eval_args.rays.rays, "rays: camera, lines, random, or a ray file")
        ->capture_default_str();
    eval->add_option("--size", eval_args.rays.size, "image size WxH for --rays camera");
    eval->add_option("--count", eval_args.rays.count, "rays for lines and random")->capture_default_str();
    eval->add_option("--seed", eval_args.rays.seed, "seed for lines and random")->capture_default_str();
    eval->add_option("--query", eval_args.rays.query, "closest, any, or all (no early termination)")
        ->check(CLI::IsMember({"closest", "any", "all"}))
        ->capture_default_str();
    eval->add_option("--estimator", eval_args.estimator,
                     "geometric (surface areas, no rays traced) or sampled (probabilities from training rays)")
        ->check(CLI::IsMember({"geometric", "sampled"}))
        ->capture_default_str();
    eval->add_option("--preset", eval_args.preset, "exact (every operation performed) or paper (the seed's formulas)")
        ->check(CLI::IsMember({"exact", "paper"}))
        ->capture_default_str();
    eval->add_option("--sample", eval_args.sample, "training rays for the sampled estimator")->capture_default_str();
    eval->add_option("--costs", eval_args.costs, "unit costs file (JSON, from rtcost calibrate)");
    eval->add_flag("--by-depth", eval_args.by_depth, "predicted and measured visits per depth");
    eval->add_option("-j,--threads", eval_args.rays.threads, "threads (0: all cores)")->check(CLI::Range(0, 1024));
    add_common(eval);
    eval->footer(hierarchy_help());

    auto* list = app.add_subcommand("list", "list hierarchies with their parameters, and built-in scenes");

    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        app.exit(e);
        return kExitBadInput;
    }

    try {
        if (*info) return cmd_info(info_scene, common);
        if (*buildc) return cmd_build(build_args, common);
        if (*trace) return cmd_trace(trace_args, common);
        if (*eval) return cmd_eval(eval_args, common);
        if (*list) return cmd_list();
    } catch (const InputError& e) {
        fmt::print(stderr, "rtcost: error: {}\n", e.what());
        return kExitBadInput;
    } catch (const std::bad_alloc&) {
        fmt::print(stderr, "rtcost: error: out of memory\n");
        return 1;
    } catch (const std::exception& e) {
        fmt::print(stderr, "rtcost: error: {}\n", e.what());
        return 1;
    }
    return 0;
}
