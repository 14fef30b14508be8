// The camera and light a scene without them gets (meshes): a view that shows the object, so that
// camera rays hit it and shadow rays have something to be stopped by.
#include "rtcost/scene.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

namespace rtcost {

namespace {

constexpr int kScoreRaster = 64;  // scores a direction, on at most ~20,000 primitives
constexpr int kCropRaster = 256;  // crops the chosen frame, on every primitive
constexpr std::uint32_t kNone = ~0u;

struct Projected {
    double r, u, z;  // right, up, and depth away from the eye
};

// A coarse z-buffer of a frame [r0, r0 + w) x [u0, u0 + h) seen along a direction without
// perspective: per cell the nearest primitive at the cell's centre. Enough to tell how much of an
// image the object fills and how many of its primitives the image shows. A primitive smaller than
// a cell marks its cell when `mark_small` (scoring reads only a subset of a large mesh's
// primitives, each standing for its neighbours); otherwise only if it covers the centre, as a ray
// through it would.
struct ViewRaster {
    int n;
    bool mark_small;
    double r0, u0, w, h;
    std::vector<float> depth = std::vector<float>(std::size_t(n) * n, kInf);
    std::vector<std::uint32_t> prim = std::vector<std::uint32_t>(std::size_t(n) * n, kNone);

