// The Whitted ray tree (SPD testing procedure), rays spawned from camera hits, and the shared
// recursion that render.cpp shades with. See whitted.hpp for the conventions.
#include "rays/whitted_tracer.hpp"

#include <fmt/format.h>

#include <atomic>
#include <cmath>
#include <mutex>
#include <numbers>
#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>

#include "rtcost/error.hpp"
#include "rtcost/trace.hpp"
#include "util/rng.hpp"

namespace rtcost {

std::size_t KindCounts::total() const {
    std::size_t n = 0;
    for (std::size_t r : rays) n += r;
    return n;
}

float ao_length(const Scene& scene) { return 0.05f * length(scene.bounds().extent()); }

float spawn_offset(const Scene& scene) {
    float diag = length(scene.bounds().extent());
    return diag > 0 ? 1e-5f * diag : 1e-5f;
}

namespace detail {

WhittedTracer::WhittedTracer(const Hierarchy& h, int max_depth, bool shadow_tests)
    : scene_(h.scene()), h_(h), max_depth_(max_depth), shadow_tests_(shadow_tests), eps_(spawn_offset(h.scene())),
      light_scale_(h.scene().lights.empty() ? 1.0f : 1.0f / std::sqrt(static_cast<float>(h.scene().lights.size()))) {}

bool WhittedTracer::surface(const Ray& ray, Hit& hit, Surface& s) const {
    if (!hit.hit()) return false;
    scene_.complete_hit(ray, hit);
    s.dir = normalize(ray.d);
    s.p = ray.o + ray.d * hit.t;
    s.front = dot(hit.ng, s.dir) < 0;
    s.n = s.front ? hit.ng : -hit.ng;
    s.m = &scene_.materials[scene_.prims[hit.prim].material];
    return true;
}

Vec3 WhittedTracer::trace(const Ray& ray, RayKind kind, int depth, Recorder* rec) const {
    Hit hit;
    h_.closest(ray, hit);
    if (rec) rec->add(ray, kind, hit.hit());
    Surface s;
    if (!surface(ray, hit, s)) return scene_.background;
    const Material& m = *s.m;

    Vec3 color = m.color * (kAmbient * m.kd);
    const Vec3 refl = mirrored(s);
    for (const Light& light : scene_.lights) {
        // No shadow ray when the light is behind the surface as the ray sees it.
        Vec3 o = s.p + s.n * eps_;
        Vec3 to_light = light.position - o;
        if (!(dot(s.n, to_light) > 0)) continue;
        Ray shadow{o, to_light, 0, 1};
        if (!shadow_tests_) {
            // Only the rays are wanted: whether this one is blocked spawns nothing.
            if (rec) rec->add(shadow, RayKind::Shadow, false);
            continue;
        }
        Hit sh;
        bool blocked = h_.any(shadow, sh);
        if (rec) rec->add(shadow, RayKind::Shadow, blocked);
        if (blocked) continue;
        Vec3 l = normalize(to_light);
        Vec3 lc = light.color * light_scale_;
        color += m.color * lc * (m.kd * dot(s.n, l));
        float rl = dot(refl, l);
        if (m.ks > 0 && rl > 0) color += lc * (m.ks * std::pow(rl, m.shine));
    }
    if (depth >= max_depth_) return color;

    // Transmitters reflect too (their Ks may be 0): the published SPD counts include those rays.
    bool reflect = m.ks > 0 || m.t > 0, refract = m.t > 0;
    float reflect_weight = m.ks;
    Vec3 refr;
    if (refract) {
        if (const std::optional<Vec3> d = refracted(s)) {
            refr = *d;
        } else {  // total internal reflection: the transmitted part reflects
            refract = false;
            reflect = true;
            reflect_weight += m.t;
        }
    }
    if (reflect)
        color += trace(Ray{s.p + s.n * eps_, refl, 0, kInf}, RayKind::Reflection, depth + 1, rec) * reflect_weight;
    if (refract)
        color += trace(Ray{s.p - s.n * eps_, refr, 0, kInf}, RayKind::Refraction, depth + 1, rec) * m.t;
    return color;
}

void run_rows(int rows, int threads, const std::function<void(int)>& row,
              const std::function<void(std::size_t)>& progress) {
    tbb::task_arena arena(threads > 0 ? threads : default_threads());
    std::atomic<std::size_t> done{0};
    std::mutex mutex;
    arena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<int>(0, rows, 1), [&](const tbb::blocked_range<int>& r) {
            for (int j = r.begin(); j != r.end(); ++j) row(j);
            std::size_t d = done.fetch_add(r.size()) + r.size();
            if (progress) {
                std::lock_guard lock(mutex);
                progress(d);
            }
        });
    });
}

}  // namespace detail

