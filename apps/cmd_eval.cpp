// `rtcost eval`: predict each hierarchy's cost with the model, measure it, compare and rank.
#include <algorithm>
#include <iostream>
#include <map>

#include "cli.hpp"
#include "rtcost/evaluate.hpp"

namespace rtcost::cli {
namespace {

struct EvalArgs {
    std::string scene;
    std::string hierarchies = "all";
    std::vector<std::string> set;
    RaySpec rays;
    std::string query = "closest";
    std::string shadow = "any";
    int threads = 0;
    std::string estimator = "segments";
    std::string preset = "exact";
    std::size_t sample = 0;
    std::string sample_file;
    std::string costs;
    bool by_depth = false;
    int repeat = 0;
    int timing_threads = 1;
    bool interleave = false;
};

/// "both" (sampled, geometric), "all", or a comma-separated list; the first is the headline.
std::vector<Estimator> parse_estimators(const std::string& list) {
    if (list == "both") return {Estimator::Sampled, Estimator::Geometric};
    if (list == "all") return {Estimator::Segments, Estimator::Sampled, Estimator::Geometric};
    std::vector<Estimator> out;
    std::size_t start = 0;
    while (start <= list.size()) {
        std::size_t comma = std::min(list.find(',', start), list.size());
        const std::string e = list.substr(start, comma - start);
        start = comma + 1;
        if (e == "geometric") out.push_back(Estimator::Geometric);
        else if (e == "sampled") out.push_back(Estimator::Sampled);
        else if (e == "segments") out.push_back(Estimator::Segments);
        else if (e == "both" || e == "all")
            throw InputError("--estimator", 0, "'" + e + "' stands alone, not in a list ('" + list + "')");
        else throw InputError("--estimator", 0, "'" + e + "': geometric, sampled, segments, a list of them, both or all");
    }
    return out;
}

int cmd_eval(EvalArgs& a, const Common& common) {
    Scene scene = load(a.scene, common, a.rays.view);
    EvalOptions opt;
    opt.costs = a.costs.empty() ? UnitCosts{} : UnitCosts::read(a.costs);
    opt.hierarchies = parse_hierarchy_list(a.hierarchies, scene.size());
    opt.left_out = left_out_of_all(a.hierarchies, scene.size());
    if (!a.set.empty()) {
        if (opt.hierarchies.size() > 1)
            throw InputError("--set", 0,
                             "parameters apply to one hierarchy: name a single one with --hierarchy, or give each "
                             "its own as -H name:key=value,...");
        for (const auto& s : a.set) opt.hierarchies[0].params.push_back(s);
    }
    opt.estimators = parse_estimators(a.estimator);
    opt.presets = a.preset == "both" ? std::vector<Preset>{Preset::Exact, Preset::Paper}
                                     : std::vector<Preset>{a.preset == "paper" ? Preset::Paper : Preset::Exact};
    opt.query = parse_query(a.query);
    opt.occlusion = parse_query(a.shadow);
    // With a sample file, --sample is only the sampled estimator's training rays: without that
    // estimator it would be ignored.
    if (a.sample > 0 && !a.sample_file.empty() &&
        std::find(opt.estimators.begin(), opt.estimators.end(), Estimator::Sampled) == opt.estimators.end())
        throw InputError("--sample", 0,
                         "the segments estimator's sample is --sample-file's, and no other estimator asked for takes "
                         "--sample (the sampled one's training rays)");
    if (a.sample > 0) opt.sample = opt.segments = a.sample;
    opt.sample_file = a.sample_file;
    opt.sample_seed = a.rays.seed;
    opt.threads = a.threads;
    opt.timing_threads = a.timing_threads;
    opt.repeat = a.repeat;
    opt.interleave_timing = a.interleave;
    // Each step of each hierarchy is named on a terminal while it runs (trace passes with the
    // time left), and each row is printed as it finishes, so an interrupted run keeps what it
    // measured.
    Progress progress("eval", 0, common.quiet || common.json);
    opt.on_step = [&](const std::string& step) { progress.note(step); };
    // A new bar whenever the step changes: the runner need not report 0 before its first rays.
    std::string shown_step;
    opt.on_progress = [&](const std::string& step, std::size_t done, std::size_t total) {
        if (step != shown_step || done == 0) {
            progress.restart(step, total);
            shown_step = step;
        }
        progress.update(done);
    };
    // The scene line goes out with the first row, not before: a run that stops on bad input
    // (a sample file of another scene, say) prints its error and nothing on stdout.
    bool first = true;
    auto scene_line = [&] {
        if (first) fmt::print("scene {} ({} primitives: {})\n", scene.name, scene.size(), kind_summary(scene));
    };
    opt.on_row = [&](const EvalRow& row) {
        progress.finish();
        shown_step.clear();
        if (common.json) return;
        scene_line();
        if (first) std::cout << eval_columns();
        first = false;
        std::cout << eval_row(row) << std::flush;
    };
    const EvalResult r = evaluate(scene, a.rays, opt);
    progress.finish();
    if (common.json) {
        std::cout << to_json(r, a.by_depth).dump(2) << "\n";
        return 0;
    }
    scene_line();
    std::cout << "\n" << eval_header(r) << eval_summary(r, a.by_depth);
    return 0;
}


Subcommand setup_eval(CLI::App& parent, Common& common) {
    auto a = std::make_shared<EvalArgs>();
    auto* eval = parent.add_subcommand("eval", "predict each hierarchy's cost with the model and measure it");
    eval->add_option("SCENE", a->scene, "scene file or builtin:NAME[:level]")->required();
    eval->add_option("-H,--hierarchy", a->hierarchies, "comma-separated hierarchies (name[:key=value...]), or all: those that make sense at the scene's size (the header names what it left out)")->capture_default_str();
    eval->add_option("--set", a->set, "parameter key=value for a single hierarchy (repeatable)");
    add_ray_args(eval, a->rays);
    eval->add_option("--query", a->query, "closest, any, or all (no early termination)")
        ->check(CLI::IsMember({"closest", "any", "all"}))
        ->capture_default_str();
    eval->add_option("--shadow", a->shadow, "query for shadow and ambient-occlusion rays: any or closest")
        ->check(CLI::IsMember({"closest", "any"}))
        ->capture_default_str();
    eval->add_option("--estimator", a->estimator,
                     "geometric (none of your rays: surface areas, and with early termination the visibility of the scene file's camera, lights and materials), sampled (a probe of training rays with real primitive "
                     "tests), segments (a ray sample's ended segments: no primitive tests), a comma-separated list, "
                     "both (sampled,geometric) or all; the first is the headline")
        ->capture_default_str();
    eval->add_option("--preset", a->preset, "exact (every operation performed), paper (the seed's formulas), or both")
        ->check(CLI::IsMember({"exact", "paper", "both"}))
        ->capture_default_str();
    eval->add_option("--sample", a->sample,
                     "rays in the sample: training rays for sampled (default 20000), the drawn sample for segments "
                     "(default 2% of the rays, at most 4096)")
        ->check(whole_number(1, kMaxRays));
    eval->add_option("--sample-file", a->sample_file, "the segments estimator's sample, from rtcost sample");
    eval->add_option("--costs", a->costs, "unit costs file (JSON, from rtcost calibrate)");
    eval->add_flag("--by-depth", a->by_depth, "predicted and measured visits per depth");
    eval->add_option("--repeat", a->repeat,
                     "timed passes over the test rays (default: as many as take 0.2 s); the median is reported")
        ->check(CLI::Range(0, 10000));
    eval->add_flag("--interleave", a->interleave,
                   "time the hierarchies in rounds of one pass each, every round in a new order, once all are "
                   "built (all kept in memory), so that the machine's changing load weighs on each alike");
    eval->add_option("--timing-threads", a->timing_threads, "threads of the timed passes (ns/ray is CPU time per ray)")
        ->check(CLI::Range(1, 1024))
        ->capture_default_str();
    eval->add_option("-j,--threads", a->threads, "threads of the counting passes (0: all cores)")
        ->check(CLI::Range(0, 1024));
    add_common(eval, common);
    eval->footer(hierarchy_footer());
    return {eval, [a, &common] { return cmd_eval(*a, common); }};
}

const CommandRegistration reg{40, setup_eval};

}  // namespace
}  // namespace rtcost::cli
