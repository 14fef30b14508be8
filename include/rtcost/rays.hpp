#pragma once
/// \file rays.hpp
/// Ray distributions: the sets of rays whose cost a hierarchy is measured and predicted on.
/// Every generator is deterministic for a given seed (same seed, same rays, on every machine).

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "rtcost/scene.hpp"

namespace rtcost {

/// One eye ray per pixel centre of a `width` x `height` image from the scene's camera. The
/// direction is not normalised: its component along the view axis is 1, so tmin = hither clips
/// at the hither plane exactly.
std::vector<Ray> camera_rays(const Camera& cam, int width, int height);

/// `n` isotropic random lines through `box` under the invariant measure of lines (uniform
/// direction on the sphere, then a uniform point on the box's projection perpendicular to it),
/// clipped to the box: origin at the entry point, unit direction, (0, chord length), both ends
/// extended by 1e-4 of the box's half-diagonal so that geometry on the box's faces is met.
std::vector<Ray> line_rays(const Box3& box, std::size_t n, std::uint64_t seed);

/// `n` rays for correctness tests: origins uniform in `box` grown by half its size on each side
/// (so some start inside and some outside), directions uniform on the sphere, (0, +inf).
std::vector<Ray> random_rays(const Box3& box, std::size_t n, std::uint64_t seed);

/// What a ray in a ray set is for. Generated distributions are all `Eye` or `Line`; the SPD
/// Whitted tree mixes eye, reflection, refraction and shadow rays.
enum class RayKind : std::uint8_t { Eye, Reflection, Refraction, Shadow, Diffuse, AO, Line, Test, File };
inline constexpr int kRayKinds = 9;
std::string_view ray_kind_name(RayKind k);
/// Whether rays of `kind` are occlusion queries (shadow and ambient-occlusion rays): traced
/// any-hit unless asked otherwise.
bool is_occlusion(RayKind kind);

/// A batch of rays with their kinds. Shadow and ambient-occlusion rays are occlusion queries
/// (any hit) unless traced otherwise.
struct RaySet {
    std::vector<Ray> rays;
    std::vector<RayKind> kinds;   ///< one per ray
    std::string described;        ///< e.g. "camera 512x512"
    /// Counts by kind (and, for generated trees, hits by kind), for reports.
    std::vector<std::pair<std::string, std::size_t>> summary;
};

/// How to make a ray set: `name` is a distribution (camera, lines, random, spd, shadow, diffuse,
/// ao) or a ray file path.
struct RaySpec {
    std::string name = "camera";
    std::string size;                 ///< "WxH" for camera-based distributions; empty: the scene's
    std::size_t count = 100000;       ///< rays for lines and random
    std::uint64_t seed = 1;
};

/// Names accepted by make_rays besides file paths.
std::vector<std::string> distribution_names();

/// Builds the ray set `spec` names over `scene`; throws InputError for a bad spec or file.
RaySet make_rays(const Scene& scene, const RaySpec& spec);

/// Parses "WxH" (e.g. "512x512"); throws InputError naming `what` otherwise.
void parse_size(const std::string& text, const std::string& what, int& width, int& height);

}  // namespace rtcost
