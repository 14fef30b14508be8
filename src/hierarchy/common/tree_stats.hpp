#pragma once
// Structural statistics of a tree stored as one array, shared by the hierarchies so stored.

#include <algorithm>
#include <vector>

#include "rtcost/stats.hpp"

namespace rtcost {

/// Leaves, empty leaves, references, interior nodes and depth of a tree stored as an array in
/// which the root comes first and a node's `fanout(n)` children follow it, contiguous from
/// `n.index`; a leaf (`is_leaf(n)`) holds `n.count` references. `bytes` is left to the caller.
template <class Nodes, class IsLeaf, class Fanout>
StructureStats tree_structure(const Nodes& nodes, IsLeaf is_leaf, Fanout fanout) {
    StructureStats s;
    std::vector<int> depth(nodes.size(), 0);  // children are stored after their parent
    for (std::size_t i = 0; i < nodes.size(); ++i) {
        const auto& n = nodes[i];
        if (is_leaf(n)) {
            ++s.leaves;
            s.empty_leaves += n.count == 0;
            s.references += n.count;
            s.depth = std::max(s.depth, depth[i]);
        } else {
            ++s.interior;
            for (std::uint32_t k = 0; k < fanout(n); ++k) depth[n.index + k] = depth[i] + 1;
        }
    }
    return s;
}

}  // namespace rtcost
