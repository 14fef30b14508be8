// What the command line writes, as a user meets it: data onto `-` alone on standard output, no
// output over a command's own input, a write error on standard output reported, an interrupted
// write leaving nothing behind; and inputs that once ended in a crash or an internal error
// (a heat map too wide to draw, a costs file of another shape, an uncounted row in a report, a
// scene whose resolution is beyond what rtcost traces).
#include <gtest/gtest.h>

#include <csignal>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <poll.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "test_support.hpp"

namespace fs = std::filesystem;

namespace {

using rtcost::test::CliRun;
using rtcost::test::run_cli;
using rtcost::test::slurp;

fs::path dir() { return rtcost::test::temp_dir("cli_out"); }

fs::path write(const std::string& name, const std::string& bytes) { return rtcost::test::write_file(dir() / name, bytes); }

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

const char* const kScene = rtcost::test::kSmallNff;

TEST(CliOutputs, DataOntoDashIsAloneOnStandardOutput) {
    // Ten rays are 320 bytes; the summary goes to stderr (nowhere with --quiet).
    CliRun r = run_cli("rays builtin:tetra:3 --dist lines --count 10 -o -");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(r.out.size(), 320u);
    EXPECT_TRUE(has(r.err, "written    -")) << r.err;
    CliRun q = run_cli("rays builtin:tetra:3 --dist lines --count 10 -o - -q");
    ASSERT_EQ(q.code, 0) << q.err;
    EXPECT_EQ(q.out, r.out);
    EXPECT_EQ(q.err, "");
    // What was written onto `-` reads back as a ray file.
    const fs::path rays = write("dash.rays", q.out);
    CliRun t = run_cli("trace builtin:tetra:3 -H bvh-sah --rays " + rays.string() + " --hits - -q");
    ASSERT_EQ(t.code, 0) << t.err;
    EXPECT_EQ(t.out.size(), 10u * 8);
}

TEST(CliOutputs, AnOutputOverAnInputIsRefusedAndTheInputKept) {
    const fs::path scene = write("in.nff", kScene);
    for (const std::string& args : {"render " + scene.string() + " --size 8x8 -o " + scene.string(),
                                    "rays " + scene.string() + " --dist lines --count 5 -o " + scene.string(),
                                    "trace " + scene.string() + " --hits " + scene.string(),
                                    "sample " + scene.string() + " --count 4 -o " + scene.string()}) {
        CliRun r = run_cli(args + " -q");
        EXPECT_EQ(r.code, 2) << args;
        EXPECT_TRUE(has(r.err, "rtcost: error: " + scene.string() + ": is the same file as the input")) << r.err;
        EXPECT_EQ(slurp(scene), kScene) << args;
    }
    // A ray file read and written by the same command.
    ASSERT_EQ(run_cli("rays " + scene.string() + " --dist lines --count 5 -o " + (dir() / "r.rays").string() + " -q").code, 0);
    const std::string before = slurp(dir() / "r.rays");
    CliRun t = run_cli("trace " + scene.string() + " --rays " + (dir() / "r.rays").string() + " --hits " +
                       (dir() / "r.rays").string() + " -q");
    EXPECT_EQ(t.code, 2);
    EXPECT_EQ(slurp(dir() / "r.rays"), before);
}

TEST(CliOutputs, EmptyOutputPathsAreRefused) {
    for (const char* args : {"rays builtin:tetra:3 --dist lines --count 5 -o ''", "trace builtin:tetra:3 --hits ''"}) {
        CliRun r = run_cli(args);
        EXPECT_EQ(r.code, 2) << args;
        EXPECT_TRUE(has(r.err, "empty output path")) << r.err;
    }
}

TEST(CliOutputs, AFailedWriteOnStandardOutputIsAnError) {
    if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full here";
    const int code = std::system((std::string(RTCOST_CLI) + " info builtin:tetra:3 > /dev/full 2> /dev/null").c_str());
    ASSERT_TRUE(WIFEXITED(code));
    EXPECT_EQ(WEXITSTATUS(code), 2);
}

TEST(CliOutputs, AnInterruptedWriteLeavesNoTemporaryFile) {
    // Deterministic: the temporary rtcost will write is made a FIFO first, so its write stalls
    // once the pipe is full (10,000 rays are 320 KB); a byte read from it says the write has
    // begun, and the process is then ended. Its handler must remove the temporary.
    const fs::path out = fs::weakly_canonical(dir() / "stalled.rays");
    int go[2];
    ASSERT_EQ(::pipe(go), 0);
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
        char c;
        if (::read(go[0], &c, 1) != 1) ::_exit(126);
        const int null = ::open("/dev/null", O_WRONLY);
        ::dup2(null, STDOUT_FILENO);
        ::dup2(null, STDERR_FILENO);
        ::execl(RTCOST_CLI, RTCOST_CLI, "rays", "builtin:tetra:3", "--dist", "lines", "--count", "10000", "-o",
                out.c_str(), "-q", static_cast<char*>(nullptr));
        ::_exit(127);
    }
    const fs::path tmp = out.string() + ".tmp." + std::to_string(pid);
    ASSERT_EQ(::mkfifo(tmp.c_str(), 0600), 0);
    const int fifo = ::open(tmp.c_str(), O_RDONLY | O_NONBLOCK);
    ASSERT_GE(fifo, 0);
    ASSERT_EQ(::write(go[1], "x", 1), 1);
    pollfd p{fifo, POLLIN, 0};
    const bool writing = ::poll(&p, 1, 120000) == 1 && (p.revents & POLLIN);
    char byte;
    EXPECT_TRUE(writing && ::read(fifo, &byte, 1) == 1);
    ::kill(pid, SIGTERM);
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    ::close(fifo);
    ::close(go[0]);
    ::close(go[1]);
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM) << status;
    EXPECT_FALSE(fs::exists(tmp));
    EXPECT_FALSE(fs::exists(out));
    fs::remove(tmp);
}

