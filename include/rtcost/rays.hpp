#pragma once
/// \file rays.hpp
/// Ray distributions: the sets of rays whose cost a hierarchy is measured and predicted on.
/// Every generator is deterministic for a given seed (same seed, same rays, on every machine).

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "rtcost/scene.hpp"

namespace rtcost {

class Hierarchy;

/// One eye ray per pixel centre of a `width` x `height` image from the scene's camera. The
/// direction is not normalised: its component along the view axis is 1, so tmin = hither clips
/// at the hither plane exactly.
std::vector<Ray> camera_rays(const Camera& cam, int width, int height);
/// The eye ray of any one pixel of camera_rays' image, bit for bit its element: for a subset of
/// the pixels (a ray sample's), without making the whole image's rays.
class CameraRay {
public:
    CameraRay(const Camera& cam, int width, int height);
    /// The ray of pixel `pixel` (row-major, from the top left).
    Ray operator()(std::size_t pixel) const;
    /// The ray through image point (u, v), in pixels right and up of the image's centre.
    Ray through(double u, double v) const {
        return Ray{from_, fwd_ + right_ * static_cast<float>(u * scale_) + up_ * static_cast<float>(v * scale_), hither_,
                   kInf};
    }

private:
    Vec3 from_, fwd_, right_, up_;
    double scale_;
    float hither_;
    int width_, height_;
};
/// `n` eye rays of the same camera through uniformly random points of its `width` x `height`
/// image (between its outermost pixel centres, not at them); directions as camera_rays'.
std::vector<Ray> view_rays(const Camera& cam, int width, int height, std::size_t n, std::uint64_t seed);

/// `n` isotropic random lines through `box` under the invariant measure of lines (uniform
/// direction on the sphere, then a uniform point on the box's projection perpendicular to it),
/// clipped to the box: origin at the entry point, unit direction, (0, chord length), both ends
/// extended by 1e-4 of the box's half-diagonal so that geometry on the box's faces is met.
std::vector<Ray> line_rays(const Box3& box, std::size_t n, std::uint64_t seed);

/// `n` rays for correctness tests: origins uniform in `box` grown by half its size on each side
/// (so some start inside and some outside), directions uniform on the sphere, (0, +inf).
std::vector<Ray> random_rays(const Box3& box, std::size_t n, std::uint64_t seed);

/// `n` incoherent rays that nearly all hit: origins uniform on a sphere around the scene (twice
/// its bounding sphere), each aimed at a uniformly random point of a primitive chosen uniformly
/// at random; unit directions, (0, +inf).
std::vector<Ray> aimed_rays(const Scene& scene, std::size_t n, std::uint64_t seed);
/// The same with each target's primitive chosen, with probability `by_area`, in proportion to
/// its area instead of uniformly.
std::vector<Ray> aimed_rays(const Scene& scene, std::size_t n, std::uint64_t seed, double by_area);

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
    /// Problems worth telling the user that do not make the set invalid (rays too far away).
    std::vector<std::string> warnings;
    /// Camera-based distributions: the pixels of the image their eye rays go through (a ray
    /// tree's corners for spd), and per ray the pixel whose eye ray it descends from, in
    /// ascending order (a ray sample is drawn by pixel: sample.hpp). 0 and empty otherwise.
    std::size_t image_pixels = 0;
    std::size_t image_width = 0;  ///< pixels a row (pixel index = row x width + column)
    std::vector<std::uint32_t> pixels;
};

/// How far from a scene, in units of its size (the largest side of its bounds), a ray may start
/// and still be traced exactly: float positions along the ray resolve the scene to about 1/1000
/// of its size up to there, finer than the cells of the deepest default subdivision (an octree
/// of depth 8: 1/256). Farther, cell walks can no longer step from cell to cell (the fuzzer
/// found the octree missing a head-on hit from 3.2e4 sizes), grazing hits become rounding noise,
/// and hierarchies may disagree with brute force.
inline constexpr float kMaxResolvedDistance = 1e4f;

/// Whether `ray` starts more than kMaxResolvedDistance scene sizes outside `bounds`.
bool starts_too_far(const Box3& bounds, const Ray& ray);

/// A camera and lights given on the command line instead of the scene's: `camera` is
/// "fx,fy,fz,ax,ay,az,ux,uy,uz,fov" (from, at, up, full field of view in degrees), each light
/// "x,y,z". Empty: the scene's own.
struct ViewSpec {
    std::string camera;
    std::vector<std::string> lights;
};

