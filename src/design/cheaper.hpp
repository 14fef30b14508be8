#pragma once
// The designed hierarchies' last step: of the tree built with the model's own split test and
// the tree the family's builder makes with its usual termination (the yardstick's), keep the
// one the model predicts cheaper on the design sample. The split test looks one level down, so
// it can stop above splits that pay only further down; the model then prefers the usual tree,
// and a design is never predicted worse than its yardstick on its own sample.
#include <memory>

#include "rtcost/design.hpp"

namespace rtcost::designing {

inline std::unique_ptr<Hierarchy> cheaper_on_sample(std::unique_ptr<Hierarchy> designed, std::unique_ptr<Hierarchy> usual,
                                                    const Scene& s, const DesignInput& in) {
    const double by_test = sample_cost(*designed, s, in.sample, in.costs);
    const double by_builder = sample_cost(*usual, s, in.sample, in.costs);
    return by_builder < by_test ? std::move(usual) : std::move(designed);
}

}  // namespace rtcost::designing
