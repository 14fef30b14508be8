// `rtcost report`: the evaluation, the scene's render and every hierarchy's heat map as one
// self-contained HTML page (and, with --json, the data behind it).
#include <filesystem>
#include <fstream>
#include <iostream>

#include "cli.hpp"
#include "rtcost/design.hpp"
#include "rtcost/evaluate.hpp"
#include "rtcost/html_report.hpp"

namespace rtcost::cli {
namespace {
using nlohmann::json;

struct ReportArgs {
    std::string scene;
    std::string hierarchies = "all";
    RaySpec rays;
    std::string estimator = "segments";  // eval's default: the most accurate that costs no full trace
    std::string costs;
    std::string from_eval;
    std::string heatmap = "ops";
    std::string heatmap_size;
    double scale_max = 0;
    bool log = false;
    int threads = 0;
    bool no_design = false;
    std::string out = "report.html";
};

json run_eval(const ReportArgs& a, const Scene& scene, const UnitCosts& costs, const Common& common) {
    EvalOptions opt;
    opt.hierarchies = parse_hierarchy_list(a.hierarchies, scene.size());
    opt.left_out = left_out_of_all(a.hierarchies, scene.size());
    opt.estimators = {a.estimator == "geometric" ? Estimator::Geometric
                      : a.estimator == "segments" ? Estimator::Segments
                                                  : Estimator::Sampled};
    opt.costs = costs;
    opt.threads = a.threads;
    opt.sample_seed = a.rays.seed;
    Progress progress("report: eval", opt.hierarchies.size(), common.quiet || common.json);
    std::size_t done = 0;
    opt.on_row = [&](const EvalRow&) { progress.update(++done); };
    const EvalResult r = evaluate(scene, a.rays, opt);
    progress.finish();
    return to_json(r, true);
}

json run_design(const ReportArgs& a, const Scene& scene, const Common& common) {
    DesignOptions opt;
    opt.rays = a.rays;
    opt.seed = a.rays.seed;
    opt.costs_file = a.costs;
    // Three builds per family: the designed hierarchy, its yardstick and Embree.
    const std::size_t builds = 3 * design_families().size();
    Progress progress("report: design", builds, common.quiet || common.json);
    std::size_t done = 0;
    opt.on_step = [&](const std::string& step) {
        if (step.rfind("build ", 0) == 0) progress.update(std::min(done++, builds));
    };
    const DesignResult r = design(scene, opt);
    progress.finish();
    return to_json(r);
}

/// An `rtcost eval --json` document of `scene`'s primitives (InputError otherwise).
json read_eval(const std::string& path, const Scene& scene) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) throw InputError(path, 0, "is a directory, not a file");
    std::ifstream in(path);
    if (!in) throw InputError(path, 0, "no such file");
    json j = json::parse(in, nullptr, false);
    if (j.is_discarded() || !j.is_object() || !j.contains("results") || !j["results"].is_array())
        throw InputError(path, 0, "not an `rtcost eval --json` document");
    for (const json& r : j["results"])
        if (!r.is_object() || !r.contains("hierarchy") || !r["hierarchy"].is_string())
            throw InputError(path, 0, "not an `rtcost eval --json` document: a result without its hierarchy");
    // Heat maps and the render are made on SCENE: an evaluation of another scene would be
    // reported as this one's.
    if (j.contains("primitives") && j["primitives"].is_number_unsigned() &&
        j["primitives"].get<std::uint64_t>() != scene.size())
        throw InputError(path, 0,
                         fmt::format("an evaluation of {} ({} primitives), not of {} ({} primitives)",
                                     j.value("scene", std::string("another scene")), j["primitives"].get<std::uint64_t>(),
                                     scene.name, scene.size()));
    // The same count of primitives is not the same scene (tetra at another level, an edited
    // file): the fingerprint tells, where the document has one (eval's since 2026-12-08).
    const std::string mine = fingerprint_text(scene.fingerprint());
    if (j.contains("scene_fingerprint") && j["scene_fingerprint"].is_string() && j["scene_fingerprint"] != mine)
        throw InputError(path, 0,
                         fmt::format("an evaluation of {}, not of {}: the scenes differ (fingerprints {} and {})",
                                     j.value("scene", std::string("another scene")), scene.name,
                                     j["scene_fingerprint"].get<std::string>(), mine));
    return j;
}

