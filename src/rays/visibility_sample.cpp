// A ray sample made from the scene alone: what the geometric estimator learns termination from
// when the user gives no rays. Eye rays come from the scene's camera, through uniform points of
// its view (the camera is part of the scene, as its lights are); lines and file rays, which no
// camera describes, are rays aimed at the primitives from outside. Where eye rays first meet a
// surface, secondary rays start as a renderer's would, so P comes from the scene's own
// visibility (closed surfaces, rays that start on them, occlusion near the start) rather than
// from a formula that assumes primitives scattered independently.
#include <algorithm>
#include <optional>
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

/// Where a ray first met the scene, as shading sees it.
using Landing = detail::Surface;

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
        got[i] = s;
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

// What the Whitted tree spawns at a landing (whitted.cpp): transmitters reflect too.
bool reflects(const Landing& l) { return l.m && (l.m->ks > 0 || l.m->t > 0); }
bool transmits(const Landing& l) { return l.m && l.m->t > 0; }

Ray reflected(const Landing& l, float eps) { return Ray{l.p + l.n * eps, detail::mirrored(l), 0, kInf}; }

/// Bent as the tracer bends it; straight on where the material does not transmit; none under
/// total internal reflection.
std::optional<Ray> refracted(const Landing& l, float eps) {
    Ray r{l.p - l.n * eps, l.dir, 0, kInf};
    if (!transmits(l)) return r;
    const std::optional<Vec3> d = detail::refracted(l);
    if (!d) return std::nullopt;
    r.d = *d;
    return r;
}

}  // namespace

RaySample draw_visibility_sample(const Scene& scene, std::span<const RayKind> kinds_asked, std::size_t per_kind,
                                 std::uint64_t seed, const Hierarchy& reference, Query query, Query occlusion,
                                 const Camera* view) {
    if (per_kind == 0) throw InputError("--sample", 0, "a visibility sample needs at least one ray per kind");
    const Camera& cam = view ? *view : scene.camera;
    std::vector<RayKind> kinds;  // each kind once, in the order asked: its place gives its random stream
    for (RayKind k : kinds_asked)
        if (std::find(kinds.begin(), kinds.end(), k) == kinds.end()) kinds.push_back(k);
    RaySample s;
    s.seed = seed;
    s.distribution = "visibility of the scene";
    s.rays.described = "visibility sample";
    const bool secondary =
        std::any_of(kinds.begin(), kinds.end(), [](RayKind k) { return k != RayKind::Eye && !from_outside(k); });
    const bool tree = std::any_of(kinds.begin(), kinds.end(),
                                  [](RayKind k) { return k == RayKind::Reflection || k == RayKind::Refraction; });
    const std::vector<Landing> land = secondary ? landings(reference, cam, per_kind, seed) : std::vector<Landing>{};
    const float eps = spawn_offset(scene), ao = ao_length(scene);
    // In a ray tree (reflection or refraction rays among the kinds), shadow, diffuse and
    // ambient-occlusion rays start also where the first bounce of each eye landing lands, one
    // bounce per reflection or refraction the tree would spawn there: shadow rays go from every
    // hit, not only the eye rays'.
    std::vector<Landing> bounced;
    if (tree) {
        std::vector<Ray> bounces;
        for (const Landing& l : land) {
            if (reflects(l)) bounces.push_back(reflected(l, eps));
            if (transmits(l))
                if (const std::optional<Ray> r = refracted(l, eps)) bounces.push_back(*r);
        }
        bounced = landings_of(reference, bounces);
    }
    auto add = [&](const Ray& r, RayKind k) {
        s.rays.rays.push_back(r);
        s.rays.kinds.push_back(k);
        s.queries.push_back(is_occlusion(k) ? occlusion : query);
    };
    for (std::size_t at = 0; at < kinds.size(); ++at) {
        const RayKind k = kinds[at];
        const std::uint64_t stream = at + 1;
        if (k == RayKind::Eye) {
            for (const Ray& r : eye_rays(cam, per_kind, seed + stream)) add(r, k);
            continue;
        }
        if (from_outside(k) || land.empty()) {
            // Rays from outside, or no surface that eye rays meet: aimed rays.
            for (const Ray& r : outside_rays(scene, per_kind, seed + stream)) add(r, k);
            continue;
        }
        // Reflection and refraction rays start where the material reflects or transmits (every
        // landing if none does); the other kinds at every landing, the bounces' included.
        std::vector<const Landing*> from;
        for (const Landing& l : land)
            if (k == RayKind::Reflection ? reflects(l) : k == RayKind::Refraction ? transmits(l) : true)
                from.push_back(&l);
        if (k != RayKind::Reflection && k != RayKind::Refraction)
            for (const Landing& l : bounced) from.push_back(&l);
        if (from.empty())
            for (const Landing& l : land) from.push_back(&l);
        // Shadow rays exist only where the light is in front of the surface: points that face
        // away give none, so more points are tried (a bounded number). Each try picks its
        // landing at random: the pool may hold more landings than rays are made.
        std::size_t made = 0;
        for (std::size_t i = 0; made < per_kind && i < 8 * per_kind; ++i) {
            ItemRng rng(seed + 31 * stream, i);
            const auto pick = static_cast<std::size_t>(rng.uniform() * static_cast<double>(from.size()));
            const Landing& l = *from[std::min(pick, from.size() - 1)];
            Ray r{l.p + l.n * eps, detail::cosine_direction(l.n, rng), 0, kInf};
            if (k == RayKind::Shadow && !scene.lights.empty()) {
                // One light per point, in turn: the tree's rays go to each light alike.
                r.d = scene.lights[i % scene.lights.size()].position - r.o;
                r.tmax = 1;
                if (!(dot(r.d, l.n) > 0)) continue;
            } else if (k == RayKind::AO) {
                r.tmax = ao;
            } else if (k == RayKind::Reflection) {
                r = reflected(l, eps);
            } else if (k == RayKind::Refraction) {
                const std::optional<Ray> bent = refracted(l, eps);
                if (!bent) continue;  // total internal reflection: no refraction ray
                r = *bent;
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
