#pragma once
// Which cells of a space subdivision a design sample reaches, so that a tree built only to be
// predicted on that sample (the yardstick's, to compare a design with) is built only there.

#include <cstdint>
#include <vector>

#include "../model/model_internal.hpp"
#include "rtcost/sample.hpp"

namespace rtcost::designing {

/// Whether some segment of the sample meets a cell, each segment taken as far as the segments
/// estimator can follow it (as reached_model_tree takes it: a culling closest-hit search to just
/// past its nearest crossing, any other to tmax), the cell grown by a hair so that rounding
/// never calls a reached cell unreached. Asked depth first (a cell after its parent, the root
/// at depth 0): each cell's segments are found among its parent's.
class SampleReach {
public:
    explicit SampleReach(const RaySample& sample, const Box3& root);
    bool operator()(const Box3& cell, int depth);

private:
    const RaySample& sample_;
    model::ReplaySegments seg_;
    float grow_;
    std::vector<std::vector<std::uint32_t>> by_depth_;  // the segments reaching the last cell at each depth
};

}  // namespace rtcost::designing
