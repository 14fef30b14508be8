// The report page: one HTML file with its styles, scripts, data and images inlined.
#include <fmt/format.h>
#include <sys/utsname.h>

#include <chrono>
#include <ctime>
#include <fstream>
#include <sstream>
#include <thread>

#include "report/report_assets.hpp"
#include "rtcost/error.hpp"
#include "rtcost/html_report.hpp"
#include "rtcost/report.hpp"

namespace rtcost {
namespace {
using nlohmann::json;

// Base64 (RFC 4648) for the images' data URIs: none of the libraries rtcost links offers it,
// and it is a dozen lines.
std::string base64(std::string_view in) {
    static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    out.reserve((in.size() + 2) / 3 * 4);
    for (std::size_t i = 0; i < in.size(); i += 3) {
        std::uint32_t v = static_cast<std::uint8_t>(in[i]) << 16;
        if (i + 1 < in.size()) v |= static_cast<std::uint8_t>(in[i + 1]) << 8;
        if (i + 2 < in.size()) v |= static_cast<std::uint8_t>(in[i + 2]);
        out += kAlphabet[(v >> 18) & 63];
        out += kAlphabet[(v >> 12) & 63];
        out += i + 1 < in.size() ? kAlphabet[(v >> 6) & 63] : '=';
        out += i + 2 < in.size() ? kAlphabet[v & 63] : '=';
    }
    return out;
}

std::string esc(std::string_view s) {
    std::string out;
    for (char c : s) {
        switch (c) {
            case '&': out += "&amp;"; break;
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '"': out += "&quot;"; break;
            default: out += c;
        }
    }
    return out;
}

// A script inlined in <script>: without its source-map comment (the page has no map to fetch),
// and with no "</script" inside it that would end the element early.
std::string inline_script(std::string_view js) {
    std::string s(js);
    for (std::size_t p; (p = s.find("//# sourceMappingURL=")) != std::string::npos;)
        s.erase(p, s.find('\n', p) == std::string::npos ? std::string::npos : s.find('\n', p) - p);
    for (std::size_t p = 0; (p = s.find("</script", p)) != std::string::npos; p += 2) s.replace(p, 2, "<\\/");
    return s;
}

// JSON inside <script type="application/json">: "</" written as "<\/" (the same JSON string).
std::string inline_json(const json& j) {
    std::string s = j.dump();
    for (std::size_t p = 0; (p = s.find("</", p)) != std::string::npos; p += 3) s.replace(p, 2, "<\\/");
    return s;
}

std::string first_line_of(const char* path, const std::string& key) {
    std::ifstream in(path);
    std::string line;
    while (std::getline(in, line))
        if (line.rfind(key, 0) == 0) {
            std::size_t colon = line.find(':');
            return colon == std::string::npos ? line : line.substr(line.find_first_not_of(" \t", colon + 1));
        }
    return "";
}

// This process's command line, each argument quoted for a POSIX shell when it needs it.
std::string command_line() {
    std::ifstream in("/proc/self/cmdline", std::ios::binary);
    std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>()), out, arg;
    std::istringstream args(all);
    while (std::getline(args, arg, '\0')) {
        bool plain = !arg.empty() && arg.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                                           "0123456789-_./:=,+@%") == std::string::npos;
        if (!out.empty()) out.push_back(' ');
        if (plain) {
            out.append(arg);
            continue;
        }
        out.push_back('\'');
        for (char c : arg) {
            if (c == '\'') out.append("'\\''");
            else out.push_back(c);
        }
        out.push_back('\'');
    }
    return out;
}

std::string num(const json& v, const char* format) {
    if (!v.is_number()) return "-";
    return fmt::format(fmt::runtime(format), v.get<double>());
}

/// `obj[key]`, or null where `obj` is no object or has no such key (an uncounted hierarchy's
/// `measured`, or a hand-edited evaluation): the table shows "-" there.
json field(const json& obj, const char* key) {
    return obj.is_object() && obj.contains(key) ? obj[key] : json();
}

std::string whole(const json& v) { return v.is_number_integer() ? std::to_string(v.get<long long>()) : "-"; }

std::string eval_table(const json& eval) {
    std::string t = "<table id=\"eval\"><thead><tr><th>hierarchy</th><th>build s</th><th>nodes</th><th>bytes</th>"
                    "<th>predicted</th><th>measured</th><th>error</th><th>Mrays/s</th><th>rank predicted</th>"
                    "<th>rank measured</th></tr></thead><tbody>\n";
    for (const json& r : eval.at("results")) {
        const json b = field(r, "build");
        const bool modelled = field(r, "predicted").is_object();
        t += fmt::format(
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td>"
            "<td>{}</td></tr>\n",
            esc(field(r, "hierarchy").is_string() ? r["hierarchy"].get<std::string>() : "?"),
            num(field(b, "seconds"), "{:.4f}"),
            field(b, "N_IN").is_number_unsigned() && field(b, "N_V").is_number_unsigned()
                ? std::to_string(b["N_IN"].get<std::uint64_t>() + b["N_V"].get<std::uint64_t>())
                : "-",
            field(b, "bytes").is_number_unsigned() ? esc(human_bytes(b["bytes"].get<std::uint64_t>())) : "-",
            modelled ? num(field(r["predicted"], "cost"), "{:.2f}") : "-",
            num(field(field(r, "measured"), "cost"), "{:.2f}"),
            modelled && field(r, "error").is_number() ? num(json(100 * r["error"].get<double>()), "{:+.1f}%") : "-",
            num(field(r, "mrays_per_s"), "{:.3f}"), modelled ? whole(field(r, "rank_predicted")) : "-",
            whole(field(r, "rank_measured")));
    }
    return t + "</tbody></table>\n";
}

