// libFuzzer: small whole scenes traced by every hierarchy against brute force. The bytes are
// read as a scale, then primitives whose coordinates are small integers in sixteenths (so that
// coincident, coplanar and axis-aligned geometry is common), all multiplied by the scale
// (1e-11 .. 1e11). Scenes that loading would refuse are skipped; every other must give brute
// force's closest hits in every hierarchy (Embree aside: it is not exact).
#include <cmath>
#include <vector>

#include "fuzz_support.hpp"
#include "rtcost/rays.hpp"

namespace {

class Bytes {
public:
    Bytes(const std::uint8_t* d, std::size_t n) : d_(d), n_(n) {}
    bool more() const { return i_ < n_; }
    std::uint8_t next() { return i_ < n_ ? d_[i_++] : 0; }
    float coord(float scale) { return (static_cast<int>(next()) - 128) / 16.0f * scale; }

private:
    const std::uint8_t* d_;
    std::size_t n_, i_ = 0;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace rtcost;
    if (size < 2 || size > 1024) return 0;
    Bytes b(data, size);
    const float scale = std::pow(10.0f, static_cast<float>(b.next() % 23) - 11.0f);
    Scene s;
    std::vector<Vec3> poly;
    while (b.more() && s.size() < 64) {
        auto v = [&] { return Vec3{b.coord(scale), b.coord(scale), b.coord(scale)}; };
        switch (b.next() % 4) {
            case 0: {
                Triangle t{v(), v(), v()};
                s.add(t, 0);
                break;
            }
            case 1: {
                Vec3 c = v();
                const float r = (1 + b.next()) / 32.0f * scale;
                s.add(Sphere{c, r}, 0);
                break;
            }
            case 2: {
                Vec3 base = v();
                const float rb = b.next() / 32.0f * scale;
                Vec3 apex = v();
                const float ra = b.next() / 32.0f * scale;
                if (base == apex || (rb == 0 && ra == 0)) break;  // what the NFF reader skips
                s.add(Cone{base, rb, apex, ra}, 0);
                break;
            }
            default: {
                poly.clear();
                const int n = 3 + b.next() % 4;
                for (int i = 0; i < n; ++i) poly.push_back(v());
                s.add_polygon(poly, 0);
                break;
            }
        }
    }
    // Zero-area triangles are what the readers skip; a scene of them is not a scene.
    Scene kept;
    for (std::uint32_t id = 0; id < s.size(); ++id) {
        const PrimRef& p = s.prims[id];
        if (p.kind == PrimKind::Triangle) {
            const Triangle& t = s.triangles[p.index];
            if (!(area(t) > 0)) continue;
            kept.add(t, 0);
        } else if (p.kind == PrimKind::Sphere) {
            kept.add(s.spheres[p.index], 0);
        } else if (p.kind == PrimKind::Cone) {
            kept.add(s.cones[p.index], 0);
        } else {
            const Polygon& q = s.polygons[p.index];
            kept.add_polygon(std::span(s.polygon_vertices).subspan(q.first, q.count), 0);
        }
    }
    kept.finalize();
    try {
        check_scene(kept);
    } catch (const InputError&) {
        return 0;
    }
    std::vector<Ray> rays = random_rays(kept.bounds(), 48, size);
    std::vector<Ray> lines = line_rays(kept.bounds(), 16, size + 1);
    rays.insert(rays.end(), lines.begin(), lines.end());
    // Rays aimed at each primitive's box centre (vertices and edges are where traversals differ).
    std::vector<Ray> from = random_rays(kept.bounds(), kept.size(), size + 2);
    for (std::uint32_t id = 0; id < kept.size(); ++id) {
        Ray r = from[id];
        r.d = kept.prim_bounds(id).center() - r.o;
        if (!(std::max({std::fabs(r.d.x), std::fabs(r.d.y), std::fabs(r.d.z)}) > 0)) continue;
        rays.push_back(r);
    }
    auto brute = build_hierarchy(kept, "brute");
    for (const HierarchyInfo* info : hierarchies()) {
        if (info->name == "embree" || info->name == "brute") continue;
        auto h = build_hierarchy(kept, info->name);
        fuzz::require_same_hits(*h, *brute, rays, "scene");
    }
    return 0;
}
