#include "rtcost/scene.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include <fmt/format.h>

#include "rtcost/error.hpp"
#include <numbers>

namespace rtcost {

namespace {

// The intersection finds a polygon's hit on its plane and decides containment in the projection
// that drops the normal's largest axis. A non-planar polygon's hits therefore lie off its
// vertices' box, where no hierarchy looks. Moving each vertex along the dropped axis onto the
// plane keeps the projected outline (what the inside test reads) and puts the hits inside the
// vertices' box again. Nothing changes when every vertex is within 1e-6 of the polygon's size of
// its (float) plane.
enum class Flattening { none, rounding, nonplanar };

// Whether the vertices leave a plane fitted in double (Newell's normal through their centroid) by
// more than 1e-5 of the polygon's size: planar input written as text and read into floats stays
// far below that, while the float normal alone can put a thin planar quad 1e-6 off its plane.
bool visibly_nonplanar(const Vec3* v, std::uint32_t count, double size) {
    double n[3] = {0, 0, 0}, c[3] = {0, 0, 0};
    for (std::uint32_t i = 0; i < count; ++i) {
        const Vec3 a = v[i], b = v[(i + 1) % count];
        n[0] += (double(a.y) - b.y) * (double(a.z) + b.z);
        n[1] += (double(a.z) - b.z) * (double(a.x) + b.x);
        n[2] += (double(a.x) - b.x) * (double(a.y) + b.y);
        for (int k = 0; k < 3; ++k) c[k] += double(a[k]) / count;
    }
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(len > 0)) return true;
    double off = 0;
    for (std::uint32_t i = 0; i < count; ++i)
        off = std::max(off, std::fabs((n[0] * (v[i].x - c[0]) + n[1] * (v[i].y - c[1]) + n[2] * (v[i].z - c[2])) / len));
    return off > 1e-5 * size;
}

Flattening flatten_polygon(const Polygon& p, std::vector<Vec3>& pool) {
    Vec3* v = pool.data() + p.first;
    Box3 box;
    for (std::uint32_t i = 0; i < p.count; ++i) box.extend(v[i]);
    const Vec3 e = box.extent();
    const double size = std::sqrt(double(e.x) * e.x + double(e.y) * e.y + double(e.z) * e.z);
    const double n[3] = {p.normal.x, p.normal.y, p.normal.z};
    double off = 0;
    for (std::uint32_t i = 0; i < p.count; ++i)
        off = std::max(off, std::fabs(n[0] * v[i].x + n[1] * v[i].y + n[2] * v[i].z - double(p.plane_d)));
    if (!(off > 1e-6 * size)) return Flattening::none;
    const bool nonplanar = visibly_nonplanar(v, p.count, size);
    const int k = p.drop_axis, a = (k + 1) % 3, b = (k + 2) % 3;
    for (std::uint32_t i = 0; i < p.count; ++i)
        v[i][k] = static_cast<float>((double(p.plane_d) - n[a] * v[i][a] - n[b] * v[i][b]) / n[k]);
    return nonplanar ? Flattening::nonplanar : Flattening::rounding;
}

}  // namespace

std::string no_primitives_message(const std::vector<std::string>& warnings) {
    if (warnings.empty()) return "scene has no primitives";
    return fmt::format("scene has no primitives ({} warning{} while reading; the first: {})", warnings.size(),
                       warnings.size() == 1 ? "" : "s", warnings.front());
}

