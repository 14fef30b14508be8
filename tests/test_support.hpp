#pragma once
// Helpers shared by the tests: where the shared scenes are, the hard rays every hierarchy must
// get right, the comparison of two hit lists, one ray's counters, files and the CLI.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "rtcost/hierarchy.hpp"
#include "rtcost/io.hpp"
#include "rtcost/model.hpp"
#include "rtcost/rays.hpp"
#include "rtcost/trace.hpp"

namespace rtcost::test {

/// 0, 1, ..., n - 1: every primitive of a scene, or every ray of a sample.
inline std::vector<std::uint32_t> indices(std::size_t n) {
    std::vector<std::uint32_t> v(n);
    for (std::uint32_t i = 0; i < n; ++i) v[i] = i;
    return v;
}

/// Camera rays of a 40 x 40 image and 2,500 random rays through the scene's box, as one set of
/// test rays: the segments estimator's tests draw their samples from it.
inline RaySet mixed_rays(const Scene& s) {
    RaySet set;
    set.rays = camera_rays(s.camera, 40, 40);
    std::vector<Ray> more = random_rays(s.bounds(), 2500, 31);
    set.rays.insert(set.rays.end(), more.begin(), more.end());
    set.kinds.assign(set.rays.size(), RayKind::Test);
    set.described = "camera 40x40 and random 2500";
    return set;
}

/// `../shared` beside the repository (RTCOST_SHARED overrides it).
inline std::string shared_dir() {
    if (const char* env = std::getenv("RTCOST_SHARED")) return env;
    return RTCOST_SHARED_DIR;
}

inline std::string spd_path(const std::string& scene) { return shared_dir() + "/scenes/spd/" + scene + ".nff"; }

/// Skips the calling test when the shared SPD scene is not present.
#define RTCOST_REQUIRE_SPD(name)                                                                 \
    do {                                                                                         \
        if (!std::filesystem::exists(::rtcost::test::spd_path(name)))                            \
            GTEST_SKIP() << "shared scene " << ::rtcost::test::spd_path(name) << " not present"; \
    } while (0)

/// Random rays plus the hard cases: axis-parallel rays (two zero direction components), rays
/// with one zero component, rays aimed exactly at primitive vertices and at edge midpoints, and
/// rays starting inside the scene box (random_rays starts a third of its rays inside).
inline std::vector<Ray> hard_rays(const Scene& s, std::size_t n_random, std::uint64_t seed) {
    std::vector<Ray> rays = random_rays(s.bounds(), n_random, seed);
    std::vector<Ray> extra = random_rays(s.bounds(), 6000, seed + 1);
    for (std::size_t i = 0; i < extra.size(); ++i) {
        Ray r = extra[i];
        int axis = static_cast<int>(i % 3);
        if (i % 2 == 0) {  // axis-parallel
            Vec3 d{0, 0, 0};
            d[axis] = (i % 4 == 0) ? 1.0f : -1.0f;
            r.d = d;
        } else {  // one zero component
            r.d[axis] = 0;
            if (r.d == Vec3{0, 0, 0}) r.d[(axis + 1) % 3] = 1;
        }
        rays.push_back(r);
    }
    // Aim at vertices, edge midpoints and sphere centres of a spread of primitives.
    std::vector<Ray> origins = random_rays(s.bounds(), 4000, seed + 2);
    for (std::size_t i = 0; i < origins.size(); ++i) {
        std::uint32_t id = static_cast<std::uint32_t>((i * 2654435761u) % s.size());
        const PrimRef& p = s.prims[id];
        Vec3 target;
        switch (p.kind) {
            case PrimKind::Triangle: {
                const Triangle& t = s.triangles[p.index];
                target = (i % 2) ? t.v0 : (t.v0 + t.v1) * 0.5f;
                break;
            }
            case PrimKind::Polygon: {
                const Polygon& poly = s.polygons[p.index];
                Vec3 a = s.polygon_vertices[poly.first], b = s.polygon_vertices[poly.first + 1];
                target = (i % 2) ? a : (a + b) * 0.5f;
                break;
            }
            case PrimKind::Sphere: target = s.spheres[p.index].center; break;
            case PrimKind::Cone: target = s.cones[p.index].base; break;
        }
        Ray r = origins[i];
        r.d = target - r.o;
        if (r.d == Vec3{0, 0, 0}) continue;
        rays.push_back(r);
    }
    return rays;
}

/// Closest hits through `h`.
inline std::vector<Hit> closest_hits(const Hierarchy& h, std::span<const Ray> rays) {
    return trace_rays(h, rays).hits;
}

/// Counts rays where `got` disagrees with `want`: hit/miss differ, or t differs by more than
/// `rel_tol` relative. With rel_tol 0 the same primitive must come with exactly the same t, and a
/// different primitive is accepted only as a tie (a ray through a shared edge or vertex meets
/// several primitives at the same point, whose t each primitive's arithmetic rounds a little
/// differently): within 1e-6 relative.
/// `abs_tol` adds an absolute floor for hits very near the origin, where float peers round
/// differently in absolute terms (t ~ 1e-5 from a ray starting on a surface).
inline std::size_t count_mismatches(std::span<const Hit> want, std::span<const Hit> got, float rel_tol,
                                    std::string* first = nullptr, float abs_tol = 0) {
    std::size_t bad = 0;
    for (std::size_t i = 0; i < want.size(); ++i) {
        bool ok = want[i].hit() == got[i].hit();
        if (ok && want[i].hit()) {
            float tol = rel_tol * std::fabs(want[i].t) + abs_tol;
            if (rel_tol == 0 && want[i].prim != got[i].prim) tol = 1e-6f * std::fabs(want[i].t);
            ok = std::fabs(want[i].t - got[i].t) <= tol;
        }
        if (!ok && bad++ == 0 && first) {
            *first = "ray " + std::to_string(i) + ": want prim " + std::to_string(want[i].prim) + " t " +
                     std::to_string(want[i].t) + ", got prim " + std::to_string(got[i].prim) + " t " +
                     std::to_string(got[i].t);
        }
    }
    return bad;
}

/// A hierarchy to build: its name and its `--set` assignments.
using Variant = std::pair<std::string, std::vector<std::string>>;

/// The test variants the registered hierarchies declare for `use` (TestUse bits), in registry
/// order. Read inside a test, never at static initialisation (the registry fills then).
inline std::vector<Variant> registered_variants(unsigned use) {
    std::vector<Variant> out;
    for (const HierarchyInfo* info : hierarchies())
        for (const TestVariant& v : info->tests)
            if (v.uses & use) out.push_back({info->name, v.set});
    return out;
}

/// The parameters the tests that read a hierarchy's whole model tree build it with: its
/// kTestModelTree variant, or the defaults.
inline std::vector<std::string> model_tree_set(const HierarchyInfo& info) {
    for (const TestVariant& v : info.tests)
        if (v.uses & kTestModelTree) return v.set;
    return {};
}

/// Every variant returns exactly brute force's closest hits for `rays` (ties at shared edges aside).
inline void expect_variants_match_brute(const Scene& s, std::span<const Ray> rays, const std::string& what,
                                        const std::vector<Variant>& variants) {
    auto brute = build_hierarchy(s, "brute");
    std::vector<Hit> want = closest_hits(*brute, rays);
    for (const auto& [name, set] : variants) {
        auto h = build_hierarchy(s, name, set);
        std::string first;
        EXPECT_EQ(count_mismatches(want, closest_hits(*h, rays), 0.0f, &first), 0u)
            << what << " " << name << " " << ::testing::PrintToString(set) << ": " << first;
    }
}

/// How many nodes of two model trees differ (region, leaf, children or primitives, plane), or
/// SIZE_MAX when their node counts or primitive lists differ: 0 for the same tree.
inline std::size_t model_tree_differences(const ModelTree& a, const ModelTree& b) {
    if (a.nodes.size() != b.nodes.size() || a.prims != b.prims) return SIZE_MAX;
    std::size_t bad = 0;
    for (std::size_t i = 0; i < a.nodes.size(); ++i) {
        const ModelNode &x = a.nodes[i], &y = b.nodes[i];
        bad += !(x.region.lo == y.region.lo && x.region.hi == y.region.hi && x.leaf == y.leaf && x.count == y.count &&
                 x.first == y.first && x.axis == y.axis && x.split == y.split);
    }
    return bad;
}

/// The counters of one closest-hit query of `r`; `hit` is reset first and receives the hit.
inline RayCounters count_one(const Hierarchy& h, const Ray& r, Hit& hit) {
    RayCounters c;
    hit = Hit{};
    h.closest(r, hit, c);
    return c;
}

/// The whole of file `p` (empty when it cannot be read).
inline std::string slurp(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

/// A directory of this test process under the system's temporary directory, `rtcost_<tag>_<pid>`
/// (made if missing): the tests of one binary share it, binaries running at once do not.
inline std::filesystem::path temp_dir(const std::string& tag) {
    std::filesystem::path d = std::filesystem::temp_directory_path() / ("rtcost_" + tag + "_" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
}

/// Writes `bytes` to `p` (replacing it) and returns `p`.
inline std::filesystem::path write_file(const std::filesystem::path& p, const std::string& bytes) {
    std::ofstream(p, std::ios::binary) << bytes;
    return p;
}

/// A small NFF scene for the command-line tests: a camera of 8x8 pixels, a light, a sphere and a
/// triangle behind it.
inline constexpr const char* kSmallNff =
    "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 40\nhither 0.1\nresolution 8 8\n"
    "l 0 5 5\nf 1 0 0 1 0 0 0 1\ns 0 0 0 1\np 3\n-3 -3 -2\n3 -3 -2\n0 3 -2\n";

/// How a run of the rtcost binary ended: its exit code (-1: killed), stdout and stderr.
struct CliRun {
    int code;
    std::string out, err;
};

/// Runs the rtcost binary (RTCOST_CLI) with `args` and stdin from /dev/null, its output captured
/// through files in a directory of this process. With `seconds` > 0 `timeout` kills a hang (exit
/// 124), which then fails the test instead of stalling the suite.
inline CliRun run_cli(const std::string& args, int seconds = 0) {
    const std::filesystem::path d =
        std::filesystem::temp_directory_path() / ("rtcost_test_cli_" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    const std::string limit = seconds > 0 ? "timeout " + std::to_string(seconds) + " " : "";
    const std::string cmd = limit + RTCOST_CLI + " " + args + " > " + (d / "out").string() + " 2> " +
                            (d / "err").string() + " < /dev/null";
    const int status = std::system(cmd.c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(d / "out"), slurp(d / "err")};
}

struct Measured {
    double mean = 0, se = 0;  // scalar cost per ray and its standard error
    CostVector by_kind;
};

/// Mean scalar cost per ray (and its standard error) measured by the counters.
inline Measured measure_all(const Hierarchy& h, std::span<const Ray> rays, const UnitCosts& costs, Query q) {
    Measured m;
    RayCounters total;
    double sum = 0, sum2 = 0;
    for (const Ray& r : rays) {
        RayCounters c;
        Hit hit;
        if (q == Query::All) h.all(r, hit, c);
        else h.closest(r, hit, c);
        double v = costs.scalar(measured_cost(c));
        sum += v;
        sum2 += v * v;
        total += c;
    }
    double n = static_cast<double>(rays.size());
    m.mean = sum / n;
    m.se = std::sqrt(std::max(0.0, sum2 / n - m.mean * m.mean) / n);
    m.by_kind = measured_cost(total);
    return m;
}

/// With isotropic lines, `--query all` and the geometric estimator the model is exact in
/// expectation: predicted and measured cost agree within three standard errors, in total and by kind.
inline void expect_model_exact(const Scene& s, const std::string& name, const std::vector<std::string>& set = {},
                               std::size_t n_lines = 200000, double n_se = 3) {
    auto h = build_hierarchy(s, name, set);
    ASSERT_TRUE(h->modelled()) << name;
    ModelOptions opt;
    opt.query = Query::All;
    Prediction p = predict_geometric(*h, opt);  // in place, as eval does
    auto lines = line_rays(s.bounds(), n_lines, 11);
    Measured m = measure_all(*h, lines, UnitCosts{}, Query::All);
    EXPECT_NEAR(p.scalar, m.mean, n_se * m.se + 1e-9) << name << " predicted " << p.scalar << " measured " << m.mean
                                                   << " se " << m.se;
    // Kind by kind too (same standard error bound is loose but real: kinds are parts of the sum).
    EXPECT_NEAR(p.cost.box, m.by_kind.box, n_se * m.se + 1e-9) << name;
    EXPECT_NEAR(p.cost.prim_tests(), m.by_kind.prim_tests(), n_se * m.se + 1e-9) << name;
    EXPECT_NEAR(p.cost.steps, m.by_kind.steps, n_se * m.se + 1e-9) << name;
}

}  // namespace rtcost::test
