// A ray sample made from the scene alone: what the geometric estimator learns termination from
// when the user gives no rays. Rays aimed at the primitives from outside stand for eye rays;
// where they first meet a surface, secondary rays start as a renderer's would, so P comes
// from the scene's own visibility (closed surfaces, rays that start on them, occlusion near
// the start) rather than from a formula that assumes primitives scattered independently.
#include <algorithm>
#include <oneapi/tbb/parallel_for.h>

#include "rays/whitted_tracer.hpp"
#include "rtcost/error.hpp"
#include "rtcost/sample.hpp"
#include "util/rng.hpp"

namespace rtcost {
namespace {

/// Rays from outside that stand for eye rays: aimed rays (rays.hpp) whose targets are chosen half
/// by primitive and half by area. By primitive alone, finely tessellated detail draws most of
/// them; by area alone, a floor does. Isotropic lines through the bounds and rays aimed at
/// uniform points of the bounds were tried too, on the SPD scenes and 2CylinderEngine: they
/// ranked the hierarchies worse (Spearman's rho down to 0.60 and 0.72 on camera rays).
std::vector<Ray> outside_rays(const Scene& scene, std::size_t n, std::uint64_t seed) {
    return aimed_rays(scene, n, seed, 0.5);
}

/// Where a ray from outside first met the scene, as shading sees it.
struct Landing {
    Vec3 p, dir, n;  // n faces the incoming ray
};

/// The first hits of rays from outside, until `want` of them or a bounded number of rays (a
/// scene they nearly never meet yields fewer).
std::vector<Landing> landings(const Hierarchy& h, std::size_t want, std::uint64_t seed) {
    const Scene& scene = h.scene();
    detail::WhittedTracer tracer(h, 1);
    std::vector<Landing> out;
    const std::size_t batch = std::max<std::size_t>(want, 1024);
    for (std::uint64_t round = 0; round < 16 && out.size() < want; ++round) {
        const std::vector<Ray> rays = outside_rays(scene, batch, seed * 7919 + 101 + round);
        std::vector<Landing> got(rays.size());
        std::vector<char> hit(rays.size(), 0);
        tbb::parallel_for(std::size_t(0), rays.size(), [&](std::size_t i) {
            Hit hh;
            h.closest(rays[i], hh);
            detail::Surface s;
            if (!tracer.surface(rays[i], hh, s)) return;
            got[i] = {s.p, s.dir, s.n};
            hit[i] = 1;
        });
        for (std::size_t i = 0; i < rays.size() && out.size() < want; ++i)
            if (hit[i]) out.push_back(got[i]);
    }
    return out;
}

bool from_outside(RayKind k) {
    return k == RayKind::Eye || k == RayKind::Line || k == RayKind::Test || k == RayKind::File;
}

}  // namespace

RaySample draw_visibility_sample(const Scene& scene, std::span<const RayKind> kinds, std::size_t per_kind,
                                 std::uint64_t seed, const Hierarchy& reference, Query query, Query occlusion) {
    if (per_kind == 0) throw InputError("--sample", 0, "a visibility sample needs at least one ray per kind");
    RaySample s;
    s.seed = seed;
    s.distribution = "visibility of the scene";
    s.rays.described = "visibility sample";
    const bool secondary = std::any_of(kinds.begin(), kinds.end(), [](RayKind k) { return !from_outside(k); });
    const std::vector<Landing> land = secondary ? landings(reference, per_kind, seed) : std::vector<Landing>{};
    const float eps = spawn_offset(scene), ao = ao_length(scene);
    auto add = [&](const Ray& r, RayKind k) {
        s.rays.rays.push_back(r);
        s.rays.kinds.push_back(k);
        s.queries.push_back(is_occlusion(k) ? occlusion : query);
    };
    std::uint64_t stream = 0;
    for (RayKind k : kinds) {
        ++stream;
        if (from_outside(k) || land.empty()) {
            // Rays from outside, or no surface that they meet: the aimed rays themselves.
            for (const Ray& r : outside_rays(scene, per_kind, seed + stream)) add(r, k);
            continue;
        }
        // Shadow rays exist only where the light is in front of the surface: points that face
        // away give none, so more points are tried (a bounded number).
        std::size_t made = 0;
        for (std::size_t i = 0; made < per_kind && i < 8 * per_kind; ++i) {
            const Landing& l = land[i % land.size()];
            ItemRng rng(seed + 31 * stream, i);
            const Vec3 up = l.p + l.n * eps;
            Ray r{up, detail::cosine_direction(l.n, rng), 0, kInf};
            if (k == RayKind::Shadow && !scene.lights.empty()) {
                // One light per point, in turn: the tree's rays go to each light alike.
                r.d = scene.lights[i % scene.lights.size()].position - up;
                r.tmax = 1;
                if (!(dot(r.d, l.n) > 0)) continue;
            } else if (k == RayKind::AO) {
                r.tmax = ao;
            } else if (k == RayKind::Reflection) {
                r.d = l.dir - l.n * (2 * dot(l.dir, l.n));
            } else if (k == RayKind::Refraction) {
                r.o = l.p - l.n * eps;
                r.d = l.dir;
            }
            add(r, k);
            ++made;
        }
    }
    s.population = 0;
    find_ends(s, reference);
    return s;
}

}  // namespace rtcost
