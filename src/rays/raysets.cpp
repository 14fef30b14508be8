// Named ray distributions: the one place that turns `--rays NAME` into rays.
#include <fmt/format.h>

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

std::vector<std::string> distribution_names() { return {"camera", "spd", "shadow", "diffuse", "ao", "lines", "random"}; }

namespace {
RaySet uniform(std::vector<Ray> rays, RayKind kind, std::string described) {
    RaySet set;
    set.kinds.assign(rays.size(), kind);
    set.summary.push_back({std::string(ray_kind_name(kind)), rays.size()});
    set.rays = std::move(rays);
    set.described = std::move(described);
    return set;
}
}  // namespace

RaySet make_rays(const Scene& scene, const RaySpec& spec) {
    if (spec.name == "camera") {
        int w = scene.camera.width, h = scene.camera.height;
        if (!spec.size.empty()) parse_size(spec.size, "--size", w, h);
        return uniform(camera_rays(scene.camera, w, h), RayKind::Eye, fmt::format("camera {}x{}", w, h));
    }
    if (spec.name == "lines")
        return uniform(line_rays(scene.bounds(), spec.count, spec.seed), RayKind::Line,
                       fmt::format("lines {} seed {}", spec.count, spec.seed));
    if (spec.name == "random")
        return uniform(random_rays(scene.bounds(), spec.count, spec.seed), RayKind::Test,
                       fmt::format("random {} seed {}", spec.count, spec.seed));
    if (is_tree_distribution(spec.name)) return make_tree_rays(scene, spec);
    if (std::error_code ec; !std::filesystem::exists(spec.name, ec)) {
        std::string names;
        for (const auto& n : distribution_names()) names += (names.empty() ? "" : ", ") + n;
        throw InputError(spec.name, 0, "no such file, and not a distribution (" + names + ")");
    }
    return uniform(read_rays(spec.name), RayKind::File, spec.name);
}

}  // namespace rtcost
