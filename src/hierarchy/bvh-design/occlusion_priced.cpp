// The order bytes priced on the sample, subtree by subtree: each binary node's order for each
// direction sign is the one under which its subtree costs least for the sample's occlusion rays
// that meet both its children, the orders below it being decided the same way. An any-hit walk
// without culling finds a hit in a subtree exactly when one of the ray's crossings lies in it,
// whatever the order inside, so a subtree's cost for a ray depends only on the orders within it,
// and deciding from the bottom up gives each subtree its cheapest orders for every ray that
// enters it. (Not the whole tree's optimum: which rays get to a node at all depends on the
// orders above it. Weighing only those, one node's turn at a time, did no better on the test
// rays and did not settle in a dozen sweeps.) Where the ends-per-primitive rule of
// occlusion_bits.cpp guesses, this prices; a node or sign that no ray meeting both its children
// tells apart keeps its guessed bit.
#include <algorithm>
#include <array>
#include <span>
#include <vector>

#include "occlusion_order.hpp"

namespace rtcost::bvh {

void price_occlusion_bits(const BvhData& d, const Scene& s, const RaySample& sample, const UnitCosts& costs,
                          std::vector<std::uint8_t>& bits) {
    const std::size_t nn = d.nodes.size();
    if (nn == 0) return;
    // A reference's test; a polygon's also walks the edges its test walks on the ray (no hit
    // yet: an any-hit walk stops at its first).
    std::vector<double> prim_cost(d.refs.size());
    std::vector<bool> polygon(d.refs.size());
    for (std::size_t k = 0; k < d.refs.size(); ++k) {
        prim_cost[k] = costs.prim[static_cast<int>(s.kind(d.refs[k]))];
        polygon[k] = s.kind(d.refs[k]) == PrimKind::Polygon;
    }
    const double interior_cost = costs.step + 2 * costs.box, leaf_step = costs.step;
    // The occlusion rays that cross something before their end: a ray that crosses nothing costs
    // either order alike everywhere (no subtree ends it), so it cannot tell two orders apart.
    std::vector<std::uint32_t> rays;
    for (std::uint32_t r = 0; r < sample.size(); ++r) {
        if (sample.queries[r] != Query::Any) continue;
        const Ray& ray = sample.rays.rays[r];
        const auto known = sample.crossings_of(r);
        if (std::any_of(known.begin(), known.end(), [&](const Crossing& c) { return c.t < ray.tmax; })) rays.push_back(r);
    }
    // Per node and sign: the rays' costs with the first child entered first, and with the
    // second, summed over the rays that meet both.
    std::vector<std::array<double, 4>> sums(nn);
    struct Walked {
        double cost;
        bool ends;
    };
    const Ray* ray = nullptr;
    RayInv ri(Ray{});
    PairRay pair_ray(ri);
    model::KnownCrossings known;
    // The subtree of `node` walked by the ray (every child it meets, the orders as they are).
    auto walk = [&](auto&& self, std::uint32_t node) -> Walked {
        const Node& n = d.nodes[node];
        if (n.leaf) {
            double c = leaf_step;
            for (std::uint32_t k = n.index; k < n.index + n.count; ++k) {
                c += prim_cost[k];
                if (polygon[k]) c += costs.polygon_edge * s.edges_walked(d.refs[k], *ray);
                Hit hit;
                if (known.hit(d.refs[k], *ray, hit)) return {c, true};
            }
            return {c, false};
        }
        bool ma, mb = false;
        if (n.count == 2) {
            float ta, tb;
            pair_entry(d.nodes[n.index].box, d.nodes[n.index + 1].box, pair_ray, ray->tmin, ray->tmax, ta, tb);
            ma = ta != kInf, mb = tb != kInf;
        } else {
            ma = box_entry(d.nodes[n.index].box, ri, ray->tmin, ray->tmax) != kInf;
        }
        if (!ma && !mb) return {interior_cost, false};
        if (ma != mb) {
            const Walked w = self(self, n.index + (ma ? 0 : 1));
            return {interior_cost + w.cost, w.ends};
        }
        const Walked a = self(self, n.index), b = self(self, n.index + 1);
        const int sign = ri.neg[bits[node] & 3];
        const double first = a.cost + (a.ends ? 0.0 : b.cost), second = b.cost + (b.ends ? 0.0 : a.cost);
        sums[node][2 * sign] += first;
        sums[node][2 * sign + 1] += second;
        const bool second_first = !any_order_first_child_first(bits[node], ri.neg);
        return {interior_cost + (second_first ? second : first), a.ends || b.ends};
    };
    // Each sweep decides every bit from the costs under the previous sweep's bits: the nodes of
    // height h are final after h sweeps, so this ends by the tree's height plus one (3 or 4
    // sweeps on the SPD scenes' trees).
    const int max_sweeps = kMaxDepth + 2;
    for (int sweep = 0; sweep < max_sweeps; ++sweep) {
        std::fill(sums.begin(), sums.end(), std::array<double, 4>{0, 0, 0, 0});
        for (std::uint32_t r : rays) {
            ray = &sample.rays.rays[r];
            ri = RayInv(*ray);
            pair_ray = PairRay(ri);
            known = model::KnownCrossings(sample.crossings_of(r));
            if (box_entry(d.nodes[0].box, ri, ray->tmin, ray->tmax) != kInf) walk(walk, 0);
        }
        bool changed = false;
        for (std::size_t i = 0; i < nn; ++i) {
            const std::array<double, 4>& sum = sums[i];
            for (int sign = 0; sign < 2; ++sign) {
                if (sum[2 * sign] == sum[2 * sign + 1]) continue;  // no ray tells them apart: as it is
                const auto bit = static_cast<std::uint8_t>(1u << (2 + sign));
                const auto b = static_cast<std::uint8_t>(sum[2 * sign + 1] < sum[2 * sign] ? bits[i] | bit : bits[i] & ~bit);
                changed |= b != bits[i];
                bits[i] = b;
            }
        }
        if (!changed) break;
    }
}

}  // namespace rtcost::bvh
