// `rtcost rays`: make a ray distribution, report its counts by kind and write it as a ray file.
#include <chrono>
#include <iostream>
#include <optional>

#include "cli.hpp"
#include "rtcost/whitted.hpp"

namespace rtcost::cli {
namespace {
using nlohmann::json;

struct RaysArgs {
    std::string scene;
    RaySpec spec;
    std::string out;
    bool out_given = false;  ///< -o given (an empty path is refused, not taken for none)
    int threads = 0;
};

int cmd_rays(const RaysArgs& a, const Common& common) {
    if (a.out_given) check_output_path(a.out, "--out", common, {a.scene, a.spec.name});
    Scene scene = load(a.scene, common, a.spec.view);
    auto start = std::chrono::steady_clock::now();
    RaySet set;
    {
        // Distributions made by tracing report rows; the number is known once they start.
        std::optional<Progress> progress;
        RayMaking making;
        making.threads = checked_threads(a.threads, common.quiet || common.json);
        making.progress = [&](std::size_t done, std::size_t rows) {
            if (!progress) progress.emplace(fmt::format("rays {} (rows)", a.spec.name), rows, common.quiet || common.json);
            progress->update(done);
        };
        set = make_rays(scene, a.spec, making);
    }
    print_warnings(set.warnings, common.quiet || common.json);
    double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!a.out.empty()) write_rays(a.out, set.rays);

    if (common.json) {
        json counts = json::object();
        for (const auto& [name, n] : set.summary) counts[name] = n;
        json j = {{"scene", scene.name},     {"distribution", a.spec.name}, {"described", set.described},
                  {"rays", set.rays.size()}, {"counts", counts},            {"seconds", seconds}};
        j["out"] = a.out.empty() ? json(nullptr) : json(a.out);
        std::cout << j.dump(2) << "\n";
        return 0;
    }
    fmt::print("scene      {} ({} primitives: {})\n", scene.name, scene.size(), kind_summary(scene));
    fmt::print("rays       {} ({}) in {:.3f} s\n", set.rays.size(), set.described, seconds);
    for (std::size_t i = 0; i < set.summary.size(); ++i) {
        const auto& [name, n] = set.summary[i];
        bool has_hits = i + 1 < set.summary.size() && set.summary[i + 1].first == name + "_hits";
        if (has_hits) {
            fmt::print("           {:<11} {:>9} rays {:>9} hits\n", name, n, set.summary[i + 1].second);
            ++i;
        } else {
            fmt::print("           {:<11} {:>9} rays\n", name, n);
        }
    }
    if (!a.out.empty()) fmt::print("written    {} ({} bytes)\n", a.out, set.rays.size() * 32);
    return 0;
}

Subcommand setup_rays(CLI::App& parent, Common& common) {
    auto a = std::make_shared<RaysArgs>();
    auto* cmd = parent.add_subcommand("rays", "make a ray distribution (e.g. the SPD Whitted ray tree), count it by kind, "
                                              "write it as a ray file");
    cmd->add_option("SCENE", a->scene, "scene file or builtin:NAME[:level]")->required();
    std::string names;
    for (const auto& n : distribution_names()) names += (names.empty() ? "" : ", ") + n;
    cmd->add_option("-r,--rays,-d,--dist", a->spec.name, "distribution (" + names + ") or a ray file")
        ->capture_default_str();
    cmd->add_option("-o,--out", a->out, "write the rays here (8 float32 per ray); without it, only the counts")
        ->each([a](const std::string&) { a->out_given = true; });
    cmd->add_option("--size", a->spec.size,
                    "image size WxH (spd: 512x512, eye rays through its (W+1)x(H+1) corners; others: the scene's)");
    cmd->add_option("--count", a->spec.count, "number of rays for lines and random")
        ->check(whole_number(1, kMaxRays))
        ->capture_default_str();
    cmd->add_option("--seed", a->spec.seed, "seed for random distributions")->check(whole_number(0))->capture_default_str();
    add_view_args(cmd, a->spec.view);
    cmd->add_option("-j,--threads", a->threads, "threads (0: all cores)")->check(CLI::Range(0, 1024))->capture_default_str();
    add_common(cmd, common);
    cmd->footer("Ray kinds in the counts: eye, reflection, refraction, shadow (hits of shadow rays are occluded\n"
                "segments); shadow, diffuse and ao are spawned from the hits of camera rays, which they do not include.");
    return {cmd, [a, &common] { return cmd_rays(*a, common); }};
}

const CommandRegistration reg{50, setup_rays};

}  // namespace
}  // namespace rtcost::cli
