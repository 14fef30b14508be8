// `rtcost design`: hierarchies designed by the cost model for a ray distribution, beside their
// families' yardsticks, measured on rays the design never saw (the work is rtcost::design).
#include <unistd.h>

#include <cstdio>
#include <iostream>

#include "cli.hpp"
#include "rtcost/design.hpp"

namespace rtcost::cli {
namespace {

struct DesignArgs {
    std::string scene;
    std::string families = "all";
    DesignOptions opt;
};

int cmd_design(DesignArgs& a, const Common& common) {
    Scene scene = load(a.scene, common, a.opt.rays.view);
    if (a.families != "all") {
        std::size_t start = 0;
        while (start <= a.families.size()) {
            const std::size_t comma = std::min(a.families.find(',', start), a.families.size());
            a.opt.families.push_back(a.families.substr(start, comma - start));
            start = comma + 1;
        }
    }
    const bool tty = !common.quiet && !common.json && ::isatty(STDERR_FILENO);
    if (tty) a.opt.on_step = [](const std::string& step) { fmt::print(stderr, "\r\033[K{}...", step); };
    const DesignResult r = design(scene, a.opt);
    if (tty) fmt::print(stderr, "\r\033[K");
    if (common.json) std::cout << to_json(r).dump(2) << "\n";
    else std::cout << design_table(r);
    return 0;
}

Subcommand setup_design(CLI::App& parent, Common& common) {
    auto a = std::make_shared<DesignArgs>();
    auto* cmd = parent.add_subcommand("design", "build hierarchies designed by the cost model for a ray distribution and "
                                                "measure them against their yardsticks");
    cmd->add_option("SCENE", a->scene, "scene file or builtin:NAME[:level]")->required();
    cmd->add_option("-r,--rays", a->opt.rays.name, "the distribution to design for (see rtcost rays)")->capture_default_str();
    cmd->add_option("--size", a->opt.rays.size, "image size WxH for camera-based rays (default: the scene's)");
    add_view_args(cmd, a->opt.rays.view);
    cmd->add_option("--family", a->families, "families to design, comma-separated (grid, bvh, ...), or all")
        ->capture_default_str();
    // The ranges of the designed hierarchies' own `--set sample=` and `seed=` (design_param_specs).
    cmd->add_option("--sample", a->opt.sample, "rays in the design sample")
        ->check(whole_number(1, std::uint64_t{1} << 20))
        ->capture_default_str();
    cmd->add_option("--seed", a->opt.seed, "seed of the sample's draw")
        ->check(whole_number(0, std::uint64_t{1} << 62))
        ->capture_default_str();
    cmd->add_option("--costs", a->opt.costs_file, "what the designs minimise: a costs file of rtcost calibrate (its ns per operation; the table too), unit (operation counts), ops (operation counts, a polygon's edges at a share of its test), typical (built-in ns per operation) or typical-bvh (built-in, a BVH's box test against its primitive tests); default: each family's own (typical-bvh for bvh, typical for kd, ops for grid, octree and bsp)");
    cmd->add_flag("--control", a->opt.control,
                  "also build and evaluate each family's structures a second time, the yardstick first: how far apart "
                  "two evaluations time the yardstick (twice the time)");
    add_common(cmd, common);
    return {cmd, [a, &common] { return cmd_design(*a, common); }};
}

const CommandRegistration reg{47, setup_design};

}  // namespace
}  // namespace rtcost::cli
