// `kd-design`: kd-sah's planes with the model's termination. kd-sah's planes are laid down to
// where even a traversal priced at a quarter of a test stops paying by the SAH, then judged
// bottom up (prune.hpp): a subtree stays only where the cost model, with visit probabilities from
// the design sample (the share of a node's sample segments, clipped where each ray's search
// ends, that meet each child cell, blended with the surface-area ratio where few reach the
// node), prices it below one leaf of its references -- Subramanian and Fussell's automatic
// termination with the user's rays instead of isotropic lines, judged with every level below
// known (a one-level test stops above splits that pay only further down). kd-sah's plane choice
// has one free constant that the sample can decide, the bonus of a split that cuts off empty
// space: by default the tree is designed with no bonus and with kd-sah's 0.2 (a sweep of kd-sah
// found either one best depending on the scene), and of the two, and of kd-sah's own
// termination, the model's cheapest on the sample, its size's cache misses included, is kept
// (design/cheaper.hpp).
#include "../kd/kdtree.hpp"
#include "design/cell_rays.hpp"
#include "prune.hpp"
#include "design/cheaper.hpp"

namespace rtcost::kd {
namespace {

const Registration reg{
    {"kd-design",
     "kd-sah's planes, each subtree kept only where the cost model with a sample of the given rays prices it below one leaf",
     [] {
         std::vector<ParamSpec> p = design_param_specs();
         p.push_back(kMaxDepthParam);
         p.push_back(ParamSpec::real("trust", "32", 0, 1e30, "sample segments at a node at which sample and surface area weigh alike"));
         p.push_back(ParamSpec::real("empty_bonus", "auto", 0, 1,
                                     "kd-sah's plane choice: a split with an empty side costs (1 - empty_bonus) x its SAH "
                                     "cost; auto: designed with 0 and with 0.2, the model's cheaper on the sample kept",
                                     {"auto"}));
         p.push_back(spatial::kAssignParam);
         p.push_back(spatial::kMailboxParam);
         return p;
     }(),
     [](const Scene& s, const Params& p) -> std::unique_ptr<Hierarchy> {
         const DesignInput in = draw_design_input(s, p);
         BuildOptions build;
         build.max_prims = 0;
         build.max_depth = p.is("max_depth", "auto") ? default_max_depth(s.size()) : static_cast<int>(p.integer("max_depth"));
         build.assign = spatial::parse_assign(p);
         const SahOptions usual_sah;  // kd-sah's defaults
         std::vector<float> bonuses = {usual_sah.empty_bonus, 0.0f};
         if (!p.is("empty_bonus", "auto")) bonuses = {static_cast<float>(p.real("empty_bonus"))};
         SahOptions usual = usual_sah;  // kd-sah's defaults, with this tree's depth and assignment
         usual.build = build;
         usual.build.max_prims = 1;
         auto usual_tree = std::make_unique<KdTree>(s, "kd-design", build_sah(s, usual), p.flag("mailbox"));
         // A node visit's price: a step, and with a calibrated time model the cache misses of a
         // structure of the yardstick's size (the designed tree's own size is known only once
         // built; a costs file without the time model's terms prices neither).
         const double k_step = in.costs.step + in.costs.cache * in.costs.cache_doublings(usual_tree->structure().bytes);
         std::vector<std::unique_ptr<KdTree>> trees;  // a tie keeps the earlier: kd-sah's bonus first
         for (float bonus : bonuses) {
             // An interior visit of kd-sah's traversal, beyond the step any visit takes: one plane.
             const designing::CellRays cells(s, in, p.real("trust"), in.costs.plane, k_step);
             // kd-sah's planes down to where even a cheap traversal (a quarter of a test) stops
             // paying by the SAH, then the model's pruning.
             SahOptions deep = usual_sah;
             deep.build = build;
             deep.c_trav = deep.c_isect / 4;
             deep.empty_bonus = bonus;
             const Chooser choose = [&deep](const std::vector<BuildRef>& refs, const Box3& cell, int) {
                 return sah_plane(refs, cell, deep, false);
             };
             trees.push_back(std::make_unique<KdTree>(s, "kd-design", prune(build_tree(s, deep.build, choose), cells),
                                                      p.flag("mailbox")));
         }
         trees.push_back(std::move(usual_tree));
         return designing::cheapest_on_sample(std::move(trees), s, in);
     },
     kLargeScene}};  // kd-sah's O(N log^2 N) planes, each judged on the sample: 19 s for a million triangles

}  // namespace
}  // namespace rtcost::kd
