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
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_group.h>

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
         // kd-sah's planes down to where even a cheap traversal (a quarter of a test) stops paying
         // by the SAH, for each bonus; then the model's pruning.
         std::vector<SahOptions> deep(bonuses.size(), usual_sah);
         for (std::size_t i = 0; i < bonuses.size(); ++i) {
             deep[i].build = build;
             deep[i].c_trav = deep[i].c_isect / 4;
             deep[i].empty_bonus = bonuses[i];
         }
         // The yardstick's tree and each bonus's deep tree are independent single-threaded builds:
         // built side by side where there are cores (on balls-mesh, 5.4 s one after the other).
         // Each is the same tree either way.
         KdData usual_data;
         std::vector<KdData> deep_data(bonuses.size());
         {
             tbb::task_group builds;
             builds.run([&] { usual_data = build_sah(s, usual); });
             for (std::size_t i = 0; i < bonuses.size(); ++i)
                 builds.run([&, i] {
                     const Chooser choose = [&deep, i](const std::vector<BuildRef>& refs, const Box3& cell, int) {
                         return sah_plane(refs, cell, deep[i], false);
                     };
                     deep_data[i] = build_tree(s, deep[i].build, choose);
                 });
             builds.wait();
         }
         auto usual_tree = std::make_unique<KdTree>(s, "kd-design", std::move(usual_data), p.flag("mailbox"));
         // A node visit's price: a step, and with a calibrated time model the cache misses of a
         // structure of the yardstick's size (the designed tree's own size is known only once
         // built; a costs file without the time model's terms prices neither).
         const double k_step = in.costs.step + in.costs.cache * in.costs.cache_doublings(usual_tree->structure().bytes);
         // Each deep tree pruned (an interior visit of kd-sah's traversal, beyond the step any
         // visit takes: one plane); a tie keeps the earlier: kd-sah's bonus first.
         std::vector<std::unique_ptr<KdTree>> trees(bonuses.size());
         tbb::parallel_for(std::size_t{0}, bonuses.size(), [&](std::size_t i) {
             const designing::CellRays cells(s, in, p.real("trust"), in.costs.plane, k_step);
             trees[i] = std::make_unique<KdTree>(s, "kd-design", prune(deep_data[i], cells), p.flag("mailbox"));
             deep_data[i] = KdData{};
         });
         trees.push_back(std::move(usual_tree));
         return designing::cheapest_on_sample(std::move(trees), s, in);
     },
     kLargeScene}};  // kd-sah's O(N log^2 N) planes, each judged on the sample: 19 s for a million triangles

}  // namespace
}  // namespace rtcost::kd
