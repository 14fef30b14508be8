// Camera-based distributions sampled by pixel: a pixel subset makes exactly the whole set's rays
// of those pixels, a sample traced at its pixels only is the one drawn from the whole
// distribution, its pixels cover the image evenly, and the test rays share no pixel with it.
#include <set>
#include <stdexcept>

#include "rtcost/sample.hpp"
#include "test_support.hpp"

namespace rtcost::test {
namespace {

bool same_ray(const Ray& a, const Ray& b) { return a.o == b.o && a.d == b.d && a.tmin == b.tmin && a.tmax == b.tmax; }

RaySpec spec_of(const std::string& name, const std::string& size) {
    RaySpec spec;
    spec.name = name;
    spec.size = size;
    return spec;
}

// The registered distributions that say they are camera-based (RaySet::image_pixels), checked
// to include the built-in ones.
std::vector<std::string> camera_based(const Scene& s) {
    std::vector<std::string> out;
    for (const RayDistributionInfo* d : ray_distributions()) {
        RaySpec spec = spec_of(d->name, "8x8");
        spec.count = 16;
        if (make_rays(s, spec).image_pixels) out.push_back(d->name);
    }
    EXPECT_EQ(out, (std::vector<std::string>{"camera", "spd", "shadow", "diffuse", "ao"}));
    return out;
}

TEST(PixelSample, APixelSubsetMakesTheWholeSetsRaysOfThosePixels) {
    const Scene s = builtin_scene("balls", 2);
    for (const std::string& name : camera_based(s)) {
        const RaySpec spec = spec_of(name, "24x24");
        const RaySet all = make_rays(s, spec);
        ASSERT_EQ(all.pixels.size(), all.rays.size()) << name;
        EXPECT_EQ(all.image_pixels, name == "spd" ? 25u * 25u : 24u * 24u) << name;
        EXPECT_TRUE(std::is_sorted(all.pixels.begin(), all.pixels.end())) << name;
        const std::vector<std::uint32_t> some{0, 7, 250, 301, 302, 575};
        RayMaking making;
        making.only_pixels = &some;
        const RaySet part = make_rays(s, spec, making);
        EXPECT_EQ(part.image_pixels, all.image_pixels) << name;
        std::vector<std::size_t> want;
        for (std::size_t i = 0; i < all.rays.size(); ++i)
            if (std::find(some.begin(), some.end(), all.pixels[i]) != some.end()) want.push_back(i);
        ASSERT_EQ(part.rays.size(), want.size()) << name;
        ASSERT_GT(want.size(), 0u) << name;
        for (std::size_t k = 0; k < want.size(); ++k) {
            EXPECT_TRUE(same_ray(part.rays[k], all.rays[want[k]])) << name << " ray " << k;
            EXPECT_EQ(part.kinds[k], all.kinds[want[k]]) << name << " ray " << k;
            EXPECT_EQ(part.pixels[k], all.pixels[want[k]]) << name << " ray " << k;
        }
        const std::vector<std::uint32_t> none, unsorted{5, 3}, outside{static_cast<std::uint32_t>(all.image_pixels)};
        making.only_pixels = &none;
        EXPECT_TRUE(make_rays(s, spec, making).rays.empty()) << name;
        making.only_pixels = &unsorted;
        EXPECT_THROW(make_rays(s, spec, making), std::invalid_argument) << name;
        making.only_pixels = &outside;
        EXPECT_THROW(make_rays(s, spec, making), std::invalid_argument) << name;
    }
}

TEST(PixelSample, TheDrawTracedAtItsPixelsIsTheDrawFromTheWholeDistribution) {
    const Scene s = builtin_scene("balls", 2);
    auto ref = build_hierarchy(s, "bvh-sah");
    for (const std::string& name : camera_based(s)) {
        for (std::size_t count : {200u, 100000u}) {  // the second more than half the image holds
            const RaySpec spec = spec_of(name, "48x40");
            const RaySet all = make_rays(s, spec);
            const RaySample whole = draw_sample_from(s, all, count, 3, *ref);
            const RaySample traced = draw_sample(s, spec, count, 3, *ref);
            EXPECT_EQ(whole.population, all.rays.size());
            EXPECT_EQ(traced.population, 0u);
            EXPECT_EQ(whole.size(), sample_size(all, count, 3)) << name;
            if (count == 200) {
                EXPECT_EQ(whole.size(), 200u) << name;
            } else {
                EXPECT_LT(whole.size(), all.rays.size()) << name;
            }
            ASSERT_EQ(traced.size(), whole.size()) << name << " " << count;
            for (std::size_t i = 0; i < whole.size(); ++i) {
                ASSERT_TRUE(same_ray(traced.rays.rays[i], whole.rays.rays[i])) << name << " ray " << i;
                EXPECT_EQ(traced.rays.kinds[i], whole.rays.kinds[i]);
                EXPECT_EQ(traced.queries[i], whole.queries[i]);
                EXPECT_EQ(traced.t_end[i], whole.t_end[i]);
                EXPECT_EQ(traced.crossings_of(i).size(), whole.crossings_of(i).size());
            }
            // Another seed, other pixels (half the image holds too few rays for the second
            // count: then a seed only picks one of two interleavings of the pixels).
            if (count != 200) continue;
            const RaySample other = draw_sample_from(s, all, count, 4, *ref);
            bool differs = other.size() != whole.size();
            for (std::size_t i = 0; !differs && i < whole.size(); ++i) differs = !same_ray(other.rays.rays[i], whole.rays.rays[i]);
            EXPECT_TRUE(differs) << name;
        }
    }
}

// The draw takes pixels spread over the image: with one ray a pixel and a sample of 256 out of
// 64 x 64, its 512 pixels put 8 into every 8 x 8 block (a uniform random draw of 512 pixels
// leaves some block with 3 or fewer, and puts 13 or more into another, nearly always).
TEST(PixelSample, ThePixelsCoverTheImageEvenlyAndTheTestRaysShareNoneOfThem) {
    const Scene s = builtin_scene("balls", 2);
    const RaySet all = make_rays(s, spec_of("camera", "64x64"));
    for (std::uint64_t seed : {1u, 2u, 99u}) {
        const RaySet rest = rays_outside_sample(all, 256, seed);
        ASSERT_EQ(rest.pixels.size(), rest.rays.size());
        std::set<std::uint32_t> kept(rest.pixels.begin(), rest.pixels.end());
        ASSERT_EQ(all.rays.size() - rest.rays.size(), 512u) << seed;
        int blocks[8][8] = {};
        for (std::uint32_t p = 0; p < 64 * 64; ++p)
            if (!kept.count(p)) ++blocks[p / 64 / 8][p % 64 / 8];
        for (auto& row : blocks)
            for (int n : row) {
                EXPECT_GE(n, 4) << seed;
                EXPECT_LE(n, 12) << seed;
            }
    }
    // Across and down alike, whatever the width: an order along the pixel index alone, on an
    // image 256 wide, took every 16th or 32nd pixel, that is, 8 to 16 whole columns.
    const RaySet wide = make_rays(s, spec_of("camera", "256x200"));
    const RaySet rest = rays_outside_sample(wide, 1310, 1);
    std::set<std::uint32_t> kept(rest.pixels.begin(), rest.pixels.end()), columns, rows;
    for (std::uint32_t p = 0; p < 256 * 200; ++p)
        if (!kept.count(p)) columns.insert(p % 256), rows.insert(p / 256);
    EXPECT_GE(columns.size(), 240u);
    EXPECT_GE(rows.size(), 190u);
    // A ray tree: every ray of a drawn pixel is left out of the test rays, sampled or not.
    auto ref = build_hierarchy(s, "bvh-sah");
    const RaySet spd = make_rays(s, spec_of("spd", "32x32"));
    const RaySample smp = draw_sample_from(s, spd, 300, 1, *ref);
    const RaySet spd_rest = rays_outside_sample(spd, 300, 1);
    std::set<std::uint32_t> test_pixels(spd_rest.pixels.begin(), spd_rest.pixels.end()), drawn;
    for (std::uint32_t p : spd.pixels)
        if (!test_pixels.count(p)) drawn.insert(p);
    EXPECT_LE(drawn.size(), spd.image_pixels / 2);
    std::size_t left_out = 0;
    for (std::size_t i = 0; i < spd.rays.size(); ++i) left_out += drawn.count(spd.pixels[i]);
    EXPECT_EQ(left_out, spd.rays.size() - spd_rest.rays.size());
    EXPECT_GE(left_out, 600u);
    for (const Ray& r : smp.rays.rays) {
        std::size_t at = 0;
        while (at < spd.rays.size() && !same_ray(spd.rays[at], r)) ++at;
        ASSERT_LT(at, spd.rays.size());
        EXPECT_TRUE(drawn.count(spd.pixels[at])) << "a sampled ray of a pixel the test rays have";
    }
}

}  // namespace
}  // namespace rtcost::test
