// `rtcost info`, `rtcost build` and `rtcost list`: scenes and structures without rays.
#include <iostream>

#include "cli.hpp"

namespace rtcost::cli {
namespace {
using nlohmann::json;

int cmd_info(const std::string& spec, const Common& common) {
    Scene scene = load(spec, common);
    if (common.json) {
        std::cout << to_json(scene).dump(2) << "\n";
        return 0;
    }
    const Box3& b = scene.bounds();
    const Camera& c = scene.camera;
    fmt::print("scene      {}\n", scene.name);
    fmt::print("primitives {} ({})\n", scene.size(), kind_summary(scene));
    fmt::print("bounds     ({:g}, {:g}, {:g}) - ({:g}, {:g}, {:g})\n", b.lo.x, b.lo.y, b.lo.z, b.hi.x, b.hi.y, b.hi.z);
    fmt::print("lights     {}\n", scene.lights.size());
    for (const Light& l : scene.lights) fmt::print("           at ({:g}, {:g}, {:g})\n", l.position.x, l.position.y, l.position.z);
    fmt::print("camera     from ({:g}, {:g}, {:g}) at ({:g}, {:g}, {:g}) angle {:g} hither {:g} {}x{}{}\n", c.from.x,
               c.from.y, c.from.z, c.at.x, c.at.y, c.at.z, c.angle, c.hither, c.width, c.height,
               scene.has_camera ? "" : " (default framing)");
    fmt::print("materials  {}\n", scene.materials.size());
    fmt::print("memory     {}\n", human_bytes(scene.bytes()));
    if (!scene.warnings.empty()) fmt::print("warnings   {} (skipped input)\n", scene.warnings.size());
    return 0;
}

int cmd_build(const BuildArgs& a, const Common& common) {
    Scene scene = load(a.scene, common);
    auto h = build(scene, a, common);
    StructureStats s = h->structure();
    if (common.json) {
        json j = {{"scene", scene.name},
                  {"primitives", scene.size()},
                  {"hierarchy", h->name()},
                  {"params", params_json(Params(find_hierarchy(h->name())->params, a.set).values())},
                  {"build", to_json(s)}};
        std::cout << j.dump(2) << "\n";
        return 0;
    }
    fmt::print("{} over {} ({} primitives)\n", h->name(), scene.name, scene.size());
    fmt::print("  build     {:.4f} s\n", s.seconds);
    fmt::print("  N_IN      {}   interior nodes\n", s.interior);
    fmt::print("  N_V       {}   leaves\n", s.leaves);
    fmt::print("  N_EV      {}   empty leaves\n", s.empty_leaves);
    fmt::print("  N_OIV     {}   primitive references in leaves\n", s.references);
    fmt::print("  depth     {}\n", s.depth);
    fmt::print("  memory    {}\n", human_bytes(s.bytes));
    return 0;
}

int cmd_list(const Common& common) {
    if (common.json) {
        json hs = json::array();
        for (const HierarchyInfo* h : hierarchies()) {
            json params = json::array();
            for (const ParamSpec& p : h->params) {
                json one = {{"name", p.name}, {"default", param_json(p.default_value)}, {"help", p.help},
                            {"kind", param_kind_name(p.kind)}, {"domain", p.domain()}};
                if (p.kind == ParamKind::Integer || p.kind == ParamKind::Real) {
                    one["min"] = p.lo;
                    one["max"] = p.hi;
                }
                if (!p.words.empty()) one["choices"] = p.words;
                params.push_back(one);
            }
            hs.push_back({{"name", h->name}, {"description", h->description}, {"params", params}});
        }
        json scenes = json::array();
        for (const BuiltinInfo& b : builtin_scenes())
            scenes.push_back({{"name", "builtin:" + b.name},
                              {"levels", {{"min", b.min_level}, {"max", b.max_level}, {"default", b.default_level}}}});
        json dists = distribution_names();
        json dist_info = json::array();
        for (const RayDistributionInfo* d : ray_distributions())
            dist_info.push_back({{"name", d->name}, {"description", d->description}, {"seeded_draws", d->seeded_draws}});
        std::cout << json{{"hierarchies", hs}, {"builtin_scenes", scenes}, {"distributions", dists}, {"distribution_info", dist_info}}.dump(2) << "\n";
        return 0;
    }
    fmt::print("{}", hierarchy_help());
    fmt::print("Built-in scenes (SCENE = builtin:NAME[:level]):\n");
    for (const BuiltinInfo& b : builtin_scenes())
        fmt::print("  {:<8} levels {}..{}, default {}\n", b.name, b.min_level, b.max_level, b.default_level);
    fmt::print("Ray distributions (--rays NAME, or a ray file):\n");
    for (const RayDistributionInfo* d : ray_distributions()) fmt::print("  {:<8} {}\n", d->name, d->description);
    return 0;
}


Subcommand setup_info(CLI::App& parent, Common& common) {
    auto scene = std::make_shared<std::string>();
    auto* cmd = parent.add_subcommand("info", "summarise a scene: primitives by kind, bounds, lights, camera, memory");
    cmd->add_option("SCENE", *scene, "scene file or builtin:NAME[:level]")->required();
    add_common(cmd, common);
    return {cmd, [scene, &common] { return cmd_info(*scene, common); }};
}

Subcommand setup_build(CLI::App& parent, Common& common) {
    auto a = std::make_shared<BuildArgs>();
    auto* cmd = parent.add_subcommand("build", "build a hierarchy and print its structural statistics");
    add_build_args(cmd, *a);
    add_common(cmd, common);
    cmd->footer(hierarchy_footer());
    return {cmd, [a, &common] { return cmd_build(*a, common); }};
}

Subcommand setup_list(CLI::App& parent, Common& common) {
    auto* cmd = parent.add_subcommand("list", "list hierarchies with their parameters, built-in scenes and ray distributions");
    add_common(cmd, common);
    return {cmd, [&common] { return cmd_list(common); }};
}

const CommandRegistration reg_info{10, setup_info};
const CommandRegistration reg_build{20, setup_build};
const CommandRegistration reg_list{90, setup_list};

}  // namespace
}  // namespace rtcost::cli