void check_scene(const Scene& s) {
    if (s.empty()) throw InputError(s.name, 0, no_primitives_message(s.warnings));
    const auto& sums = s.summaries();
    auto beyond = [](Vec3 v) {
        return std::fabs(v.x) > kMaxCoordinate || std::fabs(v.y) > kMaxCoordinate || std::fabs(v.z) > kMaxCoordinate;
    };
    for (std::uint32_t id = 0; id < sums.size(); ++id) {
        const Box3& b = sums[id].bounds;
        const std::string what = fmt::format("primitive {} ({})", id, prim_kind_name(sums[id].kind));
        if (b.empty() || !is_finite(b.lo) || !is_finite(b.hi))
            throw InputError(s.name, 0, what + " has no finite bounds");
        if (beyond(b.lo) || beyond(b.hi))
            throw InputError(s.name, 0,
                             fmt::format("{} reaches {:g}, beyond +-{:g}, the largest coordinate the float "
                                         "intersection and box tests handle (scale the scene down)",
                                         what, std::max({std::fabs(b.lo.x), std::fabs(b.lo.y), std::fabs(b.lo.z),
                                                         std::fabs(b.hi.x), std::fabs(b.hi.y), std::fabs(b.hi.z)}),
                                         kMaxCoordinate));
    }
    const Vec3 e = s.bounds().extent();
    const float extent = std::max({e.x, e.y, e.z});
    if (!(extent >= kMinSceneExtent))
        throw InputError(s.name, 0,
                         fmt::format("the scene's extent {:g} is below {:g}, the smallest the float arithmetic "
                                     "handles (scale the scene up)",
                                     extent, kMinSceneExtent));
    if (s.has_camera && (beyond(s.camera.from) || beyond(s.camera.at)))
        throw InputError(s.name, 0, fmt::format("the viewpoint lies beyond +-{:g}", kMaxCoordinate));
    for (const Light& l : s.lights)
        if (beyond(l.position)) throw InputError(s.name, 0, fmt::format("a light lies beyond +-{:g}", kMaxCoordinate));
}

std::uint32_t Scene::add(const Triangle& t, std::uint32_t material) {
    prims.push_back({PrimKind::Triangle, static_cast<std::uint32_t>(triangles.size()), material});
    triangles.push_back(t);
    return static_cast<std::uint32_t>(prims.size() - 1);
}

std::uint32_t Scene::add(const Sphere& s, std::uint32_t material) {
    prims.push_back({PrimKind::Sphere, static_cast<std::uint32_t>(spheres.size()), material});
    spheres.push_back(s);
    return static_cast<std::uint32_t>(prims.size() - 1);
}

std::uint32_t Scene::add(const Cone& c, std::uint32_t material) {
    prims.push_back({PrimKind::Cone, static_cast<std::uint32_t>(cones.size()), material});
    cones.push_back(c);
    return static_cast<std::uint32_t>(prims.size() - 1);
}

bool Scene::add_polygon(std::span<const Vec3> verts, std::uint32_t material, std::uint32_t* id, bool* flattened) {
    Polygon p;
    p.first = static_cast<std::uint32_t>(polygon_vertices.size());
    p.count = static_cast<std::uint32_t>(verts.size());
    polygon_vertices.insert(polygon_vertices.end(), verts.begin(), verts.end());
    if (!setup_polygon(p, polygon_vertices)) {
        polygon_vertices.resize(p.first);
        return false;
    }
    if (flattened) *flattened = false;
    const Flattening f = p.count > 3 ? flatten_polygon(p, polygon_vertices) : Flattening::none;
    if (f != Flattening::none) {
        if (flattened) *flattened = f == Flattening::nonplanar;
        if (!setup_polygon(p, polygon_vertices)) {
            polygon_vertices.resize(p.first);
            return false;
        }
    }
    prims.push_back({PrimKind::Polygon, static_cast<std::uint32_t>(polygons.size()), material});
    polygons.push_back(p);
    if (id) *id = static_cast<std::uint32_t>(prims.size() - 1);
    return true;
}

Box3 Scene::prim_bounds(std::uint32_t id) const {
    if (id < summaries_.size()) return summaries_[id].bounds;
    const PrimRef& p = prims[id];
    switch (p.kind) {
        case PrimKind::Triangle: return rtcost::bounds(triangles[p.index]);
        case PrimKind::Polygon: return rtcost::bounds(polygons[p.index], polygon_vertices);
        case PrimKind::Sphere: return rtcost::bounds(spheres[p.index]);
        case PrimKind::Cone: return rtcost::bounds(cones[p.index]);
    }
    return {};
}