namespace {

using detail::Recorder;

// Rows recorded apart (in parallel) and joined in row order, so the result never depends on
// the threads.
RayTree join(std::vector<Recorder>& rows, bool record) {
    RayTree tree;
    std::size_t n = 0;
    for (const Recorder& r : rows) {
        n += r.rays.size();
        for (int k = 0; k < kRayKinds; ++k) {
            tree.counts.rays[k] += r.counts.rays[k];
            tree.counts.hits[k] += r.counts.hits[k];
        }
    }
    if (!record) return tree;
    tree.rays.reserve(n);
    tree.kinds.reserve(n);
    tree.pixels.reserve(n);
    for (Recorder& r : rows) {
        tree.rays.insert(tree.rays.end(), r.rays.begin(), r.rays.end());
        tree.kinds.insert(tree.kinds.end(), r.kinds.begin(), r.kinds.end());
        tree.pixels.insert(tree.pixels.end(), r.pixels.begin(), r.pixels.end());
        r = Recorder{};  // free as we go: the full SPD tree is ~100 MB
    }
    return tree;
}

using PixelRng = ItemRng;  // one stream per pixel

/// The rays a distribution's rows record, bounded by kMaxRays as --size bounds an image: a tree
/// or a scene of many lights spawns many rays per pixel, which would otherwise end in running
/// out of memory. Checked after each row (rows run in parallel), so the bound is passed by at
/// most a row per thread before the InputError.
class RayBudget {
public:
    void charge(std::size_t rays) {
        if (total_.fetch_add(rays) + rays > kMaxRays)
            throw InputError("--size", 0,
                             fmt::format("the rays this distribution spawns at this size (with the scene's {} lights) "
                                         "pass {}, the most rtcost makes: choose a smaller size",
                                         lights_, kMaxRays));
    }
    explicit RayBudget(std::size_t lights) : lights_(lights) {}

private:
    std::atomic<std::uint64_t> total_{0};
    std::size_t lights_;
};

}  // namespace

namespace detail {
// Malley's method: uniform on the disc, projected up.
Vec3 cosine_direction(Vec3 n, ItemRng& rng) {
    double u1 = rng.uniform(), u2 = rng.uniform();
    double r = std::sqrt(u1), phi = 2 * std::numbers::pi * u2;
    Vec3 a = std::fabs(n.x) < 0.9f ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
    Vec3 t = normalize(cross(n, a));
    Vec3 b = cross(n, t);
    Vec3 d = t * static_cast<float>(r * std::cos(phi)) + b * static_cast<float>(r * std::sin(phi)) +
             n * static_cast<float>(std::sqrt(std::max(0.0, 1 - u1)));
    return normalize(d);
}
}  // namespace detail

using detail::cosine_direction;

RayTree whitted_tree(const Hierarchy& h, const WhittedOptions& opt) {
    const Scene& scene = h.scene();
    // Each pixel's eye ray made where it is traced: a sample traces a few pixels of the image.
    const CameraRay eye(scene.camera, opt.width, opt.height);
    detail::WhittedTracer tracer(h, opt.max_depth, opt.shadow_tests);
    std::vector<Recorder> rows(static_cast<std::size_t>(opt.height));
    RayBudget budget(scene.lights.size());
    detail::run_rows(
        opt.height, opt.threads,
        [&](int j) {
            Recorder& rec = rows[j];
            rec.keep = opt.record;
            detail::for_pixels_of_row(j, opt.width, opt.pixels, [&](int, std::size_t pixel) {
                rec.pixel = static_cast<std::uint32_t>(pixel);
                tracer.trace(eye(pixel), RayKind::Eye, 1, &rec);
            });
            budget.charge(rec.rays.size());
        },
        opt.progress);
    return join(rows, opt.record);
}

RayTree camera_hit_rays(const Hierarchy& h, CameraHitRays which, int width, int height, std::uint64_t seed,
                        int threads, const std::function<void(std::size_t)>& progress, bool test_spawned,
                        const std::vector<std::uint32_t>* pixels) {
    const Scene& scene = h.scene();
    const CameraRay eye(scene.camera, width, height);  // as whitted_tree's
    detail::WhittedTracer tracer(h, 1);
    const float eps = spawn_offset(scene), ao = ao_length(scene);
    std::vector<Recorder> rows(static_cast<std::size_t>(height));
    RayBudget budget(scene.lights.size());
    detail::run_rows(
        height, threads,
        [&](int j) {
            Recorder& rec = rows[j];
            detail::for_pixels_of_row(j, width, pixels, [&](int, std::size_t pixel) {
                rec.pixel = static_cast<std::uint32_t>(pixel);
                const Ray ray = eye(pixel);
                Hit hit;
                h.closest(ray, hit);
                rec.count(RayKind::Eye, hit.hit());
                detail::Surface s;
                if (!tracer.surface(ray, hit, s)) return;
                if (which == CameraHitRays::Shadow) {
                    Vec3 o = s.p + s.n * eps;
                    for (const Light& light : scene.lights) {
                        Vec3 to_light = light.position - o;
                        if (!(dot(s.n, to_light) > 0)) continue;
                        Ray r{o, to_light, 0, 1};
                        Hit sh;
                        rec.add(r, RayKind::Shadow, test_spawned && h.any(r, sh));
                    }
                    return;
                }
                PixelRng rng(seed, pixel);
                Ray r{s.p + s.n * eps, cosine_direction(s.n, rng), 0, kInf};
                Hit sh;
                if (which == CameraHitRays::Diffuse) {
                    if (test_spawned) h.closest(r, sh);
                    rec.add(r, RayKind::Diffuse, sh.hit());
                } else {
                    r.tmax = ao;
                    rec.add(r, RayKind::AO, test_spawned && h.any(r, sh));
                }
            });
            budget.charge(rec.rays.size());
        },
        progress);
    return join(rows, true);
}

