// `grid-design`: the resolution search over candidate grids, each priced on the design sample
// by its own traversal with the sample's known crossings (no primitive tests), and the
// registration.
#include "grid_design.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "design/replay.hpp"

namespace rtcost::grid {

std::vector<Candidate> search_resolution(const Scene& s, const DesignInput& in, spatial::Assign assign, bool mailbox,
                                         std::uint64_t max_cells, std::unique_ptr<Grid>* cheapest) {
    std::map<std::array<int, 3>, double> seen;
    const Box3 box = s.bounds();
    const designing::SampleReplay replay(s, in.sample, in.costs);
    const std::vector<Box3> bounds = spatial::prim_bounds(s);  // once for every candidate
    // The cheapest grid built so far, kept rather than built again at the end.
    std::unique_ptr<Grid> kept;
    double kept_cost = kInf;
    auto cost = [&](std::array<int, 3> r) -> double {
        for (int a = 0; a < 3; ++a) r[a] = std::clamp(r[a], 1, kMaxRes);
        if (auto it = seen.find(r); it != seen.end()) return it->second;
        const std::uint64_t cells = std::uint64_t(r[0]) * r[1] * r[2];
        double c = kInf;
        if (cells <= max_cells) {
            auto g = std::make_unique<Grid>(s, r, assign, mailbox, bounds);
            c = replay.time(*g);
            if (cheapest && c < kept_cost) kept = std::move(g), kept_cost = c;
        }
        seen[r] = c;
        return c;
    };
    std::array<int, 3> best{1, 1, 1};
    double best_cost = kInf;
    // From one cell per primitive, doubling while the cost falls, else halving while it falls
    // (the sample's cost is unimodal in the density on every scene tried; the coarsest grids
    // cost the most to replay, the finest the most to build). A candidate above the cap costs
    // nothing: it is never built, and ends the doubling.
    auto at = [&](double density) {
        const std::array<int, 3> r = resolution("hetero", density, s.size(), box);
        const double c = cost(r);
        const bool better = c < best_cost;
        if (better) best_cost = c, best = r;
        return better;
    };
    at(1.0);
    bool finer = false;
    for (double density = 2.0; density <= 64.0 && at(density); density *= 2) finer = true;
    if (!finer)
        for (double density = 0.5; density >= 0.125 && at(density); density /= 2) {
        }
    // Coordinate descent: each axis up or down by a third until no step lowers the cost.
    for (int round = 0; round < 6; ++round) {
        bool improved = false;
        for (int a = 0; a < 3; ++a) {
            const float ext = std::max({box.hi[0] - box.lo[0], box.hi[1] - box.lo[1], box.hi[2] - box.lo[2]});
            if (!(box.hi[a] - box.lo[a] > kFlat * ext)) continue;
            for (double f : {4.0 / 3.0, 3.0 / 4.0}) {
                std::array<int, 3> r = best;
                r[a] = std::max(1, static_cast<int>(std::lround(best[a] * f)));
                if (r[a] == best[a]) r[a] = f > 1 ? best[a] + 1 : std::max(1, best[a] - 1);
                if (r == best) continue;
                const double c = cost(r);
                if (c < best_cost) {
                    best_cost = c, best = r, improved = true;
                    break;
                }
            }
        }
        if (!improved) break;
    }
    std::vector<Candidate> out;
    for (const auto& [r, c] : seen) out.push_back({r, c});
    // Cheapest first; ties to the fewest cells, then the resolution, so the order is the same
    // on every machine.
    std::sort(out.begin(), out.end(), [](const Candidate& x, const Candidate& y) {
        if (x.cost != y.cost) return x.cost < y.cost;
        const auto cx = std::uint64_t(x.res[0]) * x.res[1] * x.res[2], cy = std::uint64_t(y.res[0]) * y.res[1] * y.res[2];
        if (cx != cy) return cx < cy;
        return x.res < y.res;
    });
    // The cheapest first: the grid kept unless a tie put another resolution first.
    if (cheapest) *cheapest = kept && kept->res() == out.front().res ? std::move(kept) : nullptr;
    return out;
}

namespace {

std::vector<ParamSpec> params() {
    std::vector<ParamSpec> p = design_param_specs("ops");
    // 32, not 8: on balls and tree the model's optimum lies beyond 8 cells per primitive, where a
    // sweep of grids measured the fastest (16 and more), and the search stopped at the cap.
    p.push_back(ParamSpec::real("max_density", "32", 0.01, 64, "largest candidate grid, in cells per primitive"));
    p.push_back(spatial::kAssignParam);
    p.push_back(spatial::kMailboxParam);
    return p;
}

const Registration reg{
    {"grid-design",
     "uniform grid whose per-axis resolution minimises the cost model's prediction for a sample of the given rays",
     params(),
     [](const Scene& s, const Params& p) -> std::unique_ptr<Hierarchy> {
         const DesignInput in = draw_design_input(s, p);
         const spatial::Assign assign = spatial::parse_assign(p);
         const bool mailbox = p.flag("mailbox");
         const double md = p.real("max_density");
         const auto max_cells =
             std::min<std::uint64_t>(kMaxCells, static_cast<std::uint64_t>(std::max(1.0, md * static_cast<double>(s.size()))) + 64);
         std::unique_ptr<Grid> g;
         std::vector<Candidate> tried = search_resolution(s, in, assign, mailbox, max_cells, &g);
         if (!g) g = std::make_unique<Grid>(s, tried.front().res, assign, mailbox);
         return std::make_unique<GridDesign>(s, std::move(g), std::move(tried));
     },
     kLargeScene}};  // each candidate grid's model tree holds two nodes per cell: minutes for a million

}  // namespace
}  // namespace rtcost::grid
