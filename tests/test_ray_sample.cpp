// The ray sample: it belongs to the scene and the distribution (its ends are brute force's, it
// is stratified along the distribution, its file round-trips and names the scene it was drawn
// on), not to any hierarchy.
#include <cstring>
#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "rtcost/evaluate.hpp"
#include "rtcost/sample.hpp"
#include "test_support.hpp"

namespace rtcost::test {
namespace {

std::string temp_path(const std::string& name) {
    return (std::filesystem::temp_directory_path() / ("rtcost-test-" + std::to_string(::getpid()) + "-" + name)).string();
}

TEST(RaySample, EndsAreTheClosestHitsAndCrossingsAreOrderedAndUnique) {
    Scene s = builtin_scene("balls", 2);
    auto ref = build_hierarchy(s, "bvh-sah");
    auto brute = build_hierarchy(s, "brute");
    const RaySet all = mixed_rays(s);
    const RaySample smp = draw_sample_from(s, all, 500, 7, *ref);
    ASSERT_EQ(smp.size(), 500u);
    EXPECT_EQ(smp.population, all.rays.size());
    std::size_t hits = 0;
    for (std::size_t i = 0; i < smp.size(); ++i) {
        Hit h;
        brute->closest(smp.rays.rays[i], h);
        const auto c = smp.crossings_of(i);
        if (h.hit()) {
            ++hits;
            ASSERT_FALSE(c.empty());
            EXPECT_EQ(smp.t_end[i], h.t);
            EXPECT_EQ(static_cast<std::int32_t>(c[0].prim), h.prim);
        } else {
            EXPECT_TRUE(c.empty());
            EXPECT_EQ(smp.t_end[i], smp.rays.rays[i].tmax);
        }
        for (std::size_t k = 1; k < c.size(); ++k) {
            EXPECT_LT(c[k - 1].t, c[k].t);
            for (std::size_t j = 0; j < k; ++j) EXPECT_NE(c[j].prim, c[k].prim);
        }
    }
    EXPECT_GT(hits, 100u);
}

TEST(RaySample, SameSeedSameSampleAndTheTestRaysAreTheRest) {
    Scene s = builtin_scene("tetra", 3);
    auto ref = build_hierarchy(s, "bvh-sah");
    const RaySet all = mixed_rays(s);
    const RaySample a = draw_sample_from(s, all, 300, 5, *ref), b = draw_sample_from(s, all, 300, 5, *ref);
    const RaySample c = draw_sample_from(s, all, 300, 6, *ref);
    ASSERT_EQ(a.size(), b.size());
    bool differs = false;
    for (std::size_t i = 0; i < a.size(); ++i) {
        EXPECT_EQ(a.rays.rays[i].o, b.rays.rays[i].o);
        EXPECT_EQ(a.t_end[i], b.t_end[i]);
        differs |= !(a.rays.rays[i].o == c.rays.rays[i].o);
    }
    EXPECT_TRUE(differs) << "another seed draws other rays";
    // Sample and test rays partition the distribution.
    const RaySet rest = rays_outside_sample(all, 300, 5);
    ASSERT_EQ(rest.rays.size() + a.size(), all.rays.size());
    std::size_t in = 0, out = 0;
    for (const Ray& r : all.rays) {
        auto same = [&](const Ray& x) { return x.o == r.o && x.d == r.d; };
        in += std::any_of(a.rays.rays.begin(), a.rays.rays.end(), same);
        out += std::any_of(rest.rays.begin(), rest.rays.end(), same);
    }
    EXPECT_EQ(in, a.size());
    EXPECT_EQ(out, rest.rays.size());
}

// The sample is stratified along the distribution's order: one ray from each run of equal
// length, so camera rays cover the image evenly. Its mean then varies less from seed to seed
// than a simple random sample's would (p(1 - p) / n, finite-population corrected); here p is
// the share of pixels that see the sphereflake rather than the floor.
TEST(RaySample, OneRayPerRunOfTheDistributionAndLessVarianceThanARandomDraw) {
    Scene s = builtin_scene("balls", 3);
    auto ref = build_hierarchy(s, "bvh-sah");
    RaySet all;
    all.rays = camera_rays(s.camera, 64, 64);
    all.kinds.assign(all.rays.size(), RayKind::Eye);
    all.described = "camera 64x64";
    const std::size_t n = 128, total = all.rays.size();
    std::vector<char> hit(total);  // the ray's closest hit is a sphere
    for (std::size_t i = 0; i < total; ++i) {
        Hit h;
        ref->closest(all.rays[i], h);
        hit[i] = h.hit() && s.kind(static_cast<std::uint32_t>(h.prim)) == PrimKind::Sphere;
    }
    double p = 0;
    for (char h : hit) p += h;
    p /= double(total);
    ASSERT_GT(p, 0.2);
    ASSERT_LT(p, 0.8);
    std::vector<double> means;
    for (std::uint64_t seed = 1; seed <= 200; ++seed) {
        const RaySample smp = draw_sample_from(s, all, n, seed, *ref);
        ASSERT_EQ(smp.size(), n);
        double m = 0;
        std::size_t run = 0;
        for (std::size_t i = 0; i < n; ++i) {
            // Which ray of the distribution it is: camera rays differ by direction.
            const auto it = std::find_if(all.rays.begin() + std::ptrdiff_t(run * total / n), all.rays.end(),
                                         [&](const Ray& r) { return r.d == smp.rays.rays[i].d; });
            const std::size_t k = std::size_t(it - all.rays.begin());
            EXPECT_GE(k, i * total / n) << "ray " << i << " of seed " << seed;
            EXPECT_LT(k, (i + 1) * total / n) << "ray " << i << " of seed " << seed;
            run = i + 1;
            const auto met = smp.crossings_of(i);  // nearest first
            m += !met.empty() && s.kind(met[0].prim) == PrimKind::Sphere ? 1 : 0;
        }
        means.push_back(m / double(n));
    }
    double mean = 0, var = 0;
    for (double m : means) mean += m / double(means.size());
    for (double m : means) var += (m - mean) * (m - mean) / double(means.size() - 1);
    const double random_draw = p * (1 - p) / double(n) * double(total - n) / double(total - 1);
    EXPECT_NEAR(mean, p, 4 * std::sqrt(random_draw / double(means.size())));
    // Over 200 draws the variance is known to about 10%: a random draw would give 1.0 +- 0.1.
    EXPECT_LT(var, 0.8 * random_draw) << "stratified variance " << var << ", a random draw's " << random_draw;
}

TEST(RaySample, FileRoundTripsAndBadFilesAreRefused) {
    Scene s = builtin_scene("balls", 2);
    auto ref = build_hierarchy(s, "bvh-sah");
    const RaySample a = draw_sample_from(s, mixed_rays(s), 400, 3, *ref, Query::Closest, Query::Any);
    const std::string path = temp_path("sample.bin");
    write_sample(path, a);
    const RaySample b = read_sample(path);
    ASSERT_EQ(b.size(), a.size());
    EXPECT_EQ(b.distribution, a.distribution);
    EXPECT_EQ(b.population, a.population);
    EXPECT_EQ(b.seed, a.seed);
    EXPECT_EQ(a.scene, s.fingerprint());
    EXPECT_EQ(b.scene, a.scene);
    EXPECT_EQ(a.file_version, 0u);
    EXPECT_EQ(b.file_version, 3u);
    ASSERT_EQ(b.crossings.size(), a.crossings.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
        EXPECT_EQ(b.rays.rays[i].d, a.rays.rays[i].d);
        EXPECT_EQ(b.t_end[i], a.t_end[i]);
        EXPECT_EQ(b.queries[i], a.queries[i]);
        EXPECT_EQ(b.first[i], a.first[i]);
    }
    for (std::size_t i = 0; i < a.crossings.size(); ++i) {
        EXPECT_EQ(b.crossings[i].prim, a.crossings[i].prim);
        EXPECT_EQ(b.crossings[i].t, a.crossings[i].t);
    }
    const std::string bytes = slurp(path);
    // A version-1 file (no scene fingerprint after the counts) is read, its scene unknown; a
    // version-2 file (version 3's layout) is read alike; version 4 is refused.
    {
        std::string v2 = bytes;
        ASSERT_EQ(v2[8], 3);
        v2[8] = 2;
        std::ofstream(path, std::ios::binary).write(v2.data(), static_cast<std::streamsize>(v2.size()));
        const RaySample d = read_sample(path);
        EXPECT_EQ(d.file_version, 2u);
        EXPECT_EQ(d.scene, a.scene);
        EXPECT_EQ(d.crossings.size(), a.crossings.size());
        std::string v1 = bytes;
        v1[8] = 1;
        v1.erase(8 + 4 + 4 + 4 * 8, 8);
        std::ofstream(path, std::ios::binary).write(v1.data(), static_cast<std::streamsize>(v1.size()));
        const RaySample c = read_sample(path);
        EXPECT_EQ(c.scene, 0u);
        ASSERT_EQ(c.size(), a.size());
        EXPECT_EQ(c.crossings.size(), a.crossings.size());
        std::string v4 = bytes;
        v4[8] = 4;
        std::ofstream(path, std::ios::binary).write(v4.data(), static_cast<std::streamsize>(v4.size()));
        EXPECT_THROW(read_sample(path), InputError);
    }
    // Truncated, and not a sample at all.
    for (std::size_t cut : {std::size_t(4), std::size_t(40), bytes.size() - 3}) {
        std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(cut));
        EXPECT_THROW(read_sample(path), InputError) << "cut at " << cut;
    }
    std::ofstream(path, std::ios::binary) << "not a sample file at all, just text";
    EXPECT_THROW(read_sample(path), InputError);
    // A ray with a negative tmin (refused in a ray file too), and a negative crossing.
    auto refused = [&](std::string edited, const std::string& words) {
        std::ofstream(path, std::ios::binary).write(edited.data(), static_cast<std::streamsize>(edited.size()));
        try {
            read_sample(path);
            ADD_FAILURE() << "read: " << words;
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
        }
    };
    const std::size_t first_ray = 8 + 4 + 4 + 5 * 8 + 4 + a.distribution.size();
    const float minus_one = -1;
    std::string tmin = bytes;
    std::memcpy(tmin.data() + first_ray + 6 * 4, &minus_one, 4);
    refused(tmin, "ray 0: tmin -1 is negative");
    ASSERT_FALSE(a.crossings.empty());
    std::string crossing = bytes;
    std::memcpy(crossing.data() + bytes.size() - 4, &minus_one, 4);  // the last crossing's t
    refused(crossing, "a crossing's t is negative or NaN");
    std::filesystem::remove(path);
}

TEST(RaySample, AFileDrawnOnAnotherSceneIsRefusedByEval) {
    // Samples of two scenes whose primitive ids overlap (a sample's ids all exist in the other
    // scene): the fingerprint, not the ids, tells them apart. The same scene built twice agrees.
    Scene balls = builtin_scene("balls", 1), tetra = builtin_scene("tetra", 2);
    ASSERT_LT(balls.size(), tetra.size());
    EXPECT_EQ(builtin_scene("balls", 1).fingerprint(), balls.fingerprint());
    EXPECT_NE(balls.fingerprint(), tetra.fingerprint());
    EXPECT_NE(builtin_scene("balls", 2).fingerprint(), balls.fingerprint());
    RaySpec spec;
    spec.name = "lines";
    spec.count = 2000;
    auto ref = build_hierarchy(balls, "bvh-sah");
    const RaySample smp = draw_sample_from(balls, make_rays(balls, spec), 64, 1, *ref);
    const std::string path = temp_path("balls.sample");
    write_sample(path, smp);
    EvalOptions opt;
    opt.hierarchies = {HierarchyRequest{"bvh-sah", {}}};
    opt.estimators = {Estimator::Segments};
    opt.sample_file = path;
    opt.repeat = 1;
    try {
        evaluate(tetra, spec, opt);
        ADD_FAILURE() << "a sample of another scene was accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("drawn on another scene"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
        EXPECT_EQ(std::string(e.what()).find("version-2"), std::string::npos) << e.what();
    }
    EXPECT_EQ(evaluate(balls, spec, opt).rows.size(), 1u);
    // The same file as version 2 (written before three-vertex NFF polygons became triangles):
    // its own scene still takes it; another is refused with that possible cause named.
    {
        std::string bytes = slurp(path);
        ASSERT_EQ(bytes[8], 3);
        bytes[8] = 2;
        std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    }
    EXPECT_EQ(evaluate(balls, spec, opt).rows.size(), 1u);
    try {
        evaluate(tetra, spec, opt);
        ADD_FAILURE() << "a version-2 sample of another scene was accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("drawn on another scene"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("version-2 sample file): draw it again"), std::string::npos) << e.what();
    }
    std::filesystem::remove(path);
}

}  // namespace
}  // namespace rtcost::test
