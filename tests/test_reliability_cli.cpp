// Regression tests for issue 17 through the rtcost binary (RTCOST_CLI): exit codes and messages
// for bad options and inputs, outputs onto devices, links and directories, the mesh checks that
// assimp does not make, and hangs that must now end.
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "test_support.hpp"

namespace {
namespace fs = std::filesystem;

using CliResult = rtcost::test::CliRun;
using rtcost::test::slurp;

fs::path dir() { return rtcost::test::temp_dir("relcli"); }

// Runs the binary with a time limit (`timeout` kills a hang, which then fails the test).
CliResult rtcost(const std::string& args, int seconds = 60) { return rtcost::test::run_cli(args, seconds); }

fs::path file(const std::string& name, const std::string& bytes) { return rtcost::test::write_file(dir() / name, bytes); }

bool has(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

// Exit 2 with "rtcost: error: ..." (or CLI11's message for an option) saying `says`.
void expect_bad_input(const CliResult& r, const std::string& says, int line) {
    EXPECT_EQ(r.code, 2) << "line " << line << ": " << r.err;
    EXPECT_TRUE(has(r.err, "rtcost: error: ") || has(r.err, "--")) << "line " << line << ": " << r.err;
    EXPECT_TRUE(has(r.err, says)) << "line " << line << ": wanted '" << says << "' in: " << r.err;
}
#define EXPECT_BAD_INPUT(run, says) expect_bad_input((run), (says), __LINE__)

TEST(ReliabilityCli, CountSizeAndThreadsAreValidatedClearly) {
    EXPECT_BAD_INPUT(rtcost("trace builtin:tetra:2 --rays lines --count -1"), "--count");
    EXPECT_BAD_INPUT(rtcost("trace builtin:tetra:2 --rays lines --count 99999999999999999999"), "--count");
    EXPECT_BAD_INPUT(rtcost("trace builtin:tetra:2 --rays camera --size 65536x65536"), "4294967296 rays");
    CliResult r = rtcost("trace builtin:tetra:2 -H bvh-sah --rays lines --count 100 --threads 1000 --json");
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_FALSE(has(r.out, "\"threads\": 1000")) << r.out;
    EXPECT_BAD_INPUT(rtcost("eval builtin:tetra:2 -H bvh-sah --rays camera --size 1x1 --estimator sampled"),
                     "training and test rays");
    // A designed hierarchy's own image size is named as given (it was blamed on --size).
    r = rtcost("trace builtin:tetra:2 -H bvh-design --set size=0x0 --rays lines --count 5");
    EXPECT_BAD_INPUT(r, "--set size: '0x0'");
    EXPECT_FALSE(has(r.err, "--size")) << r.err;
}

// Every unsigned count and seed of every command: a negative number, one beyond 64 bits and
// text are refused by name, with the value as typed (CLI11 alone read "-1" as 2^64 - 1, and a
// number beyond 64 bits as that too: `rays --count -1` died in vector::reserve, `sample --count
// -1` wrote a sample, `design --sample -5` was blamed on "--set: sample=18446744073709551611").
TEST(ReliabilityCli, UnsignedOptionsRefuseNegativeHugeAndTextAsTyped) {
    const fs::path out = dir() / "refused.smp";
    const std::string sample = "sample builtin:tetra:2 --rays camera --size 8x8 --out " + out.string();
    struct Case {
        std::string args, option;
    };
    const Case cases[] = {
        {"rays builtin:tetra:2 --rays lines --count", "--count"},
        {"rays builtin:tetra:2 --rays random --seed", "--seed"},
        {"trace builtin:tetra:2 -H bvh-sah --rays random --seed", "--seed"},
        {sample + " --count", "--count"},
        {sample + " --seed", "--seed"},
        {"sample builtin:tetra:2 --rays lines --out " + out.string() + " --population", "--population"},
        {"eval builtin:tetra:2 -H bvh-sah --rays camera --size 8x8 --estimator segments --sample", "--sample"},
        {"design builtin:tetra:2 --rays camera --size 8x8 --family grid --sample", "--sample"},
        {"design builtin:tetra:2 --rays camera --size 8x8 --family grid --seed", "--seed"},
    };
    for (const Case& c : cases)
        for (const std::string value : {"-1", "99999999999999999999", "abc"}) {
            const CliResult r = rtcost(c.args + " " + value + " -q");
            EXPECT_BAD_INPUT(r, c.option + ": '" + value + "' is not a whole number");
        }
    EXPECT_FALSE(fs::exists(out));
    // The bounds are those of the designed hierarchies' own parameters (--set sample=, seed=).
    EXPECT_BAD_INPUT(rtcost("design builtin:tetra:2 --family grid --sample 2000000 -q"), "in [1, 1048576]");
    EXPECT_BAD_INPUT(rtcost("design builtin:tetra:2 --family grid --seed 9223372036854775807 -q"),
                     "in [0, 4611686018427387904]");
    // The largest seed is taken.
    const CliResult r = rtcost("rays builtin:tetra:2 --rays random --count 10 --seed 18446744073709551615 -q");
    EXPECT_EQ(r.code, 0) << r.err;
}

// With --sample-file, --sample is only the sampled estimator's training rays: without that
// estimator it was ignored without a word (and the header said the file's sample took "0.00 s to
// draw").
TEST(ReliabilityCli, SampleBesideASampleFileNeedsTheSampledEstimator) {
    const fs::path smp = dir() / "beside.smp";
    const std::string scene = "builtin:tetra:2 --rays camera --size 16x16";
    ASSERT_EQ(rtcost("sample " + scene + " --count 20 -q --out " + smp.string()).code, 0);
    const std::string eval = "eval " + scene + " -H bvh-sah --sample-file " + smp.string();
    EXPECT_BAD_INPUT(rtcost(eval + " --estimator segments --sample 5"), "--sample: the segments estimator's sample is");
    CliResult r = rtcost(eval + " --estimator segments,sampled --sample 50 -q");
    EXPECT_EQ(r.code, 0) << r.err;
    r = rtcost(eval + " --estimator segments -q");
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(has(r.out, "a sample of 20 rays (read from " + smp.string() + ")")) << r.out;
    r = rtcost(eval + " --estimator segments -q --json");
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(has(r.out, "\"sample_file\": \"" + smp.string() + "\"")) << r.out;
}

// A heat map's scale top: CLI::PositiveNumber took "nan" (a map scaled by NaN was written) and 0.
TEST(ReliabilityCli, ScaleMaxIsAFiniteNumberAboveZero) {
    const fs::path png = dir() / "scaled.png", html = dir() / "scaled.html";
    for (const std::string value : {"nan", "inf", "-1", "0", "1x"}) {
        EXPECT_BAD_INPUT(rtcost("render builtin:tetra:2 --heatmap box --scale-max " + value + " -q -o " + png.string()),
                         "--scale-max: '" + value + "' is not a finite number above 0");
        EXPECT_BAD_INPUT(rtcost("report builtin:tetra:2 --scale-max " + value + " -q -o " + html.string()),
                         "--scale-max: '" + value + "' is not a finite number above 0");
    }
    EXPECT_FALSE(fs::exists(png));
    EXPECT_FALSE(fs::exists(html));
    const CliResult r = rtcost("render builtin:tetra:2 --heatmap box --scale-max 2.5e1 -q -o " + png.string());
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(fs::exists(png));
}

TEST(ReliabilityCli, RayFileThatIsADirectoryIsNamed) {
    const std::string d = dir().string();
    EXPECT_BAD_INPUT(rtcost("trace builtin:tetra:2 --rays " + d), d + ": is a directory");
    // A costs file that is a directory: the designs' --set costs and eval's --costs.
    EXPECT_BAD_INPUT(rtcost("build builtin:tetra:2 -H bvh-design --set size=16x16 --set costs=" + d), d + ": is a directory");
    EXPECT_BAD_INPUT(rtcost("eval builtin:tetra:2 -H bvh-sah --size 16x16 --costs " + d), d + ": is a directory");
}

TEST(ReliabilityCli, OutputsOntoDevicesLinksAndDirectories) {
    CliResult r = rtcost("trace builtin:tetra:2 -H bvh-sah --rays lines --count 100 --hits /dev/null -q");
    EXPECT_EQ(r.code, 0) << r.err;
    struct stat st{};
    ASSERT_EQ(::stat("/dev/null", &st), 0);
    EXPECT_TRUE(S_ISCHR(st.st_mode)) << "/dev/null was replaced";
    if (fs::exists("/dev/full")) EXPECT_BAD_INPUT(rtcost("rays builtin:tetra:2 --dist lines --count 5000 --out /dev/full"), "/dev/full");
    // A link: the file it points to is written, the link stays.
    const fs::path target = file("hits.target", "old"), link = dir() / "hits.link";
    fs::remove(link);
    fs::create_symlink(target, link);
    r = rtcost("trace builtin:tetra:2 -H bvh-sah --rays lines --count 100 -q --hits " + link.string());
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(fs::is_symlink(link));
    EXPECT_EQ(fs::file_size(target), 800u);
    // A directory: exit 2 naming it, before any work.
    const std::string d = dir().string();
    EXPECT_BAD_INPUT(rtcost("trace builtin:tetra:2 --rays lines --count 100 --hits " + d), d + ": is a directory");
    EXPECT_BAD_INPUT(rtcost("render builtin:tetra:2 --size 8x8 -o " + d), d + ": is a directory");
    EXPECT_BAD_INPUT(rtcost("rays builtin:tetra:2 --dist lines --count 10 --out " + d), d + ": is a directory");
    EXPECT_BAD_INPUT(rtcost("calibrate builtin:tetra:2 -H bvh-sah -o " + d), d + ": is a directory");
}

TEST(ReliabilityCli, ASampleOfAnotherSceneStopsEvalBeforeAnyOutput) {
    const std::string smp = (dir() / "tetra.sample").string();
    ASSERT_EQ(rtcost("sample builtin:tetra:2 --rays lines --population 2000 --count 64 -q -o " + smp).code, 0);
    // tetra:3 holds every primitive id of tetra:2's sample (only the fingerprint tells them
    // apart); balls:1 holds fewer primitives than the sample's ids. Either way the fingerprint
    // is checked first.
    for (const char* other : {"builtin:balls:1", "builtin:tetra:3"}) {
        const CliResult r =
            rtcost(std::string("eval ") + other + " -H bvh-sah --rays lines --count 2000 --estimator segments --sample-file " + smp);
        EXPECT_BAD_INPUT(r, smp + ": the sample was drawn on another scene");
        EXPECT_EQ(r.out, "") << other << ": stdout before the error";
    }
    EXPECT_EQ(rtcost("eval builtin:tetra:2 -H bvh-sah --rays lines --count 2000 --estimator segments -q --sample-file " + smp).code, 0);
    // A version-1 file has no fingerprint: a primitive id beyond the scene is what tells, and
    // the error names the file (it said "sample").
    std::string v1 = slurp(smp);
    ASSERT_EQ(v1[8], 3);
    v1[8] = 1;
    v1.erase(8 + 4 + 4 + 4 * 8, 8);
    const std::string old_file = file("tetra-v1.sample", v1).string();
    const CliResult r = rtcost("eval builtin:balls:1 -H bvh-sah --rays lines --count 2000 --estimator segments --sample-file " +
                               old_file);
    EXPECT_BAD_INPUT(r, old_file + ": primitive ");
    EXPECT_TRUE(has(r.err, "is not in the scene")) << r.err;
}

TEST(ReliabilityCli, PlyWithoutEndHeaderEndsWithAnError) {
    const fs::path p = file("noend.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                                         "property float y\nproperty float z\n0 0 0\n1 0 0\n0 1 0\n");
    EXPECT_BAD_INPUT(rtcost("info " + p.string(), 20), "end_header");
}

TEST(ReliabilityCli, PlyAndOffCountsAndIndicesAreChecked) {
    auto ply = [](int v, const std::string& body) {
        return "ply\nformat ascii 1.0\nelement vertex " + std::to_string(v) +
               "\nproperty float x\nproperty float y\nproperty float z\nelement face 1\n"
               "property list uchar int vertex_indices\nend_header\n" + body;
    };
    const std::string verts = "0 0 0\n1 0 0\n0 1 0\n";
    EXPECT_EQ(rtcost("info -q " + file("ok.ply", ply(3, verts + "3 0 1 2\n")).string()).code, 0);
    EXPECT_BAD_INPUT(rtcost("info " + file("idx.ply", ply(3, verts + "3 0 1 7\n")).string()), "refers to vertex '7'");
    EXPECT_BAD_INPUT(rtcost("info " + file("count.ply", ply(5, verts + "3 0 1 2\n")).string()), "file ends");
    EXPECT_EQ(rtcost("info -q " + file("ok.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n").string()).code, 0);
    EXPECT_BAD_INPUT(rtcost("info " + file("idx.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n").string()),
                     "refers to vertex '3'");
    EXPECT_BAD_INPUT(rtcost("info " + file("count.off", "OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n").string()),
                     "declares 1 faces");
    // The mesh fuzzer's finding: "OFF" with its counts glued on ("OFF111777777770 0111...") was
    // not taken for OFF by the check, and assimp then tried to allocate 53 GB for the vertices.
    EXPECT_BAD_INPUT(rtcost("info " + file("glued.off", "OFF111777777770 01111 0\n0 0 0\n").string()),
                     "declares 111777777770 vertices");
    EXPECT_EQ(rtcost("info -q " + file("glued-ok.off", "OFF3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n").string()).code, 0);
    // Its third: assimp reads "Ply" as PLY (the check only knew "ply") and spun on a header
    // without end_header. Now any .ply goes through the check.
    EXPECT_BAD_INPUT(rtcost("info " + file("caps.ply", "Ply\nformat ascii 1.0\nelement vertex 2\nend_head0\n3 0 1 2\n").string()),
                     "no 'end_header' line");
    EXPECT_EQ(rtcost("info -q " + file("caps-ok.ply", "Ply" + ply(3, verts + "3 0 1 2\n").substr(3)).string()).code, 0);
    EXPECT_BAD_INPUT(rtcost("info " + file("nomagic.ply", "hello\n").string()), "nomagic.ply:1: PLY: the file does not begin with a line 'ply'");
    // CI's fuzz run found assimp spinning (over 120 s) on a header with garbled keywords
    // ("propr", "ppropery lis 0 0") whose `end_header` ends the file without a line end.
    const std::string garbled = "ply\nformat ascii 1.0\nelement vertex 3\npropr teyfloat \x82\n"
                                "pr$peorace 1\nppropery lis 0 0\n0 1 0\n3 0 1 2\nend_header";
    EXPECT_BAD_INPUT(rtcost("info " + file("garbled.ply", garbled).string(), 30), "garbled.ply:9: PLY: the file ends at 'end_header'");
    // rtcost now reads PLY and OFF itself. With the line end, the garbled lines are skipped as
    // text PLY does not define, and the vertex element is found to have no coordinates.
    EXPECT_BAD_INPUT(rtcost("info " + file("garbled-nl.ply", garbled + "\n").string(), 30),
                     "garbled-nl.ply: PLY: the vertex element has no properties x, y and z");
    // Values that are not numbers, and a non-integer list length or index, are named.
    EXPECT_BAD_INPUT(rtcost("info " + file("word.ply", ply(3, "0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n")).string()),
                     "word.ply:11: PLY: 'zero' is not a number");
    EXPECT_BAD_INPUT(rtcost("info " + file("frac.ply", ply(3, verts + "3 0 1.5 2\n")).string()),
                     "frac.ply:13: PLY: '1.5' is not an integer");
    EXPECT_BAD_INPUT(rtcost("info " + file("arity.ply", "ply\nformat ascii 1.0\nelement vertex 3 4\nend_header\n").string()),
                     "arity.ply:3: PLY: expected 'element NAME COUNT'");
    EXPECT_BAD_INPUT(rtcost("info " + file("noformat.ply", "ply\nelement vertex 0\nend_header\n").string()), "no 'format' line");
    EXPECT_BAD_INPUT(rtcost("info " + file("magic.ply", "ply junk\nformat ascii 1.0\nend_header\n").string()),
                     "magic.ply:1: PLY: the file does not begin with a line 'ply'");
    // Its fourth: "BINARY" anywhere on the first line let the file through to assimp unchecked.
    EXPECT_BAD_INPUT(rtcost("info " + file("bin-glued.off", "OFF111777777770 0111BINARY11 0\n").string()),
                     "bad vertex and face counts");
    EXPECT_BAD_INPUT(rtcost("info " + file("bin.off", "OFF BINARY\n").string()), "binary OFF is not supported");
    // Its second finding: assimp takes the keyword as optional, so a first line of counts is OFF
    // too (here 77770 vertices and an overflowing face count: a 45 GB allocation).
    EXPECT_EQ(rtcost("info -q " + file("bare.off", "3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n").string()).code, 0);
    EXPECT_BAD_INPUT(rtcost("info " + file("bare-huge.off", "77770 0111111111111111111111111r11 0\n1 1\n").string()),
                     "bad vertex and face counts");
    EXPECT_BAD_INPUT(rtcost("info " + file("neither.off", "hello\n3 1 0\n").string()), "neither an OFF keyword");
    // Two counts: assimp would read the next line as the third.
    EXPECT_BAD_INPUT(rtcost("info " + file("two.off", "OFF\n3 1\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n").string()),
                     "needs three numbers");
}

TEST(ReliabilityCli, FormerHangsEnd) {
    // Lines through a flat scene (one axis-aligned triangle).
    const fs::path flat = file("flat.nff", "p 3\n0 0 0\n1 0 0\n0 1 0\n");
    CliResult r = rtcost("trace " + flat.string() + " -H bvh-sah --rays lines --count 1000 --json", 30);
    EXPECT_EQ(r.code, 0) << r.err;
    // rc5d eager without a cap is refused; with a small cap it stops and says so.
    EXPECT_BAD_INPUT(rtcost("build builtin:balls:2 -H rc5d --set build=eager --set max_bytes=0", 30), "max_bytes");
    r = rtcost("build builtin:balls:2 -H rc5d --set build=eager --set max_bytes=100000 --json", 30);
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(has(r.err, "rtcost: warning: rc5d: subdivision stopped at the memory cap")) << r.err;
    EXPECT_TRUE(has(r.out, "\"limits\"")) << r.out;
}

TEST(ReliabilityCli, LimitsAreStatedAtLoad) {
    EXPECT_BAD_INPUT(rtcost("info " + file("far.nff", "s 1e20 0 0 1\n").string()), "1e+12");
    EXPECT_BAD_INPUT(rtcost("info " + file("small.nff", "s 0 0 0 1e-20\n").string()), "below 1e-12");
    CliResult r = rtcost("info " + file("deg.nff", "s 0 0 0 0\n").string());
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(has(r.err, "degenerate sphere")) << r.err;
}

}  // namespace
