// The registry of ray distributions, and make_rays: the one place that turns `--rays NAME`
// (or a ray file) into rays. The distributions register themselves in their own files.
#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <deque>
#include <cmath>
#include <filesystem>

#include "rtcost/error.hpp"
#include "rtcost/io.hpp"
#include "rtcost/rays.hpp"
#include "rtcost/whitted.hpp"

namespace rtcost {

std::string_view ray_kind_name(RayKind k) {
    switch (k) {
        case RayKind::Eye: return "eye";
        case RayKind::Reflection: return "reflection";
        case RayKind::Refraction: return "refraction";
        case RayKind::Shadow: return "shadow";
        case RayKind::Diffuse: return "diffuse";
        case RayKind::AO: return "ao";
        case RayKind::Line: return "line";
        case RayKind::Test: return "test";
        case RayKind::File: return "file";
    }
    return "?";
}

bool is_occlusion(RayKind kind) { return kind == RayKind::Shadow || kind == RayKind::AO; }

namespace {
// Stable addresses: registrations keep pointers to their entries.
std::deque<RayDistributionInfo>& registry() {
    static std::deque<RayDistributionInfo> r;
    return r;
}
}  // namespace

RayDistributionRegistration::RayDistributionRegistration(RayDistributionInfo info) {
    registry().push_back(std::move(info));
}

std::vector<const RayDistributionInfo*> ray_distributions() {
    std::vector<const RayDistributionInfo*> out;
    for (const RayDistributionInfo& d : registry()) out.push_back(&d);
    std::stable_sort(out.begin(), out.end(), [](auto* a, auto* b) { return a->order < b->order; });
    return out;
}

const RayDistributionInfo* find_ray_distribution(std::string_view name) {
    for (const RayDistributionInfo& d : registry())
        if (d.name == name) return &d;
    return nullptr;
}

std::vector<std::string> distribution_names() {
    std::vector<std::string> out;
    for (const RayDistributionInfo* d : ray_distributions()) out.push_back(d->name);
    return out;
}

RaySet one_kind(std::vector<Ray> rays, RayKind kind, std::string described) {
    RaySet set;
    set.kinds.assign(rays.size(), kind);
    set.summary.push_back({std::string(ray_kind_name(kind)), rays.size()});
    set.rays = std::move(rays);
    set.described = std::move(described);
    return set;
}

namespace {
/// Comma-separated finite numbers, exactly `n` of them.
std::vector<float> numbers(const std::string& text, std::size_t n, const std::string& what) {
    std::vector<float> out;
    std::size_t start = 0;
    while (start <= text.size()) {
        std::size_t comma = std::min(text.find(',', start), text.size());
        const std::string item = text.substr(start, comma - start);
        start = comma + 1;
        float v = 0;
        auto [end, ec] = std::from_chars(item.data(), item.data() + item.size(), v);
        if (item.empty() || ec != std::errc() || end != item.data() + item.size() || !std::isfinite(v))
            throw InputError(what, 0, "'" + text.substr(0, 80) + "': expected " + std::to_string(n) +
                                          " comma-separated finite numbers");
        out.push_back(v);
    }
    if (out.size() != n)
        throw InputError(what, 0, "'" + text.substr(0, 80) + "': expected " + std::to_string(n) + " numbers, got " +
                                      std::to_string(out.size()));
    return out;
}
}  // namespace

void apply_view(Scene& scene, const ViewSpec& view) {
    if (!view.camera.empty()) {
        const std::vector<float> v = numbers(view.camera, 10, "--camera");
        for (int k = 0; k < 6; ++k)  // from and at: as a ray file's origins and a scene's points
            if (std::fabs(v[k]) > kMaxCoordinate)
                throw InputError("--camera", 0,
                                 fmt::format("coordinate {:g} beyond +-{:g}, the largest rtcost traces exactly", v[k],
                                             kMaxCoordinate));
        Camera c = scene.camera;
        c.from = {v[0], v[1], v[2]};
        c.at = {v[3], v[4], v[5]};
        c.up = {v[6], v[7], v[8]};
        c.angle = v[9];
        const Vec3 fwd = c.at - c.from;
        if (length(fwd) == 0) throw InputError("--camera", 0, "from and at are the same point");
        if (length(cross(fwd, c.up)) == 0) throw InputError("--camera", 0, "up is parallel to the view direction");
        if (!(c.angle > 0 && c.angle < 180)) throw InputError("--camera", 0, "the field of view must be in (0, 180) degrees");
        scene.camera = c;
        scene.has_camera = true;
    }
    // As for a ray file's far origins: the eye rays may start where float cannot resolve the scene.
    if (scene.has_camera && starts_too_far(scene.bounds(), Ray{scene.camera.from, {1, 0, 0}, 0, kInf}))
        scene.warnings.push_back(fmt::format(
            "{}: the camera lies more than {:g} scene sizes away; float positions cannot resolve the scene there, so "
            "hits may be rounding noise and hierarchies may disagree with brute force",
            view.camera.empty() ? scene.name : "--camera", kMaxResolvedDistance));
    if (!view.lights.empty()) {
        std::vector<Light> lights;
        for (const std::string& l : view.lights) {
            const std::vector<float> v = numbers(l, 3, "--light");
            for (float x : v)
                if (std::fabs(x) > kMaxCoordinate)
                    throw InputError("--light", 0, fmt::format("coordinate {:g} beyond +-{:g}", x, kMaxCoordinate));
            lights.push_back({{v[0], v[1], v[2]}, {1, 1, 1}});
        }
        scene.lights = std::move(lights);
    }
}

RaySet make_rays(const Scene& scene, const RaySpec& spec, const RayMaking& making) {
    if (const RayDistributionInfo* d = find_ray_distribution(spec.name)) return d->make(scene, spec, making);
    if (std::error_code ec; !std::filesystem::exists(spec.name, ec)) {
        std::string names;
        for (const auto& n : distribution_names()) names += (names.empty() ? "" : ", ") + n;
        throw InputError(spec.name, 0, "no such file, and not a distribution (" + names + ")");
    }
    RaySet set = one_kind(read_rays(spec.name), RayKind::File, spec.name);
    std::size_t far = 0, first = 0;
    for (std::size_t i = set.rays.size(); i-- > 0;)
        if (starts_too_far(scene.bounds(), set.rays[i])) ++far, first = i;
    if (far)
        set.warnings.push_back(fmt::format("{}: {} rays (the first: ray {}) start more than {:g} scene sizes away; "
                                           "float positions cannot resolve the scene there, so hits may be rounding "
                                           "noise and hierarchies may disagree with brute force",
                                           spec.name, far, first, kMaxResolvedDistance));
    return set;
}

bool starts_too_far(const Box3& bounds, const Ray& ray) {
    const Vec3 e = bounds.extent();
    const double size = std::max({e.x, e.y, e.z});
    double d2 = 0;
    for (int a = 0; a < 3; ++a) {
        const double out = std::max({0.0, double(bounds.lo[a]) - ray.o[a], double(ray.o[a]) - bounds.hi[a]});
        d2 += out * out;
    }
    return std::sqrt(d2) > double(kMaxResolvedDistance) * size;
}

}  // namespace rtcost
