#include <charconv>
#include <cmath>
#include <numbers>

#include "rtcost/error.hpp"
#include "rtcost/rays.hpp"
#include "util/rng.hpp"

namespace rtcost {

std::vector<Ray> camera_rays(const Camera& cam, int width, int height) {
    Vec3 fwd = normalize(cam.at - cam.from);
    Vec3 right = normalize(cross(fwd, cam.up));
    Vec3 up = cross(right, fwd);
    // NFF: the angle spans from the centre of the top pixel row to the centre of the bottom one.
    double half = std::tan(0.5 * cam.angle * std::numbers::pi / 180.0);
    double scale = height > 1 ? half / (0.5 * (height - 1)) : 0.0;
    std::vector<Ray> rays;
    rays.reserve(static_cast<std::size_t>(width) * height);
    for (int j = 0; j < height; ++j) {
        for (int i = 0; i < width; ++i) {
            double u = (i + 0.5 - 0.5 * width) * scale;
            double v = (0.5 * height - j - 0.5) * scale;
            Ray r;
            r.o = cam.from;
            r.d = fwd + right * static_cast<float>(u) + up * static_cast<float>(v);
            r.tmin = cam.hither;
            r.tmax = kInf;
            rays.push_back(r);
        }
    }
    return rays;
}

std::vector<Ray> line_rays(const Box3& box, std::size_t n, std::uint64_t seed) {
    Rng rng(seed);
    std::vector<Ray> rays;
    rays.reserve(n);
    Vec3 c = box.center();
    float radius = 0.5f * length(box.extent());
    const float margin = 1e-4f * radius;
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
            float tn = (box.lo[k] - o[k]) * ri.inv[k], tf = (box.hi[k] - o[k]) * ri.inv[k];
            if (tn > tf) std::swap(tn, tf);
            t0 = tn > t0 ? tn : t0;
            t1 = tf < t1 ? tf : t1;
        }
        if (!(t0 < t1)) continue;
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

void parse_size(const std::string& text, const std::string& what, int& width, int& height) {
    auto x = text.find('x');
    auto num = [&](std::string_view s, int& out) {
        auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
        return ec == std::errc() && p == s.data() + s.size() && out > 0 && out <= 65536;
    };
    if (x == std::string::npos || !num(std::string_view(text).substr(0, x), width) ||
        !num(std::string_view(text).substr(x + 1), height)) {
        throw InputError(what, 0, "'" + text + "': expected WxH with 1 <= W, H <= 65536, e.g. 512x512");
    }
}

}  // namespace rtcost