float Scene::prim_area(std::uint32_t id) const {
    if (id < summaries_.size()) return summaries_[id].area;
    const PrimRef& p = prims[id];
    switch (p.kind) {
        case PrimKind::Triangle: return rtcost::area(triangles[p.index]);
        case PrimKind::Polygon: return rtcost::area(polygons[p.index], polygon_vertices);
        case PrimKind::Sphere: return rtcost::area(spheres[p.index]);
        case PrimKind::Cone: return rtcost::area(cones[p.index]);
    }
    return 0;
}

void Scene::complete_hit(const Ray& ray, Hit& hit) const {
    if (!hit.hit()) return;
    const PrimRef& p = prims[hit.prim];
    Vec3 point = ray.o + ray.d * hit.t;
    switch (p.kind) {
        case PrimKind::Triangle: hit.ng = normal_at(triangles[p.index]); break;
        case PrimKind::Polygon: hit.ng = polygons[p.index].normal; break;
        case PrimKind::Sphere: hit.ng = normal_at(spheres[p.index], point); break;
        case PrimKind::Cone: hit.ng = normal_at(cones[p.index], point); break;
    }
}

std::array<std::size_t, kPrimKinds> Scene::kind_counts() const {
    return {triangles.size(), polygons.size(), spheres.size(), cones.size()};
}

std::size_t Scene::bytes() const {
    return prims.capacity() * sizeof(PrimRef) + triangles.capacity() * sizeof(Triangle) +
           polygons.capacity() * sizeof(Polygon) + polygon_vertices.capacity() * sizeof(Vec3) +
           spheres.capacity() * sizeof(Sphere) + cones.capacity() * sizeof(Cone) +
           summaries_.capacity() * sizeof(PrimSummary) +
           materials.capacity() * sizeof(Material) + lights.capacity() * sizeof(Light);
}

namespace {

constexpr int kRaster = 32;

// Marks the cells of a kRaster x kRaster raster of the frame [r0, r0 + w) x [u0, u0 + h) whose
// centres a projected primitive covers: how much of a camera's image the object fills.
struct Rasterizer {
    std::vector<std::uint8_t>& covered;
    double r0, u0, w, h;

    int cell(double v, double lo, double span) const {
        const double x = (v - lo) / span * kRaster;
        if (!(x >= 0)) return 0;  // below the frame, or NaN (a degenerate primitive's bounds)
        return x >= kRaster - 1 ? kRaster - 1 : static_cast<int>(x);
    }
    double centre_r(int i) const { return r0 + (i + 0.5) * w / kRaster; }
    double centre_u(int j) const { return u0 + (j + 0.5) * h / kRaster; }
    void rect(double lr, double hr, double lu, double hu) {
        for (int j = cell(lu, u0, h); j <= cell(hu, u0, h); ++j)
            for (int i = cell(lr, r0, w); i <= cell(hr, r0, w); ++i) covered[j * kRaster + i] = 1;
    }
    void triangle(std::array<double, 2> a, std::array<double, 2> b, std::array<double, 2> c) {
        auto edge = [](const std::array<double, 2>& p, const std::array<double, 2>& q, double x, double y) {
            return (q[0] - p[0]) * (y - p[1]) - (q[1] - p[1]) * (x - p[0]);
        };
        const double area = edge(a, b, c[0], c[1]);
        const int i0 = cell(std::min({a[0], b[0], c[0]}), r0, w), i1 = cell(std::max({a[0], b[0], c[0]}), r0, w);
        const int j0 = cell(std::min({a[1], b[1], c[1]}), u0, h), j1 = cell(std::max({a[1], b[1], c[1]}), u0, h);
        if (i0 == i1 && j0 == j1) {  // smaller than a cell: it covers some of that one
            covered[j0 * kRaster + i0] = 1;
            return;
        }
        if (area == 0) return;  // seen edge on
        for (int j = j0; j <= j1; ++j) {
            for (int i = i0; i <= i1; ++i) {
                const double x = centre_r(i), y = centre_u(j);
                const double e0 = edge(a, b, x, y), e1 = edge(b, c, x, y), e2 = edge(c, a, x, y);
                if (area > 0 ? (e0 >= 0 && e1 >= 0 && e2 >= 0) : (e0 <= 0 && e1 <= 0 && e2 <= 0))
                    covered[j * kRaster + i] = 1;
            }
        }
    }
};

}  // namespace

