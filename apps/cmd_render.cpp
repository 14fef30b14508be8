// `rtcost render`: the Whitted render whose rays `--rays spd` counts, shaded and written as PNG.
#include <chrono>
#include <iostream>

#include "cli.hpp"
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
};

int cmd_render(const RenderArgs& a, const Common& common) {
    check_output_path(a.out, "--out");
    Scene scene = load(a.b.scene, common);
    RenderOptions opt;
    opt.width = scene.camera.width;
    opt.height = scene.camera.height;
    if (!a.size.empty()) parse_size(a.size, "--size", opt.width, opt.height);
    opt.max_depth = a.depth;
    opt.threads = checked_threads(a.threads, common.quiet || common.json);
    auto h = build(scene, a.b, common);
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
    cmd->add_option("--depth", a->depth, "maximum ray tree depth (eye ray: 1)")->check(CLI::Range(1, 64))->capture_default_str();
    cmd->add_option("-j,--threads", a->threads, "threads (0: all cores)")->check(CLI::Range(0, 1024))->capture_default_str();
    add_common(cmd, common);
    cmd->footer(hierarchy_help());
    return {cmd, [a, &common] { return cmd_render(*a, common); }};
}

const CommandRegistration reg{60, setup_render};

}  // namespace
}  // namespace rtcost::cli
