// Drawing a ray sample: rays of a distribution picked without replacement (stratified along
// their order), and how each ends.
#include "rtcost/sample.hpp"

#include <algorithm>
#include <oneapi/tbb/parallel_for.h>

#include "rtcost/error.hpp"
#include "util/rng.hpp"

namespace rtcost {
namespace {

/// The indices of a sample of `count` out of `n`, ascending, stratified: one index drawn
/// uniformly from each of `count` runs of consecutive indices of equal length (to one). A
/// distribution's rays come in their order (camera-based kinds pixel by pixel, a ray tree's
/// kinds together), so the sample covers the image evenly and each kind in its proportion,
/// where an unstratified draw leaves clusters and gaps: the mean cost of nearby pixels is
/// alike, so the sample's mean varies less (`tests/test_segments.cpp` measures by how much).
std::vector<std::size_t> pick(std::size_t n, std::size_t count, std::uint64_t seed) {
    count = std::min(count, n);
    std::vector<std::size_t> idx(count);
    Rng rng(seed);
    for (std::size_t j = 0; j < count; ++j) {
        // Run j is [j n / count, (j + 1) n / count), never empty since count <= n.
        const std::size_t lo = static_cast<std::size_t>(static_cast<unsigned __int128>(j) * n / count);
        const std::size_t hi = static_cast<std::size_t>(static_cast<unsigned __int128>(j + 1) * n / count);
        idx[j] = lo + static_cast<std::size_t>(rng.engine() % (hi - lo));
    }
    return idx;
}

/// The first primitives `ray` meets, nearest first, each once (a closed surface is met again
/// on its way out): closest-hit queries, each starting where the last hit was.
std::vector<Crossing> crossings(const Hierarchy& h, const Ray& ray) {
    std::vector<Crossing> out;
    Ray r = ray;
    // A primitive met twice (entry and exit of a sphere) costs an extra query, so allow some.
    for (std::size_t step = 0; step < 2 * kMaxCrossings && out.size() < kMaxCrossings; ++step) {
        Hit hit;
        h.closest(r, hit);
        if (!hit.hit()) break;
        const auto id = static_cast<std::uint32_t>(hit.prim);
        if (std::none_of(out.begin(), out.end(), [&](const Crossing& c) { return c.prim == id; }))
            out.push_back({id, hit.t});
        if (!(hit.t > r.tmin)) break;  // no progress (cannot happen with the open interval)
        r.tmin = hit.t;
    }
    return out;
}

}  // namespace

RaySet rays_outside_sample(const RaySet& all, std::size_t count, std::uint64_t seed) {
    const std::vector<std::size_t> in = pick(all.rays.size(), count, seed);
    RaySet out;
    out.described = all.described;
    out.rays.reserve(all.rays.size() - in.size());
    out.kinds.reserve(all.rays.size() - in.size());
    std::size_t next = 0;
    for (std::size_t i = 0; i < all.rays.size(); ++i) {
        if (next < in.size() && in[next] == i) {
            ++next;
            continue;
        }
        out.rays.push_back(all.rays[i]);
        out.kinds.push_back(all.kinds[i]);
    }
    return out;
}

void find_ends(RaySample& s, const Hierarchy& reference) {
    const std::size_t n = s.rays.rays.size();
    std::vector<std::vector<Crossing>> per(n);
    tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) { per[i] = crossings(reference, s.rays.rays[i]); });
    s.first.clear();
    s.t_end.clear();
    s.crossings.clear();
    s.first.reserve(n + 1);
    s.t_end.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
        s.first.push_back(static_cast<std::uint32_t>(s.crossings.size()));
        s.t_end.push_back(per[i].empty() ? s.rays.rays[i].tmax : per[i].front().t);
        s.crossings.insert(s.crossings.end(), per[i].begin(), per[i].end());
    }
    s.first.push_back(static_cast<std::uint32_t>(s.crossings.size()));
}

RaySample draw_sample(const Scene& scene, const RaySpec& spec, std::size_t count, std::uint64_t seed,
                      const Hierarchy& reference, Query query, Query occlusion) {
    return draw_sample_from(scene, make_rays(scene, spec), count, seed, reference, query, occlusion);
}

RaySample draw_sample_from(const Scene& scene, const RaySet& all, std::size_t count, std::uint64_t seed,
                           const Hierarchy& reference, Query query, Query occlusion) {
    (void)scene;
    if (count == 0) throw InputError("--count", 0, "a sample needs at least one ray");
    if (all.rays.empty()) throw InputError(all.described, 0, "the distribution has no rays");
    const std::vector<std::size_t> idx = pick(all.rays.size(), count, seed);
    RaySample s;
    s.distribution = all.described;
    s.seed = seed;
    s.population = all.rays.size();
    s.rays.described = all.described + " (sample)";
    for (std::size_t i : idx) {
        s.rays.rays.push_back(all.rays[i]);
        s.rays.kinds.push_back(all.kinds[i]);
        s.queries.push_back(is_occlusion(all.kinds[i]) ? occlusion : query);
    }
    find_ends(s, reference);
    return s;
}

}  // namespace rtcost