TEST(CliOutputs, AnIgnoredSignalStaysIgnored) {
    // nohup's SIGHUP: the handlers that remove a temporary are not put in its place. The signal
    // comes half a second in (2 million rays take longer), once main has installed its handlers.
    const fs::path out = dir() / "hup.rays";
    const std::string cmd = "bash -c 'trap \"\" HUP; " + std::string(RTCOST_CLI) +
                            " rays builtin:tetra:3 --dist lines --count 2000000 -o " + out.string() +
                            " -q > /dev/null & sleep 0.5; kill -HUP $!; wait $!'";
    const int status = std::system(cmd.c_str());
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 0);
    EXPECT_EQ(fs::file_size(out), 2000000u * 32);
    fs::remove(out);
}

TEST(CliOutputs, AnOutputNamedLikeADistributionIsNotTakenForIt) {
    // `--dist lines -o lines` twice: the distribution's name is not the file of that name.
    const fs::path d = dir() / "named";
    fs::create_directories(d);
    const std::string cmd = "cd " + d.string() + " && " + RTCOST_CLI +
                            " rays builtin:tetra:3 --dist lines --count 5 -o lines -q > /dev/null 2>&1";
    ASSERT_EQ(std::system(cmd.c_str()), 0);
    EXPECT_EQ(std::system(cmd.c_str()), 0);
    EXPECT_EQ(fs::file_size(d / "lines"), 5u * 32);
}

TEST(CliOutputs, ALongOutputOnAFullDiskIsAnError) {
    // `list` prints more than stdio's buffer holds, so the write fails inside the command.
    if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full here";
    const int code = std::system((std::string(RTCOST_CLI) + " list > /dev/full 2> /dev/null").c_str());
    ASSERT_TRUE(WIFEXITED(code));
    EXPECT_EQ(WEXITSTATUS(code), 2);
}

TEST(CliOutputs, AHeatMapTooWideToDrawIsRefused) {
    // It once crashed: the drawing library cannot make an image over 32,767 pixels a side.
    CliRun r = run_cli("render builtin:tetra:1 --heatmap ops --size 40000x1 -o " + (dir() / "h.png").string() + " -q", 120);
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(has(r.err, "beyond the 32767 pixels a side")) << r.err;
    EXPECT_FALSE(fs::exists(dir() / "h.png"));
}

TEST(CliOutputs, CostsFilesOfAnotherShapeAreRefused) {
    for (const char* text : {"[]", "null", "{}", "{\"box\": 1e300}", "{\"prim\": 5}"}) {
        const fs::path costs = write("c.json", text);
        CliRun r = run_cli("eval builtin:balls:3 -H bvh-sah --size 16x16 -q --costs " + costs.string());
        EXPECT_EQ(r.code, 2) << text;
        EXPECT_TRUE(has(r.err, "rtcost: error: " + costs.string() + ": ")) << text << ": " << r.err;
    }
}

