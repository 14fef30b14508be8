#pragma once
// The designed hierarchies' last step: of the tree built with the model's own split test and
// the tree the family's builder makes with its usual termination (the yardstick's), keep the
// one the model predicts cheaper on the design sample. The split test looks one level down, so
// it can stop above splits that pay only further down; the model then prefers the usual tree,
// and a design is never predicted worse than its yardstick on its own sample.
#include <memory>
#include <vector>

#include "rtcost/design.hpp"

namespace rtcost::designing {

/// Of `trees`, the one the model predicts cheapest on the design sample; a tie keeps the earlier.
inline std::unique_ptr<Hierarchy> cheapest_on_sample(std::vector<std::unique_ptr<Hierarchy>> trees, const Scene& s,
                                                     const DesignInput& in) {
    std::size_t best = 0;
    double best_cost = kInf;
    for (std::size_t i = 0; i < trees.size(); ++i) {
        const double c = sample_cost(*trees[i], s, in.sample, in.costs);
        if (c < best_cost) best = i, best_cost = c;
    }
    return std::move(trees[best]);
}

inline std::unique_ptr<Hierarchy> cheaper_on_sample(std::unique_ptr<Hierarchy> designed, std::unique_ptr<Hierarchy> usual,
                                                    const Scene& s, const DesignInput& in) {
    std::vector<std::unique_ptr<Hierarchy>> trees;
    trees.push_back(std::move(designed));
    trees.push_back(std::move(usual));
    return cheapest_on_sample(std::move(trees), s, in);
}

}  // namespace rtcost::designing
