#pragma once
/// \file whitted.hpp
/// The Whitted ray tree of a scene (the SPD testing procedure), the rays spawned from camera hits
/// (shadow, diffuse, ambient occlusion), and Whitted shading to an RGB image written as PNG.
///
/// Conventions (those of the SPD notes): the shading normal is the geometric normal turned to face
/// the incoming ray; a ray refracts entering (ratio 1 / ior) when it meets the side the geometric
/// normal points to and leaving (ratio ior) otherwise; a hit on a reflector (Ks > 0) or a
/// transmitter (T > 0) spawns a reflection ray, one on a transmitter also a refraction ray unless
/// the reflection is total; a shadow ray goes to each light on the side the shading normal faces
/// (these reproduce the published SPD counts, docs/spd-rays.md). Secondary
/// rays start on the surface moved by `spawn_offset` along the normal to the side they travel into.

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "rtcost/hierarchy.hpp"
#include "rtcost/rays.hpp"

namespace rtcost {

/// Rays and hits by RayKind (indexed by the enum's value). For shadow and ambient-occlusion rays
/// a hit means the segment is occluded.
struct KindCounts {
    std::array<std::size_t, kRayKinds> rays{}, hits{};
    std::size_t total() const;
};

struct WhittedOptions {
    /// Grid of eye rays; the SPD procedure is 513 x 513, the corners of a 512 x 512 image.
    int width = 513, height = 513;
    int max_depth = 5;   ///< the eye ray is depth 1
    bool record = true;  ///< keep the rays; false gives the counts alone
    /// Test the shadow rays; false records them untested (no hits counted, no light in the
    /// colour): the same rays, for when only the rays are wanted.
    bool shadow_tests = true;
    int threads = 0;     ///< 0: all cores
    /// Only the ray trees of these pixels (ascending indices into the width x height grid of
    /// eye rays); null: all.
    const std::vector<std::uint32_t>* pixels = nullptr;
    /// Called now and then with eye-ray rows done of `height` (serialised).
    std::function<void(std::size_t)> progress;
};

/// Rays in pixel order (row-major), each pixel's tree depth first: the ray, its shadow rays, its
/// reflection subtree, then its refraction subtree. The same on every run and thread count.
struct RayTree {
    std::vector<Ray> rays;
    std::vector<RayKind> kinds;
    std::vector<std::uint32_t> pixels;  ///< per ray, the pixel of the eye ray it descends from
    KindCounts counts;
};

/// The whole Whitted ray tree of `h.scene()` from its camera. Hits are exact, so the tree is
/// the same whichever hierarchy `h` is; only the time differs.
RayTree whitted_tree(const Hierarchy& h, const WhittedOptions& opt = {});

/// Rays spawned once from the hits of camera rays (pixel centres of a width x height image).
enum class CameraHitRays {
    Shadow,   ///< a segment to each light the shading normal faces
    Diffuse,  ///< one cosine-weighted direction about the shading normal, to infinity
    AO,       ///< one cosine-weighted segment of length ao_length()
};
/// `seed` drives the random directions (per pixel, so independent of threads). The camera rays
/// themselves are counted in `counts` (kind Eye) but are not in `rays`. With `test_spawned`
/// false the spawned rays are recorded without being traced (no hits counted for them).
RayTree camera_hit_rays(const Hierarchy& h, CameraHitRays which, int width, int height, std::uint64_t seed,
                        int threads = 0, const std::function<void(std::size_t)>& progress = {},
                        bool test_spawned = true, const std::vector<std::uint32_t>* pixels = nullptr);

/// Length of ambient-occlusion segments: 5% of the scene box's diagonal.
float ao_length(const Scene& scene);
/// How far secondary rays start off the surface: 1e-5 of the scene box's diagonal.
float spawn_offset(const Scene& scene);

/// The ray sets `spd`, `shadow`, `diffuse` and `ao` of make_rays, traced through
/// `making.tracer` (null: an internal bvh-sah). spd's default size is 512 (513 x 513 eye rays);
/// the others default to the scene's resolution. `making.progress` gets eye-ray rows done; with
/// `making.rays_only` the tests that decide no ray are skipped (RayMaking). Throws InputError
/// for another name.
RaySet make_tree_rays(const Scene& scene, const RaySpec& spec, const RayMaking& making = {});
/// True for the names make_tree_rays takes.
bool is_tree_distribution(const std::string& name);

/// 8-bit RGB, rows top to bottom.
struct Image {
    int width = 0, height = 0;
    std::vector<std::uint8_t> rgb;
};

struct RenderOptions {
    int width = 512, height = 512;  ///< pixel centres, like the camera distribution
    int max_depth = 5;
    int threads = 0;
    std::function<void(std::size_t)> progress;  ///< rows done
};

/// Whitted shading of `h.scene()`: ambient plus Phong diffuse and highlight from each unshadowed
/// light (intensity 1 / sqrt(lights), the SPD suggestion), plus Ks times the reflected and T times
/// the refracted colour; rays that miss take the background colour.
Image render(const Hierarchy& h, const RenderOptions& opt = {});

/// PNG bytes of `img` (libpng).
std::string encode_png(const Image& img);
/// Writes `img` as PNG atomically; throws InputError when it cannot.
void write_png(const std::string& path, const Image& img);

}  // namespace rtcost
