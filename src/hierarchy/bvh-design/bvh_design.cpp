// `bvh-design`: a binned BVH builder whose split cost takes each child's visit probability from
// the design sample (the share of the node's sample segments, clipped where each ray's search
// ends, that meet the child's box), blended with the surface-area ratio where few segments reach
// the node, among the surface area's 32 cheapest splits (or, with candidates=auto, 8, 16 or 32 of
// them: the count that designs the cheapest tree on half the sample when designed on the other
// half); a node stays a leaf
// where no split pays; and the order in which occlusion rays enter
// a node's children: front to back, leaf children first or as stored, whichever the model predicts
// cheapest on the sample (or, with occlusion=sample, an order per node and direction priced on the
// sample, on the designed tree or on bvh-sah's; of those trees with their orders or in stored order,
// whichever its own walk prices cheapest on the sample: occlusion_order.hpp).
// Otherwise traversed as every BVH (../bvh/bvh.hpp).
#include <algorithm>
#include <optional>

#include <oneapi/tbb/parallel_for.h>

#include "../bvh/topdown.hpp"
#include "boxes_met.hpp"
#include "design/replay.hpp"
#include "occlusion_order.hpp"
#include "split_candidates.hpp"
#include "rtcost/design.hpp"

namespace rtcost::bvh {
namespace {

/// A trust at or above this: no sample weight at all.
constexpr double kNoTrust = 1e30;

struct DesignOptions {
    int max_prims = 32;   ///< a larger node is always split
    int max_depth = 64;
    int bins = 16;
    int candidates = 32;  ///< SAH-cheapest splits re-weighed with the sample (0: chosen on held-out rays)
    int sweep = 2;        ///< and this many SAH-cheapest of every split of the centroid-sorted primitives
    double trust = 32;    ///< sample segments at which the sample and the surface area weigh alike
};


/// The root's centroid orders of the sweep (AxisOrders), sorted once for a design's several builds.
std::optional<AxisOrders> root_orders(const Scene& s, const DesignOptions& o, const PrimInfo& info) {
    if (o.sweep <= 0 || o.trust >= kNoTrust) return std::nullopt;
    std::vector<std::uint32_t> all(s.size());
    for (std::uint32_t i = 0; i < s.size(); ++i) all[i] = i;
    return AxisOrders(all, info);
}

/// `info`: the scene's PrimInfo; `root`: root_orders(s, o, info). (Both made once for a design's
/// several builds.)
BvhData build_design(const Scene& s, const DesignInput& in, const DesignOptions& o, const PrimInfo& info,
                     const std::optional<AxisOrders>& root) {
    const RaySample& smp = in.sample;
    // Each sample ray's segment: from tmin to where its search ends.
    std::vector<Segment> segments;
    segments.reserve(smp.size());
    for (std::size_t i = 0; i < smp.size(); ++i) {
        const Ray& ray = smp.rays.rays[i];
        segments.emplace_back(RayInv(ray), ray.tmin, std::min(ray.tmax, smp.t_end[i]));
    }
    // Mean cost of a primitive test and of a binary node's visit (a step and two box tests), in the
    // costs' units.
    double prim_cost = 0;
    for (std::uint32_t i = 0; i < s.size(); ++i)  // with every edge a polygon's test may walk
        prim_cost += in.costs.prim[static_cast<int>(s.kind(i))] + in.costs.polygon_edge * s.edges_walked(i);
    prim_cost = s.size() ? prim_cost / s.size() : 1;
    const double trav_cost = in.costs.step + 2 * in.costs.box;

    // The sample segments reaching each node. A node is split before its subtrees are built, and
    // the left child's subtree is done before the right one's: a split at depth d leaves its
    // children's lists in slot d + 1, each tagged with the child's first primitive, and nothing
    // deeper overwrites them before the child is split (a map keyed by the first primitive, and
    // two new lists per node, were a tenth of the design time).
    struct Reaching {
        std::uint32_t begin[2] = {0, 0};
        std::vector<std::uint32_t> rays[2];
    };
    std::vector<Reaching> reaching(static_cast<std::size_t>(o.max_depth) + 2);
    {
        const Box3 root_box[1] = {s.bounds()};
        BoxColumns root;
        root.assign(root_box);
        for (std::uint32_t r = 0; r < smp.size(); ++r)
            root.each_met(segments[r], [&](std::size_t) { reaching[0].rays[0].push_back(r); });
    }
    // Reused from node to node: the candidates' boxes and how many segments meet each.
    std::vector<Box3> boxes;
    BoxColumns columns;
    std::vector<std::uint32_t> met;
    CutScratch scratch;
    std::vector<Cut> cuts;
    // The sweep's centroid orders, kept only where a sample weighs the cuts.
    std::optional<AxisOrders> orders = root;
    std::vector<std::uint32_t> ids(s.size());
    for (std::uint32_t i = 0; i < s.size(); ++i) ids[i] = i;
    Box3 cb;  // the centroids' box of the node whose bounds came last: the node split next
    auto bounds = [&](std::uint32_t begin, std::uint32_t end) {
        Box3 box;
        cb = Box3{};
        for (std::uint32_t i = begin; i < end; ++i) box.extend(info.bounds[ids[i]]), cb.extend(info.centroids[ids[i]]);
        return box;
    };
    BvhData data = build_nodes(static_cast<std::uint32_t>(s.size()), bounds, [&](std::uint32_t begin, std::uint32_t end,
                                                                                 const Box3& box, int depth) -> std::uint32_t {
        Reaching& slot = reaching[static_cast<std::size_t>(depth)];
        std::vector<std::uint32_t>& rays = slot.rays[slot.begin[0] == begin ? 0 : 1];
        const std::uint32_t n = end - begin;
        if (depth >= o.max_depth) return begin;
        const double area = box.area();
        const double m = static_cast<double>(rays.size());
        // trust >= kNoTrust: the surface area alone, computed as bvh-sah computes it (in float, the
        // first cheapest cut), so that the design falls back to the SAH's tree exactly.
        const double w = o.trust >= kNoTrust ? 0 : m / (m + o.trust);
        binned_cuts(ids, begin, end, info, cb, o.bins, w == 0 ? 1 : static_cast<std::size_t>(o.candidates), scratch,
                    cuts);
        // The sweep's too where the sample weighs them; without sample weight the SAH's bins alone,
        // so that the design falls back to its tree exactly.
        if (w > 0 && orders) swept_cuts(*orders, begin, end, info, static_cast<std::size_t>(o.sweep), scratch, cuts);
        // Expected cost below this node, per ray reaching it: a leaf tests every primitive; a split
        // tests both child boxes and each child's primitives as often as the child is entered.
        double best = kInf;
        int chosen = -1;
        const int k = w == 0 ? std::min<int>(1, static_cast<int>(cuts.size())) : static_cast<int>(cuts.size());
        // How many segments meet each candidate's left and right box (met[2c], met[2c + 1]), as
        // box_entry finds them on the segments, every box of a segment at once (boxes_met.hpp).
        // Only the chosen cut's segments are listed, below: listing every candidate's took a fifth
        // of the design time.
        if (w > 0) {
            boxes.clear();
            for (int c = 0; c < k; ++c) boxes.insert(boxes.end(), {cuts[c].left, cuts[c].right});
            columns.assign(boxes);
            met.assign(columns.padded(), 0);
            columns.count_met(rays, segments.data(), met.data());
        }
        for (int c = 0; c < k; ++c) {
            const Cut& cut = cuts[c];
            double pl = area > 0 ? cut.left.area() / area : 1, pr = area > 0 ? cut.right.area() / area : 1;
            if (w > 0) {
                pl = w * (met[2 * c] / m) + (1 - w) * pl;
                pr = w * (met[2 * c + 1] / m) + (1 - w) * pr;
            }
            const double cost =
                w == 0 ? static_cast<double>(static_cast<float>(trav_cost) +
                                             static_cast<float>(prim_cost) * (area > 0 ? cut.sah / static_cast<float>(area) : n))
                       : trav_cost + prim_cost * (pl * cut.n_left + pr * cut.n_right);
            if (cost < best) best = cost, chosen = c;
        }
        const double leaf = w == 0 ? static_cast<double>(static_cast<float>(prim_cost) * n) : prim_cost * n;
        if (static_cast<int>(n) <= o.max_prims && leaf <= best) return begin;
        // The segments reaching each child.
        Reaching& next = reaching[static_cast<std::size_t>(depth) + 1];
        std::vector<std::uint32_t>& best_left = next.rays[0];
        std::vector<std::uint32_t>& best_right = next.rays[1];
        best_left.clear();
        best_right.clear();
        if (w > 0 && chosen >= 0) {
            const Box3 pair[2] = {cuts[chosen].left, cuts[chosen].right};
            columns.assign(pair);
            for (std::uint32_t r : rays)
                columns.each_met(segments[r], [&](std::size_t j) { (j == 0 ? best_left : best_right).push_back(r); });
        }
        std::uint32_t mid;
        if (chosen < 0) {
            // All centroids coincide: halve the list.
            mid = begin + n / 2;
            std::nth_element(ids.begin() + begin, ids.begin() + mid, ids.begin() + end, by_centroid(info, 0));
            best_left = best_right = rays;
        } else if (cuts[chosen].swept) {
            mid = begin + static_cast<std::uint32_t>(cuts[chosen].at);
            const std::span<const std::uint32_t> sorted = orders->of(cuts[chosen].axis, begin, end);
            std::copy(sorted.begin(), sorted.end(), ids.begin() + begin);
        } else {
            const Cut& cut = cuts[chosen];
            const float lo = cb.lo[cut.axis], scale = o.bins / (cb.hi[cut.axis] - lo);
            auto it = std::partition(ids.begin() + begin, ids.begin() + end, [&](std::uint32_t id) {
                const int b = std::min(o.bins - 1, static_cast<int>((info.centroids[id][cut.axis] - lo) * scale));
                return b < cut.at;
            });
            mid = static_cast<std::uint32_t>(it - ids.begin());
        }
        // No sample segment reaches a node below one that none reaches, and such nodes never sweep.
        if (orders && !rays.empty()) orders->split(ids, begin, mid, end);
        next.begin[0] = begin;
        next.begin[1] = mid;
        return mid;
    });
    data.refs = std::move(ids);
    return data;
}

/// Sample rays i with i % 2 == parity (the sample is stratified along the distribution's order, so
/// each half is too).
RaySample half_of(const RaySample& smp, std::size_t parity) {
    RaySample h;
    h.distribution = smp.distribution;
    h.seed = smp.seed;
    h.first.push_back(0);
    for (std::size_t i = parity; i < smp.size(); i += 2) {
        h.rays.rays.push_back(smp.rays.rays[i]);
        h.rays.kinds.push_back(smp.rays.kinds[i]);
        h.queries.push_back(smp.queries[i]);
        h.t_end.push_back(smp.t_end[i]);
        const std::span<const Crossing> c = smp.crossings_of(i);
        h.crossings.insert(h.crossings.end(), c.begin(), c.end());
        h.first.push_back(static_cast<std::uint32_t>(h.crossings.size()));
    }
    return h;
}

/// How many SAH-cheapest splits each node re-weighs with the sample: more let the sample find
/// better splits and fit its own noise (on spd rays, with 16 instead of 8 mount's tree tested 22.7%
/// fewer operations than bvh-sah's instead of 16.4%, teapot's 9.7% instead of 15.9%; with 32,
/// lattice's shadow rays 22.1% instead of 13.5%). Each count is designed on half the sample
/// and priced on the other half; the cheapest there is kept. (Three more builds, each on a core
/// of its own where there are cores.)
int held_out_candidates(const Scene& s, const DesignInput& in, const DesignOptions& o, const PrimInfo& info,
                        const std::optional<AxisOrders>& root) {
    static constexpr int kCounts[] = {8, 16, 32};
    DesignInput half;
    half.costs = in.costs;
    half.sample = half_of(in.sample, 0);
    const RaySample other = half_of(in.sample, 1);
    const designing::SampleReplay replay(s, other, in.costs);
    double cost[std::size(kCounts)];
    tbb::parallel_for(std::size_t{0}, std::size(kCounts), [&](std::size_t i) {
        DesignOptions with = o;
        with.candidates = kCounts[i];
        const Bvh h(s, "bvh-design", build_design(s, half, with, info, root), true);
        cost[i] = replay.time(h);
    });
    std::size_t best = 0;  // a tie keeps the fewer
    for (std::size_t i = 1; i < std::size(kCounts); ++i)
        if (cost[i] < cost[best]) best = i;
    return kCounts[best];
}

const Registration reg{
    {"bvh-design",
     "binned BVH whose splits minimise the cost model with visit probabilities from a sample of the given rays",
     [] {
         std::vector<ParamSpec> p = design_param_specs("typical-bvh");
         p.push_back(ParamSpec::integer("max_prims", "32", 1, 1 << 20, "largest leaf (bigger nodes are always split)"));
         p.push_back(ParamSpec::integer("max_depth", "64", 0, kMaxDepth, "deepest leaf"));
         p.push_back(ParamSpec::integer("bins", "16", 2, 256, "bins per axis"));
         p.push_back(ParamSpec::integer("sweep", "2", 0, 3 * 256,
                                        "and the surface-area-cheapest splits of a sweep over the centroid-sorted "
                                        "primitives weighed again with the sample"));
         // 32 by default: auto's three more builds doubled the design time (within 10x bvh-sah's
         // build on 1 of docs/design.md's 60 bvh rows, against 40 of 60 with 32) for 0.4 point
         // more gain in operations on average (8.8% against 8.3% over those rows, 2026-12-08).
         p.push_back(ParamSpec::integer("candidates", "32", 1, 3 * 256,
                                        "surface-area-cheapest splits weighed again with the sample; auto: 8, 16 "
                                        "or 32, whichever designs the tree cheapest on half the sample when "
                                        "designed on the other half (three more builds)",
                                        {"auto"}));
         p.push_back(ParamSpec::choice(
             "occlusion", "auto", {"auto", "near", "leaves", "stored", "sample"},
             "order in which occlusion rays enter a node's children: near (front to back), leaves (leaf children "
             "first, then front to back), stored (first child first, unsorted: bvh-sah's default), auto (of near, "
             "leaves and stored, the one the model predicts cheapest on the sample), or sample (by node and by the "
             "way the ray crosses it, the child whose order makes the subtree cheapest for the sample first; of the "
             "designed tree and bvh-sah's, each with those orders or stored, whichever its walk prices cheapest "
             "on the sample, the orders' walk priced 15% dearer)"));
         p.push_back(ParamSpec::real("trust", "32", 0, 1e30,
                                     "sample segments at a node at which sample and surface area weigh alike "
                                     "(large: the surface area heuristic)"));
         return p;
     }(),
     [](const Scene& s, const Params& p) -> std::unique_ptr<Hierarchy> {
         DesignOptions o;
         o.max_prims = static_cast<int>(p.integer("max_prims"));
         o.max_depth = static_cast<int>(p.integer("max_depth"));
         o.bins = static_cast<int>(p.integer("bins"));
         o.sweep = static_cast<int>(p.integer("sweep"));
         o.candidates = p.is("candidates", "auto") ? 0 : static_cast<int>(p.integer("candidates"));
         o.trust = p.real("trust");
         DesignInput in = draw_design_input(s, p);
         if (p.is("costs", "typical-bvh") && large_triangle_mesh(s)) {
             // Such a mesh's leaves are tested four triangles at a time (bvh-sah's leaf costs,
             // sah_builder.cpp), and the built-in table was fitted where a leaf's triangles were
             // tested one by one: a triangle priced at a quarter of its test. (At the table's
             // price, yxa_1's tree for spd rays had 56,327 leaves against bvh-sah's 16-triangle
             // ones; at a quarter, 21,949.)
             in.costs.prim[static_cast<int>(PrimKind::Triangle)] /= 4;
             in.costs.prim[static_cast<int>(PrimKind::Polygon)] /= 4;
         }
         const PrimInfo info(s);
         const std::optional<AxisOrders> root = root_orders(s, o, info);
         if (o.candidates == 0) o.candidates = o.trust < kNoTrust ? held_out_candidates(s, in, o, info, root) : 8;
         BvhData designed_tree = build_design(s, in, o, info, root);
         // bvh-sah's tree where the model predicts it cheaper on the sample than the designed
         // splits (as design/cheaper.hpp does for the other families).
         const SahOptions sah_defaults = sah_leaf_costs(s);
         SahOptions usual = sah_defaults;
         usual.max_depth = o.max_depth;
         usual.bins = o.bins;
         // With bvh-sah's defaults that tree is the sample's reference, already built.
         const auto* reference = dynamic_cast<const Bvh*>(in.reference.get());
         const bool as_reference = reference && usual.max_depth == sah_defaults.max_depth && usual.bins == sah_defaults.bins;
         auto by_sah = std::make_unique<Bvh>(s, "bvh-design", as_reference ? reference->data() : build_sah(s, usual), true);
         const bool any_query =
             std::find(in.sample.queries.begin(), in.sample.queries.end(), Query::Any) != in.sample.queries.end();
         // Without occlusion rays an order for them has nothing to gain: the plain BVH, which
         // takes no order bytes. (It was timed 3% faster than DesignedBvh on the same tree on
         // sombrero's camera rays; the same bvh-sah tree moves that much with where its data
         // land in memory, docs/design.md.)
         if (!p.is("occlusion", "sample") || !any_query) {
             auto designed = std::make_unique<Bvh>(s, "bvh-design", std::move(designed_tree), true);
             // Each tree in the order asked for, or in the order the model predicts cheapest on
             // the sample (only its occlusion rays can tell them apart).
             enum class Order { Near, Leaves, Stored };
             auto tried = [&](Order o) {
                 if (p.is("occlusion", "leaves")) return o == Order::Leaves;
                 if (p.is("occlusion", "stored")) return o == Order::Stored;
                 // near, and sample without occlusion rays: front to back alone.
                 return o == Order::Near || (p.is("occlusion", "auto") && any_query);
             };
             auto set_order = [](Bvh& h, Order o) {
                 h.set_occlusion_order(o == Order::Leaves   ? OcclusionOrder::LeavesFirst
                                       : o == Order::Stored ? OcclusionOrder::Stored
                                                            : OcclusionOrder::AsClosest);
             };
             struct Choice {
                 Bvh* h;
                 Order order;
                 double cost;
             } best{nullptr, Order::Near, 0};
             // Each priced by its own traversal of the sample (design/replay.hpp): the model's
             // prediction without materialising the trees' model trees.
             const designing::SampleReplay replay(s, in.sample, in.costs);
             using Rays = designing::SampleReplay::Rays;
             for (Bvh* h : {designed.get(), by_sah.get()}) {  // a tie keeps the designed splits
                 // The other rays go the same way in any order: replayed once.
                 const RayCounters others = replay.counters(*h, Rays::Others);
                 for (Order o : {Order::Near, Order::Leaves, Order::Stored}) {
                     if (!tried(o)) continue;
                     set_order(*h, o);
                     RayCounters whole = others;
                     whole += replay.counters(*h, Rays::Occlusion);
                     const double c = replay.time(*h, whole);
                     if (!best.h || c < best.cost) best = {h, o, c};
                 }
             }
             set_order(*best.h, best.order);
             if (best.h == designed.get()) return designed;
             return by_sah;
         }
         // Each tree walked as bvh-sah walks it (occlusion rays in stored order) or with its order
         // bytes, the cheapest by its own traversal of the sample; a tie keeps the designed splits,
         // then the stored walk.
         by_sah->set_occlusion_order(OcclusionOrder::Stored);
         const designing::SampleReplay replay(s, in.sample, in.costs);
         std::vector<std::uint8_t> sah_order = occlusion_bits(by_sah->data(), s, in.sample);
         price_occlusion_bits(by_sah->data(), s, in.sample, in.costs, sah_order);
         auto sah_ordered = std::make_unique<DesignedBvh>(s, by_sah->data(), std::move(sah_order));
         std::vector<std::uint8_t> designed_order = occlusion_bits(designed_tree, s, in.sample);
         price_occlusion_bits(designed_tree, s, in.sample, in.costs, designed_order);
         auto designed_stored = std::make_unique<Bvh>(s, "bvh-design", designed_tree, true);
         designed_stored->set_occlusion_order(OcclusionOrder::Stored);
         auto designed_ordered = std::make_unique<DesignedBvh>(s, std::move(designed_tree), std::move(designed_order));
         // A tree takes its other rays alike with its order bytes or without (DesignedBvh orders
         // occlusion rays only): replayed once.
         using Rays = designing::SampleReplay::Rays;
         const RayCounters sah_others = replay.counters(*by_sah, Rays::Others),
                           designed_others = replay.counters(*designed_stored, Rays::Others);
         auto stored_time = [&](const Bvh& h, RayCounters whole) {
             whole += replay.counters(h, Rays::Occlusion);
             return replay.time(h, whole);
         };
         // The order bytes' walk decides at every node which child goes first, a branch the
         // stored walk does not take: on rows of docs/design.md whose trees test as many
         // operations either way (2026-12-06), it took 14-19% more ns per operation (tetra ao 190
         // against 161 ns per ray, rings ao 309 against 266, tree ao 106 against 93, sombrero ao
         // 243 against 211). Its occlusion rays' operations are priced that much dearer.
         constexpr double kOrderedWalkPremium = 1.15;
         auto ordered_time = [&](const DesignedBvh& h, RayCounters whole) {
             const RayCounters occlusion = replay.counters(h, Rays::Occlusion);
             whole += occlusion;
             return replay.time(h, whole) +
                    (kOrderedWalkPremium - 1) * (replay.time(h, occlusion) - replay.time(h, RayCounters{}));
         };
         const double c_designed_stored = stored_time(*designed_stored, designed_others),
                      c_designed = ordered_time(*designed_ordered, designed_others),
                      c_sah_ordered = ordered_time(*sah_ordered, sah_others), c_sah = stored_time(*by_sah, sah_others);
         const double best = std::min({c_designed_stored, c_designed, c_sah_ordered, c_sah});
         if (c_designed_stored == best) return designed_stored;
         if (c_designed == best) return designed_ordered;
         if (c_sah_ordered == best) return sah_ordered;
         return by_sah;
     }}};

}  // namespace
}  // namespace rtcost::bvh