Camera Scene::default_camera(Vec3 c, float radius) const {
    // A three-quarter view, the usual default of mesh viewers, from whichever of 16 directions
    // (8 diagonal, 8 along an axis's azimuth; from a low and a high elevation, for flat objects
    // such as a terrain) fills the most of its frame with the object. The frame is
    // fitted to the primitives' boxes, not the scene's: the image's aspect follows the object's
    // projected extent (512 pixels on its long side) and its centre the middle of that extent, so
    // that most camera rays meet the object rather than the box's empty corners.
    Camera cam;
    cam.angle = 45;
    const double tan_half = std::tan(0.5 * cam.angle * std::numbers::pi / 180.0);
    // Scoring reads at most about 20,000 primitives (every k-th); the frame reads them all.
    const std::size_t stride = std::max<std::size_t>(1, prims.size() / 20000);
    struct Frame {
        Vec3 dir, right, up;
        double lo_r, hi_r, lo_u, hi_u;
    };
    auto frame = [&](Vec3 dir, std::size_t step) {
        Frame f{dir, {}, {}, kInf, -kInf, kInf, -kInf};
        const Vec3 fwd = dir * -1.0f;
        f.right = normalize(cross(fwd, Vec3{0, 1, 0}));
        f.up = cross(f.right, fwd);
        for (std::size_t id = 0; id < summaries_.size(); id += step) {
            const Box3& b = summaries_[id].bounds;
            for (int k = 0; k < 8; ++k) {
                const Vec3 q = Vec3{k & 1 ? b.hi.x : b.lo.x, k & 2 ? b.hi.y : b.lo.y, k & 4 ? b.hi.z : b.lo.z} - c;
                const double r = dot(q, f.right), u = dot(q, f.up);
                f.lo_r = std::min(f.lo_r, r), f.hi_r = std::max(f.hi_r, r);
                f.lo_u = std::min(f.lo_u, u), f.hi_u = std::max(f.hi_u, u);
            }
        }
        return f;
    };
    Vec3 best_dir{0.8f, 0.6f, 1.0f};
    double best_score = -1;
    for (float sy : {0.6f, 1.6f}) {
        for (Vec3 xz : {Vec3{0.8f, 0, 1}, Vec3{-0.8f, 0, 1}, Vec3{0.8f, 0, -1}, Vec3{-0.8f, 0, -1}, Vec3{1, 0, 0},
                        Vec3{-1, 0, 0}, Vec3{0, 0, 1}, Vec3{0, 0, -1}}) {
            const Vec3 dir = normalize(Vec3{xz.x, sy, xz.z});
            const Frame f = frame(dir, stride);
            // The share of the frame the object covers, on a raster of its projected primitives
            // (seen along dir, without perspective): what camera rays would hit.
            double w = std::max(f.hi_r - f.lo_r, 1e-30), h = std::max(f.hi_u - f.lo_u, 1e-30);
            w = std::max(w, 0.25 * h), h = std::max(h, 0.25 * w);  // the image's aspect stays in 1:4 .. 4:1
            const double r0 = 0.5 * (f.lo_r + f.hi_r - w), u0 = 0.5 * (f.lo_u + f.hi_u - h);
            double score = 0;
            std::vector<std::uint8_t> covered(kRaster * kRaster, 0);
            Rasterizer raster{covered, r0, u0, w, h};
            for (std::size_t id = 0; id < prims.size(); id += stride) {
                auto at = [&](Vec3 v) { return std::array<double, 2>{dot(v - c, f.right), dot(v - c, f.up)}; };
                const PrimRef& p = prims[id];
                if (p.kind == PrimKind::Triangle) {
                    const Triangle& t = triangles[p.index];
                    raster.triangle(at(t.v0), at(t.v1), at(t.v2));
                } else if (p.kind == PrimKind::Polygon) {
                    const Polygon& q = polygons[p.index];
                    const Vec3* v = polygon_vertices.data() + q.first;
                    for (std::uint32_t k = 1; k + 1 < q.count; ++k) raster.triangle(at(v[0]), at(v[k]), at(v[k + 1]));
                } else {
                    // Round primitives: the projected box of their bounds.
                    const Box3& b = summaries_[id].bounds;
                    double lr = kInf, hr = -kInf, lu = kInf, hu = -kInf;
                    for (int k = 0; k < 8; ++k) {
                        const auto [r, u] = at(Vec3{k & 1 ? b.hi.x : b.lo.x, k & 2 ? b.hi.y : b.lo.y, k & 4 ? b.hi.z : b.lo.z});
                        lr = std::min(lr, r), hr = std::max(hr, r), lu = std::min(lu, u), hu = std::max(hu, u);
                    }
                    raster.rect(lr, hr, lu, hu);
                }
            }
            for (std::uint8_t v : covered) score += v;
            if (score > best_score * (1 + 1e-6)) best_score = score, best_dir = dir;
        }
    }
    const Frame f = frame(best_dir, 1);
    const double span_r = f.hi_r - f.lo_r, span_u = f.hi_u - f.lo_u;
    const double aspect = span_r > 0 && span_u > 0 ? std::clamp(span_r / span_u, 0.25, 4.0) : 1.0;
    cam.width = aspect >= 1 ? 512 : std::max(128, static_cast<int>(std::lround(512 * aspect)));
    cam.height = aspect >= 1 ? std::max(128, static_cast<int>(std::lround(512 / aspect))) : 512;
    const Vec3 at = c + f.right * static_cast<float>(0.5 * (f.lo_r + f.hi_r)) + f.up * static_cast<float>(0.5 * (f.lo_u + f.hi_u));
    // Moved in until every box corner fits: the vertical angle spans the rows' centres, the
    // horizontal one follows the aspect.
    const double tan_v = tan_half, tan_h = tan_half * cam.width / cam.height;
    const Vec3 fwd = best_dir * -1.0f;
    double dist = 0;
    for (const PrimSummary& p : summaries_) {
        for (int k = 0; k < 8; ++k) {
            const Vec3 q = Vec3{k & 1 ? p.bounds.hi.x : p.bounds.lo.x, k & 2 ? p.bounds.hi.y : p.bounds.lo.y,
                                k & 4 ? p.bounds.hi.z : p.bounds.lo.z} - at;
            const double depth = dot(q, fwd);  // towards the far side: the corner is nearer the eye when < 0
            const double reach = std::max(std::fabs(dot(q, f.right)) / tan_h, std::fabs(dot(q, f.up)) / tan_v);
            dist = std::max(dist, reach - depth);
        }
    }
    dist = std::max(dist * 1.02, 1e-3 * radius);
    cam.at = at;
    cam.from = at + best_dir * static_cast<float>(dist);
    cam.up = Vec3{0, 1, 0};
    cam.hither = radius * 1e-3f;
    return cam;
}