std::string design_table(const json& d) {
    std::string t = "<table id=\"design\"><thead><tr><th>family</th><th>hierarchy</th><th>structure</th><th>build s</th>"
                    "<th>predicted</th><th>measured</th><th>ns/ray</th><th>gain</th></tr></thead><tbody>\n";
    for (const json& r : d.at("results")) {
        const json &b = r.at("build_seconds"), &p = r.at("predicted"), &m = r.at("measured"), &ns = r.at("ns_per_ray");
        std::string designed = r.value("designed", "?");
        for (const json& kv : r.value("set", json::array())) designed.append(":").append(kv.get<std::string>());
        t += fmt::format("<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n",
                         esc(r.value("family", "?")), esc(designed), esc(r.value("structure", "")),
                         num(b.value("designed", json()), "{:.3f}"), num(p.value("designed", json()), "{:.2f}"),
                         num(m.value("designed", json()), "{:.2f}"), num(ns.value("designed", json()), "{:.1f}"),
                         num(json(100 * r.value("gain", 0.0)), "{:+.1f}%"));
        t += fmt::format("<tr><td></td><td>{}</td><td></td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td></td></tr>\n",
                         esc(r.value("yardstick", "?")), num(b.value("yardstick", json()), "{:.3f}"),
                         num(p.value("yardstick", json()), "{:.2f}"), num(m.value("yardstick", json()), "{:.2f}"),
                         num(ns.value("yardstick", json()), "{:.1f}"));
    }
    return t + "</tbody></table>\n";
}

// A picture as a data URI; heat maps carry their title in the image, so only the render has a caption.
std::string figure(const ReportImage& img, const std::string& cls, bool caption) {
    return fmt::format("<figure class=\"{}\"><img alt=\"{}\" src=\"data:image/png;base64,{}\">{}</figure>\n", cls,
                       esc(img.title), base64(img.png),
                       caption ? "<figcaption>" + esc(img.title) + "</figcaption>" : std::string());
}

