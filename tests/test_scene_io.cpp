// Scene input: the NFF reader on the SPD scenes and on broken input, meshes through assimp,
// the built-in generators and load_scene's dispatch.

#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "rtcost/io.hpp"

namespace fs = std::filesystem;
using namespace rtcost;

namespace {

std::string spd_dir() {
    if (const char* env = std::getenv("RTCOST_SHARED")) return std::string(env) + "/scenes/spd/";
    return std::string(RTCOST_SHARED_DIR) + "/scenes/spd/";
}

const std::string kModels = "/usr/share/assimp/models/";

// A private temporary directory for the broken files, removed at exit.
const fs::path& temp_dir() {
    struct Dir {
        fs::path path = fs::temp_directory_path() / ("rtcost_scene_io_" + std::to_string(::getpid()));
        Dir() { fs::create_directories(path); }
        ~Dir() {
            std::error_code ec;
            fs::remove_all(path, ec);
        }
    };
    static Dir dir;
    return dir.path;
}

std::string write_file(const std::string& name, std::string_view bytes) {
    fs::path p = temp_dir() / name;
    std::ofstream(p, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    return p.string();
}

// Runs `f`, expecting an InputError; returns it (or fails the test).
template <class F>
InputError expect_input_error(F&& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e;
    }
    ADD_FAILURE() << "no InputError thrown";
    return InputError("", 0, "");
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

std::size_t count(const Scene& s, PrimKind k) { return s.kind_counts()[static_cast<int>(k)]; }

// --- NFF: the SPD scenes ---------------------------------------------------------------------

struct SpdCase {
    const char* name;
    std::size_t prims, triangles, polygons, spheres, cones, lights;
};

void PrintTo(const SpdCase& c, std::ostream* os) { *os << c.name; }

class NffSpd : public ::testing::TestWithParam<SpdCase> {};

TEST_P(NffSpd, LoadsWithTheExpectedCountsAndKinds) {
    const SpdCase& c = GetParam();
    std::string path = spd_dir() + c.name + ".nff";
    if (!fs::exists(path)) GTEST_SKIP() << "shared scene " << path << " not present";
    Scene s = read_nff_file(path);
    EXPECT_EQ(s.size(), c.prims);
    EXPECT_EQ(count(s, PrimKind::Triangle), c.triangles);
    EXPECT_EQ(count(s, PrimKind::Polygon), c.polygons);
    EXPECT_EQ(count(s, PrimKind::Sphere), c.spheres);
    EXPECT_EQ(count(s, PrimKind::Cone), c.cones);
    EXPECT_EQ(s.lights.size(), c.lights);
    EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
    EXPECT_TRUE(s.has_camera);
    EXPECT_EQ(s.camera.width, 512);
    EXPECT_EQ(s.camera.height, 512);
    EXPECT_EQ(s.background, (Vec3{0.078f, 0.361f, 0.753f}));
    EXPECT_FALSE(s.bounds().empty());
    for (const PrimRef& p : s.prims) ASSERT_LT(p.material, s.materials.size());
}

INSTANTIATE_TEST_SUITE_P(NffStandard, NffSpd,
                         ::testing::Values(SpdCase{"balls", 7382, 0, 1, 7381, 0, 3},
                                           SpdCase{"gears", 9345, 0, 9345, 0, 0, 5},
                                           SpdCase{"mount", 8196, 8192, 0, 4, 0, 1},
                                           SpdCase{"rings", 8401, 0, 1, 4200, 4200, 3},
                                           SpdCase{"teapot", 9264, 9120, 144, 0, 0, 2},
                                           SpdCase{"tetra", 4096, 4096, 0, 0, 0, 1},
                                           SpdCase{"tree", 8191, 0, 1, 4095, 4095, 7},
                                           SpdCase{"lattice", 8281, 0, 0, 2197, 6084, 6},
                                           SpdCase{"shells", 5761, 0, 0, 5761, 0, 1},
                                           SpdCase{"sombrero", 1922, 1922, 0, 0, 0, 1}),
                         [](const auto& info) { return std::string(info.param.name); });

INSTANTIATE_TEST_SUITE_P(NffLarge, NffSpd,
                         ::testing::Values(SpdCase{"balls-s5", 66431, 0, 1, 66430, 0, 3},
                                           SpdCase{"gears-s8", 74753, 0, 74753, 0, 0, 5},
                                           SpdCase{"mount-s8", 131076, 131072, 0, 4, 0, 1},
                                           SpdCase{"rings-s10", 23101, 0, 1, 11550, 11550, 3},
                                           SpdCase{"tetra-s8", 65536, 65536, 0, 0, 0, 1},
                                           SpdCase{"tree-s14", 65535, 0, 1, 32767, 32767, 7}),
                         [](const auto& info) {
                             std::string n = info.param.name;
                             for (char& ch : n)
                                 if (ch == '-') ch = '_';
                             return n;
                         });

TEST(NffSpdDetail, BallsHeaderMaterialsAndOrder) {
    std::string path = spd_dir() + "balls.nff";
    if (!fs::exists(path)) GTEST_SKIP() << "shared scene " << path << " not present";
    Scene s = read_nff_file(path);
    EXPECT_EQ(s.camera.from, (Vec3{2.1f, 1.3f, 1.7f}));
    EXPECT_EQ(s.camera.up, (Vec3{0, 0, 1}));
    EXPECT_EQ(s.camera.angle, 45.0f);
    EXPECT_EQ(s.camera.hither, 0.01f);
    ASSERT_EQ(s.materials.size(), 2u);
    EXPECT_EQ(s.materials[0].color, (Vec3{1, 0.75f, 0.33f}));
    EXPECT_EQ(s.materials[1].ks, 0.5f);
    EXPECT_EQ(s.materials[1].shine, 3.0827f);
    // File order: the ground polygon, then the spheres, root first.
    EXPECT_EQ(s.prims[0].kind, PrimKind::Polygon);
    EXPECT_EQ(s.prims[0].material, 0u);
    EXPECT_EQ(s.prims[1].kind, PrimKind::Sphere);
    EXPECT_EQ(s.prims[1].material, 1u);
    EXPECT_EQ(s.spheres[0].radius, 0.5f);
    EXPECT_EQ(s.polygons[0].count, 4u);
}

TEST(NffSpdDetail, RingsConesAndTeapotPatches) {
    std::string rings = spd_dir() + "rings.nff", teapot = spd_dir() + "teapot.nff";
    if (!fs::exists(rings) || !fs::exists(teapot)) GTEST_SKIP() << "shared scenes not present";
    Scene r = read_nff_file(rings);
    // "c 0.930995 2.61313 0 0.07412 0.287693 1.7277 0 0.07412", the first cone, is primitive 1.
    ASSERT_EQ(r.prims[1].kind, PrimKind::Cone);
    const Cone& c = r.cones[r.prims[1].index];
    EXPECT_EQ(c.base, (Vec3{0.930995f, 2.61313f, 0}));
    EXPECT_EQ(c.apex, (Vec3{0.287693f, 1.7277f, 0}));
    EXPECT_EQ(c.base_radius, 0.07412f);
    Scene t = read_nff_file(teapot);
    // Each of the 9,120 `pp 3` patches is one triangle, each of the floor's 144 `p 4` one polygon.
    EXPECT_EQ(count(t, PrimKind::Triangle), 9120u);
    EXPECT_EQ(count(t, PrimKind::Polygon), 144u);
}

// --- NFF: the grammar on small inputs --------------------------------------------------------

TEST(NffGrammar, EachEntityIsOnePrimitiveInFileOrder) {
    Scene s = read_nff(
        "# a comment line\n"
        "b 0.1 0.2 0.3   # trailing comment\n"
        "v\nfrom 0 -5 0\nat 0 0 0\nup 0 0 1\nangle 40\nhither 0.5\nresolution 320 240\n"
        "l 1 2 3\n"
        "l 4 5 6 0.5 0.25 1\n"
        "s 0 0 0 -1\n"  // inside visible: stored with |r|
        "f 1 0 0 1 0.5 10 0 1\n"
        "c 0 0 0 1 0 0 2 0.5\n"  // both circles on one line
        "c 0 0 0 -1\n0 0 2 -0.5\n"  // on two lines, inside visible
        "p 3\n0 0 0\n1 0 0\n0 1 0\n"
        "f 0 1 0 1 0 10 0.5 1.5\n"
        "pp 4\n0 0 1 0 0 1\n1 0 1 0 0 1\n1 1 1 0 0 1\n0 1 1 0 0 1\n"
        "s 3 3 3 0.25\n",
        "grammar.nff");
    ASSERT_EQ(s.size(), 6u);
    EXPECT_TRUE(s.warnings.empty());
    // `p 3` is stored as a triangle (the same test), `pp 4` as a polygon.
    const PrimKind kinds[] = {PrimKind::Sphere, PrimKind::Cone, PrimKind::Cone,
                              PrimKind::Triangle, PrimKind::Polygon, PrimKind::Sphere};
    for (std::uint32_t id = 0; id < 6; ++id) EXPECT_EQ(s.kind(id), kinds[id]) << id;
    // Material 0 is the default one added for the sphere that precedes any `f`.
    ASSERT_EQ(s.materials.size(), 3u);
    const std::uint32_t mats[] = {0, 1, 1, 1, 2, 2};
    for (std::uint32_t id = 0; id < 6; ++id) EXPECT_EQ(s.prims[id].material, mats[id]) << id;
    EXPECT_EQ(s.materials[1].color, (Vec3{1, 0, 0}));
    EXPECT_EQ(s.materials[2].t, 0.5f);
    EXPECT_EQ(s.materials[2].ior, 1.5f);
    EXPECT_EQ(s.spheres[0].radius, 1.0f);
    EXPECT_EQ(s.cones[0].apex_radius, 0.5f);
    EXPECT_EQ(s.cones[1].base_radius, 1.0f);
    EXPECT_EQ(s.cones[1].apex_radius, 0.5f);
    EXPECT_EQ(s.cones[0].apex, s.cones[1].apex);
    ASSERT_EQ(s.triangles.size(), 1u);
    EXPECT_EQ(s.triangles[0].v0, (Vec3{0, 0, 0}));
    EXPECT_EQ(s.triangles[0].v1, (Vec3{1, 0, 0}));
    EXPECT_EQ(s.triangles[0].v2, (Vec3{0, 1, 0}));
    ASSERT_EQ(s.polygons.size(), 1u);
    EXPECT_EQ(s.polygons[0].count, 4u);  // not triangulated
    EXPECT_EQ(s.polygon_vertices.size(), 4u);  // the triangle's vertices are not left in the pool
    EXPECT_EQ(s.polygon_vertices[s.polygons[0].first + 2], (Vec3{1, 1, 1}));
    EXPECT_EQ(s.background, (Vec3{0.1f, 0.2f, 0.3f}));
    ASSERT_EQ(s.lights.size(), 2u);
    EXPECT_EQ(s.lights[0].color, (Vec3{1, 1, 1}));
    EXPECT_EQ(s.lights[1].position, (Vec3{4, 5, 6}));
    EXPECT_EQ(s.lights[1].color, (Vec3{0.5f, 0.25f, 1}));
    EXPECT_TRUE(s.has_camera);
    EXPECT_EQ(s.camera.from, (Vec3{0, -5, 0}));
    EXPECT_EQ(s.camera.angle, 40.0f);
    EXPECT_EQ(s.camera.hither, 0.5f);
    EXPECT_EQ(s.camera.width, 320);
    EXPECT_EQ(s.camera.height, 240);
}

TEST(NffGrammar, NoViewpointMeansNoCameraAndFinalizeFillsDefaults) {
    Scene s = read_nff("s 0 0 0 1\n", "plain.nff");
    EXPECT_FALSE(s.has_camera);
    EXPECT_EQ(s.materials.size(), 1u);
    EXPECT_FALSE(s.lights.empty());  // finalize() adds one
    EXPECT_EQ(s.background, (Vec3{0, 0, 0}));
}

TEST(NffGrammar, NumbersInOtherSpellings) {
    Scene s = read_nff("s +1 -2.5e-1 .5 1E0\r\ns\t0 0 0\t2\ns 1e-50 -1e-42 0 1\n", "spell.nff");
    ASSERT_EQ(s.size(), 3u);
    EXPECT_EQ(s.spheres[2].center.x, 0.0f);  // underflow rounds to zero or a subnormal
    EXPECT_LE(std::fabs(s.spheres[2].center.y), 2e-42f);
    EXPECT_EQ(s.spheres[0].center, (Vec3{1, -0.25f, 0.5f}));
    EXPECT_EQ(s.spheres[0].radius, 1.0f);
    EXPECT_EQ(s.spheres[1].radius, 2.0f);
}

// --- NFF: bad input --------------------------------------------------------------------------

struct BadNff {
    const char* label;
    const char* text;
    int line;
    const char* problem;
};

void PrintTo(const BadNff& c, std::ostream* os) { *os << c.label; }

class NffBadInput : public ::testing::TestWithParam<BadNff> {};

TEST_P(NffBadInput, NamesFileLineAndProblem) {
    const BadNff& c = GetParam();
    InputError e = expect_input_error([&] { read_nff(c.text, "bad.nff"); });
    EXPECT_EQ(e.file(), "bad.nff");
    EXPECT_EQ(e.line(), c.line) << e.what();
    EXPECT_TRUE(contains(e.what(), c.problem)) << e.what();
    std::string prefix = c.line > 0 ? "bad.nff:" + std::to_string(c.line) + ": " : "bad.nff: ";
    EXPECT_EQ(std::string(e.what()).rfind(prefix, 0), 0u) << e.what();
}

INSTANTIATE_TEST_SUITE_P(
    NffCases, NffBadInput,
    ::testing::Values(
        BadNff{"TruncatedPolygon", "s 0 0 0 1\np 4\n0 0 0\n1 0 0\n", 2,
               "file ends inside polygon: expected 4 vertices, got 2"},
        BadNff{"TruncatedVertex", "p 3\n0 0 0\n1 0 0\n0 1", 1, "file ends inside polygon: expected 3 vertices, got 2"},
        BadNff{"PolygonCutByNextEntity", "p 4\n0 0 0\n1 0 0\n0 1 0\ns 0 0 0 1\n", 5,
               "polygon ends early: expected 4 vertices, got 3 before 's'"},
        BadNff{"TruncatedPatch", "pp 3\n0 0 0 0 0 1\n1 0 0 0 0 1\n", 1,
               "file ends inside polygonal patch: expected 3 vertices, got 2"},
        BadNff{"TruncatedSphere", "s 0 0 0 1\ns 1 2", 2, "file ends inside sphere"},
        BadNff{"TruncatedCone", "c 0 0 0 1\n", 1, "file ends inside cone"},
        BadNff{"MalformedNumber", "s 0 0 0 1\n\ns 0 0 abc 1\n", 3, "expected a number, got 'abc'"},
        BadNff{"NumberWithTrailingJunk", "s 0 0 0 1.5x\n", 1, "expected a number, got '1.5x'"},
        BadNff{"MalformedVertex", "p 3\n0 0 0\n1 0,0 0\n0 1 0\n", 3, "expected a number, got '0,0'"},
        BadNff{"UnknownKeyword", "s 0 0 0 1\nq 1 2 3\n", 2, "unknown entity 'q'"},
        BadNff{"ExtraNumber", "s 0 0 0 1 7\n", 1, "unexpected number '7' where an entity belongs"},
        BadNff{"HugeNumber", "s 0 0 0 1e300\n", 1, "number out of range: '1e300'"},
        BadNff{"NanSphereCentre", "s 0 0 0 1\ns 1 2 nan 1\n", 2, "sphere centre is not finite"},
        BadNff{"InfSphereRadius", "s 0 0 0 inf\n", 1, "sphere radius is not finite"},
        BadNff{"NegativeInfinity", "s 0 -inf 0 1\n", 1, "sphere centre is not finite"},
        BadNff{"OutOfRangeNumber", "s 0 0 0 1e39\n", 1, "number out of range: '1e39'"},
        BadNff{"NanPolygonVertex", "p 3\n0 0 0\n1 NaN 0\n0 1 0\n", 3, "polygon vertex 2 is not finite"},
        BadNff{"InfPatchNormal", "pp 3\n0 0 0 0 0 1\n1 0 0 0 inf 1\n0 1 0 0 0 1\n", 3,
               "polygonal patch normal 2 is not finite"},
        BadNff{"InfConeApexOnSecondLine", "c 0 0 0 1\n0 0 inf 1\n", 2, "cone apex centre is not finite"},
        BadNff{"PolygonWithTwoVertices", "p 2\n0 0 0\n1 0 0\n", 1, "polygon needs at least 3 vertices, got 2"},
        BadNff{"PolygonCountNotInteger", "p 3.5\n", 1, "expected an integer, got '3.5'"},
        BadNff{"ZeroResolution", "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 45\nhither 0\nresolution 0 512\ns 0 0 0 1\n", 7,
               "bad resolution 0 x 512"},
        BadNff{"NegativeResolution", "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 45\nhither 0\nresolution 512 -2\n", 7,
               "bad resolution"},
        BadNff{"ViewpointWithoutResolution", "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 45\ns 0 0 0 1\n", 1,
               "viewpoint lacks 'resolution'"},
        BadNff{"ViewAngle", "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 180\nresolution 4 4\n", 1, "bad view angle"},
        BadNff{"UpParallelToView", "v\nfrom 0 0 5\nat 0 0 0\nup 0 0 1\nangle 45\nresolution 4 4\n", 1,
               "parallel to the view direction"},
        BadNff{"EmptyFile", "", 0, "scene has no primitives"},
        BadNff{"OnlyComments", "# nothing\n\n   # here\nb 0 0 0\nl 1 1 1\n", 0, "scene has no primitives"},
        BadNff{"OnlyDegenerates", "s 0 0 0 0\n", 0, "scene has no primitives"}),
    [](const auto& info) { return std::string(info.param.label); });

TEST(NffBadInput, MissingFile) {
    InputError e = expect_input_error([] { read_nff_file("/no/such/dir/scene.nff"); });
    EXPECT_EQ(e.file(), "/no/such/dir/scene.nff");
    EXPECT_TRUE(contains(e.what(), "no such file")) << e.what();
}

TEST(NffBadInput, ErrorsFromFilesNameThePath) {
    std::string path = write_file("trunc.nff", "s 0 0 0 1\ns 0 0 0 1\np 4\n0 0 0\n1 0 0\n");
    InputError e = expect_input_error([&] { read_nff_file(path); });
    EXPECT_TRUE(contains(e.what(), path + ":3: file ends inside polygon")) << e.what();
}

TEST(NffDegenerate, SkippedWithWarningsAndConsecutiveIds) {
    Scene s = read_nff(
        "s 0 0 0 1\n"                                      // line 1: id 0
        "s 5 5 5 0\n"                                      // 2: zero radius
        "p 4\n0 0 0\n1 1 1\n2 2 2\n3 3 3\n"                 // 3: collinear
        "s 1 0 0 1\n"                                      // 8: id 1
        "c 1 1 1 0.5 1 1 1 0.2\n"                          // 9: coincident ends
        "c 0 0 0 0\n0 0 1 -0\n"                            // 10: both radii zero
        "p 3\n1 2 3\n1 2 3\n1 2 3\n"                       // 12: zero-area triangle, one point
        "p 3\n0 0 0\n1 0 0\n2 0 0\n"                       // 16: zero-area triangle, collinear
        "pp 3\n0 0 0 0 0 1\n0 0 0 0 0 1\n1 1 0 0 0 1\n"     // 20: two vertices coincide
        "c 0 0 0 1 0 0 1 0\n"                              // 24: id 2, a true cone (one radius 0)
        "p 4\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n",               // 25: id 3
        "degen.nff");
    ASSERT_EQ(s.size(), 4u);
    EXPECT_EQ(s.kind(0), PrimKind::Sphere);
    EXPECT_EQ(s.kind(1), PrimKind::Sphere);
    EXPECT_EQ(s.kind(2), PrimKind::Cone);
    EXPECT_EQ(s.kind(3), PrimKind::Polygon);
    EXPECT_EQ(s.spheres[s.prims[1].index].center, (Vec3{1, 0, 0}));
    EXPECT_EQ(s.polygons.size(), 1u);
    EXPECT_EQ(s.polygon_vertices.size(), 4u);  // nothing left behind by the skipped polygons
    const std::vector<std::string> want = {
        "degen.nff:2: degenerate sphere skipped (zero radius)",
        "degen.nff:3: degenerate polygon skipped (collinear vertices)",
        "degen.nff:9: degenerate cone skipped (coincident ends)",
        "degen.nff:10: degenerate cone skipped (zero radii)",
        "degen.nff:12: degenerate polygon skipped (all vertices coincide)",
        "degen.nff:16: degenerate polygon skipped (collinear vertices)",
        "degen.nff:20: degenerate polygonal patch skipped (collinear vertices)",
    };
    EXPECT_EQ(s.warnings, want);
}

// --- Meshes through assimp -------------------------------------------------------------------

#define REQUIRE_MODEL(rel)                                                                        \
    do {                                                                                          \
        if (!fs::exists(kModels + rel)) GTEST_SKIP() << kModels + rel << " not present (assimp-testmodels)"; \
    } while (0)

// Triangle counts determined from the files themselves: face lists of OBJ and PLY, the facet
// count of STL, the index count of the glTF box; degenerate triangles counted separately.
TEST(MeshModels, ObjSpider) {
    REQUIRE_MODEL("OBJ/spider.obj");
    Scene s = read_mesh(kModels + "OBJ/spider.obj");
    // 1,368 triangular faces, 56 of them with two equal vertices.
    EXPECT_EQ(s.size(), 1368u - 56u);
    EXPECT_EQ(count(s, PrimKind::Triangle), s.size());
    ASSERT_EQ(s.warnings.size(), 1u);
    EXPECT_TRUE(contains(s.warnings[0], "56 degenerate triangles skipped")) << s.warnings[0];
    EXPECT_FALSE(s.has_camera);
    EXPECT_FALSE(s.lights.empty());
    // Material "Skin" has Kd 0.827451 0.792157 0.772549.
    bool skin = false;
    for (const Material& m : s.materials) skin |= m.color == Vec3{0.827451f, 0.792157f, 0.772549f};
    EXPECT_TRUE(skin);
    for (const PrimRef& p : s.prims) ASSERT_LT(p.material, s.materials.size());
}

TEST(MeshModels, ObjQuadsAreTriangulated) {
    REQUIRE_MODEL("OBJ/box.obj");
    Scene s = read_mesh(kModels + "OBJ/box.obj");  // 6 quads
    EXPECT_EQ(s.size(), 12u);
    EXPECT_TRUE(s.warnings.empty());
}

TEST(MeshModels, ObjPointsAndLinesAreSkippedWithOneWarning) {
    REQUIRE_MODEL("OBJ/testmixed.obj");
    Scene s = read_mesh(kModels + "OBJ/testmixed.obj");  // 6 quads among lines and points
    EXPECT_EQ(s.size(), 12u);
    ASSERT_EQ(s.warnings.size(), 1u);
    EXPECT_TRUE(contains(s.warnings[0], "point or line faces skipped")) << s.warnings[0];
}

TEST(MeshModels, PlyAsciiAndBinary) {
    REQUIRE_MODEL("PLY/Wuson.ply");
    EXPECT_EQ(read_mesh(kModels + "PLY/Wuson.ply").size(), 3732u);  // 3,732 triangles
    EXPECT_EQ(read_mesh(kModels + "PLY/cube.ply").size(), 12u);     // 6 quads
    EXPECT_EQ(read_mesh(kModels + "PLY/cube_binary.ply").size(), 12u);
}

TEST(MeshModels, PolygonsAreSplitInsideThemselves) {
    // A dart: a quad whose fourth corner is reflex, area 1.5. Split from its reflex corner its
    // two triangles cover it exactly (0.75 each); a fan from the first corner would cover 2.5,
    // outside the quad. A convex pentagon (area 3) is a fan of three.
    auto area = [](const Triangle& t) { return 0.5 * length(cross(t.v1 - t.v0, t.v2 - t.v0)); };
    Scene dart = read_mesh(write_file("dart.off", "OFF\n4 1 0\n0 0 0\n2 1 0\n0 2 0\n0.5 1 0\n4 0 1 2 3\n"));
    ASSERT_EQ(dart.triangles.size(), 2u);
    EXPECT_DOUBLE_EQ(area(dart.triangles[0]), 0.75);
    EXPECT_DOUBLE_EQ(area(dart.triangles[1]), 0.75);
    Scene penta = read_mesh(write_file("penta.ply", "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\n"
                                                    "property float y\nproperty float z\nelement face 1\n"
                                                    "property list uchar int vertex_indices\nend_header\n"
                                                    "0 0 0\n2 0 0\n2 1 0\n1 2 0\n0 1 0\n5 0 1 2 3 4\n"));
    ASSERT_EQ(penta.triangles.size(), 3u);
    double sum = 0;
    for (const Triangle& t : penta.triangles) sum += area(t);
    EXPECT_DOUBLE_EQ(sum, 3.0);
}

TEST(MeshModels, StlAsciiAndBinary) {
    REQUIRE_MODEL("STL/Spider_binary.stl");
    EXPECT_EQ(read_mesh(kModels + "STL/Spider_binary.stl").size() + 56u, 1368u);
    EXPECT_EQ(read_mesh(kModels + "STL/Spider_ascii.stl").size() + 56u, 1368u);
    EXPECT_EQ(read_mesh(kModels + "STL/triangle.stl").size(), 1u);
}

TEST(MeshModels, GltfBinaryBox) {
    REQUIRE_MODEL("glTF2/BoxTextured-glTF-Binary/BoxTextured.glb");
    Scene s = read_mesh(kModels + "glTF2/BoxTextured-glTF-Binary/BoxTextured.glb");
    EXPECT_EQ(s.size(), 12u);
    // The box is a unit cube after its node transform.
    EXPECT_NEAR(s.bounds().extent().x, 1.0f, 1e-5f);
    EXPECT_NEAR(s.bounds().extent().y, 1.0f, 1e-5f);
    EXPECT_NEAR(s.bounds().extent().z, 1.0f, 1e-5f);
}

TEST(MeshModels, NodeTransformsAreApplied) {
    // glTF: one triangle (0,0,0) (1,0,0) (0,1,0), instanced by a node translated by +10 in x
    // and by a node scaled by 2; the vertex buffer is embedded as base64.
    std::string path = write_file("instanced.gltf", R"({
  "asset": {"version": "2.0"},
  "buffers": [{"byteLength": 36, "uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                 "min": [0, 0, 0], "max": [1, 1, 0]}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
  "nodes": [{"mesh": 0, "translation": [10, 0, 0]}, {"mesh": 0, "scale": [2, 2, 2]}],
  "scenes": [{"nodes": [0, 1]}],
  "scene": 0
})");
    Scene s = read_mesh(path);
    ASSERT_EQ(s.size(), 2u);
    EXPECT_EQ(s.bounds().lo, (Vec3{0, 0, 0}));
    EXPECT_EQ(s.bounds().hi, (Vec3{11, 2, 0}));
    Box3 b0 = s.prim_bounds(0), b1 = s.prim_bounds(1);
    if (b0.lo.x > b1.lo.x) std::swap(b0, b1);
    EXPECT_EQ(b0.hi, (Vec3{2, 2, 0}));  // scaled instance
    EXPECT_EQ(b1.lo, (Vec3{10, 0, 0}));  // translated instance
}

TEST(MeshBadInput, NonFiniteVertexNamesFileAndMesh) {
    // Binary STL: 80-byte header, count, then per facet normal, 3 vertices, attribute word.
    std::string bytes(80, ' ');
    auto put_u32 = [&](std::uint32_t v) { bytes.append(reinterpret_cast<const char*>(&v), 4); };
    auto put_f = [&](float v) { bytes.append(reinterpret_cast<const char*>(&v), 4); };
    put_u32(2);
    const float tris[2][9] = {{0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 0, 1, 1, 0, 1, std::nanf(""), 1, 1}};
    for (const auto& t : tris) {
        for (int k = 0; k < 3; ++k) put_f(k == 2 ? 1.0f : 0.0f);
        for (float v : t) put_f(v);
        bytes.append(2, '\0');
    }
    std::string path = write_file("nan.stl", bytes);
    InputError e = expect_input_error([&] { read_mesh(path); });
    EXPECT_EQ(e.file(), path);
    EXPECT_TRUE(contains(e.what(), "mesh 0")) << e.what();
    EXPECT_TRUE(contains(e.what(), "face 1")) << e.what();
    EXPECT_TRUE(contains(e.what(), "not finite")) << e.what();
}

TEST(MeshBadInput, InfiniteVertexInPly) {
    std::string path = write_file("inf.ply",
                                  "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                                  "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                                  "end_header\n0 0 0\n1 0 0\n0 1e39 0\n3 0 1 2\n");
    InputError e = expect_input_error([&] { read_mesh(path); });
    EXPECT_TRUE(contains(e.what(), path)) << e.what();
    EXPECT_TRUE(contains(e.what(), "not finite")) << e.what();
}

TEST(MeshBadInput, TruncatedPly) {
    // The header promises 4 vertices and 2 faces; the body stops after two vertices.
    std::string path = write_file("trunc.ply",
                                  "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                                  "property float z\nelement face 2\nproperty list uchar int vertex_indices\n"
                                  "end_header\n0 0 0\n1 0 0\n");
    InputError e = expect_input_error([&] { read_mesh(path); });
    EXPECT_EQ(e.file(), path);
    EXPECT_GT(std::string(e.what()).size(), path.size() + 4) << "no problem description: " << e.what();
}

TEST(MeshBadInput, TruncatedBinaryPly) {
    std::string head =
        "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
    std::string path = write_file("trunc_bin.ply", head + std::string(20, '\0'));  // 36 bytes of vertices due
    InputError e = expect_input_error([&] { read_mesh(path); });
    EXPECT_EQ(e.file(), path);
    EXPECT_GT(std::string(e.what()).size(), path.size() + 4) << e.what();
}

TEST(MeshBadInput, ObjFaceIndexOutOfRange) {
    std::string path = write_file("badindex.obj", "v 0 0 0\nv 1 0 0\nf 1 2 3\n");
    InputError e = expect_input_error([&] { read_mesh(path); });
    EXPECT_EQ(e.file(), path);
    EXPECT_GT(std::string(e.what()).size(), path.size() + 4) << e.what();
}

TEST(MeshBadInput, ObjWithoutFacesHasNoPrimitives) {
    std::string path = write_file("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
    InputError e = expect_input_error([&] { read_mesh(path); });
    EXPECT_EQ(e.file(), path);
    EXPECT_TRUE(contains(e.what(), path + ": ")) << e.what();
}

TEST(MeshBadInput, AssimpInvalidModels) {
    REQUIRE_MODEL("invalid/malformed.obj");
    for (const char* rel : {"invalid/malformed.obj", "invalid/empty.obj", "invalid/empty.ply", "OBJ/point_cloud.obj",
                            "Collada/lights.dae"}) {
        std::string path = kModels + rel;
        if (!fs::exists(path)) continue;
        InputError e = expect_input_error([&] { read_mesh(path); });
        EXPECT_EQ(e.file(), path);
        EXPECT_GT(std::string(e.what()).size(), path.size() + 4) << e.what();
    }
    // BoxWithInfinites.glb has infinite vertex coordinates.
    std::string inf = kModels + "glTF2/BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb";
    if (fs::exists(inf)) {
        InputError e = expect_input_error([&] { read_mesh(inf); });
        EXPECT_TRUE(contains(e.what(), "not finite")) << e.what();
    }
}

TEST(MeshBadInput, ZeroAreaTrianglesAreSkippedAndCounted) {
    std::string path = write_file("degen.obj",
                                  "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\n"
                                  "f 1 2 3\nf 1 2 4\nf 1 3 2\nf 2 4 1\n");
    Scene s = read_mesh(path);
    EXPECT_EQ(s.size(), 2u);
    ASSERT_EQ(s.warnings.size(), 1u);
    EXPECT_TRUE(contains(s.warnings[0], "2 degenerate triangles skipped")) << s.warnings[0];
    EXPECT_EQ(s.triangles[1].v1, (Vec3{0, 1, 0}));  // the third face, reversed winding kept
}

TEST(MeshBadInput, OnlyDegenerateTrianglesIsAnEmptyScene) {
    std::string path = write_file("flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");
    InputError e = expect_input_error([&] { read_mesh(path); });
    EXPECT_TRUE(contains(e.what(), "scene has no primitives")) << e.what();
}

TEST(MeshBadInput, GarbageAndMissingFiles) {
    std::string path = write_file("garbage.ply", "ply\nthis is not a ply header\n");
    InputError e = expect_input_error([&] { read_mesh(path); });
    EXPECT_EQ(e.file(), path);
    InputError m = expect_input_error([] { read_mesh("/no/such/mesh.obj"); });
    EXPECT_TRUE(contains(m.what(), "/no/such/mesh.obj")) << m.what();
}

// --- Built-in scenes -------------------------------------------------------------------------

TEST(BuiltinScenes, Names) {
    EXPECT_EQ(builtin_scene_names(), (std::vector<std::string>{"balls", "tetra"}));
}

TEST(BuiltinScenes, BallsDefaultIsTheSpdSize) {
    Scene s = builtin_scene("balls");
    EXPECT_EQ(s.size(), 7382u);
    EXPECT_EQ(count(s, PrimKind::Sphere), 7381u);
    EXPECT_EQ(count(s, PrimKind::Polygon), 1u);
    EXPECT_EQ(s.lights.size(), 3u);
    EXPECT_TRUE(s.has_camera);
    EXPECT_EQ(s.camera.from, (Vec3{2.1f, 1.3f, 1.7f}));
    EXPECT_EQ(s.camera.hither, 0.01f);
    EXPECT_EQ(s.materials.size(), 2u);
    EXPECT_TRUE(s.warnings.empty());
    EXPECT_EQ(s.name, "builtin:balls:4");
}

TEST(BuiltinScenes, BallsLevels) {
    Scene l0 = builtin_scene("balls", 0);
    EXPECT_EQ(l0.size(), 2u);  // root sphere + ground
    EXPECT_EQ(count(l0, PrimKind::Sphere), 1u);
    Scene l1 = builtin_scene("balls", 1);
    EXPECT_EQ(l1.size(), 11u);
    EXPECT_EQ(count(l1, PrimKind::Sphere), 10u);
    EXPECT_EQ(builtin_scene("balls", 2).size(), 92u);
    // Children touch their parent: centre distance = r + r/3.
    const Sphere& root = l1.spheres[0];
    for (std::size_t i = 1; i < 10; ++i) {
        const Sphere& c = l1.spheres[i];
        EXPECT_NEAR(c.radius, root.radius / 3, 1e-6f);
        EXPECT_NEAR(length(c.center - root.center), root.radius + c.radius, 1e-6f);
        EXPECT_GE(c.center.z, -1e-6f);  // none below the parent's equator
    }
}

TEST(BuiltinScenes, TetraDefaultIsTheSpdSize) {
    Scene s = builtin_scene("tetra");
    EXPECT_EQ(s.size(), 4096u);
    EXPECT_EQ(count(s, PrimKind::Triangle), 4096u);
    EXPECT_EQ(s.lights.size(), 1u);
    EXPECT_TRUE(s.has_camera);
    EXPECT_EQ(s.bounds().lo, (Vec3{-1, -1, -1}));
    EXPECT_EQ(s.bounds().hi, (Vec3{1, 1, 1}));
}

TEST(BuiltinScenes, TetraLevels) {
    Scene l1 = builtin_scene("tetra", 1);
    ASSERT_EQ(l1.size(), 4u);  // one tetrahedron
    // Faces are counter-clockwise seen from outside: normals point away from the centre.
    for (const Triangle& t : l1.triangles) {
        Vec3 n = cross(t.v1 - t.v0, t.v2 - t.v0);
        EXPECT_GT(dot(n, (t.v0 + t.v1 + t.v2) / 3.0f), 0.0f);
    }
    EXPECT_EQ(builtin_scene("tetra", 2).size(), 16u);
    EXPECT_EQ(builtin_scene("tetra", 4).size(), 256u);
}

// The generators reproduce the SPD files: same primitives, same order.
void expect_balls_match(const std::string& file, int level) {
    std::string path = spd_dir() + file + ".nff";
    if (!fs::exists(path)) GTEST_SKIP() << "shared scene " << path << " not present";
    Scene f = read_nff_file(path), g = builtin_scene("balls", level);
    ASSERT_EQ(f.size(), g.size());
    for (std::uint32_t id = 0; id < f.size(); ++id) {
        ASSERT_EQ(f.kind(id), g.kind(id)) << id;
        ASSERT_EQ(f.prims[id].material, g.prims[id].material) << id;
        if (f.kind(id) != PrimKind::Sphere) continue;
        const Sphere& a = f.spheres[f.prims[id].index];
        const Sphere& b = g.spheres[g.prims[id].index];
        // The file has 6 significant digits.
        for (int k = 0; k < 3; ++k)
            ASSERT_NEAR(a.center[k], b.center[k], 6e-6f * std::max(std::fabs(a.center[k]), 0.1f)) << "sphere " << id;
        ASSERT_NEAR(a.radius, b.radius, 6e-6f * a.radius) << "sphere " << id;
    }
    EXPECT_EQ(f.camera.from, g.camera.from);
    EXPECT_EQ(f.camera.hither, g.camera.hither);
    ASSERT_EQ(f.lights.size(), g.lights.size());
    for (std::size_t i = 0; i < f.lights.size(); ++i) EXPECT_EQ(f.lights[i].position, g.lights[i].position);
    EXPECT_EQ(f.background, g.background);
}

void expect_tetra_match(const std::string& file, int level) {
    std::string path = spd_dir() + file + ".nff";
    if (!fs::exists(path)) GTEST_SKIP() << "shared scene " << path << " not present";
    Scene f = read_nff_file(path), g = builtin_scene("tetra", level);
    ASSERT_EQ(f.size(), g.size());
    for (std::uint32_t id = 0; id < f.size(); ++id) {
        // The file's `p 3` polygons are stored as triangles, as the built-in scene's are.
        ASSERT_EQ(f.kind(id), PrimKind::Triangle) << id;
        const Triangle& p = f.triangles[f.prims[id].index];
        const Triangle& t = g.triangles[g.prims[id].index];
        // Dyadic coordinates: exact.
        ASSERT_EQ(p.v0, t.v0) << id;
        ASSERT_EQ(p.v1, t.v1) << id;
        ASSERT_EQ(p.v2, t.v2) << id;
    }
    EXPECT_EQ(f.camera.from, g.camera.from);
    EXPECT_EQ(f.camera.at, g.camera.at);
    EXPECT_EQ(f.camera.up, g.camera.up);
    EXPECT_EQ(f.camera.hither, g.camera.hither);
    ASSERT_EQ(f.lights.size(), 1u);
    EXPECT_EQ(f.lights[0].position, g.lights[0].position);
    EXPECT_EQ(f.materials[0].color, g.materials[0].color);
}

TEST(BuiltinScenes, BallsMatchesTheSpdFile) { expect_balls_match("balls", 4); }
TEST(BuiltinScenes, BallsLevel5MatchesTheSpdFile) { expect_balls_match("balls-s5", 5); }
TEST(BuiltinScenes, TetraMatchesTheSpdFile) { expect_tetra_match("tetra", 6); }
TEST(BuiltinScenes, TetraLevel8MatchesTheSpdFile) { expect_tetra_match("tetra-s8", 8); }

TEST(BuiltinScenes, BadNameAndLevel) {
    InputError n = expect_input_error([] { builtin_scene("cubes"); });
    EXPECT_TRUE(contains(n.what(), "unknown built-in scene 'cubes'")) << n.what();
    EXPECT_TRUE(contains(n.what(), "balls")) << n.what();
    EXPECT_TRUE(contains(n.what(), "tetra")) << n.what();
    InputError b = expect_input_error([] { builtin_scene("balls", 7); });
    EXPECT_EQ(b.file(), "builtin:balls");
    EXPECT_TRUE(contains(b.what(), "level must be 0..6")) << b.what();
    InputError t = expect_input_error([] { builtin_scene("tetra", 0); });
    EXPECT_TRUE(contains(t.what(), "level must be 1..9")) << t.what();
    EXPECT_THROW(builtin_scene("tetra", 10), InputError);
}

// --- load_scene ------------------------------------------------------------------------------

TEST(LoadScene, BuiltinSpecs) {
    Scene a = load_scene("builtin:tetra");
    EXPECT_EQ(a.size(), 4096u);
    EXPECT_EQ(a.name, "builtin:tetra");
    Scene b = load_scene("builtin:balls:1");
    EXPECT_EQ(b.size(), 11u);
    EXPECT_EQ(b.name, "builtin:balls:1");
    for (const char* bad : {"builtin:balls:x", "builtin:balls:", "builtin:balls:2x", "builtin:balls:-1"}) {
        InputError e = expect_input_error([&] { load_scene(bad); });
        EXPECT_EQ(e.file(), bad);
        EXPECT_TRUE(contains(e.what(), "bad level")) << e.what();
    }
    InputError u = expect_input_error([] { load_scene("builtin:nosuchscene"); });
    EXPECT_TRUE(contains(u.what(), "nosuchscene")) << u.what();
    EXPECT_THROW(load_scene("builtin:balls:9"), InputError);
}

TEST(LoadScene, DispatchesOnExtension) {
    std::string nff = write_file("upper.NFF", "s 0 0 0 1\n");
    Scene s = load_scene(nff);
    EXPECT_EQ(s.kind(0), PrimKind::Sphere);  // read as NFF, not by assimp
    EXPECT_EQ(s.name, nff);
    std::string obj = write_file("tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    Scene m = load_scene(obj);
    EXPECT_EQ(m.size(), 1u);
    EXPECT_EQ(m.kind(0), PrimKind::Triangle);
    EXPECT_EQ(m.name, obj);
}

TEST(LoadScene, MissingPathIsNoSuchFile) {
    for (const char* p : {"/no/such/scene.nff", "/no/such/mesh.ply"}) {
        InputError e = expect_input_error([&] { load_scene(p); });
        EXPECT_EQ(e.file(), p);
        EXPECT_TRUE(contains(e.what(), "no such file")) << e.what();
    }
}

TEST(LoadScene, SpdFileBySpec) {
    std::string path = spd_dir() + "tree.nff";
    if (!fs::exists(path)) GTEST_SKIP() << "shared scene " << path << " not present";
    Scene s = load_scene(path);
    EXPECT_EQ(s.size(), 8191u);
    EXPECT_EQ(s.name, path);
}

}  // namespace