bool is_tree_distribution(const std::string& name) {
    return name == "spd" || name == "shadow" || name == "diffuse" || name == "ao";
}

RaySet make_tree_rays(const Scene& scene, const RaySpec& spec, const RayMaking& making) {
    if (!is_tree_distribution(spec.name)) throw InputError(spec.name, 0, "not a ray tree distribution");
    const bool spd = spec.name == "spd";
    int w = 512, h = 512;
    if (!spd || !spec.size.empty()) image_size(scene, spec.size, w, h);
    const std::size_t image_pixels = spd ? static_cast<std::size_t>(w + 1) * (h + 1) : static_cast<std::size_t>(w) * h;
    check_pixel_subset(making.only_pixels, image_pixels);
    // Hits are exact, so the rays are the same whichever hierarchy finds them: use a fast one.
    std::unique_ptr<Hierarchy> own;
    if (!making.tracer) own = build_hierarchy(scene, "bvh-sah");
    const Hierarchy& bvh = making.tracer ? *making.tracer : *own;
    const int threads = making.threads;
    const int rows = spd ? h + 1 : h;
    std::function<void(std::size_t)> rows_done;
    if (making.progress) rows_done = [&](std::size_t d) { making.progress(d, static_cast<std::size_t>(rows)); };

    RayTree tree;
    std::string described;
    if (spd) {
        WhittedOptions opt;
        opt.width = w + 1;
        opt.height = h + 1;
        opt.threads = threads;
        opt.progress = rows_done;
        opt.shadow_tests = !making.rays_only;
        opt.pixels = making.only_pixels;
        tree = whitted_tree(bvh, opt);
        described = fmt::format("spd {}x{} ({}x{} corner eye rays, depth 5)", w, h, w + 1, h + 1);
    } else {
        CameraHitRays which = spec.name == "shadow"    ? CameraHitRays::Shadow
                              : spec.name == "diffuse" ? CameraHitRays::Diffuse
                                                       : CameraHitRays::AO;
        tree = camera_hit_rays(bvh, which, w, h, spec.seed, threads, rows_done, !making.rays_only, making.only_pixels);
        described = which == CameraHitRays::Shadow ? fmt::format("shadow rays of camera {}x{} hits", w, h)
                                                   : fmt::format("{} rays of camera {}x{} hits seed {}", spec.name, w, h,
                                                                 spec.seed);
    }
    RaySet set;
    set.rays = std::move(tree.rays);
    set.kinds = std::move(tree.kinds);
    set.pixels = std::move(tree.pixels);
    set.image_pixels = image_pixels;
    set.image_width = static_cast<std::size_t>(spd ? w + 1 : w);
    set.described = std::move(described);
    for (int k = 0; k < kRayKinds; ++k) {
        RayKind kind = static_cast<RayKind>(k);
        bool listed = kind == RayKind::Eye || (spd && (kind == RayKind::Reflection || kind == RayKind::Refraction ||
                                                       kind == RayKind::Shadow));
        if (!listed && tree.counts.rays[k] == 0) continue;
        // Camera rays only seed the other sets and are not in them: say so by the name.
        std::string name(!spd && kind == RayKind::Eye ? "camera" : ray_kind_name(kind));
        set.summary.push_back({name, tree.counts.rays[k]});
        // Rays made without their tests have no hit count.
        const bool tested = !making.rays_only || kind == RayKind::Eye || kind == RayKind::Reflection ||
                            kind == RayKind::Refraction;
        if (tested) set.summary.push_back({name + "_hits", tree.counts.hits[k]});
    }
    return set;
}

namespace {
RaySet make_tree(const Scene& scene, const RaySpec& spec, const RayMaking& making) {
    return make_tree_rays(scene, spec, making);
}
const RayDistributionRegistration kSpd{
    {.name = "spd",
     .description = "the SPD Whitted ray trees of 512x512 pixel corners (or --size): eye, shadow, reflection and refraction rays",
     .order = 10,
     .benchmarked = true,
     .make = make_tree}};
const RayDistributionRegistration kShadow{
    {.name = "shadow",
     .description = "shadow rays from the camera rays' hits to each light (any-hit)",
     .order = 20,
     .benchmarked = true,
     .make = make_tree}};
const RayDistributionRegistration kDiffuse{
    {.name = "diffuse",
     .description = "one cosine-weighted diffuse bounce from each camera ray's hit (--seed)",
     .order = 30,
     .benchmarked = true,
     .make = make_tree}};
const RayDistributionRegistration kAo{
    {.name = "ao",
     .description = "ambient-occlusion rays from the camera rays' hits, 5% of the scene's diagonal long (any-hit, --seed)",
     .order = 40,
     .make = make_tree}};
}  // namespace

}  // namespace rtcost