/// Replaces the scene's camera and lights by `view`'s (those it gives); throws InputError
/// naming the option for a malformed or degenerate one.
void apply_view(Scene& scene, const ViewSpec& view);

/// How to make a ray set: `name` is a distribution (camera, lines, random, aimed, spd, shadow,
/// diffuse, ao) or a ray file path.
struct RaySpec {
    std::string name = "camera";
    std::string size;                 ///< "WxH" for camera-based distributions; empty: the scene's
    std::size_t count = 100000;       ///< rays for lines, random and aimed
    std::uint64_t seed = 1;
    ViewSpec view;                    ///< camera and lights (see apply_view; make_rays reads the scene's)
};

/// Names accepted by make_rays besides file paths: the registered distributions, in order.
std::vector<std::string> distribution_names();

/// How long work reports itself while a distribution makes its rays.
struct RayMaking {
    int threads = 0;  ///< 0: all cores (distributions made by tracing)
    std::function<void(std::size_t done, std::size_t total)> progress;  ///< rows, for those that trace
    /// An exact hierarchy over the scene for the distributions made by tracing (hits are exact,
    /// so the rays are the same whichever); null: they build a bvh-sah of their own.
    const Hierarchy* tracer = nullptr;
    /// Only the rays are wanted: tests that decide a hit count but no ray (whether a shadow or
    /// ambient-occlusion segment is occluded, what a diffuse ray meets) are skipped, and those
    /// kinds' hit counts are left out of the summary. What a ray sample needs.
    bool rays_only = false;
    /// Camera-based distributions: only the rays of these pixels (ascending, each below the
    /// image's pixel count; an empty list makes no rays but says `image_pixels`). Null: every
    /// pixel. Each pixel's rays are the same as in the whole set. Others ignore it.
    const std::vector<std::uint32_t>* only_pixels = nullptr;
};

/// A registered ray distribution (`--rays NAME`): its name, what it is, and how it is made.
/// Each lives in its own file under src/rays/ with a RayDistributionRegistration; the CLI,
/// `list`, the Python module and the tests read the registry.
struct RayDistributionInfo {
    std::string name;
    std::string description;
    int order = 100;  ///< where listings put it (lower first)
    /// Independent draws of a seeded process over the scene (`--count`, `--seed`): another seed
    /// is a fresh sample of the same distribution, which `eval` trains the sampled estimator on.
    bool seeded_draws = false;
    /// In the trace benchmark (bench/): the rays that matter to a renderer, not those that
    /// mostly miss or exist for the model's tests.
    bool benchmarked = false;
    std::function<RaySet(const Scene&, const RaySpec&, const RayMaking&)> make;
};

/// The registered distributions, by `order`.
std::vector<const RayDistributionInfo*> ray_distributions();
/// The distribution called `name`, or nullptr.
const RayDistributionInfo* find_ray_distribution(std::string_view name);

/// Registers a distribution at static-initialisation time, once in its file:
///   static const rtcost::RayDistributionRegistration reg{{.name = "camera", .description = "...",
///                                                        .order = 0, .benchmarked = true, .make = maker}};
struct RayDistributionRegistration {
    explicit RayDistributionRegistration(RayDistributionInfo info);
};

/// A set of rays all of one kind, described as `described` (for distributions' makers).
RaySet one_kind(std::vector<Ray> rays, RayKind kind, std::string described);

/// Builds the ray set `spec` names over `scene` (a registered distribution, or a ray file);
/// throws InputError for a bad spec or file.
RaySet make_rays(const Scene& scene, const RaySpec& spec, const RayMaking& making = {});

/// Most rays one ray set may hold (--count, --size W*H): about 60 bytes each with the hits.
inline constexpr std::uint64_t kMaxRays = 50'000'000;

/// Throws std::invalid_argument unless `only` (RayMaking::only_pixels) is null or ascending
/// distinct pixel indices below `image_pixels` (for distributions' makers).
void check_pixel_subset(const std::vector<std::uint32_t>* only, std::size_t image_pixels);

/// Parses "WxH" (e.g. "512x512") with W*H <= kMaxRays; throws InputError naming `what` otherwise.
void parse_size(const std::string& text, const std::string& what, int& width, int& height);

/// The image size of camera-based rays: `size` parsed as --size where given, else the scene's
/// own resolution, refused (InputError naming the scene) beyond kMaxRays pixels.
void image_size(const Scene& scene, const std::string& size, int& width, int& height);

}  // namespace rtcost
