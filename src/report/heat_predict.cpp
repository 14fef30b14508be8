// The model's per-pixel prediction (HeatKind::Predicted): one RayCostModel per ray kind,
// learned from a small sample of the same pixels' distribution.
#include <array>
#include <memory>
#include <string>

#include <fmt/format.h>

#include "rtcost/error.hpp"
#include "rtcost/heatmap.hpp"
#include "rtcost/rays.hpp"
#include "rtcost/sample.hpp"

namespace rtcost {

std::function<CostVector(const Ray&, RayKind)> predicted_ray_cost(const Hierarchy& h, const PixelCostOptions& opt,
                                                                  std::size_t sample_rays) {
    if (!h.modelled()) throw InputError("--heatmap", 0, fmt::format("predicted: {} has no model tree", h.name()));
    const Scene& scene = h.scene();
    RaySpec spec;
    spec.name = opt.tree ? "spd" : "camera";
    spec.size = fmt::format("{}x{}", opt.width, opt.height);
    const RaySet all = make_rays(scene, spec);
    // As eval's segments estimator: 2% of the rays, at most 4,096, at least 256 where there are enough.
    const std::size_t pop = all.rays.size();
    const std::size_t n = sample_rays > 0 ? std::min(sample_rays, pop)
                                          : std::min<std::size_t>(4096, std::max(pop / 50, std::min<std::size_t>(256, pop)));
    if (n == 0) throw InputError("--heatmap", 0, "predicted: no rays to sample");
    const auto reference = build_hierarchy(scene, "bvh-sah");
    const auto sample = std::make_shared<const RaySample>(draw_sample_from(scene, all, n, 1, *reference, Query::Closest,
                                                                           opt.occlusion));
    const ModelTree tree = h.model_tree();
    auto query_of = [&](RayKind k) { return is_occlusion(k) && opt.occlusion == Query::Any ? Query::Any : Query::Closest; };
    // The sample's rays by kind, and by query for kinds the sample has none of.
    std::array<std::vector<std::uint32_t>, kRayKinds> by_kind;
    std::array<std::vector<std::uint32_t>, 2> by_query;
    for (std::uint32_t i = 0; i < sample->size(); ++i) {
        const RayKind k = sample->rays.kinds[i];
        by_kind[static_cast<int>(k)].push_back(i);
        by_query[query_of(k) == Query::Any].push_back(i);
    }
    std::array<std::shared_ptr<const RayCostModel>, kRayKinds> models;
    for (int k = 0; k < kRayKinds; ++k) {
        const Query q = query_of(static_cast<RayKind>(k));
        const auto& rays = !by_kind[k].empty() ? by_kind[k] : !by_query[q == Query::Any].empty() ? by_query[q == Query::Any]
                                                                                               : by_query[q != Query::Any];
        if (rays.empty()) continue;
        ModelOptions mo;
        mo.query = q;
        models[k] = std::make_shared<const RayCostModel>(tree, scene, *sample, rays, mo);
    }
    return [models, sample](const Ray& ray, RayKind kind) {
        const auto& m = models[static_cast<int>(kind)];
        return m ? m->predict(ray) : CostVector{};
    };
}

}  // namespace rtcost
