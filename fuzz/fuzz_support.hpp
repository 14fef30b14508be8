#pragma once
// Pieces shared by the libFuzzer harnesses: a scratch file per process, a small scene, and the
// check that a hierarchy's closest hits are brute force's (abort otherwise, which libFuzzer
// records as a crash with the input that caused it).
#include <unistd.h>

#include <cstdio>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <string>
#include <string_view>

#include "rtcost/hierarchy.hpp"
#include "rtcost/io.hpp"
#include "rtcost/rays.hpp"
#include "rtcost/trace.hpp"

namespace rtcost::fuzz {

/// Writes `bytes` to /tmp/rtcost-fuzz-PID`ext` and returns the path.
inline std::string scratch_file(std::string_view bytes, const std::string& ext) {
    std::string path = "/tmp/rtcost-fuzz-" + std::to_string(::getpid()) + ext;
    std::ofstream(path, std::ios::binary | std::ios::trunc).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    return path;
}

/// Aborts with a message when `h` and `brute` disagree on any closest hit (the adversarial
/// suite's rule: the same primitive with exactly the same t, or another primitive at the same
/// distance up to the rounding of the scene's coordinates, a tie: coplanar overlapping triangles
/// are met at one point whose t each triangle's arithmetic rounds differently). One more
/// ambiguity: a brute-force hit within that rounding of the segment's start (a ray from a
/// surface point, tangent to it, with a tiny tmin > 0) is as likely to lie before tmin as after
/// it, and a box whose face holds the origin is left at t = 0; a hierarchy may skip such a hit
/// and report the next one. Likewise a grazing hit: the ray runs along a face of the primitive's
/// box with a direction component off that face so small (but not zero) that it moves the ray by
/// less than the rounding of coordinates before the hit; exactly, the ray has left the box at
/// once, while the primitive's test, rounding, may still meet it. Rays that start beyond kMaxResolvedDistance (rtcost warns about
/// them: float positions cannot resolve the scene there) are not compared.
/// Whether brute force's hit `w` on `r` grazes a face of the primitive's box (see above).
inline bool grazes_box_face(const Scene& scene, const Ray& r, const Hit& w, float size) {
    const Box3 b = scene.prim_bounds(static_cast<std::uint32_t>(w.prim));
    const Vec3 p = r.o + w.t * r.d;
    const float round = 1e-6f * (std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)}) + size);
    for (int a = 0; a < 3; ++a)
        if (r.d[a] != 0 && std::fabs(r.d[a]) * w.t <= round &&
            (std::fabs(p[a] - b.lo[a]) <= round || std::fabs(p[a] - b.hi[a]) <= round))
            return true;
    return false;
}

inline void require_same_hits(const Hierarchy& h, const Hierarchy& brute, std::span<const Ray> rays, const char* what) {
    TraceOptions opt;
    opt.threads = 1;
    const auto want = trace_rays(brute, rays, opt).hits, got = trace_rays(h, rays, opt).hits;
    const Vec3 e = h.scene().bounds().extent();
    const float size = std::max({e.x, e.y, e.z});
    for (std::size_t i = 0; i < rays.size(); ++i) {
        if (starts_too_far(h.scene().bounds(), rays[i])) continue;
        const float tol = 1e-6f * (std::fabs(want[i].t) + size / length(rays[i].d));
        bool ok = want[i].hit() == got[i].hit();
        if (ok && want[i].hit()) ok = std::fabs(want[i].t - got[i].t) <= (want[i].prim == got[i].prim ? 0.0f : tol);
        if (!ok && want[i].hit() &&
            (want[i].t - rays[i].tmin <= tol || grazes_box_face(h.scene(), rays[i], want[i], size)))
            ok = got[i].t >= want[i].t;  // at the start, or grazing: may be skipped for a later hit
        if (!ok) {
            const std::string name(h.name());
            std::fprintf(stderr, "%s: %s differs from brute force on ray %zu: want %d t %.9g, got %d t %.9g\n", what,
                         name.c_str(), i, want[i].prim, double(want[i].t), got[i].prim, double(got[i].t));
            std::abort();
        }
    }
}

}  // namespace rtcost::fuzz
