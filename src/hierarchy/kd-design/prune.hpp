#pragma once
// kd-design's judge of a built tree: bottom up, each subtree against one leaf of its references,
// by the cost model with the design sample's visit probabilities. The split test a tree is
// built with (CellRays::split_pays) looks one level down, so it stops above splits that pay only
// further down; judged with every level below known, a tree built deeper than it needs keeps
// exactly the splits that pay.
#include "../kd/kdtree.hpp"
#include "design/cell_rays.hpp"

namespace rtcost::kd {

/// `tree` with every subtree that the model prices above a leaf of its references made that
/// leaf (each reference once, in id order). For kd-sah's trees: node boxes (kd-median's
/// KdData::boxes) are not carried over.
KdData prune(const KdData& tree, const designing::CellRays& cells);

}  // namespace rtcost::kd
