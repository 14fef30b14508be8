// `rtcost sample`: draw a ray sample of a distribution and find how each ray ends, once, for the
// segments estimator and the designed hierarchies.
#include <iostream>

#include "cli.hpp"
#include "rtcost/sample.hpp"

namespace rtcost::cli {
namespace {
using nlohmann::json;

struct SampleArgs {
    std::string scene;
    RaySpec rays;
    std::size_t count = 4096;
    std::string out;
    std::string query = "closest";
    std::string shadow = "any";
};

int cmd_sample(SampleArgs& a, const Common& common) {
    check_output_path(a.out, "--out", common, {a.scene, a.rays.name});
    Scene scene = load(a.scene, common, a.rays.view);
    if (a.count == 0) throw InputError("--count", 0, "a sample needs at least one ray");
    // Any exact hierarchy finds the same ends; the SAH BVH is quick to build and to trace.
    auto reference = build(scene, BuildArgs{a.scene, "bvh-sah", {}}, common);
    // The whole distribution, so that the file says how many rays it was drawn from (eval
    // checks that its test rays are that distribution).
    RayMaking making;
    making.tracer = reference.get();
    const RaySample s = draw_sample_from(scene, make_rays(scene, a.rays, making), a.count, a.rays.seed, *reference,
                                         parse_query(a.query), parse_query(a.shadow));
    if (s.size() < a.count && !common.quiet && !common.json)
        fmt::print(stderr,
                   "rtcost: warning: --count {}: a sample of {} rays drawn (the distribution has {}, and a sample "
                   "leaves test rays)\n",
                   a.count, s.size(), s.population);
    write_sample(a.out, s);
    std::array<std::size_t, kRayKinds> rays{}, ended{};
    for (std::size_t i = 0; i < s.size(); ++i) {
        const int k = static_cast<int>(s.rays.kinds[i]);
        ++rays[k];
        ended[k] += s.first[i + 1] > s.first[i];
    }
    if (common.json) {
        json kinds = json::object();
        for (int k = 0; k < kRayKinds; ++k)
            if (rays[k])
                kinds[std::string(ray_kind_name(static_cast<RayKind>(k)))] = {
                    {"rays", rays[k]}, {"hit", ended[k]}, {"query", is_occlusion(static_cast<RayKind>(k)) ? a.shadow : a.query}};
        std::cout << json{{"scene", scene.name},           {"distribution", s.distribution}, {"population", s.population},
                          {"rays", s.size()},              {"seed", s.seed},                 {"crossings", s.crossings.size()},
                          {"by_kind", kinds},              {"file", a.out}}
                         .dump(2)
                  << "\n";
        return 0;
    }
    fmt::print("sample     {} of {} rays ({}), seed {}\n", s.size(), s.population, s.distribution, s.seed);
    for (int k = 0; k < kRayKinds; ++k)
        if (rays[k])
            fmt::print("           {:<11} {:>7} rays {:>7} end at a hit ({} query)\n", ray_kind_name(static_cast<RayKind>(k)),
                       rays[k], ended[k], is_occlusion(static_cast<RayKind>(k)) ? a.shadow : a.query);
    fmt::print("crossings  {} ({:.2f} per ray)\nwritten to {}\n", s.crossings.size(),
               s.size() ? double(s.crossings.size()) / s.size() : 0.0, a.out);
    return 0;
}

Subcommand setup_sample(CLI::App& parent, Common& common) {
    auto a = std::make_shared<SampleArgs>();
    auto* cmd = parent.add_subcommand("sample", "draw a ray sample and find how each ray ends (for --estimator segments)");
    cmd->add_option("SCENE", a->scene, "scene file or builtin:NAME[:level]")->required();
    cmd->add_option("-r,--rays", a->rays.name, "the distribution to sample (see rtcost rays)")->capture_default_str();
    cmd->add_option("--size", a->rays.size, "image size WxH for camera-based rays (default: the scene's)");
    cmd->add_option("--count", a->count, "rays in the sample")->check(whole_number(1, kMaxRays))->capture_default_str();
    cmd->add_option("--population", a->rays.count, "rays of lines and random distributions to sample from")
        ->check(whole_number(1, kMaxRays))
        ->capture_default_str();
    cmd->add_option("--seed", a->rays.seed, "seed of the distribution and of the draw")
        ->check(whole_number(0))
        ->capture_default_str();
    cmd->add_option("-o,--out", a->out, "sample file to write")->required();
    add_view_args(cmd, a->rays.view);
    cmd->add_option("--query", a->query, "query of the rays that are not occlusion rays: closest, any or all")
        ->check(CLI::IsMember({"closest", "any", "all"}))
        ->capture_default_str();
    cmd->add_option("--shadow", a->shadow, "query for shadow and ambient-occlusion rays: any or closest")
        ->check(CLI::IsMember({"closest", "any"}))
        ->capture_default_str();
    add_common(cmd, common);
    return {cmd, [a, &common] { return cmd_sample(*a, common); }};
}

const CommandRegistration reg{45, setup_sample};

}  // namespace
}  // namespace rtcost::cli
