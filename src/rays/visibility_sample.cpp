// A ray sample made from the scene alone: what the geometric estimator learns termination from
// when the user gives no rays. Eye rays come from the scene's camera, through uniform points of
// its view (the camera is part of the scene, as its lights are); lines and file rays, which no
// camera describes, are rays aimed at the primitives from outside. Where eye rays first meet a
// surface, secondary rays start as a renderer's would, so P comes from the scene's own
// visibility (closed surfaces, rays that start on them, occlusion near the start) rather than
// from a formula that assumes primitives scattered independently.
#include <algorithm>
#include <cmath>
#include <oneapi/tbb/parallel_for.h>

#include "rays/whitted_tracer.hpp"
#include "rtcost/error.hpp"
#include "rtcost/sample.hpp"
#include "util/rng.hpp"

namespace rtcost {
namespace {

/// Rays from outside that stand for lines and file rays: aimed rays (rays.hpp) whose targets are
/// chosen half by primitive and half by area. By primitive alone, finely tessellated detail
/// draws most of them; by area alone, a floor does. Isotropic lines through the bounds and rays
/// aimed at uniform points of the bounds ranked the hierarchies worse on camera rays (Spearman's
/// rho down to 0.60 and 0.72 on the SPD scenes and 2CylinderEngine).
std::vector<Ray> outside_rays(const Scene& scene, std::size_t n, std::uint64_t seed) {
    return aimed_rays(scene, n, seed, 0.5);
}

/// Eye rays of the scene's camera through uniform points of its view. Until 2026-12-04 eye rays
/// too were aimed from outside: they missed nothing, saw every side of the scene alike, and put
/// the geometric estimate of camera rays 75% off on average (docs/model-accuracy.md).
std::vector<Ray> eye_rays(const Camera& cam, std::size_t n, std::uint64_t seed) {
    return view_rays(cam, std::max(cam.width, 1), std::max(cam.height, 1), n, seed);
}

/// Where a ray from outside first met the scene, as shading sees it.
struct Landing {
    Vec3 p, dir, n;  // n faces the incoming ray
    bool front;      // the ray met the side the geometric normal points to
    const Material* m;
};

/// Where `rays` first meet a surface, as shading sees it (misses left out), in their order.
std::vector<Landing> landings_of(const Hierarchy& h, const std::vector<Ray>& rays) {
    detail::WhittedTracer tracer(h, 1);
    std::vector<Landing> got(rays.size());
    std::vector<char> hit(rays.size(), 0);
    tbb::parallel_for(std::size_t(0), rays.size(), [&](std::size_t i) {
        Hit hh;
        h.closest(rays[i], hh);
        detail::Surface s;
        if (!tracer.surface(rays[i], hh, s)) return;
        got[i] = {s.p, s.dir, s.n, s.front, s.m};
        hit[i] = 1;
    });
    std::vector<Landing> out;
    for (std::size_t i = 0; i < rays.size(); ++i)
        if (hit[i]) out.push_back(got[i]);
    return out;
}

/// The first hits of eye rays, until `want` of them or a bounded number of rays (a scene they
/// nearly never meet yields fewer).
std::vector<Landing> landings(const Hierarchy& h, const Camera& cam, std::size_t want, std::uint64_t seed) {
    std::vector<Landing> out;
    const std::size_t batch = std::max<std::size_t>(want, 1024);
    for (std::uint64_t round = 0; round < 16 && out.size() < want; ++round) {
        const std::vector<Landing> got = landings_of(h, eye_rays(cam, batch, seed * 7919 + 101 + round));
        out.insert(out.end(), got.begin(), got.begin() + static_cast<std::ptrdiff_t>(std::min(got.size(), want - out.size())));
    }
    return out;
}

bool from_outside(RayKind k) { return k == RayKind::Line || k == RayKind::Test || k == RayKind::File; }

}  // namespace

RaySample draw_visibility_sample(const Scene& scene, std::span<const RayKind> kinds, std::size_t per_kind,
                                 std::uint64_t seed, const Hierarchy& reference, Query query, Query occlusion,
                                 const Camera* view) {
    const Camera& cam = view ? *view : scene.camera;
    if (per_kind == 0) throw InputError("--sample", 0, "a visibility sample needs at least one ray per kind");
    RaySample s;
    s.seed = seed;
    s.distribution = "visibility of the scene";
    s.rays.described = "visibility sample";
    const bool secondary =
        std::any_of(kinds.begin(), kinds.end(), [](RayKind k) { return k != RayKind::Eye && !from_outside(k); });
    const std::vector<Landing> land = secondary ? landings(reference, cam, per_kind, seed) : std::vector<Landing>{};
    const float eps = spawn_offset(scene), ao = ao_length(scene);
    auto add = [&](const Ray& r, RayKind k) {
        s.rays.rays.push_back(r);
        s.rays.kinds.push_back(k);
        s.queries.push_back(is_occlusion(k) ? occlusion : query);
    };
    // Reflection and refraction rays first: where they land, shadow, diffuse and ambient-occlusion
    // rays start too, as they do in the Whitted tree (shadow rays from every hit, not only the
    // eye rays'). Each kind keeps its own random stream, by its place in `kinds`.
    std::vector<RayKind> order(kinds.begin(), kinds.end());
    std::stable_partition(order.begin(), order.end(),
                          [](RayKind k) { return k == RayKind::Reflection || k == RayKind::Refraction; });
    std::vector<Landing> later;
    for (RayKind k : order) {
        const std::uint64_t stream = 1 + static_cast<std::uint64_t>(std::find(kinds.begin(), kinds.end(), k) - kinds.begin());
        const std::size_t first = s.rays.rays.size();
        if (k == RayKind::Eye) {
            for (const Ray& r : eye_rays(cam, per_kind, seed + stream)) add(r, k);
            continue;
        }
        if (from_outside(k) || land.empty()) {
            // Rays from outside, or no surface that eye rays meet: aimed rays.
            for (const Ray& r : outside_rays(scene, per_kind, seed + stream)) add(r, k);
            continue;
        }
        // Reflection and refraction rays start where the material reflects or transmits, as the
        // Whitted tree spawns them (transmitters reflect too); elsewhere if no landing does.
        std::vector<const Landing*> from;
        for (const Landing& l : land)
            if (k == RayKind::Reflection ? l.m && (l.m->ks > 0 || l.m->t > 0)
                                         : k == RayKind::Refraction ? l.m && l.m->t > 0 : true)
                from.push_back(&l);
        if (k != RayKind::Reflection && k != RayKind::Refraction)
            for (const Landing& l : later) from.push_back(&l);
        if (from.empty())
            for (const Landing& l : land) from.push_back(&l);
        // Shadow rays exist only where the light is in front of the surface: points that face
        // away give none, so more points are tried (a bounded number).
        std::size_t made = 0;
        for (std::size_t i = 0; made < per_kind && i < 8 * per_kind; ++i) {
            const Landing& l = *from[i % from.size()];
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
                // Snell's law as the tracer bends them; straight on where no material says how.
                r.o = l.p - l.n * eps;
                r.d = l.dir;
                if (l.m && l.m->t > 0) {
                    const float ior = l.m->ior > 0 ? l.m->ior : 1.0f, eta = l.front ? 1 / ior : ior;
                    const float cos_i = -dot(l.dir, l.n), q = 1 - eta * eta * (1 - cos_i * cos_i);
                    if (q < 0) continue;  // total internal reflection: no refraction ray
                    r.d = normalize(l.dir * eta + l.n * (eta * cos_i - std::sqrt(q)));
                }
            }
            add(r, k);
            ++made;
        }
        if (k == RayKind::Reflection || k == RayKind::Refraction) {
            const std::vector<Ray> mine(s.rays.rays.begin() + static_cast<std::ptrdiff_t>(first), s.rays.rays.end());
            const std::vector<Landing> got = landings_of(reference, mine);
            later.insert(later.end(), got.begin(), got.end());
        }
    }
    s.population = 0;
    find_ends(s, reference);
    return s;
}

}  // namespace rtcost
