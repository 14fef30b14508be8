// The Whitted ray tree (SPD testing procedure): rays of known trees, the published SPD counts,
// the same rays from every hierarchy; camera-hit distributions; the renderer and PNG output; the
// `rays` and `render` subcommands.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <fmt/format.h>
#include <map>
#include <set>
#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "rtcost/whitted.hpp"
#include "report_test_util.hpp"
#include "test_support.hpp"

namespace fs = std::filesystem;
using namespace rtcost;

namespace {

constexpr int kEye = static_cast<int>(RayKind::Eye), kRefl = static_cast<int>(RayKind::Reflection),
              kRefr = static_cast<int>(RayKind::Refraction), kShadow = static_cast<int>(RayKind::Shadow);

std::string camera(const char* from, const char* at, const char* up, int res = 1) {
    return fmt::format("v\nfrom {}\nat {}\nup {}\nangle 30\nhither 0.001\nresolution {} {}\n", from, at, up, res, res);
}

// Glass sphere (T > 0, Ks = 0) seen along its axis by one eye ray; light behind the eye.
const std::string kGlassSphere =
    camera("0 0 5", "0 0 0", "0 1 0") + "l 0 0 10\nf 1 1 1 0.1 0 0 0.9 1.5\ns 0 0 0 1\n";

// A square in z = 0 whose normal is +z, with material `f`.
std::string square(const std::string& f) { return "f " + f + "\np 4\n-5 -5 0\n5 -5 0\n5 5 0\n-5 5 0\n"; }

RayTree tree_of(const std::string& nff, int max_depth = 5, int size = 1) {
    Scene s = read_nff(nff, "test.nff");
    auto h = build_hierarchy(s, "bvh-sah");
    WhittedOptions opt;
    opt.width = opt.height = size;
    opt.max_depth = max_depth;
    return whitted_tree(*h, opt);
}

TEST(WhittedTree, GlassSphereOnAxisHasTheExpectedTree) {
    RayTree t = tree_of(kGlassSphere);
    // Depth first: eye (hits the front), its shadow ray, reflection off the front (misses),
    // refraction in, which hits the back from inside: a shadow ray towards the light (blocked by the
    // sphere), an internal reflection bouncing front, back, front until depth 5, each refraction
    // out missing. From inside the front, the light is behind the surface: no shadow ray.
    std::vector<RayKind> want = {RayKind::Eye,        RayKind::Shadow,     RayKind::Reflection, RayKind::Refraction,
                                 RayKind::Shadow,     RayKind::Reflection, RayKind::Reflection, RayKind::Shadow,
                                 RayKind::Reflection, RayKind::Refraction, RayKind::Refraction, RayKind::Refraction};
    ASSERT_EQ(t.kinds, want);
    EXPECT_EQ(t.counts.rays[kEye], 1u);
    EXPECT_EQ(t.counts.hits[kEye], 1u);
    EXPECT_EQ(t.counts.rays[kRefl], 4u);
    EXPECT_EQ(t.counts.hits[kRefl], 3u);
    EXPECT_EQ(t.counts.rays[kRefr], 4u);
    EXPECT_EQ(t.counts.hits[kRefr], 1u);
    EXPECT_EQ(t.counts.rays[kShadow], 3u);
    EXPECT_EQ(t.counts.hits[kShadow], 2u);  // both from inside the sphere
    // Normal incidence: the refraction goes straight on, starting just inside the front.
    const Ray& in = t.rays[3];
    EXPECT_NEAR(in.d.z, -1.0f, 1e-6f);
    EXPECT_LT(in.o.z, 1.0f);
    EXPECT_GT(in.o.z, 0.999f);
    // The first shadow ray ends at the light.
    const Ray& sh = t.rays[1];
    Vec3 end = sh.o + sh.d * sh.tmax;
    EXPECT_NEAR(end.z, 10.0f, 1e-4f);
}

TEST(WhittedTree, DepthLimitCountsTheEyeRayAsOne) {
    RayTree one = tree_of(kGlassSphere, 1);
    EXPECT_EQ(one.counts.total(), 2u);  // the eye ray and its shadow ray
    RayTree two = tree_of(kGlassSphere, 2);
    EXPECT_EQ(two.counts.rays[kRefl], 1u);
    EXPECT_EQ(two.counts.rays[kRefr], 1u);
    EXPECT_EQ(two.counts.rays[kShadow], 2u);
}

TEST(WhittedTree, SnellsLawEnteringAndLeavingBySideOfNormal) {
    const std::string glass = square("1 1 1 0.5 0 0 0.5 1.5");
    const std::string light = "l 0 0 10\n";
    // From the normal's side at 30 degrees: entering, sin t = sin 30 / 1.5.
    RayTree above = tree_of(camera("0 -1 1.7320508", "0 0 0", "0 0 1") + light + glass);
    ASSERT_EQ(above.counts.rays[kRefr], 1u);
    ASSERT_EQ(above.counts.rays[kRefl], 1u);
    for (std::size_t i = 0; i < above.rays.size(); ++i) {
        Vec3 d = normalize(above.rays[i].d);
        if (above.kinds[i] == RayKind::Refraction) {
            EXPECT_NEAR(d.y, 1.0f / 3.0f, 1e-5f);
            EXPECT_NEAR(d.z, -std::sqrt(8.0f / 9.0f), 1e-5f);
            EXPECT_LT(above.rays[i].o.z, 0.0f);  // starts on the far side
        }
        if (above.kinds[i] == RayKind::Reflection) {
            EXPECT_NEAR(d.y, 0.5f, 1e-5f);
            EXPECT_NEAR(d.z, std::sqrt(3.0f) / 2, 1e-5f);
            EXPECT_GT(above.rays[i].o.z, 0.0f);
        }
    }
    // From the back at 30 degrees: leaving, sin t = 1.5 sin 30 = 0.75.
    RayTree below = tree_of(camera("0 -1 -1.7320508", "0 0 0", "0 0 1") + light + glass);
    ASSERT_EQ(below.counts.rays[kRefr], 1u);
    for (std::size_t i = 0; i < below.rays.size(); ++i) {
        if (below.kinds[i] != RayKind::Refraction) continue;
        Vec3 d = normalize(below.rays[i].d);
        EXPECT_NEAR(d.y, 0.75f, 1e-5f);
        EXPECT_NEAR(d.z, std::sqrt(1 - 0.75f * 0.75f), 1e-5f);
    }
    // From the back at 60 degrees: 1.5 sin 60 > 1, total internal reflection, reflection only.
    RayTree tir = tree_of(camera("0 -1.7320508 -1", "0 0 0", "0 0 1") + light + glass);
    EXPECT_EQ(tir.counts.rays[kRefr], 0u);
    EXPECT_EQ(tir.counts.rays[kRefl], 1u);
    // The same angle from the front enters: both rays.
    RayTree front60 = tree_of(camera("0 -1.7320508 1", "0 0 0", "0 0 1") + light + glass);
    EXPECT_EQ(front60.counts.rays[kRefr], 1u);
    EXPECT_EQ(front60.counts.rays[kRefl], 1u);
}

TEST(WhittedTree, MirrorReflectsOpaqueDiffuseDoesNot) {
    const std::string cam = camera("0 -1 1.7320508", "0 0 0", "0 0 1") + "l 0 0 10\n";
    RayTree mirror = tree_of(cam + square("1 1 1 0.5 0.5 10 0 1"));
    EXPECT_EQ(mirror.counts.rays[kRefl], 1u);
    EXPECT_EQ(mirror.counts.rays[kRefr], 0u);
    RayTree matte = tree_of(cam + square("1 1 1 1 0 0 0 1"));
    EXPECT_EQ(matte.counts.rays[kRefl], 0u);
    EXPECT_EQ(matte.counts.rays[kRefr], 0u);
    EXPECT_EQ(matte.counts.total(), 2u);
}

TEST(WhittedTree, NoShadowRayToALightBehindTheSurfaceAsTheRaySeesIt) {
    const std::string matte = square("1 1 1 1 0 0 0 1");
    const std::string above = camera("0 -1 1.7320508", "0 0 0", "0 0 1");
    const std::string below = camera("0 -1 -1.7320508", "0 0 0", "0 0 1");
    EXPECT_EQ(tree_of(above + "l 0 0 10\n" + matte).counts.rays[kShadow], 1u);
    EXPECT_EQ(tree_of(above + "l 0 0 -10\n" + matte).counts.rays[kShadow], 0u);
    // Seen from its back, the surface's normal faces the eye: the light below is in front.
    EXPECT_EQ(tree_of(below + "l 0 0 -10\n" + matte).counts.rays[kShadow], 1u);
    EXPECT_EQ(tree_of(below + "l 0 0 10\n" + matte).counts.rays[kShadow], 0u);
    // Two lights, one occluded by a sphere between it and the point.
    RayTree t = tree_of(above + "l 0 0 10\nl 0 -10 10\n" + matte + "s 0 0 5 1\n");
    EXPECT_EQ(t.counts.rays[kShadow], 2u);
    EXPECT_EQ(t.counts.hits[kShadow], 1u);
}

// The published SPD counts (shared docs): eye rays that hit, reflection, refraction, shadow.
struct Published {
    const char* scene;
    double eye_hits, reflection, refraction, shadow;
};
const Published kPublished[] = {
    {"balls", 263169, 175095, 0, 954368},       {"gears", 245086, 304643, 207564, 2246955},
    {"mount", 173125, 354769, 354769, 412922},  {"rings", 263169, 315236, 0, 1085002},
    {"teapot", 161120, 225248, 0, 407656},      {"tetra", 49788, 0, 0, 46112},
    {"tree", 169836, 0, 0, 1097419},
};

void PrintTo(const Published& p, std::ostream* os) { *os << p.scene; }

class WhittedSpd : public ::testing::TestWithParam<Published> {};

TEST_P(WhittedSpd, CountsWithinTenPercentOfThePublishedTable) {
    const Published& p = GetParam();
    RTCOST_REQUIRE_SPD(p.scene);
    Scene s = load_scene(test::spd_path(p.scene));
    auto h = build_hierarchy(s, "bvh-sah");
    WhittedOptions opt;  // 513 x 513 corners, depth 5
    opt.record = false;
    RayTree t = whitted_tree(*h, opt);
    EXPECT_EQ(t.counts.rays[kEye], 263169u);
    auto near = [&](const char* what, double got, double want) {
        if (want == 0) {
            EXPECT_EQ(got, 0) << p.scene << " " << what;
        } else {
            EXPECT_NEAR(got / want, 1.0, 0.10) << p.scene << " " << what << ": " << got << " vs " << want;
        }
    };
    near("eye hits", t.counts.hits[kEye], p.eye_hits);
    near("reflection", t.counts.rays[kRefl], p.reflection);
    near("refraction", t.counts.rays[kRefr], p.refraction);
    near("shadow", t.counts.rays[kShadow], p.shadow);
    // Reflection and refraction rays come only from hits at depth < 5.
    EXPECT_LE(t.counts.rays[kRefr], t.counts.hits[kEye] + t.counts.hits[kRefl] + t.counts.hits[kRefr]);
}

INSTANTIATE_TEST_SUITE_P(Whitted, WhittedSpd, ::testing::ValuesIn(kPublished),
                         [](const auto& info) { return std::string(info.param.scene); });

bool same_rays(const RayTree& a, const RayTree& b) {
    return a.kinds == b.kinds && a.rays.size() == b.rays.size() &&
           std::memcmp(a.rays.data(), b.rays.data(), a.rays.size() * sizeof(Ray)) == 0;
}

TEST(WhittedTree, SameRaysFromEveryHierarchyAndThreadCount) {
    RTCOST_REQUIRE_SPD("mount");
    Scene s = load_scene(test::spd_path("mount"));
    WhittedOptions opt;
    opt.width = opt.height = 49;
    auto bvh = build_hierarchy(s, "bvh-sah");
    RayTree ref = whitted_tree(*bvh, opt);
    ASSERT_GT(ref.counts.rays[kRefr], 1000u);  // the glass spheres are in view
    for (const char* name : {"bvh-median", "kd-sah", "grid", "rc5d", "brute"}) {
        auto h = build_hierarchy(s, name);
        RayTree t = whitted_tree(*h, opt);
        EXPECT_EQ(t.counts.rays, ref.counts.rays) << name;
        EXPECT_EQ(t.counts.hits, ref.counts.hits) << name;
        EXPECT_TRUE(same_rays(t, ref)) << name;
    }
    opt.threads = 1;
    EXPECT_TRUE(same_rays(whitted_tree(*bvh, opt), ref));
}

TEST(WhittedRaySet, SpdThroughMakeRaysHasKindsAndSummary) {
    RTCOST_REQUIRE_SPD("mount");
    Scene s = load_scene(test::spd_path("mount"));
    RaySpec spec;
    spec.name = "spd";
    spec.size = "32x32";
    RaySet set = make_rays(s, spec);
    ASSERT_EQ(set.rays.size(), set.kinds.size());
    std::map<std::string, std::size_t> summary(set.summary.begin(), set.summary.end());
    EXPECT_EQ(summary["eye"], 33u * 33u);
    std::size_t eye = 0, refl = 0, refr = 0, shadow = 0;
    for (RayKind k : set.kinds) {
        eye += k == RayKind::Eye;
        refl += k == RayKind::Reflection;
        refr += k == RayKind::Refraction;
        shadow += k == RayKind::Shadow;
    }
    EXPECT_EQ(eye, summary["eye"]);
    EXPECT_EQ(refl, summary["reflection"]);
    EXPECT_EQ(refr, summary["refraction"]);
    EXPECT_EQ(shadow, summary["shadow"]);
    EXPECT_EQ(eye + refl + refr + shadow, set.rays.size());
    EXPECT_GT(summary["eye_hits"], 0u);
    EXPECT_LT(summary["eye_hits"], eye);  // the background is in view
    // Traced again through another hierarchy, every kind hits as often as it did when generated.
    auto kd = build_hierarchy(s, "kd-sah");
    TraceResult r = trace_ray_set(*kd, set, {});
    EXPECT_EQ(r.hits_by_kind[kEye], summary["eye_hits"]);
    EXPECT_EQ(r.hits_by_kind[kRefl], summary["reflection_hits"]);
    EXPECT_EQ(r.hits_by_kind[kRefr], summary["refraction_hits"]);
    EXPECT_EQ(r.hits_by_kind[kShadow], summary["shadow_hits"]);
}

// A matte ground facing up under one light, seen from above at an angle.
const std::string kGround = camera("0 -4 6", "0 0 0", "0 0 1", 16) + "l 0 0 10\n" + square("1 1 1 1 0 0 0 1");

TEST(WhittedRaySet, ShadowDiffuseAoFromCameraHits) {
    Scene s = read_nff(kGround, "ground.nff");
    RaySpec spec;
    spec.size = "16x16";
    for (const char* name : {"shadow", "diffuse", "ao"}) {
        spec.name = name;
        RaySet set = make_rays(s, spec);
        EXPECT_EQ(set.rays.size(), 256u) << name;  // every camera ray hits the ground
        for (std::size_t i = 0; i < set.rays.size(); ++i) {
            const Ray& r = set.rays[i];
            EXPECT_NEAR(r.o.z, 0.0f, 1e-3f) << name;
            EXPECT_GT(r.d.z, 0.0f) << name;  // into the hemisphere the eye sees
        }
        std::map<std::string, std::size_t> summary(set.summary.begin(), set.summary.end());
        EXPECT_EQ(summary["camera"], 256u) << name;
        EXPECT_EQ(summary["camera_hits"], 256u) << name;
    }
    spec.name = "ao";
    RaySet ao = make_rays(s, spec);
    EXPECT_FLOAT_EQ(ao.rays[0].tmax, ao_length(s));
    EXPECT_EQ(ao.kinds[0], RayKind::AO);
    spec.name = "shadow";
    RaySet sh = make_rays(s, spec);
    Vec3 end = sh.rays[7].o + sh.rays[7].d * sh.rays[7].tmax;
    EXPECT_NEAR(end.z, 10.0f, 1e-4f);
    EXPECT_NEAR(end.x, 0.0f, 1e-4f);
}

TEST(WhittedRaySet, DiffuseIsCosineWeightedAndSeeded) {
    Scene s = read_nff(kGround, "ground.nff");
    RaySpec spec;
    spec.name = "diffuse";
    spec.size = "200x200";
    RaySet a = make_rays(s, spec);
    // Cosine-weighted about +z: E[cos] = 2/3, E[cos^2] = 1/2.
    double sum = 0, sum2 = 0;
    for (const Ray& r : a.rays) {
        double c = normalize(r.d).z;
        sum += c;
        sum2 += c * c;
    }
    double n = static_cast<double>(a.rays.size()), mean = sum / n;
    double se = std::sqrt((sum2 / n - mean * mean) / n);
    EXPECT_NEAR(mean, 2.0 / 3.0, 3 * se);
    EXPECT_NEAR(sum2 / n, 0.5, 0.01);
    RaySet again = make_rays(s, spec);
    EXPECT_EQ(std::memcmp(a.rays.data(), again.rays.data(), a.rays.size() * sizeof(Ray)), 0);
    spec.seed = 2;
    RaySet other = make_rays(s, spec);
    EXPECT_NE(std::memcmp(a.rays.data(), other.rays.data(), a.rays.size() * sizeof(Ray)), 0);
}

// PNG decoding and pixels: the report tests' helpers.
using report_test::decode_png;
using report_test::pixel;

TEST(Render, SphereOverBackgroundAndPngRoundTrip) {
    Scene s = read_nff(camera("0 0 5", "0 0 0", "0 1 0", 16) + "b 0 0 1\nl 0 0 10\nf 1 0 0 1 0 0 0 1\ns 0 0 0 0.8\n",
                       "sphere.nff");
    auto h = build_hierarchy(s, "bvh-sah");
    RenderOptions opt;
    opt.width = 17;
    opt.height = 15;
    Image img = render(*h, opt);
    ASSERT_EQ(img.rgb.size(), 17u * 15u * 3u);
    auto centre = pixel(img, 8, 7);
    EXPECT_EQ(centre[0], 255);  // lit head-on: ambient + diffuse clamps
    EXPECT_EQ(centre[1], 0);
    EXPECT_EQ(pixel(img, 0, 0), (std::array<int, 3>{0, 0, 255}));  // background
    std::string png = encode_png(img);
    ASSERT_GT(png.size(), 8u);
    EXPECT_EQ(png.substr(1, 3), "PNG");
    Image back = decode_png(png);
    EXPECT_EQ(back.width, 17);
    EXPECT_EQ(back.height, 15);
    EXPECT_EQ(back.rgb, img.rgb);
}

TEST(Render, ShadowedPointGetsOnlyAmbient) {
    // The light is straight above the point the centre pixel sees; a square at z = 5 shades it.
    std::string lit = camera("0 -10 10", "0 0 0", "0 0 1", 9) + "l 0 0 10\n" + square("1 1 1 1 0 0 0 1");
    std::string shaded = lit + "p 4\n-1 -1 5\n-1 1 5\n1 1 5\n1 -1 5\n";
    for (int pass = 0; pass < 2; ++pass) {
        Scene s = read_nff(pass ? shaded : lit, "shadow.nff");
        auto h = build_hierarchy(s, "bvh-sah");
        RenderOptions opt;
        opt.width = opt.height = 9;
        Image img = render(*h, opt);
        int v = pixel(img, 4, 4)[0];
        EXPECT_EQ(v, pass ? 38 : 255);  // shaded: ambient 0.15 of white
    }
}

TEST(Render, WritePngIsAtomicAndNamesTheFileOnFailure) {
    Image img{2, 2, std::vector<std::uint8_t>(12, 128)};
    fs::path dir = fs::temp_directory_path() / ("rtcost_whitted_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    fs::path p = dir / "a.png";
    write_png(p.string(), img);
    EXPECT_TRUE(fs::exists(p));
    for (const auto& e : fs::directory_iterator(dir)) EXPECT_EQ(e.path().filename(), "a.png");  // no temp left
    fs::path bad = dir / "missing" / "b.png";
    try {
        write_png(bad.string(), img);
        ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(bad.string()), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(bad));
    fs::remove_all(dir);
}

// The command line.
using test::CliRun;
using test::run_cli;
using test::slurp;

fs::path temp_dir() { return test::temp_dir("rayscli"); }

TEST(RaysCli, SpdJsonCountsMatchTheFileAndTheLibrary) {
    RTCOST_REQUIRE_SPD("gears");
    fs::path out = temp_dir() / "gears.rays";
    CliRun r = run_cli("rays " + test::spd_path("gears") + " --dist spd --size 64x64 --out " + out.string() + " --json");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(r.err.empty()) << r.err;
    auto j = nlohmann::json::parse(r.out);
    auto c = j["counts"];
    EXPECT_EQ(c["eye"], 65 * 65);
    std::size_t total = 0;
    for (const char* k : {"eye", "reflection", "refraction", "shadow"}) {
        ASSERT_TRUE(c.contains(k)) << k;
        ASSERT_TRUE(c.contains(std::string(k) + "_hits")) << k;
        EXPECT_LE(c[std::string(k) + "_hits"].get<std::size_t>(), c[k].get<std::size_t>()) << k;
        total += c[k].get<std::size_t>();
    }
    EXPECT_GT(c["refraction"].get<int>(), 0);  // glass gears
    EXPECT_EQ(j["rays"], total);
    EXPECT_EQ(fs::file_size(out), total * 32);
    Scene s = load_scene(test::spd_path("gears"));
    auto h = build_hierarchy(s, "kd-sah");
    WhittedOptions opt;
    opt.width = opt.height = 65;
    RayTree t = whitted_tree(*h, opt);
    EXPECT_EQ(c["shadow"], t.counts.rays[kShadow]);
    EXPECT_EQ(c["shadow_hits"], t.counts.hits[kShadow]);
    std::vector<Ray> file = read_rays(out.string());
    ASSERT_EQ(file.size(), t.rays.size());
    EXPECT_EQ(std::memcmp(file.data(), t.rays.data(), file.size() * sizeof(Ray)), 0);
}

TEST(RaysCli, SameSeedSameBytesOtherSeedOtherBytes) {
    RTCOST_REQUIRE_SPD("balls");
    fs::path d = temp_dir();
    for (const char* dist : {"lines", "diffuse", "ao", "spd"}) {
        std::string base = "rays " + test::spd_path("balls") + " --dist " + dist + " --size 24x24 --count 5000 -q --out ";
        ASSERT_EQ(run_cli(base + (d / "a.rays").string() + " --seed 7").code, 0) << dist;
        ASSERT_EQ(run_cli(base + (d / "b.rays").string() + " --seed 7").code, 0) << dist;
        ASSERT_EQ(run_cli(base + (d / "c.rays").string() + " --seed 8").code, 0) << dist;
        std::string a = slurp(d / "a.rays");
        EXPECT_GT(a.size(), 0u) << dist;
        EXPECT_EQ(a, slurp(d / "b.rays")) << dist;
        // Nothing in spd is random; the others follow the seed.
        EXPECT_EQ(a == slurp(d / "c.rays"), std::string(dist) == "spd") << dist;
    }
}

TEST(RaysCli, TraceSpdGivesTheSameCountsForEveryHierarchy) {
    RTCOST_REQUIRE_SPD("rings");
    nlohmann::json first;
    for (const char* h : {"bvh-sah", "kd-median", "grid"}) {
        CliRun r = run_cli("trace " + test::spd_path("rings") + " -H " + h + " --rays spd --size 48x48 --json");
        ASSERT_EQ(r.code, 0) << r.err;
        auto by_kind = nlohmann::json::parse(r.out)["trace"]["by_kind"];
        for (const char* k : {"eye", "reflection", "shadow"}) {
            ASSERT_TRUE(by_kind.contains(k)) << h << " " << k;
            EXPECT_GT(by_kind[k]["per_ray"]["N_IT"].get<double>(), 0.0) << h << " " << k;
            by_kind[k].erase("per_ray");
        }
        if (first.is_null()) first = by_kind;
        else EXPECT_EQ(by_kind, first) << h;
    }
    EXPECT_EQ(first["eye"]["rays"], 49 * 49);
}

TEST(RaysCli, BadInputExitsTwoAndWritesNothing) {
    fs::path out = temp_dir() / "never.rays";
    fs::remove(out);
    CliRun r = run_cli("rays builtin:tetra:2 --dist spd --size 0x5 --out " + out.string());
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("--size"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out));
    r = run_cli("rays builtin:tetra:2 --dist nosuch --out " + out.string());
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("nosuch"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out));
    fs::path bad = temp_dir() / "no_dir" / "x.rays";
    r = run_cli("rays builtin:tetra:2 --dist camera --size 4x4 --out " + bad.string());
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find(bad.string()), std::string::npos) << r.err;
}

TEST(RenderCli, WritesPngOfTheRequestedSize) {
    fs::path out = temp_dir() / "balls.png";
    CliRun r = run_cli("render builtin:balls:2 --size 40x30 -o " + out.string() + " --json");
    ASSERT_EQ(r.code, 0) << r.err;
    auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["width"], 40);
    EXPECT_EQ(j["height"], 30);
    EXPECT_EQ(j["hierarchy"], "bvh-sah");
    Image img = decode_png(slurp(out));
    EXPECT_EQ(img.width, 40);
    EXPECT_EQ(img.height, 30);
    EXPECT_EQ(j["bytes"], fs::file_size(out));
    // Not blank: the sphereflake and its ground differ from pixel to pixel.
    std::set<std::array<int, 3>> colours;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) colours.insert(pixel(img, x, y));
    EXPECT_GT(colours.size(), 50u);
    fs::path bad = temp_dir() / "never.png";
    fs::remove(bad);
    r = run_cli("render builtin:balls:2 --size 40 -o " + bad.string());
    EXPECT_EQ(r.code, 2);
    EXPECT_FALSE(fs::exists(bad));
}

}  // namespace
