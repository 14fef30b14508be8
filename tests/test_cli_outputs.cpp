// What the command line writes, as a user meets it: data onto `-` alone on standard output, no
// output over a command's own input, a write error on standard output reported, an interrupted
// write leaving nothing behind; and inputs that once ended in a crash or an internal error
// (a heat map too wide to draw, a costs file of another shape, an uncounted row in a report, a
// scene whose resolution is beyond what rtcost traces).
#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <thread>
#include <unistd.h>

#include "test_support.hpp"

namespace fs = std::filesystem;

namespace {

using rtcost::test::CliRun;
using rtcost::test::run_cli;
using rtcost::test::slurp;

fs::path dir() {
    fs::path d = fs::temp_directory_path() / ("rtcost_cli_out_" + std::to_string(::getpid()));
    fs::create_directories(d);
    return d;
}

fs::path write(const std::string& name, const std::string& bytes) {
    fs::path p = dir() / name;
    std::ofstream(p, std::ios::binary) << bytes;
    return p;
}

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

const char* kScene =
    "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 40\nhither 0.1\nresolution 8 8\n"
    "l 0 5 5\nf 1 0 0 1 0 0 0 1\ns 0 0 0 1\np 3\n-3 -3 -2\n3 -3 -2\n0 3 -2\n";

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
    // Eight million rays (256 MB) take a while to write; the process is ended while it writes.
    const fs::path out = dir() / "big.rays";
    const std::string cmd = std::string(RTCOST_CLI) + " rays builtin:balls:2 --dist lines --count 8000000 -o " +
                            out.string() + " -q & echo $! > " + (dir() / "pid").string();
    ASSERT_EQ(std::system(cmd.c_str()), 0);
    const pid_t pid = std::stoi(slurp(dir() / "pid"));
    auto temporary = [&] {
        for (const auto& e : fs::directory_iterator(dir()))
            if (e.path().filename().string().starts_with("big.rays.tmp.")) return true;
        return false;
    };
    bool seen = false;
    for (int i = 0; i < 600 && !seen; ++i) {
        seen = temporary();
        if (!seen) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    ::kill(pid, SIGTERM);
    for (int i = 0; i < 200 && ::kill(pid, 0) == 0; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    if (!seen) GTEST_SKIP() << "the write ended before it could be interrupted";
    EXPECT_FALSE(temporary());
    EXPECT_FALSE(fs::exists(out));
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