    int cell(double v, double lo, double span) const {
        const double x = (v - lo) / span * n;
        if (!(x >= 0)) return 0;  // below the frame, or NaN (a degenerate primitive's bounds)
        return x >= n - 1 ? n - 1 : static_cast<int>(x);
    }
    void put(int i, int j, double z, std::uint32_t id) {
        const std::size_t k = std::size_t(j) * n + i;
        if (z < depth[k]) depth[k] = static_cast<float>(z), prim[k] = id;
    }
    void rect(double lr, double hr, double lu, double hu, double z, std::uint32_t id) {
        for (int j = cell(lu, u0, h); j <= cell(hu, u0, h); ++j)
            for (int i = cell(lr, r0, w); i <= cell(hr, r0, w); ++i) put(i, j, z, id);
    }
    void triangle(const Projected& a, const Projected& b, const Projected& c, std::uint32_t id) {
        auto edge = [](const Projected& p, const Projected& q, double x, double y) {
            return (q.r - p.r) * (y - p.u) - (q.u - p.u) * (x - p.r);
        };
        const double area = edge(a, b, c.r, c.u);
        const int i0 = cell(std::min({a.r, b.r, c.r}), r0, w), i1 = cell(std::max({a.r, b.r, c.r}), r0, w);
        const int j0 = cell(std::min({a.u, b.u, c.u}), u0, h), j1 = cell(std::max({a.u, b.u, c.u}), u0, h);
        if (mark_small && i0 == i1 && j0 == j1) {  // smaller than a cell: it covers some of that one
            put(i0, j0, std::min({a.z, b.z, c.z}), id);
            return;
        }
        if (area == 0) return;  // seen edge on
        for (int j = j0; j <= j1; ++j) {
            for (int i = i0; i <= i1; ++i) {
                const double x = r0 + (i + 0.5) * w / n, y = u0 + (j + 0.5) * h / n;
                const double e0 = edge(b, c, x, y) / area, e1 = edge(c, a, x, y) / area, e2 = edge(a, b, x, y) / area;
                if (e0 >= 0 && e1 >= 0 && e2 >= 0) put(i, j, e0 * a.z + e1 * b.z + e2 * c.z, id);
            }
        }
    }
    // Cells that see a primitive, in the window [i0, i1) x [j0, j1).
    int covered(int i0, int i1, int j0, int j1) const {
        int c = 0;
        for (int j = j0; j < j1; ++j)
            for (int i = i0; i < i1; ++i) c += prim[std::size_t(j) * n + i] != kNone;
        return c;
    }
    // Primitives seen in at least one cell.
    int distinct() const {
        std::vector<std::uint32_t> ids;
        for (std::uint32_t p : prim)
            if (p != kNone) ids.push_back(p);
        std::sort(ids.begin(), ids.end());
        return static_cast<int>(std::unique(ids.begin(), ids.end()) - ids.begin());
    }
};

// Trims the window's emptiest edge rows and columns while fewer than 60% of its cells see the
// object (a margin over "most" for what the raster misses), keeping at least a third of its width
// and of its height, and the image's aspect (`aspect`: width over height of the whole raster, in
// pixels) within 1:4 .. 4:1, which the camera would otherwise restore with empty rows. Returns
// [i0, i1) x [j0, j1).
std::array<int, 4> trim_empty_edges(const ViewRaster& v, double aspect) {
    int i0 = 0, i1 = v.n, j0 = 0, j1 = v.n;
    const int keep = v.n / 3;
    auto shape_ok = [&](int w, int h) {
        const double a = aspect * w / h;
        return w >= keep && h >= keep && a >= 0.25 && a <= 4;
    };
    while (5 * v.covered(i0, i1, j0, j1) < 3 * (i1 - i0) * (j1 - j0)) {
        // Each edge's share of covered cells; the emptiest one that may still go is removed.
        const int w = i1 - i0, h = j1 - j0;
        const bool cols = shape_ok(w - 1, h), rows = shape_ok(w, h - 1);
        const double left = cols ? double(v.covered(i0, i0 + 1, j0, j1)) / h : 2;
        const double right = cols ? double(v.covered(i1 - 1, i1, j0, j1)) / h : 2;
        const double bottom = rows ? double(v.covered(i0, i1, j0, j0 + 1)) / w : 2;
        const double top = rows ? double(v.covered(i0, i1, j1 - 1, j1)) / w : 2;
        const double least = std::min({left, right, bottom, top});
        if (least > 1) break;
        if (least == left) ++i0;
        else if (least == right) --i1;
        else if (least == bottom) ++j0;
        else --j1;
    }
    return {i0, i1, j0, j1};
}

// A thin object (legs, arms, a sparse frame of rods) framed whole can leave four fifths of the
// image empty. When fewer than half the camera's pixels would see the object (on a z-buffer of the
// camera's own perspective image, every primitive), the camera turns to the part of the image that
// trim_empty_edges keeps and narrows its angle to it, from where it stands: a crop of the image.
bool crop_to_object(const Scene& scene, Camera& cam) {
    const Vec3 fwd = normalize(cam.at - cam.from), right = normalize(cross(fwd, cam.up)), up = cross(right, fwd);
    const double tan_v = std::tan(0.5 * cam.angle * std::numbers::pi / 180.0), tan_h = tan_v * cam.width / cam.height;
    // Image coordinates in [-1, 1] and -1/z, which is affine across a projected triangle.
    const double near = 1e-9 * double(length(cam.at - cam.from));  // relative: a scene may be tiny
    bool behind = false;
    auto at = [&](Vec3 p) {
        const Vec3 q = p - cam.from;
        const double z = dot(q, fwd);
        behind |= !(z > near);
        return Projected{dot(q, right) / (z * tan_h), dot(q, up) / (z * tan_v), -1 / z};
    };
    ViewRaster v{kCropRaster, false, -1, -1, 2, 2};
    for (std::size_t id = 0; id < scene.prims.size(); ++id) {
        const auto pid = static_cast<std::uint32_t>(id);
        const PrimRef& p = scene.prims[id];
        behind = false;
        if (p.kind == PrimKind::Triangle) {
            const Triangle& t = scene.triangles[p.index];
            const Projected a = at(t.v0), b = at(t.v1), c = at(t.v2);
            if (!behind) v.triangle(a, b, c, pid);
        } else if (p.kind == PrimKind::Polygon) {
            const Polygon& q = scene.polygons[p.index];
            const Vec3* pv = scene.polygon_vertices.data() + q.first;
            for (std::uint32_t k = 1; k + 1 < q.count; ++k) {
                const Projected a = at(pv[0]), b = at(pv[k]), c = at(pv[k + 1]);
                if (!behind) v.triangle(a, b, c, pid);
            }
        } else {
            const Box3& b = scene.summaries()[id].bounds;
            double lr = kInf, hr = -kInf, lu = kInf, hu = -kInf, z = kInf;
            for (int k = 0; k < 8; ++k) {
                const Projected q = at(Vec3{k & 1 ? b.hi.x : b.lo.x, k & 2 ? b.hi.y : b.lo.y, k & 4 ? b.hi.z : b.lo.z});
                lr = std::min(lr, q.r), hr = std::max(hr, q.r), lu = std::min(lu, q.u), hu = std::max(hu, q.u);
                z = std::min(z, q.z);
            }
            if (!behind) v.rect(lr, hr, lu, hu, z, pid);
        }
    }
    if (v.covered(0, v.n, 0, v.n) == 0) return false;  // nothing seen (every primitive behind the eye): keep the frame
    const auto [i0, i1, j0, j1] = trim_empty_edges(v, double(cam.width) / cam.height);
    if (i1 - i0 == v.n && j1 - j0 == v.n) return false;
    // The kept window's corners, as directions from the eye; the new view is aimed at its centre
    // and spans all four corners. (Moving the eye sideways instead would keep the window's shape
    // but not its content: parallax moves a deep object's near parts out of it.)
    auto dir = [&](int i, int j) {
        return fwd + right * static_cast<float>((-1 + 2.0 * i / v.n) * tan_h) + up * static_cast<float>((-1 + 2.0 * j / v.n) * tan_v);
    };
    const Vec3 corners[4] = {dir(i0, j0), dir(i1, j0), dir(i0, j1), dir(i1, j1)};
    const Vec3 aim = normalize(corners[0] + corners[1] + corners[2] + corners[3]);
    const Vec3 r2 = normalize(cross(aim, cam.up)), u2 = cross(r2, aim);
    double th = 0, tv = 0;
    for (const Vec3& w : corners) {
        th = std::max<double>(th, std::fabs(dot(w, r2)) / dot(w, aim));
        tv = std::max<double>(tv, std::fabs(dot(w, u2)) / dot(w, aim));
    }
    if (!(th > 0 && tv > 0)) return false;
    const double aspect = std::clamp(th / tv, 0.25, 4.0);
    tv = std::max(tv, th / aspect);
    cam.width = aspect >= 1 ? 512 : std::max(128, static_cast<int>(std::lround(512 * aspect)));
    cam.height = aspect >= 1 ? std::max(128, static_cast<int>(std::lround(512 / aspect))) : 512;
    cam.angle = static_cast<float>(2 * std::atan(tv) * 180 / std::numbers::pi);
    cam.at = cam.from + aim * length(cam.at - cam.from);
    return true;
}

}  // namespace

Camera Scene::default_camera(Vec3 c, float radius) const {
    // A three-quarter view, the usual default of mesh viewers, from whichever of 32 directions
    // (8 diagonal, 8 along an axis's azimuth; a low and a high elevation, for flat objects such
    // as a terrain; above, or below) shows the most of the object: the cells of a coarse z-buffer
    // that see it times the primitives they see. Counting the nearest primitive only is what
    // keeps a backdrop (a wall behind the object, a floor under it) from winning: seen from
    // behind, it fills the frame with one or two primitives. The frame is fitted to the
    // primitives' boxes, not the scene's: the image's aspect follows the object's projected
    // extent (512 pixels on its long side), and a thin object's frame is cropped to where it is
    // (crop_to_object) so that most camera rays meet the object rather than empty corners.
    Camera cam;
    cam.angle = 45;
    const double tan_half = std::tan(0.5 * cam.angle * std::numbers::pi / 180.0);
    // Scoring reads about 20,000 primitives: every k-th, and every one large enough to span
    // several cells (a backdrop of two triangles among a million must not be left out); the final
    // frame reads them all.
    std::vector<std::uint32_t> scored;
    {
        const std::size_t stride = std::max<std::size_t>(1, prims.size() / 20000);
        const Vec3 ext = bounds_.extent();
        const float large = std::max({ext.x, ext.y, ext.z}) / 16;
        std::size_t extra = 0;
        for (std::size_t id = 0; id < prims.size(); ++id) {
            const Vec3 e = summaries_[id].bounds.extent();
            const bool big = extra < 20000 && std::max({e.x, e.y, e.z}) > large;
            if (id % stride == 0 || big) scored.push_back(static_cast<std::uint32_t>(id));
            extra += big && id % stride != 0;
        }
    }
    struct Frame {
        Vec3 dir, right, up;
        double lo_r, hi_r, lo_u, hi_u;
    };
    auto corners = [](const Box3& b, auto&& visit) {
        for (int k = 0; k < 8; ++k) visit(Vec3{k & 1 ? b.hi.x : b.lo.x, k & 2 ? b.hi.y : b.lo.y, k & 4 ? b.hi.z : b.lo.z});
    };
    // The frame seen along dir: y stays up, unless the object's projection is clearly elongated
    // along a diagonal; then the camera rolls (by at most 45 degrees) to line its long axis up with
    // the image's nearest side, so that the frame is not mostly empty corners.
    auto frame = [&](Vec3 dir, bool all) {
        Frame f{dir, {}, {}, kInf, -kInf, kInf, -kInf};
        const Vec3 fwd = dir * -1.0f;
        f.right = normalize(cross(fwd, Vec3{0, 1, 0}));
        f.up = cross(f.right, fwd);
        double n = 0, sr = 0, su = 0, srr = 0, suu = 0, sru = 0;
        for (const std::uint32_t id : scored) {
            corners(summaries_[id].bounds, [&](Vec3 p) {
                const double r = dot(p - c, f.right), u = dot(p - c, f.up);
                n += 1, sr += r, su += u, srr += r * r, suu += u * u, sru += r * u;
            });
        }
        if (n > 0) {
            const double crr = srr / n - sr * sr / (n * n), cuu = suu / n - su * su / (n * n), cru = sru / n - sr * su / (n * n);
            const double mid = 0.5 * (crr + cuu), half = std::sqrt(0.25 * (crr - cuu) * (crr - cuu) + cru * cru);
            double roll = 0.5 * std::atan2(2 * cru, crr - cuu);  // the long axis's angle from right
            if (roll > std::numbers::pi / 4) roll -= std::numbers::pi / 2;
            if (roll < -std::numbers::pi / 4) roll += std::numbers::pi / 2;
            if (mid + half > 4 * (mid - half) && std::fabs(roll) > 0.05) {  // axes' lengths over 2:1
                const float cs = static_cast<float>(std::cos(roll)), sn = static_cast<float>(std::sin(roll));
                const Vec3 r = f.right, u = f.up;
                f.right = r * cs + u * sn, f.up = u * cs - r * sn;
            }
        }
        for (std::size_t k = 0, count = all ? summaries_.size() : scored.size(); k < count; ++k) {
            corners(summaries_[all ? k : scored[k]].bounds, [&](Vec3 p) {
                const double r = dot(p - c, f.right), u = dot(p - c, f.up);
                f.lo_r = std::min(f.lo_r, r), f.hi_r = std::max(f.hi_r, r);
                f.lo_u = std::min(f.lo_u, u), f.hi_u = std::max(f.hi_u, u);
            });
        }
        return f;
    };
    // The scored primitives seen along f.dir in frame f.
    auto rasterize = [&](const Frame& f) {
        double w = std::max(f.hi_r - f.lo_r, 1e-30), h = std::max(f.hi_u - f.lo_u, 1e-30);
        w = std::max(w, 0.25 * h), h = std::max(h, 0.25 * w);  // the image's aspect stays in 1:4 .. 4:1
        ViewRaster v{kScoreRaster, true, 0.5 * (f.lo_r + f.hi_r - w), 0.5 * (f.lo_u + f.hi_u - h), w, h};
        const Vec3 fwd = f.dir * -1.0f;
        auto at = [&](Vec3 p) { return Projected{dot(p - c, f.right), dot(p - c, f.up), dot(p - c, fwd)}; };
        for (const std::uint32_t pid : scored) {
            const std::size_t id = pid;
            const PrimRef& p = prims[id];
            if (p.kind == PrimKind::Triangle) {
                const Triangle& t = triangles[p.index];
                v.triangle(at(t.v0), at(t.v1), at(t.v2), pid);
            } else if (p.kind == PrimKind::Polygon) {
                const Polygon& q = polygons[p.index];
                const Vec3* pv = polygon_vertices.data() + q.first;
                for (std::uint32_t k = 1; k + 1 < q.count; ++k) v.triangle(at(pv[0]), at(pv[k]), at(pv[k + 1]), pid);
            } else {
                // Round primitives: the projected box of their bounds, at its nearest depth.
                const Box3& b = summaries_[id].bounds;
                double lr = kInf, hr = -kInf, lu = kInf, hu = -kInf, z = kInf;
                for (int k = 0; k < 8; ++k) {
                    const Projected q = at(Vec3{k & 1 ? b.hi.x : b.lo.x, k & 2 ? b.hi.y : b.lo.y, k & 4 ? b.hi.z : b.lo.z});
                    lr = std::min(lr, q.r), hr = std::max(hr, q.r), lu = std::min(lu, q.u), hu = std::max(hu, q.u);
                    z = std::min(z, q.z);
                }
                v.rect(lr, hr, lu, hu, z, pid);
            }
        }
        return v;
    };
    Vec3 best_dir{0.8f, 0.6f, 1.0f};
    double best_score = -1;
    // From below only when it shows clearly more (a mesh whose up axis is not y, a backdrop the
    // views from above all see from behind): y is up in most mesh formats.
    for (float sy : {0.6f, 1.6f, -0.6f, -1.6f}) {
        for (Vec3 xz : {Vec3{0.8f, 0, 1}, Vec3{-0.8f, 0, 1}, Vec3{0.8f, 0, -1}, Vec3{-0.8f, 0, -1}, Vec3{1, 0, 0},
                        Vec3{-1, 0, 0}, Vec3{0, 0, 1}, Vec3{0, 0, -1}}) {
            const Vec3 dir = normalize(Vec3{xz.x, sy, xz.z});
            const ViewRaster v = rasterize(frame(dir, false));
            const double score = double(v.covered(0, v.n, 0, v.n)) * v.distinct() * (sy > 0 ? 1.0 : 0.75);
            if (score > best_score * (1 + 1e-6)) best_score = score, best_dir = dir;
        }
    }
    const Frame f = frame(best_dir, true);
    const double span_r = f.hi_r - f.lo_r, span_u = f.hi_u - f.lo_u;
    const double aspect = span_r > 0 && span_u > 0 ? std::clamp(span_r / span_u, 0.25, 4.0) : 1.0;
    cam.width = aspect >= 1 ? 512 : std::max(128, static_cast<int>(std::lround(512 * aspect)));
    cam.height = aspect >= 1 ? std::max(128, static_cast<int>(std::lround(512 / aspect))) : 512;
    const double mid_r = 0.5 * (f.lo_r + f.hi_r), mid_u = 0.5 * (f.lo_u + f.hi_u);
    const Vec3 at = c + f.right * static_cast<float>(mid_r) + f.up * static_cast<float>(mid_u);
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
    cam.up = f.up;
    cam.hither = radius * 1e-3f;
    // A turned view frames the window's corners, a little more than the window: crop again.
    for (int pass = 0; pass < 3 && crop_to_object(*this, cam); ++pass) {}
    return cam;
}

}  // namespace rtcost
