#pragma once
// The Whitted recursion shared by the SPD ray tree (which records rays) and the renderer (which
// keeps the colour): one code path, so the image shows exactly the rays that are counted.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "rtcost/whitted.hpp"
#include "util/rng.hpp"

namespace rtcost::detail {

/// Rays of one image row (or any run of pixels), with counts by kind.
struct Recorder {
    bool keep = true;
    std::vector<Ray> rays;
    std::vector<RayKind> kinds;
    std::vector<std::uint32_t> pixels;  ///< per ray, `pixel` when it was added
    std::uint32_t pixel = 0;            ///< the pixel whose rays are being recorded
    KindCounts counts;
    void count(RayKind k, bool hit) {
        ++counts.rays[static_cast<int>(k)];
        counts.hits[static_cast<int>(k)] += hit;
    }
    void add(const Ray& r, RayKind k, bool hit) {
        count(k, hit);
        if (!keep) return;
        rays.push_back(r);
        kinds.push_back(k);
        pixels.push_back(pixel);
    }
};

/// A hit point as shading sees it.
struct Surface {
    Vec3 p;       ///< the point
    Vec3 dir;     ///< unit direction of the incoming ray
    Vec3 n;       ///< unit normal facing the incoming ray
    bool front;   ///< the ray met the side the geometric normal points to
    const Material* m;
};

class WhittedTracer {
public:
    /// `shadow_tests` false: shadow rays are recorded untested (WhittedOptions::shadow_tests).
    WhittedTracer(const Hierarchy& h, int max_depth, bool shadow_tests = true);
    /// Colour seen along `ray` of depth `depth` (eye ray: 1); records every ray spawned in `rec`.
    Vec3 trace(const Ray& ray, RayKind kind, int depth, Recorder* rec) const;
    /// Fills `s` for a hit of `ray` (completing `hit`'s normal); false on a miss.
    bool surface(const Ray& ray, Hit& hit, Surface& s) const;

private:
    static constexpr float kAmbient = 0.15f;
    const Scene& scene_;
    const Hierarchy& h_;
    int max_depth_;
    bool shadow_tests_;
    float eps_;
    float light_scale_;
};

/// The mirror direction of the ray that met `s`.
inline Vec3 mirrored(const Surface& s) { return s.dir - s.n * (2 * dot(s.dir, s.n)); }

/// The direction the ray that met `s` takes through it by Snell's law (the material's index; 1
/// if not positive), entering through the side the geometric normal points to and leaving
/// through the other; none under total internal reflection.
inline std::optional<Vec3> refracted(const Surface& s) {
    const float ior = s.m->ior > 0 ? s.m->ior : 1.0f;
    const float eta = s.front ? 1.0f / ior : ior;
    const float cos_i = -dot(s.dir, s.n);
    const float k = 1 - eta * eta * (1 - cos_i * cos_i);
    if (k < 0) return std::nullopt;
    return normalize(s.dir * eta + s.n * (eta * cos_i - std::sqrt(k)));
}

/// A cosine-weighted unit direction about unit `n`.
Vec3 cosine_direction(Vec3 n, ItemRng& rng);

/// Calls `pixel(i, index)` for every pixel i of image row j (width pixels a row) that `only`
/// lists (ascending), or for every pixel of the row when `only` is null; index = j width + i.
template <class F>
void for_pixels_of_row(int j, int width, const std::vector<std::uint32_t>* only, F&& pixel) {
    const std::size_t first = static_cast<std::size_t>(j) * static_cast<std::size_t>(width);
    if (!only) {
        for (int i = 0; i < width; ++i) pixel(i, first + static_cast<std::size_t>(i));
        return;
    }
    auto at = std::lower_bound(only->begin(), only->end(), first);
    for (; at != only->end() && *at < first + static_cast<std::size_t>(width); ++at)
        pixel(static_cast<int>(*at - first), static_cast<std::size_t>(*at));
}

/// Calls row(j) for every j in [0, rows) on `threads` threads (0: all cores), reporting rows done.
void run_rows(int rows, int threads, const std::function<void(int)>& row,
              const std::function<void(std::size_t)>& progress);

}  // namespace rtcost::detail
