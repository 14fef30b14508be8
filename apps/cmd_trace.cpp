// `rtcost trace`: trace a ray set through one hierarchy; time the fast path, then count.
#include <iostream>
#include <optional>

#include "cli.hpp"

namespace rtcost::cli {
namespace {
using nlohmann::json;

struct TraceArgs {
    BuildArgs b;
    RaySpec rays;
    std::string query = "closest";
    std::string shadow = "any";
    std::string hits_out;
    bool hits_given = false;  ///< --hits given (an empty path is refused, not taken for none)
    int threads = 0;
    bool no_count = false;
};

int cmd_trace(const TraceArgs& a, const Common& common) {
    if (a.hits_given) check_output_path(a.hits_out, "--hits", common, {a.b.scene, a.rays.name});
    Scene scene = load(a.b.scene, common, a.rays.view);
    RaySet rays = make_rays(scene, a.rays);
    print_warnings(rays.warnings, common.quiet || common.json);
    auto h = build(scene, a.b, common);
    StructureStats s = h->structure();

    TraceOptions opt;
    opt.query = parse_query(a.query);
    opt.threads = checked_threads(a.threads, common.quiet || common.json);
    const Query occlusion = parse_query(a.shadow);
    TraceResult timed;
    {
        Progress progress(fmt::format("trace {}", h->name()), rays.rays.size(), common.quiet);
        opt.progress = [&](std::size_t done) { progress.update(done); };
        timed = trace_ray_set(*h, rays, opt, occlusion);
    }
    std::optional<TraceResult> counted;
    if (!a.no_count) {
        // Counting is a second pass through the counting instantiation of the same traversal, so
        // the timing above is of the fast path alone.
        Progress progress(fmt::format("count {}", h->name()), rays.rays.size(), common.quiet);
        opt.progress = [&](std::size_t done) { progress.update(done); };
        opt.count = true;
        counted = trace_ray_set(*h, rays, opt, occlusion);
    }
    if (h->lazy()) {
        // A lazily built structure meets its bounds while the rays grow it.
        s.limits = h->structure().limits;
        print_limits(s, common);
    }
    if (!a.hits_out.empty()) write_hits(a.hits_out, timed.hits);

    const std::size_t n_rays = rays.rays.size();
    double mrays = timed.seconds > 0 ? n_rays / timed.seconds / 1e6 : 0;
    // Kinds present, in enum order.
    std::vector<int> kinds;
    for (int k = 0; k < kRayKinds; ++k)
        if (timed.rays_by_kind[k]) kinds.push_back(k);
    if (common.json) {
        json trace = {{"rays", n_rays},           {"hits", timed.hit_count}, {"seconds", timed.seconds},
                      {"threads", timed.threads}, {"mrays_per_s", mrays},    {"query", a.query},
                      {"distribution", rays.described}};
        json by_kind = json::object();
        for (int k : kinds) {
            json e = {{"rays", timed.rays_by_kind[k]}, {"hits", timed.hits_by_kind[k]}};
            if (counted) e["per_ray"] = per_ray_json(counted->counters_by_kind[k]);
            by_kind[std::string(ray_kind_name(static_cast<RayKind>(k)))] = e;
        }
        trace["by_kind"] = by_kind;
        if (kinds.size() > 1 || (kinds.size() == 1 && is_occlusion(static_cast<RayKind>(kinds[0]))))
            trace["shadow_query"] = a.shadow;
        if (counted) trace["per_ray"] = per_ray_json(counted->counters);
        json j = {{"scene", scene.name}, {"primitives", scene.size()}, {"hierarchy", h->name()},
                  {"params", params_json(Params(find_hierarchy(h->name())->params, a.b.set).values())},
                  {"build", to_json(s)},  {"trace", trace}};
        std::cout << j.dump(2) << "\n";
        return 0;
    }
    fmt::print("scene      {} ({} primitives: {})\n", scene.name, scene.size(), kind_summary(scene));
    fmt::print("hierarchy  {}: built in {:.4f} s, {} interior, {} leaves, depth {}, {}\n", h->name(), s.seconds,
               s.interior, s.leaves, s.depth, human_bytes(s.bytes));
    // Shadow and ambient-occlusion rays are traced with --shadow's query, the others with --query's.
    bool has_occlusion = false, has_others = false;
    for (int k : kinds) (is_occlusion(static_cast<RayKind>(k)) ? has_occlusion : has_others) = true;
    const std::string queries =
        has_occlusion && has_others ? fmt::format("{} query ({} for shadow and ao rays)", a.query, a.shadow)
        : has_occlusion             ? fmt::format("{} query", a.shadow)
                                    : fmt::format("{} query", a.query);
    fmt::print("rays       {} ({}), {}, {} hits\n", n_rays, rays.described, queries, timed.hit_count);
    if (kinds.size() > 1) {
        for (int k : kinds)
            fmt::print("           {:<11} {:>9} rays {:>9} hits\n", ray_kind_name(static_cast<RayKind>(k)),
                       timed.rays_by_kind[k], timed.hits_by_kind[k]);
    }
    fmt::print("trace      {:.4f} s on {} thread{}: {:.3f} Mrays/s\n", timed.seconds, timed.threads,
               timed.threads == 1 ? "" : "s", mrays);
    if (counted) {
        auto line = [](const char* label, const RayCounters& c) {
            double n = c.rays ? static_cast<double>(c.rays) : 1;
            fmt::print("{:<13} N_IT {:.2f}  N_TS {:.2f}  N_ETS {:.2f}  N_EETS {:.2f}  box {:.2f}  plane {:.2f}  hop "
                       "{:.2f}  classify {:.2f}\n",
                       label, c.prim_tests() / n, c.steps / n, c.leaves / n, c.empty_leaves / n, c.box / n,
                       c.plane / n, c.hop / n, c.classify / n);
        };
        line("per ray", counted->counters);
        if (kinds.size() > 1)
            for (int k : kinds)
                line(fmt::format("  {}", ray_kind_name(static_cast<RayKind>(k))).c_str(), counted->counters_by_kind[k]);
    }
    if (!a.hits_out.empty()) fmt::print("hits       written to {}\n", a.hits_out);
    return 0;
}

Subcommand setup_trace(CLI::App& parent, Common& common) {
    auto a = std::make_shared<TraceArgs>();
    auto* cmd = parent.add_subcommand("trace", "trace rays through a hierarchy; time and count every operation");
    add_build_args(cmd, a->b);
    add_ray_args(cmd, a->rays);
    cmd->add_option("--query", a->query,
                    "closest hit, any hit (occlusion), or all (visit everything the ray meets, no early exit)")
        ->check(CLI::IsMember({"closest", "any", "all"}))
        ->capture_default_str();
    cmd->add_option("--shadow", a->shadow, "query for shadow and ambient-occlusion rays: any or closest")
        ->check(CLI::IsMember({"closest", "any"}))
        ->capture_default_str();
    cmd->add_option("--hits", a->hits_out, "write hits (int32 id, float32 t per ray) to this file")
        ->each([a](const std::string&) { a->hits_given = true; });
    cmd->add_option("-j,--threads", a->threads, "threads (0: all cores)")->check(CLI::Range(0, 1024))->capture_default_str();
    cmd->add_flag("--no-count", a->no_count, "skip the counting pass (timing only)");
    add_common(cmd, common);
    cmd->footer(hierarchy_footer());
    return {cmd, [a, &common] { return cmd_trace(*a, common); }};
}

const CommandRegistration reg{30, setup_trace};

}  // namespace
}  // namespace rtcost::cli
