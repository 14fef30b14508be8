// `rtcost calibrate`: fit nanoseconds per operation kind to measured single-thread times.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <map>
#include <memory>
#include <unistd.h>

#include "cli.hpp"
#include "rtcost/evaluate.hpp"
#include "rtcost/model.hpp"

namespace rtcost::cli {
namespace {
using nlohmann::json;

struct CalibrateArgs {
    std::vector<std::string> scenes{"builtin:balls:3", "builtin:tetra:5", "builtin:balls"};
    std::string hierarchies = "all";
    RaySpec rays;
    int repeat = 5;
    bool sequential = false;  ///< time each hierarchy right after its build, not in interleaved rounds
    std::string out = "costs.json";
    std::vector<std::string> held_out;  ///< scenes measured and predicted, not fitted
    std::string terms = "ops,steps,simd,cache,edges";
};

/// --terms: the operations always; steps, simd, cache and edges as named.
TimeTerms parse_terms(const std::string& text) {
    TimeTerms t{false, false, false, false};
    bool ops = false;
    std::size_t start = 0;
    while (start <= text.size()) {
        const std::size_t end = std::min(text.find(',', start), text.size());
        const std::string w = text.substr(start, end - start);
        if (w == "ops") ops = true;
        else if (w == "steps") t.steps = true;
        else if (w == "simd") t.simd = true;
        else if (w == "cache") t.cache = true;
        else if (w == "edges") t.edges = true;
        else throw InputError("--terms", 0, "unknown term '" + w + "' (known: ops, steps, simd, cache, edges)");
        start = end + 1;
    }
    if (!ops) throw InputError("--terms", 0, "'ops' (the operations and the fixed cost per ray, always fitted) must be among the terms");
    return t;
}

int cmd_calibrate(const CalibrateArgs& a, const Common& common) {
    const std::vector<HierarchyRequest> names = parse_hierarchy_list(a.hierarchies, 0);
    {
        std::vector<std::string> inputs = a.scenes;
        inputs.push_back(a.rays.name);
        inputs.insert(inputs.end(), a.held_out.begin(), a.held_out.end());
        check_output_path(a.out, "--out", common, inputs);
    }
    const TimeTerms terms = parse_terms(a.terms);
    std::vector<CalibrationSample> samples, held;
    std::vector<std::string> held_scene;
    // Progress in passes: per scene and hierarchy, the counted one and the timed ones.
    const std::size_t per_run = 1 + static_cast<std::size_t>(a.repeat);
    const std::size_t total = (a.scenes.size() + a.held_out.size()) * names.size() * per_run;
    std::size_t passes = 0;
    Progress progress("calibrate", total, common.quiet || common.json);
    auto measure = [&](const std::string& spec, std::vector<CalibrationSample>& into, std::vector<std::string>* scene_of) {
        Scene scene = load(spec, common, a.rays.view);
        RaySet rays = make_rays(scene, a.rays);
        print_warnings(rays.warnings, common.quiet || common.json);
        for (CalibrationSample& s : measure_for_calibration(scene, rays, names, a.repeat, a.sequential,
                                                            [&](std::size_t n) { progress.update(passes += n); })) {
            into.push_back(std::move(s));
            if (scene_of) scene_of->push_back(scene.name);
        }
    };
    for (const std::string& spec : a.scenes) measure(spec, samples, nullptr);
    for (const std::string& spec : a.held_out) measure(spec, held, &held_scene);
    progress.finish();
    Calibration c = calibrate(samples, terms);
    // write_costs renames its own temporary over the path, which would replace a device or a
    // link; it writes to a private temporary here, copied onto the output by write_file_atomic.
    {
        namespace fs = std::filesystem;
        const fs::path tmp = fs::temp_directory_path() / fmt::format("rtcost-costs-{}.json", ::getpid());
        write_costs(tmp.string(), c, samples);
        std::ifstream in(tmp, std::ios::binary);
        std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        in.close();
        std::error_code ec;
        fs::remove(tmp, ec);
        write_file_atomic(a.out, bytes);
    }
    // Held-out scenes: predicted time from the fitted costs against measured time, and per
    // scene the rank agreement of the hierarchies by predicted and by measured time.
    std::vector<double> held_pred;
    for (const CalibrationSample& h : held) held_pred.push_back(c.costs.scalar(h.ops, h.structure));
    std::map<std::string, std::pair<std::vector<double>, std::vector<double>>> by_scene;
    for (std::size_t i = 0; i < held.size(); ++i) {
        by_scene[held_scene[i]].first.push_back(held_pred[i]);
        by_scene[held_scene[i]].second.push_back(held[i].ns_per_ray);
    }
    double held_mae = 0;
    for (std::size_t i = 0; i < held.size(); ++i) held_mae += std::fabs(held_pred[i] - held[i].ns_per_ray) / held[i].ns_per_ray;
    if (!held.empty()) held_mae /= held.size();

    static const char* kKinds[] = {"box", "plane", "hop", "classify"};
    if (common.json) {
        json fit = json::object();
        for (int k = 0; k < 4; ++k) fit[kKinds[k]] = c.fitted[k] ? json(k == 0 ? c.costs.box : k == 1 ? c.costs.plane : k == 2 ? c.costs.hop : c.costs.classify) : json(nullptr);
        if (!c.fitted[0] && c.costs.box > 0) fit["box"] = c.costs.box;  // as the box tests made at once
        for (int k = 0; k < kPrimKinds; ++k)
            fit[std::string(prim_kind_name(static_cast<PrimKind>(k)))] = c.fitted[4 + k] ? json(c.costs.prim[k]) : json(nullptr);
        fit["per_ray"] = c.costs.per_ray;
        fit["step"] = terms.steps ? json(c.costs.step) : json(nullptr);
        fit["box_simd"] = c.costs.box_simd >= 0 ? json(c.costs.box_simd) : json(nullptr);
        fit["box_pair"] = c.costs.box_pair >= 0 ? json(c.costs.box_pair) : json(nullptr);
        fit["cache"] = terms.cache ? json(c.costs.cache) : json(nullptr);
        fit["cache_bytes"] = c.costs.cache_bytes;
        fit["polygon_edge"] = terms.edges ? json(c.costs.polygon_edge) : json(nullptr);
        json runs = json::array();
        for (std::size_t i = 0; i < samples.size(); ++i)
            runs.push_back({{"run", samples[i].label}, {"measured_ns_per_ray", samples[i].ns_per_ray},
                            {"fitted_ns_per_ray", c.predicted[i]}, {"operations", UnitCosts{}.scalar(samples[i].ops)},
                            {"structure_bytes", samples[i].structure.bytes},
                            {"residual", (c.predicted[i] - samples[i].ns_per_ray) / samples[i].ns_per_ray}});
        json held_runs = json::array(), rho = json::object();
        for (std::size_t i = 0; i < held.size(); ++i)
            held_runs.push_back({{"run", held[i].label}, {"measured_ns_per_ray", held[i].ns_per_ray},
                                 {"predicted_ns_per_ray", held_pred[i]}, {"operations", UnitCosts{}.scalar(held[i].ops)},
                                 {"structure_bytes", held[i].structure.bytes},
                                 {"error", (held_pred[i] - held[i].ns_per_ray) / held[i].ns_per_ray}});
        for (const auto& [scene, v] : by_scene) rho[scene] = rank_correlation(v.first, v.second);
        json out = {{"costs_file", a.out}, {"ns_per_operation", fit}, {"rms_relative_residual", c.rms_relative},
                    {"runs", runs}};
        if (!held.empty())
            out["held_out"] = {{"runs", held_runs}, {"mean_absolute_error", held_mae}, {"spearman_by_scene", rho}};
        std::cout << out.dump(2) << "\n";
        return 0;
    }
    fmt::print("unit costs (ns per operation, single thread), fitted over {} runs:\n", samples.size());
    const double vals[] = {c.costs.box, c.costs.plane, c.costs.hop, c.costs.classify};
    for (int k = 0; k < 4; ++k)
        fmt::print("  {:<10} {}\n", kKinds[k],
                   c.fitted[k]                        ? fmt::format("{:.3f}", vals[k])
                   : k == 0 && c.costs.box > 0 ? fmt::format("{:.3f} (no box tested alone: as those tested at once)", vals[k])
                                                      : "(not exercised)");
    for (int k = 0; k < kPrimKinds; ++k)
        fmt::print("  {:<10} {}\n", prim_kind_name(static_cast<PrimKind>(k)),
                   c.fitted[4 + k] ? fmt::format("{:.3f}", c.costs.prim[k]) : "(not exercised)");
    fmt::print("  {:<10} {:.3f}\n", "per ray", c.costs.per_ray);
    if (terms.steps) fmt::print("  {:<10} {:.3f} (per traversal step, besides its operations)\n", "step", c.costs.step);
    if (terms.simd)
        fmt::print("  {:<10} {}\n", "box simd",
                   c.costs.box_simd >= 0 ? fmt::format("{:.3f} (per box test of a SIMD node visit)", c.costs.box_simd)
                                         : "(no SIMD structure measured: priced as box)");
    if (terms.simd)
        fmt::print("  {:<10} {}\n", "box pair",
                   c.costs.box_pair >= 0 ? fmt::format("{:.3f} (per box test of a binary node's pair)", c.costs.box_pair)
                                         : "(no binary BVH measured: priced as box)");
    if (terms.cache)
        fmt::print("  {:<10} {:.3f} (per step, per doubling of the structure beyond {})\n", "cache", c.costs.cache,
                   human_bytes(static_cast<std::uint64_t>(c.costs.cache_bytes)));
    if (terms.edges)
        fmt::print("  {:<10} {:.3f} (per edge a polygon test walks, polygons of 4+ vertices; timed, not fitted)\n",
                   "edge", c.costs.polygon_edge);
    fmt::print("\n{:<36} {:>12} {:>12} {:>9}\n", "run", "measured ns", "fitted ns", "residual");
    for (std::size_t i = 0; i < samples.size(); ++i)
        fmt::print("{:<36} {:>12.1f} {:>12.1f} {:>+8.1f}%\n", samples[i].label, samples[i].ns_per_ray, c.predicted[i],
                   100 * (c.predicted[i] - samples[i].ns_per_ray) / samples[i].ns_per_ray);
    fmt::print("\nrms relative residual {:.1f}%; written to {} (use with eval --costs)\n", 100 * c.rms_relative, a.out);
    if (!held.empty()) {
        fmt::print("\nheld out (measured, not fitted):\n{:<36} {:>12} {:>12} {:>9}\n", "run", "measured ns", "predicted ns",
                   "error");
        for (std::size_t i = 0; i < held.size(); ++i)
            fmt::print("{:<36} {:>12.1f} {:>12.1f} {:>+8.1f}%\n", held[i].label, held[i].ns_per_ray, held_pred[i],
                       100 * (held_pred[i] - held[i].ns_per_ray) / held[i].ns_per_ray);
        fmt::print("mean absolute error {:.1f}%\n", 100 * held_mae);
        for (const auto& [scene, v] : by_scene)
            fmt::print("rank agreement on {} (Spearman's rho, predicted against measured time): {:.3f}\n", scene,
                       rank_correlation(v.first, v.second));
    }
    return 0;
}

Subcommand setup_calibrate(CLI::App& parent, Common& common) {
    auto a = std::make_shared<CalibrateArgs>();
    a->rays.size = "128x128";
    auto* cmd = parent.add_subcommand("calibrate",
                                      "fit nanoseconds per operation kind (least squares over measured counts and "
                                      "single-thread times) and write a costs file for eval --costs");
    cmd->add_option("SCENES", a->scenes, "scenes to measure on")->capture_default_str();
    cmd->add_option("-H,--hierarchy", a->hierarchies, "comma-separated hierarchies (name[:key=value...]), or all")
        ->capture_default_str();
    add_ray_args(cmd, a->rays);
    cmd->add_option("--repeat", a->repeat,
                    "timed passes per hierarchy and scene (the fastest counts), in rounds over every hierarchy of "
                    "the scene once all are built (unless --sequential)")
        ->check(CLI::Range(1, 100))
        ->capture_default_str();
    cmd->add_flag("--sequential", a->sequential,
                  "time each hierarchy right after its build and free it before the next (less memory: one "
                  "structure at a time; interleaved rounds keep a scene's hierarchies all in memory)");
    cmd->add_option("-o,--out", a->out, "costs file to write")->capture_default_str();
    cmd->add_option("--terms", a->terms,
                    "time model: ops (operations and a fixed cost per ray, always), steps (ns per traversal step), "
                    "simd (box tests made several at once priced apart: a SIMD node visit's, a binary node's pair), cache (ns per step per doubling of the "
                    "structure beyond the L2 cache), edges (ns per edge a polygon test walks, polygons of more "
                    "than three vertices)")
        ->capture_default_str();
    cmd->add_option("--held-out", a->held_out, "scenes measured and predicted with the fitted costs, not fitted (repeatable)");
    add_common(cmd, common);
    return {cmd, [a, &common] { return cmd_calibrate(*a, common); }};
}

const CommandRegistration reg{45, setup_calibrate};

}  // namespace
}  // namespace rtcost::cli
