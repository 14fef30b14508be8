#pragma once
/// \file heatmap.hpp
/// Per-pixel cost heat maps: every operation the rays of each pixel perform (its camera ray, or
/// its whole Whitted ray tree), and the time they take, drawn with a perceptual colour map and
/// a legend (scale and units) in the image.

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "rtcost/hierarchy.hpp"
#include "rtcost/model.hpp"
#include "rtcost/whitted.hpp"

namespace rtcost {

/// What a heat map shows per pixel.
enum class HeatKind {
    Box, Plane, Hop, Classify, Prim,  ///< operations of one kind (prim: primitive tests of all kinds)
    Steps,                            ///< traversal steps (N_TS)
    Ops,                              ///< all operations weighted by unit costs (calibrated: ns)
    Time,                             ///< measured traversal nanoseconds
    /// The model's predicted operations (weighted as Ops) of the pixel's rays: see
    /// predicted_ray_cost (needs PixelCostOptions::predict).
    Predicted,
};
/// "box", "plane", "hop", "classify", "prim", "steps", "ops", "time", "predicted".
std::string_view heat_kind_name(HeatKind k);
/// Parses a heat kind name; throws InputError naming `what` otherwise.
HeatKind parse_heat_kind(std::string_view name, const std::string& what = "--heatmap");
/// Every kind's name, in enum order.
std::vector<std::string> heat_kind_names();

/// Operations and time of one pixel's rays, summed.
struct PixelCost {
    std::uint32_t rays = 0;
    std::uint32_t box = 0, plane = 0, hop = 0, classify = 0, steps = 0;
    std::array<std::uint32_t, kPrimKinds> prim{};
    std::uint32_t polygon_edges = 0;  ///< RayCounters::polygon_edges
    float ns = 0;  ///< measured traversal time (when asked for), timer overhead removed
};

struct PixelCostOptions {
    int width = 256, height = 256;  ///< pixel centres of the scene's camera, as `render`
    /// The pixel's whole Whitted ray tree (the `spd` procedure's recursion: eye, shadow,
    /// reflection and refraction rays) rather than its camera ray alone.
    bool tree = false;
    int max_depth = 5;             ///< of the tree (eye ray: 1)
    Query occlusion = Query::Any;  ///< shadow rays in a tree
    bool time = false;             ///< also time each pixel's rays (the fast, uncounted traversal)
    int threads = 0;               ///< 0: all cores
    std::function<void(std::size_t)> progress;  ///< rows done
    /// The model's cost of one ray of a kind (predicted_ray_cost), summed per pixel into
    /// PixelCosts::predicted when set.
    std::function<CostVector(const Ray&, RayKind)> predict;
};

/// Per-pixel costs of `h` over its scene, rows top to bottom.
struct PixelCosts {
    int width = 0, height = 0;
    std::vector<PixelCost> pixels;
    RayCounters total;  ///< every ray's counters summed (equals trace_rays over the same rays)
    bool timed = false;
    std::vector<CostVector> predicted;  ///< per pixel, when PixelCostOptions::predict was set
    int box_lanes = 1;  ///< the hierarchy's StructureStats::box_lanes (what its box tests cost)
};

/// Traces each pixel's rays through `h` with counting (and, when asked, again timed), and sums
/// them per pixel. The rays are those of `render` (tree) or `camera_rays` (camera ray alone).
PixelCosts pixel_costs(const Hierarchy& h, const PixelCostOptions& opt = {});

/// The model's cost of single rays of `h` for the pixels `opt` describes (camera rays, or
/// Whitted trees): for each ray kind a RayCostModel learned from a sample of `sample_rays` rays
/// (0: 2% of the pixels' rays, 256 to 4,096) of the same distribution (`camera`, or `spd` at
/// the same size), drawn with bvh-sah as the reference. The hierarchy's model tree is read
/// once; the rays predicted are never traced through `h` for it. Throws InputError for a
/// hierarchy without a model tree, or rc5d (5D trees have no per-ray prediction).
std::function<CostVector(const Ray&, RayKind)> predicted_ray_cost(const Hierarchy& h, const PixelCostOptions& opt,
                                                                  std::size_t sample_rays = 0);

/// One value per pixel for `kind` (Ops: `costs.scalar` summed over the pixel's rays). Throws
/// InputError for Time when `pc` was not timed.
std::vector<double> heat_values(const PixelCosts& pc, HeatKind kind, const UnitCosts& costs = {});
/// The unit of `kind`'s values, e.g. "box tests per pixel", "ns per pixel (measured)".
std::string heat_units(HeatKind kind, const UnitCosts& costs = {});

/// How to draw a heat map.
struct HeatStyle {
    std::string title;       ///< first line of the legend (e.g. "bvh-sah on balls")
    std::string units;       ///< what the colour bar measures
    double scale_max = 0;    ///< top of the colour bar; 0: the largest value
    /// Colour by log(1 + value) (for maps whose costs span decades, e.g. several hierarchies on
    /// one scale), else linear.
    bool log = false;
};

/// Summary of the values drawn.
struct HeatSummary {
    double min = 0, max = 0, mean = 0, scale_max = 0;
    std::size_t clipped = 0;  ///< pixels above scale_max (drawn in the top colour)
};
HeatSummary summarize(const std::vector<double>& values, double scale_max);

/// The values (width x height, rows top to bottom) in viridis from 0 to the scale's top, with a
/// colour bar, its ticks, the units and the title drawn beside the map.
Image draw_heatmap(const std::vector<double>& values, int width, int height, const HeatStyle& style);

}  // namespace rtcost
