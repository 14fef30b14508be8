// `rtcost eval`: predict each hierarchy's cost with the model, measure it, compare and rank.
#include <iostream>
#include <map>

#include "cli.hpp"
#include "rtcost/model.hpp"

namespace rtcost::cli {
namespace {
using nlohmann::json;

struct EvalArgs {
    std::string scene;
    std::string hierarchies = "all";
    std::vector<std::string> set;
    RaySpec rays;
    std::string query = "closest";
    std::string shadow = "any";
    int threads = 0;
    std::string estimator = "geometric";
    std::string preset = "exact";
    std::size_t sample = 20000;
    std::string costs;
    bool by_depth = false;
};

/// Weighted mean of per-kind predictions (weights: the kinds' shares of the rays).
Prediction mix(const std::vector<std::pair<double, Prediction>>& parts, const UnitCosts& costs) {
    if (parts.size() == 1) return parts[0].second;
    Prediction out = parts.at(0).second;
    out.cost = CostVector{};
    out.visits_by_depth.clear();
    for (const auto& [w, p] : parts) {
        CostVector& c = out.cost;
        c.box += w * p.cost.box; c.plane += w * p.cost.plane; c.hop += w * p.cost.hop;
        c.classify += w * p.cost.classify;
        for (int k = 0; k < kPrimKinds; ++k) c.prim[k] += w * p.cost.prim[k];
        c.steps += w * p.cost.steps; c.leaves += w * p.cost.leaves; c.empty_leaves += w * p.cost.empty_leaves;
        if (out.visits_by_depth.size() < p.visits_by_depth.size()) out.visits_by_depth.resize(p.visits_by_depth.size());
        for (std::size_t d = 0; d < p.visits_by_depth.size(); ++d) out.visits_by_depth[d] += w * p.visits_by_depth[d];
    }
    out.scalar = costs.scalar(out.cost);
    return out;
}

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
    std::vector<Prediction> preds;  // every estimator x preset asked for; pred is the first
    CostVector meas;
    std::vector<double> meas_visits;
    double meas_scalar = 0, error = 0, mrays = 0;
    double ns_per_ray = 0;  // measured wall time per ray x threads
    int threads = 1;
    bool lazy = false;
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
    RaySet test = make_rays(scene, a.rays);
    const std::string described = test.described;
    // Estimators and presets to evaluate; the first of each is the headline prediction.
    std::vector<std::string> estimators = a.estimator == "both" ? std::vector<std::string>{"sampled", "geometric"}
                                                                : std::vector<std::string>{a.estimator};
    std::vector<std::string> presets =
        a.preset == "both" ? std::vector<std::string>{"exact", "paper"} : std::vector<std::string>{a.preset};
    const bool sampled = std::find(estimators.begin(), estimators.end(), "sampled") != estimators.end();
    RaySet train;
    if (sampled) {
        // A training sample disjoint from the test rays: a fresh draw for random distributions;
        // otherwise (camera rays, ray trees, files) a pseudo-random half of the rays, thinned to
        // --sample. Not every other ray: a ray tree's order (eye, a shadow ray per light,
        // reflection, ...) would put one light's shadow rays in training and another's in test.
        if (a.rays.name == "lines" || a.rays.name == "random") {
            RaySpec t = a.rays;
            t.seed = a.rays.seed + 7919;
            t.count = a.sample;
            train = make_rays(scene, t);
        } else {
            RaySet keep;
            const std::size_t half = test.rays.size() / 2;
            const double keep_share = half > a.sample ? static_cast<double>(a.sample) / half : 1.0;
            for (std::size_t i = 0; i < test.rays.size(); ++i) {
                // splitmix64's finaliser of the index: one bit picks the side, the rest thin.
                std::uint64_t z = (i + 1) * 0x9E3779B97F4A7C15ull;
                z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
                z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
                z ^= z >> 31;
                const bool to_train = z & 1;
                if (to_train && static_cast<double>(z >> 11) * 0x1.0p-53 >= keep_share) continue;
                RaySet& to = to_train ? train : keep;
                to.rays.push_back(test.rays[i]);
                to.kinds.push_back(test.kinds[i]);
            }
            keep.described = test.described;
            test = std::move(keep);
        }
    }
    if (sampled && (train.rays.empty() || test.rays.empty()))
        throw InputError("--rays", 0, fmt::format("the sampled estimator needs training and test rays; {} gives {} and {} "
                                                  "(use more rays)", described, train.rays.size(), test.rays.size()));
    ModelOptions mo;
    mo.preset = a.preset == "paper" ? Preset::Paper : Preset::Exact;
    mo.query = parse_query(a.query);
    const Query occlusion = parse_query(a.shadow);
    // The model is evaluated per ray kind (each kind has its own query and, when sampled, its
    // own probabilities) and mixed by the kinds' shares of the test rays.
    auto by_kind = [](const RaySet& s) {
        std::array<std::vector<Ray>, kRayKinds> out;
        for (std::size_t i = 0; i < s.rays.size(); ++i) out[static_cast<int>(s.kinds[i])].push_back(s.rays[i]);
        return out;
    };
    const auto test_kinds = by_kind(test), train_kinds = by_kind(train);
    auto query_of = [&](int k) {
        RayKind kind = static_cast<RayKind>(k);
        return kind == RayKind::Shadow || kind == RayKind::AO ? occlusion : mo.query;
    };

