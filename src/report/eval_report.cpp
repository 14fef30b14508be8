// The evaluation's JSON document and text tables (what `rtcost eval` prints).
#include <fmt/format.h>

#include <algorithm>

#include "rtcost/evaluate.hpp"
#include "rtcost/rays.hpp"
#include "rtcost/report.hpp"

namespace rtcost {
namespace {
using nlohmann::json;

json cost_json(const CostVector& c, double scalar) {
    json by_kind = json::object();
    for (int k = 0; k < kPrimKinds; ++k) by_kind[std::string(prim_kind_name(static_cast<PrimKind>(k)))] = c.prim[k];
    return {{"cost", scalar},         {"box", c.box},   {"plane", c.plane},   {"hop", c.hop},
            {"classify", c.classify}, {"prim", c.prim_tests()}, {"prim_by_kind", by_kind},
            {"N_TS", c.steps},        {"N_ETS", c.leaves}, {"N_EETS", c.empty_leaves},
            {"polygon_edges", c.polygon_edges}};
}

double relative(double predicted, double measured) { return measured > 0 ? (predicted - measured) / measured : 0.0; }

/// The query each ray kind of the test rays is traced with (the result names kinds by
/// ray_kind_name; a name of no kind is traced with the main query).
std::string_view query_of(const EvalResult& r, const std::string& kind) {
    for (int k = 0; k < kRayKinds; ++k)
        if (ray_kind_name(static_cast<RayKind>(k)) == kind)
            return is_occlusion(static_cast<RayKind>(k)) ? query_name(r.occlusion) : query_name(r.query);
    return query_name(r.query);
}

json queries_json(const EvalResult& r) {
    json q = json::object();
    for (const auto& [kind, n] : r.rays_by_kind) q[kind] = query_of(r, kind);
    return q;
}

/// Whether the headline prediction stands on rays the scene makes rather than the user's: the
/// geometric estimator with early termination (docs/model-accuracy.md).
bool from_scene_rays(const EvalResult& r) { return r.estimators.front() == Estimator::Geometric && r.query != Query::All; }

}  // namespace

nlohmann::json to_json(const EvalResult& r, bool by_depth) {
    json results = json::array();
    for (const EvalRow& row : r.rows) {
        json j = {{"hierarchy", row.name},
                  {"build", to_json(row.structure)},
                  {"measured", cost_json(row.measured, row.measured_scalar)},
                  {"mrays_per_s", row.mrays_per_s},
                  {"rank_measured", row.counted ? json(row.rank_measured) : json(nullptr)},
                  {"rank_time", row.rank_time},
                  {"measured_rays", row.measured_rays},
                  {"time", {{"measured_ns_per_ray", row.ns_per_ray}, {"threads", row.threads},
                            {"repeats", row.repeats}, {"spread", row.time_spread}}}};
        if (!row.counted) j["measured"] = nullptr;
        const Prediction* head = row.headline();
        if (r.calibrated && head) j["time"]["predicted_ns_per_ray"] = head->scalar;
        if (head) {
            j["predicted"] = cost_json(head->cost, head->scalar);
            j["error"] = row.error;
            j["rank_predicted"] = row.rank_predicted;
            j["seconds_predicting"] = head->seconds;
            if (row.sample_trace_seconds > 0) j["sample_trace_seconds"] = row.sample_trace_seconds;
            j["note"] = head->note + (row.lazy ? "; lazily built: modelled over the beams built by the rays so far" : "");
            if (row.predictions.size() > 1) {
                json all = json::array();
                for (const Prediction& p : row.predictions) {
                    json e = cost_json(p.cost, p.scalar);
                    e["estimator"] = p.estimator;
                    e["preset"] = p.preset;
                    e["error"] = relative(p.scalar, row.measured_scalar);
                    e["seconds"] = p.seconds;
                    all.push_back(e);
                }
                j["predictions"] = all;
            }
        } else {
            j["predicted"] = nullptr;
        }
        if (by_depth) {
            j["visits_by_depth"] = {{"predicted", head ? json(head->visits_by_depth) : json(nullptr)},
                                    {"measured", row.measured_visits}};
        }
        results.push_back(j);
    }
    return {{"scene", r.scene},
            {"primitives", r.primitives},
            {"scene_fingerprint", fingerprint_text(r.scene_fingerprint)},
            {"rays", r.test_rays},
            {"distribution", r.distribution},
            {"query", query_name(r.query)},
            {"queries", queries_json(r)},
            {"estimator", estimator_name(r.estimators.front())},
            {"preset", preset_name(r.presets.front())},
            {"training_rays", r.training_rays},
            {"sample_rays", r.sample_rays},
            {"distribution_rays", r.distribution_rays},
            {"sample_seconds", r.sample_seconds},
            {"sample_file", r.sample_file},
            {"visibility_rays", r.visibility_rays},
            {"visibility_seconds", r.visibility_seconds},
            {"split", r.split},
            {"unit_costs", r.calibrated ? "ns" : "operations"},
            {"left_out", r.left_out},
            {"results", results}};
}

std::string eval_columns() {
    return fmt::format("{:<14} {:>9} {:>9} {:>10} {:>11} {:>11} {:>8} {:>10} {:>7} {:>9}\n", "hierarchy", "build s",
                       "nodes", "bytes", "predicted", "counted", "error", "ns/ray", "spread", "Mrays/s");
}

namespace {
// The bounds that stopped a build, under its row: the numbers above are of a structure cut short.
std::string limit_lines(const StructureStats& s) {
    std::string out;
    for (const std::string& l : s.limits) out += fmt::format("  limit: {}\n", l);
    return out;
}
}  // namespace

std::string eval_row(const EvalRow& row) {
    const Prediction* head = row.headline();
    return fmt::format("{:<14} {:>9.4f} {:>9} {:>10} {:>11} {:>11} {:>8} {:>10.1f} {:>7} {:>9.3f}\n", row.name,
                       row.structure.seconds, row.structure.interior + row.structure.leaves,
                       human_bytes(row.structure.bytes), head ? fmt::format("{:.2f}", head->scalar) : "-",
                       row.counted ? fmt::format("{:.2f}", row.measured_scalar) : "-",
                       head && row.counted ? fmt::format("{:+.1f}%", 100 * row.error) : "-", row.ns_per_ray,
                       row.repeats > 1 ? fmt::format("{:.0f}%", 100 * row.time_spread) : std::string("-"),
                       row.mrays_per_s) +
           limit_lines(row.structure);
}

std::string eval_header(const EvalResult& r) {
    std::string kinds;
    for (const auto& [kind, n] : r.rays_by_kind)
        kinds += fmt::format("{}{} {} ({})", kinds.empty() ? "" : ", ", kind, query_of(r, kind), n);
    const Estimator est = r.estimators.front();
    std::string split = r.split == "none" ? "no rays held out"
                        : r.split == "sample"
                            ? fmt::format("a sample of {} rays ({}) left out of them", r.sample_rays,
                                          r.sample_file.empty() ? fmt::format("{:.2f} s to draw", r.sample_seconds)
                                                                : "read from " + r.sample_file)
                            : fmt::format("{} training rays ({}) left out of them", r.training_rays, r.split);
    if (r.split.find(" and ") != std::string::npos)
        split = fmt::format("a sample of {} rays and {} training rays left out of them", r.sample_rays, r.training_rays);
    std::string left_out;
    for (const std::string& name : r.left_out) left_out += (left_out.empty() ? "" : ", ") + name;
    if (!left_out.empty())
        left_out = fmt::format("left out of all at {} primitives (slow at this size; name them with -H to have them): {}\n",
                               r.primitives, left_out);
    return fmt::format("scene {} ({} primitives), {} test rays ({}); {}\nqueries: {}\nmodel: {} estimator, {} preset, "
                       "costs in {}{}{}\n{}",
                       r.scene, r.primitives, r.test_rays, r.distribution, split, kinds, estimator_name(est),
                       preset_name(r.presets.front()), r.calibrated ? "ns (calibrated)" : "operations",
                       est == Estimator::Geometric && r.visibility_rays > 0
                           ? fmt::format("; P from a visibility sample of the scene file alone (its camera, lights and "
                                         "materials; {} rays, {:.2f} s)",
                                         r.visibility_rays, r.visibility_seconds)
                       : est == Estimator::Geometric
                           ? "; P of a hit in a region of several primitives by the Poisson form 1 - exp(-sum p_i)"
                           : "",
                       from_scene_rays(r) ? "; it errs where your rays are not what the scene's camera and lights make "
                                  "(docs/model-accuracy.md)"
                                : "",
                       left_out);
}

std::string eval_summary(const EvalResult& r, bool by_depth) {
    std::string out;
    auto print = [&out]<class... T>(fmt::format_string<T...> f, T&&... args) {
        out += fmt::format(f, std::forward<T>(args)...);
    };
    // Orders: the cheapest first; rows a column does not rank are left out of it.
    auto order = [&](int EvalRow::*rank) {
        std::vector<const EvalRow*> v;
        for (const EvalRow& row : r.rows)
            if (row.*rank > 0) v.push_back(&row);
        std::sort(v.begin(), v.end(), [&](auto* a, auto* b) { return a->*rank < b->*rank; });
        std::string s;
        for (const EvalRow* row : v) s += (s.empty() ? "" : " < ") + row->name;
        return s.empty() ? std::string("-") : s;
    };
    print("\nranked, cheapest first:\n  {:<19} {}\n  {:<19} {}\n  {:<19} {}\n",
          r.calibrated ? "by predicted time" : "by predicted ops", order(&EvalRow::rank_predicted),
          "by counted ops", order(&EvalRow::rank_measured), "by measured time", order(&EvalRow::rank_time));
    for (const EvalRow& row : r.rows) {
        if (row.measured_rays && row.measured_rays < r.test_rays)
            print("{} measured on {} of the {} test rays (every {}th), to bound its time\n", row.name, row.measured_rays,
                  r.test_rays, (r.test_rays + row.measured_rays - 1) / row.measured_rays);
        if (!row.counted) print("{} is timed only: its operations are not counted and it is not modelled\n", row.name);
    }
    if (!r.rows.empty() && r.rows[0].predictions.size() > 1) {
        print("\nevery prediction (cost per ray, error; seconds to predict):\n{:<14}", "hierarchy");
        for (const Prediction& p : r.rows[0].predictions) print(" {:>30}", p.estimator + "/" + p.preset);
        print("\n");
        for (const EvalRow& row : r.rows) {
            if (!row.modelled) continue;
            print("{:<14}", row.name);
            for (const Prediction& p : row.predictions)
                print(" {:>30}", fmt::format("{:.2f} ({:+.1f}%; {:.3f} s)", p.scalar,
                                             100 * relative(p.scalar, row.measured_scalar), p.seconds));
            print("\n");
        }
    }
    if (r.calibrated) {
        const int threads = r.rows.empty() ? 1 : r.rows[0].threads;
        print("\ntime per ray (calibrated unit costs; measured on {} thread{}):\n", threads,
              threads == 1 ? "" : "s x threads");
        for (const EvalRow& row : r.rows) {
            if (!row.modelled) continue;
            const double p = row.headline()->scalar;
            print("{:<14} predicted {:10.1f} ns  measured {:10.1f} ns  {:+.1f}%\n", row.name, p, row.ns_per_ray,
                  100 * relative(p, row.ns_per_ray));
        }
    }
    print("\nby kind (predicted / counted per ray):\n");
    for (const EvalRow& row : r.rows) {
        if (!row.modelled) continue;
        const CostVector &p = row.headline()->cost, &m = row.measured;
        print("{:<14} box {:.2f}/{:.2f}  plane {:.2f}/{:.2f}  hop {:.2f}/{:.2f}  classify {:.2f}/{:.2f}  prim "
              "{:.2f}/{:.2f}  N_TS {:.2f}/{:.2f}\n",
              row.name, p.box, m.box, p.plane, m.plane, p.hop, m.hop, p.classify, m.classify, p.prim_tests(),
              m.prim_tests(), p.steps, m.steps);
    }
    if (by_depth) {
        print("\nvisits per depth (predicted / counted per ray):\n");
        for (const EvalRow& row : r.rows) {
            if (!row.modelled) continue;
            print("{}\n", row.name);
            const auto& pv = row.headline()->visits_by_depth;
            const auto& mv = row.measured_visits;
            const std::size_t depth = std::max(pv.size(), mv.size());
            for (std::size_t d = 0; d < depth; ++d)
                print("  depth {:>3}  {:10.4f} {:10.4f}\n", d, d < pv.size() ? pv[d] : 0.0, d < mv.size() ? mv[d] : 0.0);
        }
    }
    return out;
}

std::string eval_table(const EvalResult& r, bool by_depth) {
    std::string out = eval_header(r) + eval_columns();
    for (const EvalRow& row : r.rows) out += eval_row(row);
    return out + eval_summary(r, by_depth);
}

}  // namespace rtcost
