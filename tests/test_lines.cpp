// Isotropic random lines (line_rays) really follow the invariant measure of lines: checked by
// Cauchy-Crofton (a convex body inside the box is met by a fraction of the lines equal to the
// ratio of surface areas) and by the mean chord (4 V / S), each within three standard errors.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <span>
#include <vector>

#include "rtcost/io.hpp"
#include "rtcost/rays.hpp"

using namespace rtcost;

namespace {

const Box3 kScene{{-1, -2, -0.5f}, {3, 1, 2.5f}};  // 4 x 3 x 3, off the origin
constexpr std::size_t kLines = 400000;

double volume(const Box3& b) {
    Vec3 e = b.extent();
    return static_cast<double>(e.x) * e.y * e.z;
}

// The line's margin beyond the box (see line_rays): the chord is the segment less both margins.
float margin(const Box3& b) { return 1e-4f * 0.5f * length(b.extent()); }

// Each nested box is met by the share of `scene`'s lines that Cauchy-Crofton gives.
void expect_crofton(const Box3& scene, std::span<const Box3> nested, std::uint64_t seed) {
    const std::vector<Ray> lines = line_rays(scene, kLines, seed);
    ASSERT_EQ(lines.size(), kLines);
    for (const Box3& k : nested) {
        std::size_t met = 0;
        for (const Ray& r : lines) {
            RayInv ri(r);
            met += box_entry(k, ri.o, ri.inv, r.tmin, r.tmax) < kInf;
        }
        double p = static_cast<double>(k.area()) / scene.area();
        double se = std::sqrt(p * (1 - p) / kLines);
        double got = static_cast<double>(met) / kLines;
        EXPECT_NEAR(got, p, 3 * se + 1e-12) << "box (" << k.lo.x << "," << k.lo.y << "," << k.lo.z << ")-(" << k.hi.x
                                            << "," << k.hi.y << "," << k.hi.z << ") expected " << p << " got " << got;
        // The statistic can tell: a 10% change of the area would be far outside the band.
        if (p < 1) {
            EXPECT_GT(0.1 * p, 3 * se);
        }
    }
}

// The mean chord of `b`'s lines is 4 V / S.
void expect_mean_chord(const Box3& b, std::uint64_t seed) {
    const std::vector<Ray> lines = line_rays(b, kLines, seed);
    const float m = margin(b);
    double sum = 0, sum2 = 0;
    for (const Ray& r : lines) {
        ASSERT_NEAR(length(r.d), 1.0f, 1e-5f);
        ASSERT_EQ(r.tmin, 0.0f);
        double chord = r.tmax - 2 * m;
        sum += chord;
        sum2 += chord * chord;
    }
    double n = static_cast<double>(lines.size()), mean = sum / n;
    double se = std::sqrt((sum2 / n - mean * mean) / n);
    EXPECT_NEAR(mean, 4 * volume(b) / b.area(), 3 * se);
}

TEST(Lines, CauchyCroftonNestedBoxesOfManyShapes) {
    const Box3 nested[] = {
        {{0, -1, 0.5f}, {1, 0, 1.5f}},             // cube in the middle
        {{-0.9f, -1.9f, 1}, {2.9f, 0.9f, 1.05f}},  // wide flat slab (normal z)
        {{0.5f, -1.9f, -0.4f}, {0.55f, 0.9f, 2.4f}},  // thin wall (normal x)
        {{-0.95f, -0.1f, 0.9f}, {2.95f, 0.1f, 1.1f}},  // long rod along x
        {{2, 0, 1.5f}, {3, 1, 2.5f}},              // corner cube touching three faces
        {{-1, -2, -0.5f}, {3, 1, 2.5f}},           // the box itself: every line
    };
    expect_crofton(kScene, nested, 3);
}

TEST(Lines, MeanChordIsFourVolumeOverArea) {
    for (const Box3& b : {kScene, Box3{{0, 0, 0}, {10, 1, 0.2f}}}) expect_mean_chord(b, 5);
}

// A needle's box meets so few of the lines through its bounding sphere's disc that drawing them
// there never ended (a rod of 1e6 x 1e-3 x 1e-3: "no line met the scene box 1000000 times in a
// row"); such boxes are drawn from their surface, the same distribution.
TEST(Lines, NeedleBoxesFollowTheSameMeasure) {
    const Box3 needle{{0, 0, 0}, {1000, 0.01f, 0.01f}};
    const Box3 nested[] = {
        {{0, 0, 0}, {500, 0.01f, 0.01f}},                  // its first half
        {{0, 0.0025f, 0.0025f}, {1000, 0.0075f, 0.0075f}},  // a rod half as wide inside it
        {{400, 0, 0}, {600, 0.01f, 0.005f}},               // a flat piece of its middle
        needle,                                            // every line
    };
    expect_crofton(needle, nested, 7);
    expect_mean_chord(needle, 8);
    const Box3 rod{{-5e5f, 0, 0}, {5e5f, 1e-3f, 1e-3f}};
    const std::vector<Ray> lines = line_rays(rod, 1000, 1);
    ASSERT_EQ(lines.size(), 1000u);
    for (const Ray& r : lines) {
        RayInv ri(r);
        ASSERT_LT(box_entry(rod, ri.o, ri.inv, r.tmin, r.tmax), kInf);
    }
    // The same seed gives the same lines.
    const std::vector<Ray> again = line_rays(rod, 1000, 1);
    EXPECT_EQ(std::memcmp(lines.data(), again.data(), lines.size() * sizeof(Ray)), 0);
}

TEST(Lines, SegmentsAreClippedToTheBox) {
    const std::vector<Ray> lines = line_rays(kScene, 20000, 9);
    const float m = margin(kScene), tol = 2 * m + 1e-5f;
    for (const Ray& r : lines) {
        Vec3 a = r.o, b = r.o + r.d * r.tmax;
        for (int k = 0; k < 3; ++k) {
            ASSERT_GE(a[k], kScene.lo[k] - tol);
            ASSERT_LE(a[k], kScene.hi[k] + tol);
            ASSERT_GE(b[k], kScene.lo[k] - tol);
            ASSERT_LE(b[k], kScene.hi[k] + tol);
        }
        // Both ends lie on the box's surface (the clipped line enters and leaves there).
        auto on_face = [&](Vec3 p) {
            float d = kInf;
            for (int k = 0; k < 3; ++k) d = std::min({d, std::fabs(p[k] - kScene.lo[k]), std::fabs(p[k] - kScene.hi[k])});
            return d <= tol;
        };
        ASSERT_TRUE(on_face(a));
        ASSERT_TRUE(on_face(b));
    }
}

TEST(Lines, SameSeedSameBytesOtherSeedOther) {
    auto a = line_rays(kScene, 10000, 42), b = line_rays(kScene, 10000, 42), c = line_rays(kScene, 10000, 43);
    EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(Ray)), 0);
    EXPECT_NE(std::memcmp(a.data(), c.data(), a.size() * sizeof(Ray)), 0);
}

}  // namespace
