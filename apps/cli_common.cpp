// Shared pieces of the command line (see cli.hpp).
#include "cli.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fcntl.h>
#include <unistd.h>

namespace rtcost::cli {

std::vector<std::pair<int, CommandSetup>>& command_registry() {
    static std::vector<std::pair<int, CommandSetup>> registry;
    return registry;
}

CommandRegistration::CommandRegistration(int order, CommandSetup setup) {
    command_registry().emplace_back(order, setup);
}

void add_common(CLI::App* cmd, Common& common, bool with_json) {
    if (with_json) cmd->add_flag("--json", common.json, "machine-readable JSON on stdout");
    cmd->add_flag("-q,--quiet", common.quiet, "no progress and no warnings on stderr (and no summary where an output is -)");
}

CLI::Validator whole_number(std::uint64_t lo, std::uint64_t hi) {
    return CLI::Validator(
        [lo, hi](std::string& text) -> std::string {
            std::uint64_t v = 0;
            const char* end = text.data() + text.size();
            const auto [at, ec] = std::from_chars(text.data(), end, v);  // no sign, no overflow
            if (text.empty() || ec != std::errc{} || at != end || v < lo || v > hi)
                return fmt::format("'{}' is not a whole number in [{}, {}]", text, lo, hi);
            return {};
        },
        fmt::format("in [{} - {}]", lo, hi));
}

CLI::Validator positive_number() {
    return CLI::Validator(
        [](std::string& text) -> std::string {
            double v = 0;
            const char* end = text.data() + text.size();
            const auto [at, ec] = std::from_chars(text.data(), end, v);
            if (text.empty() || ec != std::errc{} || at != end || !std::isfinite(v) || !(v > 0))
                return fmt::format("'{}' is not a finite number above 0", text);
            return {};
        },
        "above 0");
}

void add_ray_args(CLI::App* cmd, RaySpec& spec) {
    std::string names;
    for (const auto& n : distribution_names()) names += (names.empty() ? "" : ", ") + n;
    cmd->add_option("-r,--rays", spec.name, "rays: a distribution (" + names + ") or a ray file (8 float32 per ray)")
        ->capture_default_str();
    cmd->add_option("--size", spec.size, "image size WxH for camera-based rays (default: the scene's)");
    cmd->add_option("--count", spec.count, "number of rays for lines and random")
        ->check(whole_number(1, kMaxRays))
        ->capture_default_str();
    cmd->add_option("--seed", spec.seed, "seed for random distributions")->check(whole_number(0))->capture_default_str();
    add_view_args(cmd, spec.view);
}

void add_view_args(CLI::App* cmd, ViewSpec& view) {
    cmd->add_option("--camera", view.camera, "camera for camera-based rays: fx,fy,fz,ax,ay,az,ux,uy,uz,fov (from, at, "
                                             "up, full field of view in degrees); default the scene's");
    cmd->add_option("--light", view.lights, "a positional light x,y,z (repeatable; replaces the scene's lights)");
}

Query parse_query(const std::string& q) { return q == "any" ? Query::Any : q == "all" ? Query::All : Query::Closest; }

void print_warnings(const std::vector<std::string>& warnings, bool quiet) {
    if (quiet || warnings.empty()) return;
    constexpr std::size_t kShown = 5;
    for (std::size_t i = 0; i < warnings.size() && i < kShown; ++i)
        fmt::print(stderr, "rtcost: warning: {}\n", warnings[i]);
    if (warnings.size() > kShown) fmt::print(stderr, "rtcost: warning: ... and {} more\n", warnings.size() - kShown);
}

Scene load(const std::string& spec, const Common& common, const ViewSpec& view) {
    Scene scene = load_scene(spec);
    apply_view(scene, view);  // which may add a warning of its own
    print_warnings(scene.warnings, common.quiet || common.json);
    return scene;
}

std::string kind_summary(const Scene& s) {
    std::string out;
    auto counts = s.kind_counts();
    for (int k = 0; k < kPrimKinds; ++k) {
        if (!counts[k]) continue;
        out += fmt::format("{}{} {}{}", out.empty() ? "" : ", ", counts[k],
                           prim_kind_name(static_cast<PrimKind>(k)), counts[k] == 1 ? "" : "s");
    }
    return out;
}

std::string hierarchy_help() {
    std::string out = "Hierarchies (--hierarchy NAME, parameters with --set key=value):\n";
    for (const HierarchyInfo* h : hierarchies()) {
        out += fmt::format("  {:<12} {}\n", h->name, h->description);
        for (const ParamSpec& p : h->params)
            out += fmt::format("      {:<22} {} [{}]\n", p.name + "=" + p.default_value, p.help, p.domain());
    }
    return out;
}

std::string hierarchy_footer() {
    std::string names;
    for (const HierarchyInfo* h : hierarchies()) names += (names.empty() ? "" : ", ") + h->name;
    return "Hierarchies: " + names + ".\n`rtcost list` prints each one's parameters with their defaults.";
}

void print_limits(const StructureStats& s, const Common& common) {
    if (common.quiet) return;  // with --json too: stderr is not the JSON
    for (const std::string& l : s.limits) fmt::print(stderr, "rtcost: warning: {}\n", l);
}

void add_build_args(CLI::App* cmd, BuildArgs& a) {
    cmd->add_option("SCENE", a.scene, "scene file (.nff, or any mesh assimp reads) or builtin:NAME[:level]")
        ->required();
    cmd->add_option("-H,--hierarchy", a.hierarchy, "hierarchy to build (see the list below)")
        ->capture_default_str();
    cmd->add_option("--set", a.set, "hierarchy parameter key=value (repeatable)");
}

std::unique_ptr<Hierarchy> build(const Scene& scene, const BuildArgs& a, const Common& common) {
    // A build reports no fraction done, so the terminal shows what is being built while it runs.
    bool tty = !common.quiet && ::isatty(STDERR_FILENO);
    if (tty) fmt::print(stderr, "building {} over {} primitives...", a.hierarchy, scene.size());
    std::fflush(stderr);
    auto h = build_hierarchy(scene, a.hierarchy, a.set);
    if (tty) fmt::print(stderr, "\r\033[K");
    if (!h->lazy()) print_limits(h->structure(), common);
    return h;
}

}  // namespace rtcost::cli

