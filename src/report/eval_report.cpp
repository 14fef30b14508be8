// The evaluation's JSON document and text tables (what `rtcost eval` prints).
#include <fmt/format.h>

#include "rtcost/evaluate.hpp"
#include "rtcost/report.hpp"

namespace rtcost {
namespace {
using nlohmann::json;

json cost_json(const CostVector& c, double scalar) {
    json by_kind = json::object();
    for (int k = 0; k < kPrimKinds; ++k) by_kind[std::string(prim_kind_name(static_cast<PrimKind>(k)))] = c.prim[k];
    return {{"cost", scalar},         {"box", c.box},   {"plane", c.plane},   {"hop", c.hop},
            {"classify", c.classify}, {"prim", c.prim_tests()}, {"prim_by_kind", by_kind},
            {"N_TS", c.steps},        {"N_ETS", c.leaves}, {"N_EETS", c.empty_leaves}};
}

double relative(double predicted, double measured) { return measured > 0 ? (predicted - measured) / measured : 0.0; }

}  // namespace

nlohmann::json to_json(const EvalResult& r, bool by_depth) {
    json results = json::array();
    for (const EvalRow& row : r.rows) {
        json j = {{"hierarchy", row.name},
                  {"build", to_json(row.structure)},
                  {"measured", cost_json(row.measured, row.measured_scalar)},
                  {"mrays_per_s", row.mrays_per_s},
                  {"rank_measured", row.rank_measured},
                  {"time", {{"measured_ns_per_ray", row.ns_per_ray}, {"threads", row.threads}}}};
        const Prediction* head = row.headline();
        if (r.calibrated && head) j["time"]["predicted_ns_per_ray"] = head->scalar;
        if (head) {
            j["predicted"] = cost_json(head->cost, head->scalar);
            j["error"] = row.error;
            j["rank_predicted"] = row.rank_predicted;
            j["seconds_predicting"] = head->seconds;
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
            {"rays", r.test_rays},
            {"distribution", r.distribution},
            {"query", query_name(r.query)},
            {"estimator", estimator_name(r.estimators.front())},
            {"preset", preset_name(r.presets.front())},
            {"training_rays", r.training_rays},
            {"sample_rays", r.sample_rays},
            {"sample_seconds", r.sample_seconds},
            {"split", r.split},
            {"unit_costs", r.calibrated ? "ns" : "operations"},
            {"results", results}};
}

std::string eval_table(const EvalResult& r, bool by_depth) {
    std::string out;
    auto print = [&out]<class... T>(fmt::format_string<T...> f, T&&... args) {
        out += fmt::format(f, std::forward<T>(args)...);
    };
    const Estimator est = r.estimators.front();
    print("scene {} ({} primitives), {} test rays ({}), {} query\n", r.scene, r.primitives, r.test_rays,
          r.distribution, query_name(r.query));
    print("model: {} estimator{}, {} preset, costs in {}\n", estimator_name(est),
          est == Estimator::Sampled    ? fmt::format(" ({} training rays)", r.training_rays)
          : est == Estimator::Segments ? fmt::format(" ({} sample rays, {:.2f} s to draw)", r.sample_rays, r.sample_seconds)
                                       : std::string(),
          preset_name(r.presets.front()), r.calibrated ? "ns" : "operations");
    print("{:<12} {:>9} {:>9} {:>10} {:>11} {:>11} {:>8} {:>9} {:>5} {:>5}\n", "hierarchy", "build s", "nodes",
          "bytes", "predicted", "measured", "error", "Mrays/s", "rk-p", "rk-m");
    for (const EvalRow& row : r.rows) {
        const Prediction* head = row.headline();
        print("{:<12} {:>9.4f} {:>9} {:>10} {:>11} {:>11.2f} {:>8} {:>9.3f} {:>5} {:>5}\n", row.name,
              row.structure.seconds, row.structure.interior + row.structure.leaves, human_bytes(row.structure.bytes),
              head ? fmt::format("{:.2f}", head->scalar) : "-", row.measured_scalar,
              head ? fmt::format("{:+.1f}%", 100 * row.error) : "-", row.mrays_per_s,
              head ? std::to_string(row.rank_predicted) : "-", row.rank_measured);
    }
    if (!r.rows.empty() && r.rows[0].predictions.size() > 1) {
        print("\nevery prediction (cost per ray, error):\n{:<12}", "hierarchy");
        for (const Prediction& p : r.rows[0].predictions) print(" {:>22}", p.estimator + "/" + p.preset);
        print("\n");
        for (const EvalRow& row : r.rows) {
            if (!row.modelled) continue;
            print("{:<12}", row.name);
            for (const Prediction& p : row.predictions)
                print(" {:>22}", fmt::format("{:.2f} ({:+.1f}%)", p.scalar, 100 * relative(p.scalar, row.measured_scalar)));
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
            print("{:<12} predicted {:10.1f} ns  measured {:10.1f} ns  {:+.1f}%\n", row.name, p, row.ns_per_ray,
                  100 * relative(p, row.ns_per_ray));
        }
    }
    print("\nby kind (predicted / measured per ray):\n");
    for (const EvalRow& row : r.rows) {
        if (!row.modelled) continue;
        const CostVector &p = row.headline()->cost, &m = row.measured;
        print("{:<12} box {:.2f}/{:.2f}  plane {:.2f}/{:.2f}  hop {:.2f}/{:.2f}  classify {:.2f}/{:.2f}  prim "
              "{:.2f}/{:.2f}  N_TS {:.2f}/{:.2f}\n",
              row.name, p.box, m.box, p.plane, m.plane, p.hop, m.hop, p.classify, m.classify, p.prim_tests(),
              m.prim_tests(), p.steps, m.steps);
    }
    if (by_depth) {
        print("\nvisits per depth (predicted / measured per ray):\n");
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

}  // namespace rtcost