    std::vector<EvalRow> rows;
    Progress progress("eval", names.size(), common.quiet || common.json);
    for (const auto& name : names) {
        auto h = build(scene, BuildArgs{a.scene, name, a.set}, common);
        EvalRow row;
        row.name = name;
        TraceOptions opt;
        opt.query = mo.query;
        // With calibrated (single-thread) unit costs, time on one thread unless told otherwise.
        opt.threads = a.threads > 0 ? a.threads : costs.calibrated ? 1 : 0;
        // Counted first, so a lazily built hierarchy (rc5d) is complete when timed.
        opt.count = true;
        TraceResult counted = trace_ray_set(*h, test, opt, occlusion);
        opt.count = false;
        TraceResult timed = trace_ray_set(*h, test, opt, occlusion);
        // Structure and model tree after tracing: a lazily built hierarchy (rc5d) exists only
        // where rays went, so the training rays go through it too.
        if (sampled && h->lazy())
            for (int k = 0; k < kRayKinds; ++k) trace_rays(*h, train_kinds[k]);
        row.s = h->structure();
        row.lazy = h->lazy();
        row.modelled = h->modelled();
        // The sampled estimator's probe indexes a materialised tree; the geometric one reads the
        // hierarchy where it lies.
        const ModelTree tree = row.modelled && sampled ? h->model_tree() : ModelTree{};
        if (row.modelled) {
            for (const std::string& est : estimators) {
                for (const std::string& preset : presets) {
                    std::vector<std::pair<double, Prediction>> parts;
                    // The geometric estimate depends on the query, not on the rays: one per query.
                    std::map<Query, Prediction> geometric;
                    for (int k = 0; k < kRayKinds; ++k) {
                        if (test_kinds[k].empty()) continue;
                        ModelOptions o = mo;
                        o.preset = preset == "paper" ? Preset::Paper : Preset::Exact;
                        o.query = query_of(k);
                        double share = static_cast<double>(test_kinds[k].size()) / test.rays.size();
                        if (est == "sampled" && train_kinds[k].empty())
                            throw InputError("--sample", 0, "no training rays of kind " +
                                                                std::string(ray_kind_name(static_cast<RayKind>(k))));
                        if (est == "sampled") {
                            parts.emplace_back(share, predict_sampled(tree, scene, train_kinds[k], o, costs));
                        } else {
                            auto it = geometric.find(o.query);
                            if (it == geometric.end())
                                it = geometric.emplace(o.query, predict_geometric(*h, o, costs)).first;
                            parts.emplace_back(share, it->second);
                        }
                    }
                    row.preds.push_back(mix(parts, costs));
                }
            }
            row.pred = row.preds.front();
        }
        row.meas = measured_cost(counted.counters);
        row.meas_scalar = costs.scalar(row.meas);
        row.error = row.modelled && row.meas_scalar > 0 ? (row.pred.scalar - row.meas_scalar) / row.meas_scalar : 0;
        row.mrays = timed.seconds > 0 ? test.rays.size() / timed.seconds / 1e6 : 0;
        row.ns_per_ray = test.rays.empty() ? 0 : timed.seconds * 1e9 * timed.threads / test.rays.size();
        row.threads = timed.threads;
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
                      {"mrays_per_s", r.mrays}, {"rank_measured", r.rank_meas},
                      {"time", {{"measured_ns_per_ray", r.ns_per_ray}, {"threads", r.threads}}}};
            if (costs.calibrated && r.modelled) j["time"]["predicted_ns_per_ray"] = r.pred.scalar;
            if (r.modelled) {
                j["predicted"] = cost_json(r.pred.cost, r.pred.scalar);
                j["error"] = r.error;
                j["rank_predicted"] = r.rank_pred;
                j["note"] = r.pred.note + (r.lazy ? "; lazily built: modelled over the beams built by the rays so far" : "");
                if (r.preds.size() > 1) {
                    json all = json::array();
                    for (const Prediction& p : r.preds) {
                        json e = cost_json(p.cost, p.scalar);
                        e["estimator"] = p.estimator;
                        e["preset"] = p.preset;
                        e["error"] = r.meas_scalar > 0 ? (p.scalar - r.meas_scalar) / r.meas_scalar : 0.0;
                        all.push_back(e);
                    }
                    j["predictions"] = all;
                }
            } else {
                j["predicted"] = nullptr;
            }
            if (a.by_depth) {
                j["visits_by_depth"] = {{"predicted", r.modelled ? json(r.pred.visits_by_depth) : json(nullptr)},
                                        {"measured", r.meas_visits}};
            }
            results.push_back(j);
        }
        json out = {{"scene", scene.name},       {"primitives", scene.size()}, {"rays", test.rays.size()},
                    {"distribution", described}, {"query", a.query},     {"estimator", estimators.front()},
                    {"preset", presets.front()},  {"training_rays", train.rays.size()},
                    {"unit_costs", costs.calibrated ? "ns" : "operations"}, {"results", results}};
        std::cout << out.dump(2) << "\n";
        return 0;
    }
    fmt::print("scene {} ({} primitives), {} test rays ({}), {} query\n", scene.name, scene.size(), test.rays.size(),
               described, a.query);
    fmt::print("model: {} estimator{}, {} preset, costs in {}\n", estimators.front(),
               estimators.front() == "sampled" ? fmt::format(" ({} training rays)", train.rays.size()) : std::string(),
               presets.front(),
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
    if (!rows.empty() && rows[0].preds.size() > 1) {
        fmt::print("\nevery prediction (cost per ray, error):\n{:<12}", "hierarchy");
        for (const Prediction& p : rows[0].preds) fmt::print(" {:>22}", p.estimator + "/" + p.preset);
        fmt::print("\n");
        for (const auto& r : rows) {
            if (!r.modelled) continue;
            fmt::print("{:<12}", r.name);
            for (const Prediction& p : r.preds)
                fmt::print(" {:>22}", fmt::format("{:.2f} ({:+.1f}%)", p.scalar,
                                                  r.meas_scalar > 0 ? 100 * (p.scalar - r.meas_scalar) / r.meas_scalar : 0.0));
            fmt::print("\n");
        }
    }
    if (costs.calibrated) {
        fmt::print("\ntime per ray (calibrated unit costs; measured on {} thread{}):\n", rows.empty() ? 1 : rows[0].threads,
                   !rows.empty() && rows[0].threads == 1 ? "" : "s x threads");
        for (const auto& r : rows) {
            if (!r.modelled) continue;
            fmt::print("{:<12} predicted {:10.1f} ns  measured {:10.1f} ns  {:+.1f}%\n", r.name, r.pred.scalar,
                       r.ns_per_ray, r.ns_per_ray > 0 ? 100 * (r.pred.scalar - r.ns_per_ray) / r.ns_per_ray : 0.0);
        }
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


Subcommand setup_eval(CLI::App& parent, Common& common) {
    auto a = std::make_shared<EvalArgs>();
    auto* eval = parent.add_subcommand("eval", "predict each hierarchy's cost with the model and measure it");
    eval->add_option("SCENE", a->scene, "scene file or builtin:NAME[:level]")->required();
    eval->add_option("-H,--hierarchy", a->hierarchies, "comma-separated hierarchies, or all")->capture_default_str();
    eval->add_option("--set", a->set, "parameter key=value for a single hierarchy (repeatable)");
    add_ray_args(eval, a->rays);
    eval->add_option("--query", a->query, "closest, any, or all (no early termination)")
        ->check(CLI::IsMember({"closest", "any", "all"}))
        ->capture_default_str();
    eval->add_option("--shadow", a->shadow, "query for shadow and ambient-occlusion rays: any or closest")
        ->check(CLI::IsMember({"closest", "any"}))
        ->capture_default_str();
    eval->add_option("--estimator", a->estimator,
                     "geometric (surface areas, no rays traced), sampled (probabilities from training rays), or both")
        ->check(CLI::IsMember({"geometric", "sampled", "both"}))
        ->capture_default_str();
    eval->add_option("--preset", a->preset, "exact (every operation performed), paper (the seed's formulas), or both")
        ->check(CLI::IsMember({"exact", "paper", "both"}))
        ->capture_default_str();
    eval->add_option("--sample", a->sample, "training rays for the sampled estimator")->capture_default_str();
    eval->add_option("--costs", a->costs, "unit costs file (JSON, from rtcost calibrate)");
    eval->add_flag("--by-depth", a->by_depth, "predicted and measured visits per depth");
    eval->add_option("-j,--threads", a->threads, "threads (0: all cores)")->check(CLI::Range(0, 1024));
    add_common(eval, common);
    eval->footer(hierarchy_help());
    return {eval, [a, &common] { return cmd_eval(*a, common); }};
}

const CommandRegistration reg{40, setup_eval};

}  // namespace
}  // namespace rtcost::cli
