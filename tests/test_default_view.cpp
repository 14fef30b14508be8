// The camera and light a mesh without them gets: the object in view rather than a backdrop's back,
// most of the image on the object even when it is thin, and shadows the camera can see.
#include <numbers>

#include "test_support.hpp"

namespace rtcost::test {
namespace {

void add_box(Scene& s, Vec3 lo, Vec3 hi) {
    const Vec3 p[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z},
                       {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
    const int faces[6][4] = {{0, 1, 2, 3}, {5, 4, 7, 6}, {4, 0, 3, 7}, {1, 5, 6, 2}, {3, 2, 6, 7}, {4, 5, 1, 0}};
    for (const auto& f : faces) {
        s.add(Triangle{p[f[0]], p[f[1]], p[f[2]]}, 0);
        s.add(Triangle{p[f[0]], p[f[2]], p[f[3]]}, 0);
    }
}

// A sphere of 2 * n * n triangles.
void add_sphere(Scene& s, Vec3 centre, float radius, int n) {
    auto at = [&](int i, int j) {
        const double th = std::numbers::pi * i / n, ph = 2 * std::numbers::pi * j / n;
        return centre + Vec3{float(std::sin(th) * std::cos(ph)), float(std::cos(th)), float(std::sin(th) * std::sin(ph))} * radius;
    };
    for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
            const Vec3 a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
            if (i + 1 < n) s.add(Triangle{a, b, c}, 0);
            if (i > 0) s.add(Triangle{a, c, d}, 0);
        }
    }
}

struct Seen {
    std::size_t rays = 0, hits = 0, object_hits = 0;  // object: primitives from `first_object` on
};

Seen look(const Scene& s, std::uint32_t first_object) {
    const auto h = build_hierarchy(s, "bvh-sah");
    const auto rays = camera_rays(s.camera, s.camera.width / 4, s.camera.height / 4);
    Seen seen;
    for (const Ray& r : rays) {
        Hit hit;
        h->closest(r, hit);
        ++seen.rays;
        seen.hits += hit.hit();
        seen.object_hits += hit.hit() && static_cast<std::uint32_t>(hit.prim) >= first_object;
    }
    return seen;
}

// A ball before a wall of two triangles, the wall first in the file, as the rings scene has it
// (with enough triangles that scoring the views reads only a subset of them). From behind the wall
// the image would be all wall and every shadow ray blocked; the default view sees the ball.
TEST(DefaultView, SeesTheObjectRatherThanTheBackOfItsBackdrop) {
    Scene s;
    s.name = "ball-before-a-wall";
    s.add(Triangle{{-12, 10, -12}, {12, 10, -12}, {12, 10, 12}}, 0);
    s.add(Triangle{{-12, 10, -12}, {12, 10, 12}, {-12, 10, 12}}, 0);
    add_sphere(s, {0, 4, 0}, 4, 160);
    ASSERT_GT(s.size(), 40000u);
    s.finalize();
    EXPECT_LT(s.camera.from.y, 10) << "the camera is behind the wall";
    ASSERT_EQ(s.lights.size(), 1u);
    EXPECT_LT(s.lights[0].position.y, 10) << "the light is behind the wall";
    const Seen seen = look(s, 2);
    // The ball is small beside the wall: about a tenth of the frame, and none of it from behind.
    EXPECT_GT(seen.object_hits, seen.rays / 20) << seen.object_hits << " of " << seen.rays;
}

// A spider: a body and eight long, thin legs. Framed whole, it leaves four fifths of the image
// empty; the default view crops to it so that most camera rays hit it.
TEST(DefaultView, MostCameraRaysHitAThinObject) {
    Scene s;
    s.name = "spider";
    add_box(s, {-2.5f, -1, -2.5f}, {2.5f, 1, 2.5f});
    for (int k = 0; k < 8; ++k) {
        const float a = static_cast<float>(2 * std::numbers::pi * (k + 0.5) / 8);
        const Vec3 dir{std::cos(a), 0, std::sin(a)}, side{-dir.z, 0, dir.x};
        // A leg: a flat ribbon 0.3 wide and 4.5 long, its top and bottom faces, in 9 pieces.
        for (int seg = 0; seg < 9; ++seg) {
            const Vec3 p = dir * (2.5f + 0.5f * seg), q = p + dir * 0.5f;
            for (float y : {-0.05f, 0.05f}) {
                const Vec3 a0 = p - side * 0.15f + Vec3{0, y, 0}, a1 = p + side * 0.15f + Vec3{0, y, 0};
                const Vec3 b0 = q - side * 0.15f + Vec3{0, y, 0}, b1 = q + side * 0.15f + Vec3{0, y, 0};
                s.add(Triangle{a0, b0, b1}, 0);
                s.add(Triangle{a0, b1, a1}, 0);
            }
        }
    }
    s.finalize();
    const Seen seen = look(s, 0);
    EXPECT_GT(seen.hits, seen.rays / 2) << seen.hits << " of " << seen.rays;
    // Cropped, not zoomed onto a leg: the body's centre is in the frame.
    const Vec3 fwd = normalize(s.camera.at - s.camera.from), right = normalize(cross(fwd, s.camera.up));
    const Vec3 up = cross(right, fwd), v = Vec3{0, 0, 0} - s.camera.from;
    const double tan_v = std::tan(0.5 * s.camera.angle * std::numbers::pi / 180);
    EXPECT_LT(std::fabs(dot(v, up)) / dot(v, fwd), tan_v);
    EXPECT_LT(std::fabs(dot(v, right)) / dot(v, fwd), tan_v * s.camera.width / s.camera.height);
}

// The same view at any scale: a tetrahedron 1e-12 across is framed as one 1 across (the crop's
// near limit was once absolute, which put every primitive of a tiny scene behind the eye).
TEST(DefaultView, ATinySceneIsFramedLikeALargeOne) {
    for (float size : {1.0f, 1e-12f}) {
        Scene s;
        s.name = "tetrahedron";
        const Vec3 p[4] = {{0, 0, 0}, {size, 0, 0}, {0, size, 0}, {0, 0, size}};
        s.add(Triangle{p[0], p[1], p[2]}, 0);
        s.add(Triangle{p[0], p[1], p[3]}, 0);
        s.add(Triangle{p[0], p[2], p[3]}, 0);
        s.add(Triangle{p[1], p[2], p[3]}, 0);
        s.finalize();
        const Seen seen = look(s, 0);
        EXPECT_GT(seen.hits, seen.rays / 2) << size << ": " << seen.hits << " of " << seen.rays;
        EXPECT_GT(s.camera.angle, 10) << size;
    }
}

}  // namespace
}  // namespace rtcost::test