namespace rtcost::cli {

void check_output_path(const std::string& path, const std::string& what, const Common& common,
                       const std::vector<std::string>& inputs) {
    namespace fs = std::filesystem;
    if (path.empty()) throw InputError(what, 0, "empty output path");
    if (path == "-") {
        // The data keeps standard output's descriptor; what the command prints goes elsewhere.
        std::fflush(stdout);
        const int data = ::dup(STDOUT_FILENO);
        // --json is output asked for: to stderr even with --quiet.
        const bool drop = common.quiet && !common.json;
        const int summary = drop ? ::open("/dev/null", O_WRONLY) : STDERR_FILENO;
        if (data < 0 || summary < 0 || ::dup2(summary, STDOUT_FILENO) < 0)
            throw InputError(what, 0, "cannot keep standard output for the data");
        if (drop) ::close(summary);
        set_standard_output_descriptor(data);
        return;
    }
    std::error_code ec;
    if (fs::is_directory(path, ec)) throw InputError(path, 0, "is a directory; give a file name for the output");
    fs::path parent = fs::path(path).parent_path();
    if (!parent.empty() && !fs::is_directory(parent, ec))
        throw InputError(path, 0, fmt::format("directory '{}' does not exist", parent.string()));
    for (const std::string& in : inputs) {
        // A distribution's name or a built-in scene is not the file of that name.
        if (in.empty() || in == "-" || in.starts_with("builtin:") || find_ray_distribution(in)) continue;
        std::error_code e1;
        if (fs::exists(path, e1) && fs::exists(in, e1) && fs::equivalent(path, in, e1))
            throw InputError(path, 0, fmt::format("is the same file as the input {}: writing it would destroy the input", in));
    }
}

int checked_threads(int requested, bool quiet) {
    const int available = default_threads();
    if (requested > available) {
        if (!quiet)
            fmt::print(stderr, "rtcost: warning: --threads {}: the machine runs {} at once; using {}\n", requested,
                       available, available);
        return available;
    }
    return requested;
}

}  // namespace rtcost::cli
