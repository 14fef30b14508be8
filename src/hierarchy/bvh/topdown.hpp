#pragma once
// Top-down binary construction shared by the median and SAH builders: a node over a range of
// primitive ids either becomes a leaf or is split in two by a policy that partitions the range.

#include "bvh.hpp"

namespace rtcost::bvh {

/// `split(ids, begin, end, box, depth)` partitions ids[begin, end) and returns the first index of
/// the right part, or `begin` (or `end`) to make the node a leaf.
template <class Split>
BvhData build_topdown(const Scene& s, const PrimInfo& info, Split&& split) {
    BvhData d;
    d.refs.resize(s.size());
    for (std::uint32_t i = 0; i < s.size(); ++i) d.refs[i] = i;
    d.nodes.reserve(2 * s.size() + 1);
    d.nodes.emplace_back();
    auto recurse = [&](auto&& self, std::uint32_t node, std::uint32_t begin, std::uint32_t end, int depth) -> void {
        Box3 box;
        for (std::uint32_t i = begin; i < end; ++i) box.extend(info.bounds[d.refs[i]]);
        d.nodes[node].box = box;
        std::uint32_t mid = begin;
        if (end - begin > 1) mid = split(d.refs, begin, end, box, depth);
        if (mid <= begin || mid >= end) {
            d.nodes[node].index = begin;
            d.nodes[node].count = end - begin;
            d.nodes[node].leaf = 1;
            return;
        }
        auto left = static_cast<std::uint32_t>(d.nodes.size());
        d.nodes.emplace_back();
        d.nodes.emplace_back();
        d.nodes[node].index = left;
        d.nodes[node].count = 2;
        d.nodes[node].leaf = 0;
        self(self, left, begin, mid, depth + 1);
        self(self, left + 1, mid, end, depth + 1);
    };
    recurse(recurse, 0, 0, static_cast<std::uint32_t>(s.size()), 0);
    d.nodes.shrink_to_fit();
    return d;
}

}  // namespace rtcost::bvh
