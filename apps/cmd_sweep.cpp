// `rtcost sweep SPEC.json`: scenes x hierarchies x parameters x distributions as jobs on Dask.
// The sweep is Python (python/rtcost/_sweep.py, on dask.distributed); this subcommand only runs
// it with the interpreter the module was built for, the package found beside this binary.
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>

#include "cli.hpp"

namespace rtcost::cli {
namespace {

struct SweepArgs {
    std::string spec, out, scheduler;
    int workers = 0;
};

#ifdef RTCOST_PYTHON_EXECUTABLE
/// The folder holding the `rtcost` package: build/python beside build/rtcost, or the installed
/// one under the prefix (bin/../lib/python3.X/dist-packages).
std::filesystem::path python_dir() {
    namespace fs = std::filesystem;
    std::error_code ec;
    fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    for (const fs::path& dir : {exe.parent_path() / "python", exe.parent_path().parent_path() / RTCOST_PYTHON_INSTALL_DIR})
        if (fs::exists(dir / "rtcost" / "__init__.py", ec)) return dir;
    throw InputError(exe.string(), 0, "the Python package rtcost is not beside this binary (build/python)");
}
#endif

int cmd_sweep(const SweepArgs& a, const Common& common) {
#ifndef RTCOST_PYTHON_EXECUTABLE
    (void)a;
    (void)common;
    throw InputError("sweep", 0, "this rtcost was built without the Python module (RTCOST_BUILD_PYTHON=OFF)");
#else
    std::string dir = python_dir().string();
    const char* old = std::getenv("PYTHONPATH");
    std::string path = old && *old ? dir + ":" + old : dir;
    ::setenv("PYTHONPATH", path.c_str(), 1);
    std::vector<std::string> args = {RTCOST_PYTHON_EXECUTABLE, "-m", "rtcost", "sweep", a.spec};
    if (!a.out.empty()) args.insert(args.end(), {"--out", a.out});
    if (!a.scheduler.empty()) args.insert(args.end(), {"--scheduler", a.scheduler});
    if (a.workers > 0) args.insert(args.end(), {"--workers", std::to_string(a.workers)});
    if (common.json) args.push_back("--json");
    if (common.quiet) args.push_back("--quiet");
    std::vector<char*> argv;
    for (std::string& s : args) argv.push_back(s.data());
    argv.push_back(nullptr);
    std::fflush(stdout);
    ::execv(argv[0], argv.data());
    throw InputError(RTCOST_PYTHON_EXECUTABLE, 0, std::string("cannot run: ") + std::strerror(errno));
#endif
}

Subcommand setup_sweep(CLI::App& parent, Common& common) {
    auto a = std::make_shared<SweepArgs>();
    auto* cmd = parent.add_subcommand(
        "sweep", "run scenes x hierarchies x parameters x distributions as jobs on Dask (python/rtcost/_sweep.py)");
    cmd->add_option("spec", a->spec, "sweep spec (JSON)")->required();
    cmd->add_option("-o,--out", a->out, "results, one JSON line per job; a rerun skips the jobs found there");
    cmd->add_option("--scheduler", a->scheduler, "a Dask scheduler's address (default: a local cluster)");
    cmd->add_option("--workers", a->workers, "worker processes of the local cluster (default: the spec's, or cores)")
        ->check(CLI::Range(1, 1024));
    add_common(cmd, common);
    return {cmd, [a, &common] { return cmd_sweep(*a, common); }};
}

const CommandRegistration reg{80, setup_sweep};

}  // namespace
}  // namespace rtcost::cli
