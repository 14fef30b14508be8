// `rtcost render`: the Whitted render whose rays `--rays spd` counts, shaded and written as PNG,
// or (`--heatmap KIND`) a per-pixel cost heat map of the chosen hierarchy.
#include <chrono>
#include <cmath>
#include <iostream>

#include "cli.hpp"
#include "rtcost/heatmap.hpp"
#include "rtcost/whitted.hpp"

namespace rtcost::cli {
namespace {
using nlohmann::json;

struct RenderArgs {
    BuildArgs b;
    std::string out = "image.png";
    std::string size;
    int depth = 5;
    int threads = 0;
    ViewSpec view;
    std::string heatmap;       // empty: the shaded image
    std::string rays = "camera";
    std::string costs;
    double scale_max = 0;
    bool log = false;
};

// Pearson's correlation of two maps, pixel by pixel (0 when either is constant).
double pearson(const std::vector<double>& x, const std::vector<double>& y) {
    const double n = static_cast<double>(x.size());
    double mx = 0, my = 0;
    for (std::size_t i = 0; i < x.size(); ++i) mx += x[i] / n, my += y[i] / n;
    double sxy = 0, sxx = 0, syy = 0;
    for (std::size_t i = 0; i < x.size(); ++i) {
        sxy += (x[i] - mx) * (y[i] - my);
        sxx += (x[i] - mx) * (x[i] - mx);
        syy += (y[i] - my) * (y[i] - my);
    }
    return sxx > 0 && syy > 0 ? sxy / std::sqrt(sxx * syy) : 0.0;
}

int cmd_heatmap(const RenderArgs& a, const Common& common, const Scene& scene, const Hierarchy& h,
                const RenderOptions& size) {
    const HeatKind kind = parse_heat_kind(a.heatmap);
    const UnitCosts costs = a.costs.empty() ? UnitCosts{} : UnitCosts::read(a.costs);
    PixelCostOptions opt;
    opt.width = size.width;
    opt.height = size.height;
    opt.tree = a.rays == "spd";
    opt.max_depth = a.depth;
    opt.time = kind == HeatKind::Time;
    opt.threads = a.threads;
    if (kind == HeatKind::Predicted) opt.predict = predicted_ray_cost(h, opt);
    PixelCosts pc;
    {
        Progress progress(fmt::format("heat map {}", h.name()), static_cast<std::size_t>(opt.height),
                          common.quiet || common.json);
        opt.progress = [&](std::size_t rows) { progress.update(rows); };
        pc = pixel_costs(h, opt);
    }
    const std::vector<double> values = heat_values(pc, kind, costs);
    HeatStyle style;
    style.title = fmt::format("{} on {}, {} ({})", h.name(), scene.name,
                              opt.tree ? fmt::format("Whitted tree, depth {}", a.depth) : "camera rays", a.heatmap);
    style.units = heat_units(kind, costs);
    style.scale_max = a.scale_max;
    style.log = a.log;
    const std::string png = encode_png(draw_heatmap(values, pc.width, pc.height, style));
    write_file_atomic(a.out, png);
    const HeatSummary s = summarize(values, a.scale_max);
    // A predicted map is shown against the measured operations of the same pixels.
    json against;
    std::string against_text;
    if (kind == HeatKind::Predicted) {
        const std::vector<double> measured = heat_values(pc, HeatKind::Ops, costs);
        const double m = summarize(measured, 0).mean;
        const double r = pearson(values, measured);
        against = {{"measured_mean", m}, {"error", m > 0 ? s.mean / m - 1 : 0.0}, {"pixel_correlation", r}};
        against_text = fmt::format("measured   mean {:.6g} (the prediction {:+.1f}%); per-pixel correlation {:.3f}\n", m,
                                   m > 0 ? 100 * (s.mean / m - 1) : 0.0, r);
    }
    if (common.json) {
        json j = {{"scene", scene.name}, {"hierarchy", h.name()}, {"out", a.out},
                  {"width", pc.width}, {"height", pc.height}, {"rays", a.rays},
                  {"heatmap", a.heatmap}, {"units", style.units}, {"traced_rays", pc.total.rays},
                  {"min", s.min}, {"mean", s.mean}, {"max", s.max}, {"scale_max", s.scale_max},
                  {"clipped", s.clipped}, {"bytes", png.size()}};
        if (!against.is_null()) j["against_measured"] = against;
        std::cout << j.dump(2) << "\n";
        return 0;
    }
    fmt::print("heat map   {} of {} on {}: {}x{}, {} rays ({})\n", a.heatmap, h.name(), scene.name, pc.width,
               pc.height, pc.total.rays, opt.tree ? "Whitted trees" : "camera rays");
    fmt::print("values     min {:.6g}  mean {:.6g}  max {:.6g} {}; scale 0 to {:.6g}{}\n", s.min, s.mean, s.max,
               style.units, s.scale_max, s.clipped ? fmt::format(" ({} pixels above)", s.clipped) : "");
    fmt::print("{}", against_text);
    fmt::print("written    {} ({})\n", a.out, human_bytes(png.size()));
    return 0;
}

int cmd_render(const RenderArgs& a, const Common& common) {
    check_output_path(a.out, "--out", common, {a.b.scene, a.costs});
    Scene scene = load(a.b.scene, common, a.view);
    RenderOptions opt;
    image_size(scene, a.size, opt.width, opt.height);
    opt.max_depth = a.depth;
    opt.threads = checked_threads(a.threads, common.quiet || common.json);
    auto h = build(scene, a.b, common);
    if (!a.heatmap.empty()) return cmd_heatmap(a, common, scene, *h, opt);
    if (a.rays != "camera" || !a.costs.empty() || a.scale_max > 0 || a.log)
        throw InputError("--heatmap", 0,
                         "--rays, --costs, --scale-max and --log-scale apply to heat maps: give --heatmap KIND");
    Image img;
    auto start = std::chrono::steady_clock::now();
    {
        Progress progress(fmt::format("render {}", h->name()), static_cast<std::size_t>(opt.height),
                          common.quiet || common.json);
        opt.progress = [&](std::size_t rows) { progress.update(rows); };
        img = render(*h, opt);
    }
    double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::string png = encode_png(img);
    write_file_atomic(a.out, png);
    if (common.json) {
        json j = {{"scene", scene.name}, {"hierarchy", h->name()}, {"out", a.out},     {"width", img.width},
                  {"height", img.height}, {"depth", a.depth},      {"seconds", seconds}, {"bytes", png.size()}};
        std::cout << j.dump(2) << "\n";
        return 0;
    }
    fmt::print("rendered   {} with {}: {}x{}, depth {}, {:.3f} s\n", scene.name, h->name(), img.width, img.height,
               a.depth, seconds);
    fmt::print("written    {} ({})\n", a.out, human_bytes(png.size()));
    return 0;
}

Subcommand setup_render(CLI::App& parent, Common& common) {
    auto a = std::make_shared<RenderArgs>();
    a->b.hierarchy = "bvh-sah";  // brute force would take minutes for a full image
    auto* cmd = parent.add_subcommand("render", "render the scene (Whitted: Phong, shadows, reflection, refraction) "
                                                "to a PNG, to see what the spd rays trace");
    add_build_args(cmd, a->b);
    cmd->add_option("-o,--out", a->out, "PNG file to write")->capture_default_str();
    cmd->add_option("--size", a->size, "image size WxH (default: the scene's resolution)");
    add_view_args(cmd, a->view);
    cmd->add_option("--depth", a->depth, "maximum ray tree depth (eye ray: 1)")->check(CLI::Range(1, 64))->capture_default_str();
    cmd->add_option("-j,--threads", a->threads, "threads (0: all cores)")->check(CLI::Range(0, 1024))->capture_default_str();
    cmd->add_option("--heatmap", a->heatmap,
                    "write a per-pixel cost heat map instead: box, plane, hop, classify, prim, steps, ops "
                    "(all operations in unit costs, or ns with --costs), time (measured ns), predicted (the model's "
                    "operations per pixel, learned from a 2% sample of the same rays, beside the measured ones)");
    cmd->add_option("--rays", a->rays, "heat map rays: camera (each pixel's camera ray) or spd (its whole Whitted tree)")
        ->check(CLI::IsMember({"camera", "spd"}))
        ->capture_default_str();
    cmd->add_option("--costs", a->costs, "unit costs file (from rtcost calibrate) for --heatmap ops");
    cmd->add_option("--scale-max", a->scale_max, "top of the heat map's colour scale (default: the largest value), "
                                                 "to compare hierarchies on one scale")
        ->check(positive_number());
    cmd->add_flag("--log-scale", a->log, "heat map colours by log(1 + value), for costs that span decades");
    add_common(cmd, common);
    cmd->footer(hierarchy_footer());
    return {cmd, [a, &common] { return cmd_render(*a, common); }};
}

const CommandRegistration reg{60, setup_render};

}  // namespace
}  // namespace rtcost::cli
