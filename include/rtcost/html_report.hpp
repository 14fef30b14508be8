#pragma once
/// \file html_report.hpp
/// `rtcost report`: one self-contained HTML page (every script and style inlined, nothing
/// fetched) with the scene's render, the evaluation table, plots of predicted against measured
/// cost (Vega-Lite, inlined at build time), the per-pixel heat maps side by side, and the
/// machine, date and command line.

#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "rtcost/heatmap.hpp"
#include "rtcost/model.hpp"
#include "rtcost/scene.hpp"

namespace rtcost {

/// A picture on the page: PNG bytes with a title.
struct ReportImage {
    std::string title;
    std::string png;
};

/// Everything the page shows.
struct ReportInput {
    /// The evaluation: the `rtcost eval --json --by-depth` document (to_json(EvalResult, true)).
    nlohmann::json eval;
    ReportImage render;                  ///< the scene shaded (empty png: none)
    std::vector<ReportImage> heatmaps;   ///< one per hierarchy, on one colour scale
    /// What the heat maps show: {"kind", "units", "rays", "width", "height", "scale_max",
    /// "maps": [{"hierarchy", "min", "mean", "max"}]}.
    nlohmann::json heat = nlohmann::json::object();
    /// {"date", "command", "machine": {...}, "rtcost", "plots"}: see report_meta().
    nlohmann::json meta = nlohmann::json::object();
    /// The design results (to_json(DesignResult), design.hpp); null: the page has no design section.
    nlohmann::json design = nullptr;
};

/// How the report's heat maps are made.
struct ReportHeatOptions {
    HeatKind kind = HeatKind::Ops;
    int width = 256, height = 256;
    bool tree = false;       ///< each pixel's Whitted tree (`--rays spd`), else its camera ray
    UnitCosts costs;         ///< for HeatKind::Ops
    double scale_max = 0;    ///< 0: the largest value over every hierarchy
    bool log = false;        ///< colours by log(1 + value)
    int threads = 0;
    std::function<void(const std::string& step)> on_step;  ///< "heat map NAME", before each
};

/// Builds each hierarchy of `labels` ("name" or "name:key=value[:key=value...]", as the
/// evaluation names them) over `scene` and adds its heat map to `in`, all on one colour scale,
/// with their summary in `in.heat`. Hierarchies whose operations are not counted (embree) get
/// a map only of time.
void add_heatmaps(ReportInput& in, const Scene& scene, const std::vector<std::string>& labels,
                  const ReportHeatOptions& opt);

/// Adds the scene shaded (`render`, through bvh-sah) at width x height, enlarged by a whole
/// factor to at least 256 pixels on its longer side.
void add_render(ReportInput& in, const Scene& scene, int width, int height, int threads = 0);

/// The machine (CPU model, cores, OS), the date (UTC, ISO 8601), the command line of this
/// process, rtcost's version and the plotting libraries' versions.
nlohmann::json report_meta();

/// The data behind the page (what `rtcost report --json` writes): meta, eval, heat maps'
/// summaries, design results and the plots' Vega-Lite specifications. Images are left out.
nlohmann::json report_json(const ReportInput& in);

/// The Vega-Lite specifications of the page's plots, by element id: cost by operation kind
/// (predicted beside measured), predicted against measured (with the ideal line), visits by
/// depth, and measured speed.
nlohmann::json report_plots(const nlohmann::json& eval);

/// The design section's plot: each family's designed hierarchy beside its yardstick (and
/// Embree), in measured single-thread ns per ray on the rays the design did not see.
nlohmann::json design_plot(const nlohmann::json& design);

/// Every plot of the page for `in`, by element id: report_plots(in.eval), and "plot-design"
/// when the page has a design section.
nlohmann::json page_plots(const ReportInput& in);

/// The page. Throws InputError when Vega-Lite was not found at build time (see
/// report_scripts_available) or the evaluation has no results.
std::string report_html(const ReportInput& in);

/// Whether the build embedded Vega, Vega-Lite and vega-embed (scripts/install-deps.sh installs
/// them into third_party/js/node_modules).
bool report_scripts_available();

}  // namespace rtcost
