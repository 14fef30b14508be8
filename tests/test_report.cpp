// `rtcost report`: the page is self-contained (no external script, style or image), carries the
// evaluation's numbers in its table and plots, its heat maps on one scale, and the CLI's errors.
// The page in a real browser: tests/browser (ctest ReportInBrowser).
#include <gtest/gtest.h>
#include <fmt/format.h>
#include <nlohmann/json.hpp>


#include "report_test_util.hpp"
#include "rtcost/design.hpp"
#include "rtcost/error.hpp"
#include "rtcost/html_report.hpp"
#include "rtcost/io.hpp"

using namespace rtcost;
using namespace rtcost::report_test;
using nlohmann::json;

namespace {

json fixture() {
    return json::parse(slurp(fs::path(RTCOST_TEST_DATA) / "eval_balls3.json"));
}

std::string unbase64(const std::string& in) {
    auto value = [](char c) -> int {
        if (c >= 'A' && c <= 'Z') return c - 'A';
        if (c >= 'a' && c <= 'z') return c - 'a' + 26;
        if (c >= '0' && c <= '9') return c - '0' + 52;
        return c == '+' ? 62 : c == '/' ? 63 : -1;
    };
    std::string out;
    int bits = 0;
    std::uint32_t acc = 0;
    for (char c : in) {
        int v = value(c);
        if (v < 0) break;
        acc = (acc << 6) | v;
        bits += 6;
        if (bits >= 8) {
            bits -= 8;
            out += static_cast<char>((acc >> bits) & 0xff);
        }
    }
    return out;
}

TEST(ReportPlots, CarryTheEvaluationsNumbers) {
    const json e = fixture();
    const json plots = report_plots(e);
    ASSERT_TRUE(plots.contains("plot-kinds") && plots.contains("plot-scatter") && plots.contains("plot-depth") &&
                plots.contains("plot-speed"));
    // Scatter: one point per modelled hierarchy at (measured, predicted).
    const json& points = plots["plot-scatter"]["layer"][1]["data"]["values"];
    ASSERT_EQ(points.size(), e["results"].size());
    for (std::size_t i = 0; i < points.size(); ++i) {
        EXPECT_EQ(points[i]["hierarchy"], e["results"][i]["hierarchy"]);
        EXPECT_DOUBLE_EQ(points[i]["predicted"].get<double>(), e["results"][i]["predicted"]["cost"].get<double>());
        EXPECT_DOUBLE_EQ(points[i]["measured"].get<double>(), e["results"][i]["measured"]["cost"].get<double>());
    }
    // The ideal line spans every point.
    const json& ideal = plots["plot-scatter"]["layer"][0]["data"]["values"];
    for (const json& p : points) {
        EXPECT_LT(ideal[0]["v"].get<double>(), std::min(p["predicted"].get<double>(), p["measured"].get<double>()));
        EXPECT_GT(ideal[1]["v"].get<double>(), std::max(p["predicted"].get<double>(), p["measured"].get<double>()));
    }
    // Kinds: five kinds, predicted and measured, per hierarchy; the values are the evaluation's.
    const json& kinds = plots["plot-kinds"]["data"]["values"];
    EXPECT_EQ(kinds.size(), e["results"].size() * 2 * 5);
    double grid_plane = -1;
    for (const json& k : kinds)
        if (k["hierarchy"] == "kd-sah" && k["source"] == "measured" && k["kind"] == "plane") grid_plane = k["value"];
    EXPECT_DOUBLE_EQ(grid_plane, e["results"][1]["measured"]["plane"].get<double>());
    // Depth: every predicted and measured depth of every hierarchy.
    std::size_t depths = 0;
    for (const json& r : e["results"])
        depths += r["visits_by_depth"]["predicted"].size() + r["visits_by_depth"]["measured"].size();
    EXPECT_EQ(plots["plot-depth"]["data"]["values"].size(), depths);
}

TEST(ReportHtml, SelfContainedWithTableImagesAndPlots) {
    if (!report_scripts_available()) GTEST_SKIP() << "built without Vega-Lite (scripts/install-deps.sh)";
    Scene scene = load_scene("builtin:balls:3");
    ReportInput in;
    in.eval = fixture();
    in.meta = report_meta();
    ReportHeatOptions heat;
    heat.width = 40;
    heat.height = 30;
    add_heatmaps(in, scene, {"bvh-sah", "grid:res=woo"}, heat);
    add_render(in, scene, 40, 30);
    ASSERT_EQ(in.heatmaps.size(), 2u);
    // One scale: the larger of the two maps' maxima.
    double top = std::max(in.heat["maps"][0]["max"].get<double>(), in.heat["maps"][1]["max"].get<double>());
    EXPECT_EQ(in.heat["scale_max"].get<double>(), top);
    EXPECT_EQ(in.heat["units"], "operations per pixel (unit costs)");
    EXPECT_GT(in.heat["maps"][1]["mean"].get<double>(), in.heat["maps"][0]["mean"].get<double>());  // grid costs more

    const std::string html = report_html(in);
    // Nothing fetched: no external script, stylesheet, image or frame.
    EXPECT_EQ(html.find("<script src"), std::string::npos);
    EXPECT_EQ(html.find("<link"), std::string::npos);
    EXPECT_EQ(html.find("<iframe"), std::string::npos);
    EXPECT_EQ(html.find("sourceMappingURL"), std::string::npos);
    std::vector<std::string> images;  // every <img>'s src (std::regex overflows its stack on long ones)
    const std::string body = html.substr(0, html.find("<script>"));  // the page before the libraries
    for (std::size_t at = 0; (at = body.find("<img ", at)) != std::string::npos; ++at) {
        std::size_t src = body.find(" src=\"", at) + 6, end = body.find('"', src);
        images.push_back(body.substr(src, end - src));
    }
    ASSERT_EQ(images.size(), 3u);  // the render and two heat maps
    for (const std::string& src : images) {
        ASSERT_EQ(src.rfind("data:image/png;base64,", 0), 0u);
        Image img = decode_png(unbase64(src.substr(22)));
        EXPECT_GE(img.width, 40);
        EXPECT_GE(img.height, 30);
    }
    // The table: one row per hierarchy, with its numbers.
    for (const json& r : in.eval["results"]) {
        std::string row = "<tr><td>" + r["hierarchy"].get<std::string>() + "</td>";
        EXPECT_NE(html.find(row), std::string::npos) << row;
    }
    const json& grid = in.eval["results"][2];
    ASSERT_EQ(grid["hierarchy"], "grid");
    const std::string cells = fmt::format("<td>{:.2f}</td><td>{:.2f}</td><td>{:+.1f}%</td>", grid["predicted"]["cost"].get<double>(),
                                          grid["measured"]["cost"].get<double>(), 100 * grid["error"].get<double>());
    EXPECT_NE(html.find(cells), std::string::npos) << cells;
    // The plots' specifications, as report_plots gives them, and a place for each.
    const std::string open = "<script type=\"application/json\" id=\"rtcost-plots\">";
    std::size_t at = html.find(open);
    ASSERT_NE(at, std::string::npos);
    std::string specs = html.substr(at + open.size(), html.find("</script>", at) - at - open.size());
    EXPECT_EQ(json::parse(specs), report_plots(in.eval));
    for (const char* id : {"plot-kinds", "plot-scatter", "plot-depth", "plot-speed"})
        EXPECT_NE(html.find(std::string("<div class=\"plot\" id=\"") + id + "\">"), std::string::npos) << id;
    // The libraries themselves are inlined.
    EXPECT_NE(html.find("vegaEmbed"), std::string::npos);
    EXPECT_GT(html.size(), 500000u);

    json data = report_json(in);
    EXPECT_EQ(data["eval"], in.eval);
    EXPECT_EQ(data["heatmaps"]["maps"].size(), 2u);
    EXPECT_FALSE(data["meta"]["date"].get<std::string>().empty());
    EXPECT_FALSE(data["meta"]["machine"]["os"].get<std::string>().empty());
}

TEST(ReportHtml, ADesignSectionWithTheDesignsNumbers) {
    if (!report_scripts_available()) GTEST_SKIP() << "built without Vega-Lite (scripts/install-deps.sh)";
    const Scene scene = load_scene("builtin:balls:1");
    DesignOptions opt;
    opt.rays.size = "32x32";
    opt.families = {"bvh", "grid"};
    const DesignResult d = design(scene, opt);
    ASSERT_EQ(d.rows.size(), 2u);
    ReportInput in;
    in.eval = fixture();
    in.design = to_json(d);
    const json plots = page_plots(in);
    ASSERT_TRUE(plots.contains("plot-design"));
    const json& bars = plots["plot-design"]["data"]["values"];
    ASSERT_EQ(bars.size(), 6u);  // designed, yardstick and Embree per family
    EXPECT_EQ(bars[0]["hierarchy"], "bvh-design");
    EXPECT_DOUBLE_EQ(bars[0]["ns"].get<double>(), d.rows[0].designed_ns);
    EXPECT_EQ(bars[4]["hierarchy"], "grid:res=hetero");
    EXPECT_DOUBLE_EQ(bars[4]["ns"].get<double>(), d.rows[1].yardstick_ns);
    const std::string html = report_html(in);
    EXPECT_NE(html.find("<h2>Design</h2>"), std::string::npos);
    EXPECT_NE(html.find("<div class=\"plot\" id=\"plot-design\">"), std::string::npos);
    for (const DesignRow& row : d.rows) {
        const std::string cells = fmt::format("<td>{:.2f}</td><td>{:.2f}</td><td>{:.1f}</td><td>{:+.1f}%</td>",
                                              row.designed_predicted, row.designed_measured, row.designed_ns, 100 * row.gain);
        EXPECT_NE(html.find(cells), std::string::npos) << cells;
    }
    EXPECT_EQ(report_json(in)["design"], in.design);
    // Without design results, no section.
    in.design = nullptr;
    EXPECT_FALSE(page_plots(in).contains("plot-design"));
    EXPECT_EQ(report_html(in).find("<h2>Design</h2>"), std::string::npos);
}

TEST(ReportHtml, RejectsAnEvaluationWithoutResults) {
    if (!report_scripts_available()) GTEST_SKIP() << "built without Vega-Lite (scripts/install-deps.sh)";
    ReportInput in;
    in.eval = {{"scene", "x"}, {"results", json::array()}};
    EXPECT_THROW(report_html(in), InputError);
}

TEST(ReportCli, FromASavedEvaluationAndBadInput) {
    if (!report_scripts_available()) GTEST_SKIP() << "built without Vega-Lite (scripts/install-deps.sh)";
    fs::path out = temp_dir() / "report.html";
    fs::remove(out);
    const std::string eval = (fs::path(RTCOST_TEST_DATA) / "eval_balls3.json").string();
    CliRun r = run_cli("report builtin:balls:3 --from-eval " + eval + " --heatmap prim --heatmap-size 24x24 -o " +
                       out.string() + " --json --no-design");
    ASSERT_EQ(r.code, 0) << r.err;
    json j = json::parse(r.out);
    EXPECT_TRUE(j["design"].is_null());
    EXPECT_EQ(j["heatmaps"]["kind"], "prim");
    EXPECT_EQ(j["heatmaps"]["maps"].size(), 4u);
    EXPECT_NE(j["meta"]["command"].get<std::string>().find("report builtin:balls:3"), std::string::npos);
    EXPECT_GT(fs::file_size(out), 500000u);
    fs::path never = temp_dir() / "never.html";
    fs::remove(never);
    r = run_cli("report builtin:balls:3 --from-eval /nonexistent/eval.json -o " + never.string());
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("/nonexistent/eval.json"), std::string::npos) << r.err;
    r = run_cli("report builtin:balls:3 --from-eval " + eval + " --heatmap boxes -o " + never.string());
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("boxes"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(never));
}

}  // namespace