constexpr const char* kStyle = R"(
body { font-family: "DejaVu Sans", Verdana, sans-serif; margin: 1.5em auto; max-width: 1280px; color: #222; padding: 0 1em; }
h1 { font-size: 1.5em; margin-bottom: 0.2em; } h2 { font-size: 1.15em; margin-top: 1.6em; border-bottom: 1px solid #ccc; }
.lead { color: #555; margin-top: 0; }
.images { display: flex; flex-wrap: wrap; gap: 12px; align-items: flex-start; }
figure { margin: 0; } figcaption { font-size: 0.8em; color: #555; max-width: 420px; }
figure.render img { border: 1px solid #ccc; }
table { border-collapse: collapse; font-size: 0.9em; }
th, td { padding: 3px 9px; border-bottom: 1px solid #e4e4e4; text-align: right; }
th:first-child, td:first-child { text-align: left; } thead th { border-bottom: 2px solid #999; }
#design td:nth-child(2), #design td:nth-child(3), #design th:nth-child(2), #design th:nth-child(3) { text-align: left; }
.plots { display: flex; flex-wrap: wrap; gap: 28px; align-items: flex-start; }
dl { display: grid; grid-template-columns: max-content auto; gap: 2px 14px; font-size: 0.9em; }
dt { color: #555; } dd { margin: 0; } code { font-size: 0.95em; word-break: break-all; }
)";

// Renders every plot as SVG; body[data-plots] says when all are done ("done") or one failed.
constexpr const char* kBoot = R"(
(function () {
  const specs = JSON.parse(document.getElementById('rtcost-plots').textContent);
  const opts = { renderer: 'svg', actions: false };
  Promise.all(Object.keys(specs).map(function (id) { return vegaEmbed('#' + id, specs[id], opts); }))
    .then(function () { document.body.dataset.plots = 'done'; },
          function (e) { console.error('rtcost report: a plot failed: ' + e); document.body.dataset.plots = 'failed'; });
})();
)";

}  // namespace

bool report_scripts_available() { return detail::report_scripts() != nullptr; }

json report_meta() {
    auto now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
    std::tm tm{};
    gmtime_r(&now, &tm);
    char date[32];
    std::strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", &tm);
    utsname u{};
    uname(&u);
    json machine = {{"cpu", first_line_of("/proc/cpuinfo", "model name")},
                    {"threads", std::thread::hardware_concurrency()},
                    {"os", fmt::format("{} {} {}", u.sysname, u.release, u.machine)},
                    {"memory", first_line_of("/proc/meminfo", "MemTotal")}};
    const auto* s = detail::report_scripts();
    return {{"date", date}, {"command", command_line()}, {"machine", machine},
            {"plots", s ? std::string(s->versions) : std::string("not embedded")}};
}

json report_json(const ReportInput& in) {
    return {{"meta", in.meta}, {"eval", in.eval}, {"heatmaps", in.heat}, {"design", in.design}, {"plots", page_plots(in)}};
}

std::string report_html(const ReportInput& in) {
    const auto* scripts = detail::report_scripts();
    if (!scripts)
        throw InputError("report", 0,
                         "this rtcost was built without Vega-Lite: run scripts/install-deps.sh, then build again");
    const json& e = in.eval;
    if (!e.contains("results") || !e["results"].is_array() || e["results"].empty())
        throw InputError("report", 0, "the evaluation has no results");
    const std::string scene = e.value("scene", "?");
    std::string h = "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n";
    h += "<title>rtcost report: " + esc(scene) + "</title>\n<style>" + std::string(kStyle) + "</style>\n</head><body>\n";
    h += "<h1>rtcost report: " + esc(scene) + "</h1>\n";
    h += fmt::format("<p class=\"lead\">{} primitives; {} test rays ({}), {} query; model: {} estimator, {} preset{}; "
                     "costs in {}.</p>\n",
                     e.value("primitives", 0ull), e.value("rays", 0ull), esc(e.value("distribution", "?")),
                     esc(e.value("query", "?")), esc(e.value("estimator", "?")), esc(e.value("preset", "?")),
                     e.value("training_rays", 0ull) ? fmt::format(" ({} training rays)", e["training_rays"].get<std::size_t>())
                                                    : "",
                     esc(e.value("unit_costs", "operations")));

    h += "<h2>Scene and per-pixel cost</h2>\n";
    if (!in.heatmaps.empty())
        h += fmt::format("<p class=\"lead\">Heat maps: {} of {}, {}x{} pixels, on one {}scale (0 to {:.6g}).</p>\n",
                         esc(in.heat.value("units", "")), esc(in.heat.value("rays", "")), in.heat.value("width", 0),
                         in.heat.value("height", 0), in.heat.value("log", false) ? "logarithmic " : "",
                         in.heat.value("scale_max", 0.0));
    h += "<div class=\"images\">\n";
    if (!in.render.png.empty()) h += figure(in.render, "render", true);
    for (const ReportImage& img : in.heatmaps) h += figure(img, "heatmap", false);
    h += "</div>\n";

    h += "<h2>Evaluation</h2>\n" + eval_table(e);
    h += "<p class=\"lead\">predicted and measured: cost per ray in " + esc(e.value("unit_costs", "operations")) +
         "; error: (predicted - measured) / measured; ranks: 1 is the cheapest.</p>\n";

    h += "<h2>Predicted and measured</h2>\n<div class=\"plots\">\n";
    const json plots = page_plots(in);
    for (const char* id : {"plot-kinds", "plot-scatter", "plot-depth", "plot-speed"})
        if (plots.contains(id)) h += fmt::format("<div class=\"plot\" id=\"{}\"></div>\n", id);
    h += "</div>\n";

    if (plots.contains("plot-design")) {
        const json& d = in.design;
        h += "<h2>Design</h2>\n";
        h += fmt::format("<p class=\"lead\">Each family's hierarchy designed by the model for {} from a sample of {} "
                         "rays, against its yardstick builder; predicted: the model on the sample; measured and ns "
                         "per ray (single thread): on the {} rays the design did not see; gain: 1 - designed / "
                         "yardstick ns per ray. Costs in {}.</p>\n",
                         esc(d.value("distribution", "?")), d.value("sample", 0ull), d.value("test_rays", 0ull),
                         esc(d.value("units", "operations")));
        h += design_table(d) + "<div class=\"plots\"><div class=\"plot\" id=\"plot-design\"></div></div>\n";
    }

    const json& m = in.meta;
    h += "<h2>Run</h2>\n<dl>\n";
    auto item = [&](const char* k, const std::string& v) { h += fmt::format("<dt>{}</dt><dd>{}</dd>\n", k, v); };
    item("date", esc(m.value("date", "")));
    item("command", "<code>" + esc(m.value("command", "")) + "</code>");
    if (m.contains("machine"))
        for (const auto& [k, v] : m["machine"].items()) item(k.c_str(), esc(v.is_string() ? v.get<std::string>() : v.dump()));
    item("plots", esc(m.value("plots", "")));
    h += "</dl>\n";

    h += "<script>" + inline_script(scripts->vega) + "</script>\n";
    h += "<script>" + inline_script(scripts->vega_lite) + "</script>\n";
    h += "<script>" + inline_script(scripts->vega_embed) + "</script>\n";
    h += "<script type=\"application/json\" id=\"rtcost-plots\">" + inline_json(plots) + "</script>\n";
    h += "<script>" + std::string(kBoot) + "</script>\n</body></html>\n";
    return h;
}

}  // namespace rtcost
