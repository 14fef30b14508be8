#pragma once
// Shared pieces of the rtcost command line: common flags, scene loading, building, ray options,
// and the registry through which each subcommand's file adds itself to the app.
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <functional>
#include <string>
#include <vector>

#include "rtcost/error.hpp"
#include "rtcost/hierarchy.hpp"
#include "rtcost/io.hpp"
#include "rtcost/rays.hpp"
#include "rtcost/report.hpp"
#include "rtcost/trace.hpp"

namespace rtcost::cli {

inline constexpr int kExitBadInput = 2;

struct Common {
    bool json = false;
    bool quiet = false;
};

/// Adds --json (unless `with_json` is false) and --quiet to `cmd`.
void add_common(CLI::App* cmd, Common& common, bool with_json = true);

/// Loads a scene (path or builtin:NAME[:level]) and prints its warnings unless quiet or JSON.
Scene load(const std::string& spec, const Common& common, const ViewSpec& view = {});

/// "7381 spheres, 1 polygon".
std::string kind_summary(const Scene& s);

/// Text listing of every hierarchy and its parameters with defaults; shown by `--help`.
std::string hierarchy_help();
/// One line naming every hierarchy, for subcommands' `--help` (`rtcost list` has the table).
std::string hierarchy_footer();

struct BuildArgs {
    std::string scene;
    std::string hierarchy = "brute";
    std::vector<std::string> set;
};
void add_build_args(CLI::App* cmd, BuildArgs& a);
/// Warns on stderr (unless quiet) of every bound that stopped a build (StructureStats::limits).
void print_limits(const StructureStats& s, const Common& common);
/// Warnings (a scene's skipped input, a ray set's far rays) to stderr, the first five, unless quiet.
void print_warnings(const std::vector<std::string>& warnings, bool quiet);
/// Builds with a note on a terminal while it runs, then warns of the bounds that stopped it
/// (for a lazily built hierarchy, call print_limits after tracing).
std::unique_ptr<Hierarchy> build(const Scene& scene, const BuildArgs& a, const Common& common);

/// --rays, --size, --count, --seed into `spec`.
void add_ray_args(CLI::App* cmd, RaySpec& spec);
/// A whole number in [lo, hi], checked on the text as typed. CLI11 reads "-1" into an unsigned
/// option as its wrapped value and a number beyond 64 bits as the largest one, both silently:
/// every unsigned count and seed of the command line takes this check.
CLI::Validator whole_number(std::uint64_t lo, std::uint64_t hi = UINT64_MAX);
/// A finite number above 0, checked on the text as typed (CLI::PositiveNumber takes "nan").
CLI::Validator positive_number();
/// --camera and --light into `view`.
void add_view_args(CLI::App* cmd, ViewSpec& view);

/// Refuses, before any long work, an output path (option `what`) that is empty, a directory,
/// in a directory that does not exist, or the same file as one of `inputs` (the command's input
/// files, which writing would destroy): InputError naming the path. `-` is standard output: the
/// command's summary then goes to stderr (nowhere when quiet), so that only data reaches it.
void check_output_path(const std::string& path, const std::string& what, const Common& common,
                       const std::vector<std::string>& inputs);

/// --threads clamped to the threads the machine runs at once (a warning on stderr when it is
/// clamped, unless quiet); 0 stays 0 (all cores).
int checked_threads(int requested, bool quiet);

/// Parses --query.
Query parse_query(const std::string& q);

/// A subcommand: the CLI11 app it added, and what runs when it is chosen.
struct Subcommand {
    CLI::App* app = nullptr;
    std::function<int()> run;
};
using CommandSetup = Subcommand (*)(CLI::App& parent, Common& common);

/// Each subcommand's file registers itself; `order` sorts them in `--help`.
struct CommandRegistration {
    CommandRegistration(int order, CommandSetup setup);
};
std::vector<std::pair<int, CommandSetup>>& command_registry();

}  // namespace rtcost::cli
