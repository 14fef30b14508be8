// The report's plots as Vega-Lite specifications, built from the `eval --json --by-depth` document.
#include <algorithm>
#include <cmath>
#include <string>

#include "rtcost/html_report.hpp"

namespace rtcost {
namespace {
using nlohmann::json;

constexpr const char* kSchema = "https://vega.github.io/schema/vega-lite/v6.json";  // names the format; never fetched
constexpr const char* kKinds[] = {"box", "plane", "hop", "classify", "prim"};

json base(const std::string& title, json data) {
    return {{"$schema", kSchema},
            {"title", title},
            {"data", {{"values", std::move(data)}}},
            {"config", {{"font", "DejaVu Sans, sans-serif"}, {"view", {{"stroke", nullptr}}}}}};
}

bool has(const json& j, const char* key) { return j.contains(key) && !j[key].is_null(); }

// Operations per ray by kind, predicted beside measured, stacked into each hierarchy's total.
json cost_by_kind(const json& results) {
    json rows = json::array();
    for (const json& r : results) {
        for (const char* source : {"predicted", "measured"}) {
            if (!has(r, source)) continue;
            for (const char* kind : kKinds)
                rows.push_back({{"hierarchy", r["hierarchy"]}, {"source", source}, {"kind", kind},
                                {"value", r[source].value(kind, 0.0)}});
        }
    }
    json spec = base("Operations per ray by kind: predicted (light) beside measured (solid)", rows);
    spec["width"] = {{"step", 22}};
    spec["height"] = 260;
    spec["mark"] = {{"type", "bar"}, {"tooltip", true}};
    spec["encoding"] = {
        {"x", {{"field", "hierarchy"}, {"type", "nominal"}, {"title", nullptr}, {"sort", nullptr}}},
        {"xOffset", {{"field", "source"}, {"type", "nominal"}, {"sort", {"predicted", "measured"}}}},
        {"y", {{"field", "value"}, {"type", "quantitative"}, {"aggregate", "sum"}, {"title", "operations per ray"}}},
        {"color", {{"field", "kind"}, {"type", "nominal"}, {"sort", {"box", "plane", "hop", "classify", "prim"}}, {"title", "operation"}}},
        {"opacity",
         {{"field", "source"}, {"type", "nominal"}, {"title", nullptr},
          {"scale", {{"domain", {"predicted", "measured"}}, {"range", {0.45, 1.0}}}}}},
        {"order", {{"field", "kind"}, {"sort", "ascending"}}},
        {"tooltip", json::array({{{"field", "hierarchy"}}, {{"field", "source"}}, {{"field", "kind"}},
                                 {{"field", "value"}, {"format", ".3f"}}})}};
    return spec;
}

// Predicted against measured cost per ray, log-log, with the line where they are equal.
json scatter(const json& results, const std::string& units) {
    json points = json::array();
    double lo = INFINITY, hi = 0;
    for (const json& r : results) {
        if (!has(r, "predicted")) continue;
        double p = r["predicted"].value("cost", 0.0), m = r["measured"].value("cost", 0.0);
        if (!(p > 0) || !(m > 0)) continue;
        points.push_back({{"hierarchy", r["hierarchy"]}, {"predicted", p}, {"measured", m},
                          {"error", r.value("error", 0.0)}});
        lo = std::min({lo, p, m});
        hi = std::max({hi, p, m});
    }
    if (points.empty()) lo = 1, hi = 10;
    lo /= 1.25;
    hi *= 1.25;
    json scale = {{"type", "log"}, {"domain", {lo, hi}}, {"nice", false}};
    json spec = base("Predicted against measured cost per ray (" + units + ")", json::array());
    spec.erase("data");
    spec["width"] = 360;
    spec["height"] = 360;
    json ideal = {{"data", {{"values", {{{"v", lo}}, {{"v", hi}}}}}},
                  {"mark", {{"type", "line"}, {"color", "#888"}, {"strokeDash", {4, 4}}}},
                  {"encoding",
                   {{"x", {{"field", "v"}, {"type", "quantitative"}, {"scale", scale}, {"title", "measured"}}},
                    {"y", {{"field", "v"}, {"type", "quantitative"}, {"scale", scale}, {"title", "predicted"}}}}}};
    ideal["encoding"]["x"]["axis"] = {{"labelOverlap", "greedy"}, {"tickCount", 6}};
    ideal["encoding"]["y"]["axis"] = {{"labelOverlap", "greedy"}, {"tickCount", 6}};
    const json axis = {{"labelOverlap", "greedy"}, {"tickCount", 6}};
    json enc = {{"x", {{"field", "measured"}, {"type", "quantitative"}, {"scale", scale}, {"axis", axis}}},
                {"y", {{"field", "predicted"}, {"type", "quantitative"}, {"scale", scale}, {"axis", axis}}},
                {"tooltip", json::array({{{"field", "hierarchy"}},
                                         {{"field", "predicted"}, {"format", ".3f"}},
                                         {{"field", "measured"}, {"format", ".3f"}},
                                         {{"field", "error"}, {"format", "+.1%"}}})}};
    json dots = {{"data", {{"values", points}}},
                 {"mark", {{"type", "point"}, {"filled", true}, {"size", 70}}},
                 {"encoding", enc}};
    dots["encoding"]["color"] = {{"field", "hierarchy"}, {"type", "nominal"}, {"legend", nullptr}};
    json labels = {{"data", {{"values", points}}},
                   {"mark", {{"type", "text"}, {"align", "left"}, {"dx", 7}, {"dy", -6}, {"fontSize", 11}}},
                   {"encoding", enc}};
    labels["encoding"]["text"] = {{"field", "hierarchy"}};
    spec["layer"] = {ideal, dots, labels};
    return spec;
}

// Visits per depth, predicted and measured, one small plot per hierarchy.
json by_depth(const json& results) {
    json rows = json::array();
    for (const json& r : results) {
        if (!r.contains("visits_by_depth")) continue;
        for (const char* source : {"predicted", "measured"}) {
            const json& v = r["visits_by_depth"][source];
            if (!v.is_array()) continue;
            for (std::size_t d = 0; d < v.size(); ++d)
                rows.push_back({{"hierarchy", r["hierarchy"]}, {"source", source}, {"depth", d}, {"visits", v[d]}});
        }
    }
    json spec = base("Visits per ray by tree depth", rows);
    spec["facet"] = {{"field", "hierarchy"}, {"type", "nominal"}, {"title", nullptr}, {"sort", nullptr}};
    spec["columns"] = 3;
    spec["spec"] = {
        {"width", 230},
        {"height", 130},
        {"mark", {{"type", "line"}, {"point", true}, {"tooltip", true}}},
        {"encoding",
         {{"x", {{"field", "depth"}, {"type", "quantitative"}, {"title", "depth"}}},
          {"y", {{"field", "visits"}, {"type", "quantitative"}, {"title", "visits per ray"}}},
          {"color", {{"field", "source"}, {"type", "nominal"}, {"sort", {"predicted", "measured"}}, {"title", nullptr}}},
          {"strokeDash",
           {{"field", "source"}, {"type", "nominal"}, {"sort", {"predicted", "measured"}}, {"legend", nullptr}}}}}};
    spec["resolve"] = {{"scale", {{"y", "independent"}, {"x", "independent"}}}};
    return spec;
}

// Measured speed.
json speed(const json& results) {
    json rows = json::array();
    for (const json& r : results)
        rows.push_back({{"hierarchy", r["hierarchy"]}, {"mrays", r.value("mrays_per_s", 0.0)}});
    json spec = base("Measured speed", rows);
    spec["width"] = 360;
    spec["height"] = {{"step", 18}};
    spec["mark"] = {{"type", "bar"}, {"tooltip", true}, {"color", "#3b528b"}};
    spec["encoding"] = {
        {"y", {{"field", "hierarchy"}, {"type", "nominal"}, {"sort", "-x"}, {"title", nullptr}}},
        {"x", {{"field", "mrays"}, {"type", "quantitative"}, {"title", "million rays per second"}}}};
    return spec;
}

}  // namespace

json design_plot(const json& design) {
    json rows = json::array();
    for (const json& r : design.at("results")) {
        const json& ns = r.at("ns_per_ray");
        const std::string family = r.value("family", "?");
        rows.push_back({{"family", family}, {"hierarchy", r.value("designed", "?")}, {"role", "designed"}, {"ns", ns.value("designed", 0.0)}});
        rows.push_back({{"family", family}, {"hierarchy", r.value("yardstick", "?")}, {"role", "yardstick"}, {"ns", ns.value("yardstick", 0.0)}});
        if (ns.value("embree", 0.0) > 0)
            rows.push_back({{"family", family}, {"hierarchy", "embree"}, {"role", "embree"}, {"ns", ns["embree"]}});
    }
    json spec = base("Designed against yardstick: measured ns per ray on rays the design did not see", rows);
    spec["width"] = {{"step", 18}};
    spec["height"] = 240;
    spec["mark"] = {{"type", "bar"}, {"tooltip", true}};
    spec["encoding"] = {
        {"x", {{"field", "family"}, {"type", "nominal"}, {"title", nullptr}, {"sort", nullptr}}},
        {"xOffset", {{"field", "role"}, {"type", "nominal"}, {"sort", {"designed", "yardstick", "embree"}}}},
        {"y", {{"field", "ns"}, {"type", "quantitative"}, {"title", "single-thread ns per ray"}}},
        {"color", {{"field", "role"}, {"type", "nominal"}, {"sort", {"designed", "yardstick", "embree"}}, {"title", nullptr}}},
        {"tooltip", json::array({{{"field", "hierarchy"}}, {{"field", "ns"}, {"format", ".1f"}}})}};
    return spec;
}

json page_plots(const ReportInput& in) {
    json plots = report_plots(in.eval);
    if (in.design.is_object() && in.design.contains("results") && !in.design["results"].empty())
        plots["plot-design"] = design_plot(in.design);
    return plots;
}

json report_plots(const json& eval) {
    const json& results = eval.at("results");
    const std::string units = eval.value("unit_costs", "operations") == "ns" ? "ns" : "unit costs";
    json plots = json::object();
    plots["plot-kinds"] = cost_by_kind(results);
    plots["plot-scatter"] = scatter(results, units);
    plots["plot-depth"] = by_depth(results);
    plots["plot-speed"] = speed(results);
    return plots;
}

}  // namespace rtcost
