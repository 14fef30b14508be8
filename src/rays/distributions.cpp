#include <algorithm>
#include <charconv>
#include <stdexcept>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "rtcost/error.hpp"
#include "rtcost/rays.hpp"
#include "util/rng.hpp"

namespace rtcost {
namespace {

Vec3 normalize_double(Vec3 v) {
    const double l = std::sqrt(double(v.x) * v.x + double(v.y) * v.y + double(v.z) * v.z);
    return {static_cast<float>(v.x / l), static_cast<float>(v.y / l), static_cast<float>(v.z / l)};
}

}  // namespace

// The image plane: the ray through image point (u, v), in pixels from the image's centre, has
// direction fwd + right u scale + up v scale (not normalised: its component along the view axis
// is 1).
CameraRay::CameraRay(const Camera& cam, int width, int height)
    : from_(cam.from), hither_(cam.hither), width_(width), height_(height) {
    // Normalised in double: a short view vector or up vector underflows in float to NaN rays.
    fwd_ = normalize_double(cam.at - cam.from);
    right_ = normalize_double(cross(fwd_, normalize_double(cam.up)));
    up_ = cross(right_, fwd_);
    // NFF: the angle spans from the centre of the top pixel row to the centre of the bottom one.
    const double half = std::tan(0.5 * cam.angle * std::numbers::pi / 180.0);
    scale_ = height > 1 ? half / (0.5 * (height - 1)) : 0.0;
}

Ray CameraRay::operator()(std::size_t pixel) const {
    const auto w = static_cast<std::size_t>(width_);
    const int i = static_cast<int>(pixel % w), j = static_cast<int>(pixel / w);
    return through(i + 0.5 - 0.5 * width_, 0.5 * height_ - j - 0.5);
}

std::vector<Ray> camera_rays(const Camera& cam, int width, int height) {
    const CameraRay ray(cam, width, height);
    std::vector<Ray> rays;
    const std::size_t n = static_cast<std::size_t>(width) * height;
    rays.reserve(n);
    for (std::size_t p = 0; p < n; ++p) rays.push_back(ray(p));
    return rays;
}

std::vector<Ray> view_rays(const Camera& cam, int width, int height, std::size_t n, std::uint64_t seed) {
    const CameraRay plane(cam, width, height);
    Rng rng(seed);
    std::vector<Ray> rays;
    rays.reserve(n);
    for (std::size_t k = 0; k < n; ++k) {
        // Uniform over the span of the pixel centres, as camera_rays covers it.
        const double u = (rng.uniform() - 0.5) * (width - 1), v = (rng.uniform() - 0.5) * (height - 1);
        rays.push_back(plane.through(u, v));
    }
    return rays;
}

namespace {

/// A line of the invariant measure through `box`, drawn where it enters the box: a point
/// uniform on the box's surface (by area) and a direction into the box with density
/// proportional to its cosine with the face's inward normal. Every line meeting a convex body
/// enters it once, at a surface point whose measure is area x cosine (Santalo), so this is the
/// same distribution as the rejection from the bounding sphere's disc, without rejections.
/// Returns the line as (entry point, direction, chord length).
Ray line_from_surface(const Box3& box, const Vec3& ext, Rng& rng) {
    const double face[3] = {double(ext.y) * ext.z, double(ext.x) * ext.z, double(ext.x) * ext.y};
    double pick = rng.uniform() * (face[0] + face[1] + face[2]);
    int k = 0;
    while (k < 2 && (pick >= face[k] || face[k] == 0)) pick -= face[k], ++k;
    const int a = (k + 1) % 3, b = (k + 2) % 3;
    const bool high = rng.uniform() < 0.5;
    Vec3 p;
    p[k] = high ? box.hi[k] : box.lo[k];
    p[a] = box.lo[a] + static_cast<float>(rng.uniform()) * ext[a];
    p[b] = box.lo[b] + static_cast<float>(rng.uniform()) * ext[b];
    // Cosine-weighted about the inward normal (-1 on the high face, +1 on the low one).
    const double r2 = rng.uniform(), phi = 2 * std::numbers::pi * rng.uniform();
    Vec3 d;
    d[a] = static_cast<float>(std::sqrt(r2) * std::cos(phi));
    d[b] = static_cast<float>(std::sqrt(r2) * std::sin(phi));
    d[k] = static_cast<float>(std::sqrt(1 - r2)) * (high ? -1.0f : 1.0f);
    d = normalize(d);
    // The chord: where the line leaves the box (a face it lies in is no bound).
    float t1 = kInf;
    for (int j = 0; j < 3; ++j) {
        if (d[j] == 0) continue;
        const float t = ((d[j] > 0 ? box.hi[j] : box.lo[j]) - p[j]) / d[j];
        t1 = std::min(t1, t);
    }
    return Ray{p, d, 0, std::max(0.0f, t1)};
}

}  // namespace

std::vector<Ray> line_rays(const Box3& box, std::size_t n, std::uint64_t seed) {
    Rng rng(seed);
    std::vector<Ray> rays;
    rays.reserve(n);
    Vec3 c = box.center();
    const Vec3 ext = box.extent();
    float radius = static_cast<float>(0.5 * std::sqrt(double(ext.x) * ext.x + double(ext.y) * ext.y + double(ext.z) * ext.z));
    // A point box (radius 0) gives every line through the point, accepted at once.
    const float margin = 1e-4f * radius;
    // The share of the disc's lines that meet the box is its mean projected area over the
    // disc's, S / 4 over pi r^2 (Cauchy): 0.64 for a cube, 0.2 for a plate of 10 x 10 x 0; a
    // needle's is tiny (a rod of 1e6 x 1e-3 x 1e-3: 3e-9) and the rejections never end. There
    // the lines are drawn from the box's surface instead (the same distribution; the disc's
    // draw is kept elsewhere so that every other scene's lines stay the ones it always had).
    const double surface = 2 * (double(ext.y) * ext.z + double(ext.x) * ext.z + double(ext.x) * ext.y);
    if (surface > 0 && surface / (4 * std::numbers::pi * double(radius) * radius) < 1e-3) {
        while (rays.size() < n) {
            const Ray l = line_from_surface(box, ext, rng);
            rays.push_back(Ray{l.o - l.d * margin, l.d, 0, l.tmax + 2 * margin});
        }
        return rays;
    }
    constexpr int kMaxRejections = 1000000;
    int rejected_in_a_row = 0;
    while (rays.size() < n) {
        Vec3 d = rng.direction();
        // Uniform point on the disc of the bounding sphere's projection, then keep it when the
        // line meets the box: rejection keeps the measure uniform on the box's projection.
        Vec3 a = std::fabs(d.x) < 0.9f ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
        Vec3 e1 = normalize(cross(d, a));
        Vec3 e2 = cross(d, e1);
        double rr = radius * std::sqrt(rng.uniform());
        double phi = 2 * std::numbers::pi * rng.uniform();
        Vec3 p = c + e1 * static_cast<float>(rr * std::cos(phi)) + e2 * static_cast<float>(rr * std::sin(phi));
        Vec3 o = p - d * (2 * radius);
        RayInv ri(Ray{o, d, -kInf, kInf});
        float t0 = -kInf, t1 = kInf;
        for (int k = 0; k < 3; ++k) {
            float tn = ((ri.neg[k] ? box.hi[k] : box.lo[k]) - o[k]) * ri.inv[k];
            float tf = ((ri.neg[k] ? box.lo[k] : box.hi[k]) - o[k]) * ri.inv[k];
            t0 = tn > t0 ? tn : t0;
            t1 = tf < t1 ? tf : t1;
        }
        // A flat box (one axis-aligned triangle) has t0 == t1 on that axis: such a line still
        // crosses it, so equality is accepted (strict rejection never accepted one, and hung).
        if (!(t0 <= t1)) {
            // The disc contains the box's projection, whose share of the disc has a positive
            // lower bound for a box with any extent; no real box gets anywhere near this.
            if (++rejected_in_a_row > kMaxRejections)
                throw InputError("lines", 0, fmt::format("no line met the scene box {} times in a row", kMaxRejections));
            continue;
        }
        rejected_in_a_row = 0;
        // The segment reaches a hair past the box on both ends, so that geometry lying exactly
        // on the box's faces (a ground polygon) is met whatever the rounding of the entry point.
        rays.push_back(Ray{o + d * (t0 - margin), d, 0, t1 - t0 + 2 * margin});
    }
    return rays;
}

std::vector<Ray> random_rays(const Box3& box, std::size_t n, std::uint64_t seed) {
    Rng rng(seed);
    std::vector<Ray> rays(n);
    Vec3 lo = box.lo - box.extent() * 0.5f, size = box.extent() * 2.0f;
    for (auto& r : rays) {
        r.o = lo + Vec3{static_cast<float>(rng.uniform()) * size.x, static_cast<float>(rng.uniform()) * size.y,
                        static_cast<float>(rng.uniform()) * size.z};
        r.d = rng.direction();
        r.tmin = 0;
        r.tmax = kInf;
    }
    return rays;
}

void check_pixel_subset(const std::vector<std::uint32_t>* only, std::size_t image_pixels) {
    if (!only) return;
    if (!std::is_sorted(only->begin(), only->end()) ||
        std::adjacent_find(only->begin(), only->end()) != only->end() ||
        (!only->empty() && only->back() >= image_pixels))
        throw std::invalid_argument("RayMaking::only_pixels: not ascending distinct pixels of the image");
}

void parse_size(const std::string& text, const std::string& what, int& width, int& height) {
    auto x = text.find('x');
    auto num = [&](std::string_view s, int& out) {
        auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
        return ec == std::errc() && p == s.data() + s.size() && out > 0 && out <= 65536;
    };
    const std::string shown = text.size() > 40 ? text.substr(0, 40) + "..." : text;
    if (x == std::string::npos || !num(std::string_view(text).substr(0, x), width) ||
        !num(std::string_view(text).substr(x + 1), height)) {
        throw InputError(what, 0, "'" + shown + "': expected WxH with 1 <= W, H <= 65536, e.g. 512x512");
    }
    if (static_cast<std::uint64_t>(width) * static_cast<std::uint64_t>(height) > kMaxRays)
        throw InputError(what, 0, fmt::format("'{}' is {} rays; at most {} (about 60 bytes each)", shown,
                                              static_cast<std::uint64_t>(width) * height, kMaxRays));
}

void image_size(const Scene& scene, const std::string& size, int& width, int& height) {
    if (!size.empty()) return parse_size(size, "--size", width, height);
    width = scene.camera.width;
    height = scene.camera.height;
    const std::uint64_t n = static_cast<std::uint64_t>(width) * static_cast<std::uint64_t>(height);
    if (n > kMaxRays)
        throw InputError(scene.name, 0,
                         fmt::format("its resolution {}x{} is {} rays, beyond the {} rtcost traces: give --size", width,
                                     height, n, kMaxRays));
}

namespace {
const RayDistributionRegistration kCamera{
    {.name = "camera",
     .description = "one eye ray per pixel centre of the scene's camera (--size WxH)",
     .order = 0,
     .benchmarked = true,
     .make = [](const Scene& scene, const RaySpec& spec, const RayMaking& making) {
         int w, h;
         image_size(scene, spec.size, w, h);
         const std::size_t n = static_cast<std::size_t>(w) * h;
         check_pixel_subset(making.only_pixels, n);
         std::vector<Ray> rays;
         std::vector<std::uint32_t> pixels;
         if (making.only_pixels) {
             // Only those pixels' rays (a sample's), not the whole image's.
             pixels = *making.only_pixels;
             const CameraRay ray(scene.camera, w, h);
             rays.reserve(pixels.size());
             for (std::uint32_t p : pixels) rays.push_back(ray(p));
         } else {
             rays = camera_rays(scene.camera, w, h);
             pixels.resize(n);
             for (std::size_t i = 0; i < n; ++i) pixels[i] = static_cast<std::uint32_t>(i);
         }
         RaySet set = one_kind(std::move(rays), RayKind::Eye, fmt::format("camera {}x{}", w, h));
         set.image_pixels = n;
         set.image_width = static_cast<std::size_t>(w);
         set.pixels = std::move(pixels);
         return set;
     }}};
const RayDistributionRegistration kLines{
    {.name = "lines",
     .description = "isotropic random lines through the scene's box (--count, --seed): the model's exact case",
     .order = 50,
     .seeded_draws = true,
     .make = [](const Scene& scene, const RaySpec& spec, const RayMaking&) {
         return one_kind(line_rays(scene.bounds(), spec.count, spec.seed), RayKind::Line,
                         fmt::format("lines {} seed {}", spec.count, spec.seed));
     }}};
const RayDistributionRegistration kRandom{
    {.name = "random",
     .description = "rays from random points of the scene's box grown by half its size, in random directions (--count, --seed)",
     .order = 60,
     .seeded_draws = true,
     .benchmarked = true,
     .make = [](const Scene& scene, const RaySpec& spec, const RayMaking&) {
         return one_kind(random_rays(scene.bounds(), spec.count, spec.seed), RayKind::Test,
                         fmt::format("random {} seed {}", spec.count, spec.seed));
     }}};
}  // namespace

}  // namespace rtcost