void Scene::finalize() {
    // Computed afresh: the geometry may have changed since the last call.
    summaries_.clear();
    std::vector<PrimSummary> sums(prims.size());
    bounds_ = Box3{};
    for (std::uint32_t id = 0; id < prims.size(); ++id) {
        sums[id] = {prim_bounds(id), prim_area(id), prims[id].kind};
        bounds_.extend(sums[id].bounds);
    }
    summaries_ = std::move(sums);
    if (materials.empty()) materials.push_back(Material{});
    if (empty()) return;
    Vec3 c = bounds_.center();
    // In double: a huge scene's squared extent overflows float, a tiny one's underflows. A scene
    // without extent (not one that loading accepts) still gets a finite camera.
    const Vec3 ext = bounds_.extent();
    float radius = static_cast<float>(0.5 * std::sqrt(double(ext.x) * ext.x + double(ext.y) * ext.y + double(ext.z) * ext.z));
    if (!(radius > 0) || !std::isfinite(radius)) radius = 1;
    if (!has_camera) camera = default_camera(c, radius);
    if (lights.empty()) {
        // One light over the camera's shoulder so that a default render is lit.
        Vec3 dir = normalize(camera.from - camera.at);
        lights.push_back({c + (dir + Vec3{0, 1, 0}) * (2 * radius), {1, 1, 1}});
    }
}

}  // namespace rtcost
