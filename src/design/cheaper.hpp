#pragma once
// The designed hierarchies' last step: of the tree built with the model's own split test and
// the tree the family's builder makes with its usual termination (the yardstick's), keep the
// one the model predicts cheaper on the design sample. The split test looks one level down, so
// it can stop above splits that pay only further down; the model then prefers the usual tree,
// and a design is never predicted worse than its yardstick on its own sample.
#include <memory>
#include <vector>

#include "replay.hpp"
#include "rtcost/design.hpp"

namespace rtcost::designing {

/// Of `trees`, the one predicted cheapest on the design sample, each priced by its own traversal
/// of the sample with its size's cache misses (SampleReplay::time); a tie keeps the earlier.
template <class H>
std::unique_ptr<Hierarchy> cheapest_on_sample(std::vector<std::unique_ptr<H>> trees, const Scene& s,
                                              const DesignInput& in) {
    const SampleReplay replay(s, in.sample, in.costs);
    std::size_t best = 0;
    double best_cost = kInf;
    for (std::size_t i = 0; i < trees.size(); ++i) {
        const double c = replay.time(*trees[i]);
        if (c < best_cost) best = i, best_cost = c;
    }
    return std::move(trees[best]);
}

}  // namespace rtcost::designing
