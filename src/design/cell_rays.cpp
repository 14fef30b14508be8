// The sample's visit probabilities of a cell's children and the model's termination test.
#include "cell_rays.hpp"

#include <algorithm>
#include <cstring>

namespace rtcost::designing {
namespace {

double surface(const Box3& b) {
    const double x = double(b.hi.x) - b.lo.x, y = double(b.hi.y) - b.lo.y, z = double(b.hi.z) - b.lo.z;
    return 2.0 * (x * y + y * z + z * x);
}

}  // namespace

CellRays::CellRays(const Scene& s, const DesignInput& in, double trust, double k_trav, double k_step)
    : scene_(s), in_(in), trust_(trust), k_trav_(k_trav), k_step_(k_step) {
    inv_.reserve(in.sample.size());
    for (std::size_t i = 0; i < in.sample.size(); ++i) inv_.emplace_back(in.sample.rays.rays[i]);
    double prim = 0;
    for (std::uint32_t i = 0; i < s.size(); ++i) prim += test_cost(i);
    k_isect_ = s.size() ? prim / s.size() : 1;
}

double CellRays::test_cost(std::uint32_t id) const {
    // Every edge: the most a test walks (it walks them when the ray meets the polygon's plane).
    return in_.costs.prim[static_cast<int>(scene_.kind(id))] + in_.costs.polygon_edge * scene_.edges_walked(id);
}

CellRays::Key CellRays::key_of(const Box3& b) {
    Key k;
    const float v[6] = {b.lo.x, b.lo.y, b.lo.z, b.hi.x, b.hi.y, b.hi.z};
    std::memcpy(k.data(), v, sizeof v);
    return k;
}

bool CellRays::meets(std::uint32_t r, const Box3& b) const {
    const Ray& ray = in_.sample.rays.rays[r];
    // The segment up to where the ray's search ends, by the BVH's box test.
    return box_entry(b, inv_[r], ray.tmin, std::min(ray.tmax, in_.sample.t_end[r])) != kInf;
}

std::vector<std::uint32_t> CellRays::reaching(const Box3& cell) {
    if (auto it = kept_.find(key_of(cell)); it != kept_.end()) {
        std::vector<std::uint32_t> rays = std::move(it->second);
        kept_.erase(it);
        return rays;
    }
    return meeting(nullptr, cell);
}

std::vector<std::uint32_t> CellRays::meeting(const std::vector<std::uint32_t>* rays, const Box3& b) const {
    std::vector<std::uint32_t> out;
    if (!rays) {
        for (std::uint32_t r = 0; r < in_.sample.size(); ++r)
            if (meets(r, b)) out.push_back(r);
        return out;
    }
    for (std::uint32_t r : *rays)
        if (meets(r, b)) out.push_back(r);
    return out;
}

double CellRays::probability(const Box3& cell, const Box3& child, std::size_t m, std::size_t met) const {
    const double sv = surface(cell);
    double p = sv > 0 ? surface(child) / sv : 1;
    if (m == 0) return p;
    const double w = double(m) / (double(m) + trust_);
    return w * (double(met) / double(m)) + (1 - w) * p;
}

bool CellRays::split_pays(const Box3& cell, std::size_t n, const Box3* children, const std::size_t* counts, int k) {
    double tests[8];
    for (int i = 0; i < k; ++i) tests[i] = k_isect_ * static_cast<double>(counts[i]);
    return split_pays(cell, k_isect_ * static_cast<double>(n), children, tests, k);
}

bool CellRays::split_pays(const Box3& cell, double tests, const Box3* children, const double* child_tests, int k) {
    const std::vector<std::uint32_t> rays = reaching(cell);
    std::vector<std::vector<std::uint32_t>> child(k);
    double expected = 0, steps = 0;
    for (int i = 0; i < k; ++i) {
        child[i] = meeting(&rays, children[i]);
        const double p = probability(cell, children[i], rays.size(), child[i].size());
        expected += p * child_tests[i];
        steps += p;
    }
    if (!(k_trav_ + k_step_ * steps + expected < tests)) return false;
    for (int i = 0; i < k; ++i) kept_[key_of(children[i])] = std::move(child[i]);
    return true;
}

}  // namespace rtcost::designing
