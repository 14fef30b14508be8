// The report's pictures: the scene shaded, and every hierarchy's heat map on one scale.
#include <fmt/format.h>

#include <algorithm>

#include "rtcost/error.hpp"
#include "rtcost/html_report.hpp"

namespace rtcost {

namespace {
// "name:key=value:key=value" into the name and its assignments.
std::pair<std::string, std::vector<std::string>> split_label(const std::string& label) {
    std::vector<std::string> parts;
    std::size_t start = 0;
    while (true) {
        std::size_t colon = label.find(':', start);
        parts.push_back(label.substr(start, colon == std::string::npos ? std::string::npos : colon - start));
        if (colon == std::string::npos) break;
        start = colon + 1;
    }
    std::string name = parts.front();
    parts.erase(parts.begin());
    return {name, parts};
}
}  // namespace

void add_heatmaps(ReportInput& in, const Scene& scene, const std::vector<std::string>& labels,
                  const ReportHeatOptions& opt) {
    struct Map {
        std::string label;
        std::vector<double> values;
        HeatSummary summary;
    };
    std::vector<Map> maps;
    for (const std::string& label : labels) {
        auto [name, params] = split_label(label);
        if (opt.on_step) opt.on_step("heat map " + label);
        auto h = build_hierarchy(scene, name, params);
        // Embree's operations are not counted: only its time can be shown.
        if (name == "embree" && opt.kind != HeatKind::Time) continue;
        PixelCostOptions po;
        po.width = opt.width;
        po.height = opt.height;
        po.tree = opt.tree;
        po.time = opt.kind == HeatKind::Time;
        po.threads = opt.threads;
        if (opt.kind == HeatKind::Predicted) {
            // Predicted beside measured, for the hierarchies the model follows ray by ray.
            try {
                po.predict = predicted_ray_cost(*h, po);
            } catch (const InputError&) {
                continue;  // no model tree, or a 5D one
            }
        }
        PixelCosts pc = pixel_costs(*h, po);
        Map m{label + ": " + std::string(heat_kind_name(opt.kind)), heat_values(pc, opt.kind, opt.costs), {}};
        m.summary = summarize(m.values, 0);
        maps.push_back(std::move(m));
        if (opt.kind == HeatKind::Predicted) {
            Map measured{label + ": ops (measured)", heat_values(pc, HeatKind::Ops, opt.costs), {}};
            measured.summary = summarize(measured.values, 0);
            maps.push_back(std::move(measured));
        }
    }
    double top = opt.scale_max;
    if (!(top > 0))
        for (const Map& m : maps) top = std::max(top, m.summary.max);
    const std::string units = heat_units(opt.kind, opt.costs);
    const std::string rays = opt.tree ? "each pixel's Whitted ray tree" : "each pixel's camera ray";
    nlohmann::json list = nlohmann::json::array();
    for (const Map& m : maps) {
        HeatStyle style;
        style.title = m.label;
        style.units = units;
        style.scale_max = top;
        style.log = opt.log;
        in.heatmaps.push_back({style.title, encode_png(draw_heatmap(m.values, opt.width, opt.height, style))});
        list.push_back({{"hierarchy", m.label.substr(0, m.label.rfind(": "))}, {"map", m.label}, {"min", m.summary.min}, {"mean", m.summary.mean}, {"max", m.summary.max}});
    }
    in.heat = {{"kind", heat_kind_name(opt.kind)}, {"units", units}, {"rays", rays}, {"width", opt.width},
               {"height", opt.height}, {"scale_max", top}, {"log", opt.log}, {"maps", list}};
}

void add_render(ReportInput& in, const Scene& scene, int width, int height, int threads) {
    auto h = build_hierarchy(scene, "bvh-sah");
    // Shown beside heat maps that are enlarged to at least 192 pixels: no smaller than 256.
    const int zoom = std::max(1, (256 + std::max(width, height) - 1) / std::max(width, height));
    width *= zoom;
    height *= zoom;
    RenderOptions opt;
    opt.width = width;
    opt.height = height;
    opt.threads = threads;
    in.render = {fmt::format("{} (Whitted shading, {}x{})", scene.name, width, height), encode_png(render(*h, opt))};
}

}  // namespace rtcost