int cmd_report(const ReportArgs& a, const Common& common) {
    check_output_path(a.out, "--out", common, {a.scene, a.costs, a.from_eval, a.rays.name});
    Scene scene = load(a.scene, common);
    const UnitCosts costs = a.costs.empty() ? UnitCosts{} : UnitCosts::read(a.costs);
    const HeatKind kind = parse_heat_kind(a.heatmap);
    ReportHeatOptions heat;
    heat.kind = kind;
    heat.tree = a.rays.name == "spd";
    heat.costs = costs;
    heat.scale_max = a.scale_max;
    heat.log = a.log;
    heat.threads = a.threads;
    if (!a.heatmap_size.empty()) parse_size(a.heatmap_size, "--heatmap-size", heat.width, heat.height);
    else if (!a.rays.size.empty()) parse_size(a.rays.size, "--size", heat.width, heat.height);

    ReportInput in;
    in.meta = report_meta();
    in.eval = a.from_eval.empty() ? run_eval(a, scene, costs, common) : read_eval(a.from_eval, scene);
    std::vector<std::string> labels;
    for (const json& r : in.eval["results"]) labels.push_back(r.value("hierarchy", ""));
    {
        Progress progress("report: heat maps", labels.size(), common.quiet || common.json);
        std::size_t done = 0;
        heat.on_step = [&](const std::string&) { progress.update(done++); };
        add_heatmaps(in, scene, labels, heat);
    }
    if (!a.no_design) in.design = run_design(a, scene, common);
    add_render(in, scene, heat.width, heat.height, a.threads);
    const std::string html = report_html(in);
    write_file_atomic(a.out, html);
    if (common.json) {
        std::cout << report_json(in).dump(2) << "\n";
        return 0;
    }
    fmt::print("report     {}: {} hierarchies, {} heat maps ({}), {}{}\n", scene.name, labels.size(), in.heatmaps.size(),
               a.heatmap, in.eval.value("distribution", "?"),
               in.design.is_object() ? fmt::format(", {} designed families", in.design["results"].size()) : "");
    fmt::print("written    {} ({})\n", a.out, human_bytes(html.size()));
    return 0;
}

Subcommand setup_report(CLI::App& parent, Common& common) {
    auto a = std::make_shared<ReportArgs>();
    auto* cmd = parent.add_subcommand("report", "evaluate hierarchies and write one self-contained HTML page: the "
                                                "table, plots of predicted against measured cost, heat maps");
    cmd->add_option("SCENE", a->scene, "scene file or builtin:NAME[:level]")->required();
    cmd->add_option("-H,--hierarchy", a->hierarchies, "comma-separated hierarchies (name[:key=value...]), or all: those that make sense at the scene's size (the header names what it left out)")->capture_default_str();
    add_ray_args(cmd, a->rays);
    cmd->add_option("--estimator", a->estimator, "the model's estimator: geometric, sampled or segments")
        ->check(CLI::IsMember({"geometric", "sampled", "segments"}))
        ->capture_default_str();
    cmd->add_option("--costs", a->costs, "unit costs file (from rtcost calibrate)");
    cmd->add_option("--from-eval", a->from_eval, "take the evaluation from this `rtcost eval --json --by-depth` file "
                                                 "instead of running it");
    cmd->add_option("--heatmap", a->heatmap, "what the heat maps show: box, plane, hop, classify, prim, steps, ops, time, predicted (the model's operations per pixel, each beside the measured map)")
        ->capture_default_str();
    cmd->add_option("--heatmap-size", a->heatmap_size, "heat maps' size WxH (default: --size, else 256x256)");
    cmd->add_option("--scale-max", a->scale_max, "top of the heat maps' colour scale (default: the largest value)")
        ->check(positive_number());
    cmd->add_flag("--log-scale", a->log, "heat map colours by log(1 + value), for costs that span decades");
    cmd->add_option("-j,--threads", a->threads, "threads (0: all cores)")->check(CLI::Range(0, 1024));
    cmd->add_flag("--no-design", a->no_design, "leave out the design section (each family's hierarchy designed for "
                                               "the rays against its yardstick, as `rtcost design` runs it)");
    cmd->add_option("-o,--out", a->out, "HTML file to write")->capture_default_str();
    add_common(cmd, common);
    cmd->footer(hierarchy_help());
    return {cmd, [a, &common] {
                if (a->from_eval.empty()) return cmd_report(*a, common);
                // A hand-made or edited evaluation whose fields have other types than eval writes.
                try {
                    return cmd_report(*a, common);
                } catch (const nlohmann::json::exception& e) {
                    throw InputError(a->from_eval, 0, std::string("not an `rtcost eval --json` document: ") + e.what());
                }
            }};
}

const CommandRegistration reg{65, setup_report};

}  // namespace
}  // namespace rtcost::cli