TEST(CliOutputs, AReportWithAnUncountedRowIsWritten) {
    // Embree's row has no counts (null measured cost and rank); the report once failed on it.
    const fs::path html = dir() / "r.html";
    CliRun r = run_cli("report builtin:tetra:3 -H embree,bvh-sah --size 16x16 --no-design -q -o " + html.string(), 300);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(has(slurp(html), "<td>embree</td>"));
}

TEST(CliOutputs, AReportOfAnotherScenesEvaluationIsRefused) {
    const fs::path eval = dir() / "e.json";
    CliRun e = run_cli("eval builtin:balls:3 -H bvh-sah --size 16x16 -q --json");
    ASSERT_EQ(e.code, 0) << e.err;
    std::ofstream(eval) << e.out;
    CliRun r = run_cli("report builtin:tetra:3 --from-eval " + eval.string() + " --no-design -q -o " +
                       (dir() / "x.html").string());
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(has(r.err, "an evaluation of builtin:balls:3 (821 primitives), not of builtin:tetra:3 (64 primitives)"))
        << r.err;
    // As many primitives, another scene (the same file with its sphere moved): the fingerprint
    // tells them apart; the scene evaluated itself is reported.
    const fs::path scene = write("fp.nff", kScene);
    std::string moved = kScene;
    moved.replace(moved.find("s 0 0 0 1"), 9, "s 0 0.5 0 1");
    const fs::path other = write("fp-moved.nff", moved);
    e = run_cli("eval " + scene.string() + " -H bvh-sah --size 8x8 -q --json");
    ASSERT_EQ(e.code, 0) << e.err;
    std::ofstream(eval) << e.out;
    r = run_cli("report " + other.string() + " --from-eval " + eval.string() + " --no-design -q -o " +
                (dir() / "x.html").string());
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(has(r.err, "not of " + other.string() + ": the scenes differ")) << r.err;
    EXPECT_FALSE(fs::exists(dir() / "x.html"));
    r = run_cli("report " + scene.string() + " --from-eval " + eval.string() + " --no-design -q -o " +
                (dir() / "x.html").string());
    EXPECT_EQ(r.code, 0) << r.err;
}

TEST(CliOutputs, ASceneResolutionBeyondTheRayLimitNeedsASize) {
    std::string text = kScene;
    text.replace(text.find("resolution 8 8"), 14, "resolution 65536 65536");
    const fs::path scene = write("huge.nff", text);
    CliRun r = run_cli("trace " + scene.string() + " -H bvh-sah -q", 60);
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(has(r.err, scene.string() + ": its resolution 65536x65536 is 4294967296 rays")) << r.err;
    EXPECT_EQ(run_cli("trace " + scene.string() + " -H bvh-sah --size 8x8 -q", 60).code, 0);
}

TEST(CliOutputs, AFarCameraIsWarnedOfAndOneBeyondTheCoordinateBoundRefused) {
    // From 1e8 away float cannot resolve a scene of size 1: hits may be rounding noise (as for a
    // ray file's far origins); beyond 1e12 no coordinate is traced.
    CliRun far = run_cli("trace builtin:tetra:3 -H bvh-sah --size 4x4 --camera 1e8,-5,0,0,0,0,0,0,1,0.001");
    EXPECT_EQ(far.code, 0) << far.err;
    EXPECT_TRUE(has(far.err, "--camera: the camera lies more than 10000 scene sizes away")) << far.err;
    CliRun near = run_cli("trace builtin:tetra:3 -H bvh-sah --size 4x4 --camera 0,-5,0,0,0,0,0,0,1,40");
    EXPECT_EQ(near.code, 0);
    EXPECT_FALSE(has(near.err, "scene sizes away")) << near.err;
    CliRun beyond = run_cli("trace builtin:tetra:3 -H bvh-sah --size 4x4 --camera 1e13,-5,0,0,0,0,0,0,1,40");
    EXPECT_EQ(beyond.code, 2);
    EXPECT_TRUE(has(beyond.err, "rtcost: error: --camera: coordinate 1e+13 beyond +-1e+12")) << beyond.err;
    CliRun light = run_cli("trace builtin:tetra:3 -H bvh-sah --size 4x4 --rays shadow --light 0,0,1e13");
    EXPECT_EQ(light.code, 2);
    EXPECT_TRUE(has(light.err, "rtcost: error: --light: coordinate 1e+13 beyond +-1e+12")) << light.err;
}

}  // namespace
