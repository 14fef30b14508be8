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

CellRays::CellRays(const Scene& s, const DesignInput& in, double trust, double k_trav)
    : in_(in), trust_(trust), k_trav_(k_trav) {
    inv_.reserve(in.sample.size());
    for (std::size_t i = 0; i < in.sample.size(); ++i) inv_.emplace_back(in.sample.rays.rays[i]);
    double prim = 0;
    for (std::uint32_t i = 0; i < s.size(); ++i) prim += in.costs.prim[static_cast<int>(s.kind(i))];
    k_isect_ = s.size() ? prim / s.size() : 1;
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
    std::vector<std::uint32_t> rays;
    for (std::uint32_t r = 0; r < in_.sample.size(); ++r)
        if (meets(r, cell)) rays.push_back(r);
    return rays;
}

bool CellRays::split_pays(const Box3& cell, std::size_t n, const Box3* children, const std::size_t* counts, int k) {
    const std::vector<std::uint32_t> rays = reaching(cell);
    const double m = static_cast<double>(rays.size());
    const double w = m / (m + trust_), sv = surface(cell);
    std::vector<std::vector<std::uint32_t>> child(k);
    double expected = 0;
    for (int i = 0; i < k; ++i) {
        for (std::uint32_t r : rays)
            if (meets(r, children[i])) child[i].push_back(r);
        double p = sv > 0 ? surface(children[i]) / sv : 1;
        if (m > 0) p = w * (child[i].size() / m) + (1 - w) * p;
        expected += p * static_cast<double>(counts[i]);
    }
    if (!(k_trav_ + k_isect_ * expected < k_isect_ * static_cast<double>(n))) return false;
    for (int i = 0; i < k; ++i) kept_[key_of(children[i])] = std::move(child[i]);
    return true;
}

}  // namespace rtcost::designing
