// The rtcost command line. Each subcommand lives in its own apps/cmd_*.cpp and registers itself.
#include <algorithm>
#include <malloc.h>
#include <new>

#include <fcntl.h>
#include <unistd.h>

#include "cli.hpp"

using namespace rtcost;
using namespace rtcost::cli;

int main(int argc, char** argv) {
    // Keep freed blocks of up to 64 MiB for reuse instead of handing them back to the system:
    // a run builds, models and traces one hierarchy after another with arrays of megabytes,
    // and memory handed back is paid for again, page by page, when the next array touches it
    // (on virtual machines a page fault costs microseconds: fresh per-node arrays of a 10^6-node
    // model tree took longer than the prediction that used them).
    mallopt(M_MMAP_THRESHOLD, 64 << 20);
    mallopt(M_TRIM_THRESHOLD, 256 << 20);
    CLI::App app{"rtcost: build, trace, count and model ray tracing acceleration structures"};
    app.require_subcommand(1);
    app.set_help_all_flag("--help-all", "help for every subcommand");
    app.set_version_flag("--version", std::string("rtcost ") + RTCOST_VERSION);
    Common common;
    auto registry = command_registry();
    std::stable_sort(registry.begin(), registry.end(), [](auto& x, auto& y) { return x.first < y.first; });
    std::vector<Subcommand> commands;
    for (const auto& [order, setup] : registry) commands.push_back(setup(app, common));

    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        // The project's error form, naming the subcommand whose --help lists the options.
        std::string where = "rtcost";
        for (const Subcommand& c : commands)
            if (c.app->parsed()) where += " " + c.app->get_name();
        fmt::print(stderr, "rtcost: error: {} (see {} --help)\n", e.what(), where);
        return kExitBadInput;
    }

    // Descriptors 0-2 closed by the caller would be reused by the first files opened (and `-o -`
    // would send its summary into the data): held on /dev/null instead.
    for (int fd = 0; fd < 3; ++fd)
        if (::fcntl(fd, F_GETFD) < 0 && ::open("/dev/null", fd == 0 ? O_RDONLY : O_WRONLY) < 0) return 1;
    // An output being written when Ctrl-C or a kill ends the run is removed, not left half-written.
    remove_output_on_signals();
    try {
        for (const Subcommand& c : commands)
            if (*c.app) {
                const int status = c.run();
                // What the command printed must have reached standard output (a full disk, a
                // closed pipe): a summary or JSON cut short is an error, not a success.
                std::cout.flush();
                if (!std::cout || std::fflush(stdout) != 0 || std::ferror(stdout)) {
                    fmt::print(stderr, "rtcost: error: standard output: write failed\n");
                    return kExitBadInput;
                }
                return status;
            }
    } catch (const InputError& e) {
        fmt::print(stderr, "rtcost: error: {}\n", e.what());
        return kExitBadInput;
    } catch (const std::bad_alloc&) {
        fmt::print(stderr, "rtcost: error: out of memory\n");
        return 1;
    } catch (const std::exception& e) {
        // A printed table or JSON larger than stdio's buffer fails inside fmt::print (a full
        // disk, a closed pipe): the same error as a short one found at the end.
        if (std::ferror(stdout)) {
            fmt::print(stderr, "rtcost: error: standard output: write failed\n");
            return kExitBadInput;
        }
        fmt::print(stderr, "rtcost: error: {}\n", e.what());
        return 1;
    }
    return 0;
}
