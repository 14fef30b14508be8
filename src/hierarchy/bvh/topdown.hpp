#pragma once
// Top-down binary construction shared by the median and SAH builders: a node over a range of
// primitive ids either becomes a leaf or is split in two by a policy that partitions the range.

#include "bvh.hpp"

namespace rtcost::bvh {

/// The node structure of a top-down build over `n` primitives in some builder-owned order:
/// `bounds(begin, end)` gives the box of the primitives [begin, end) and `split(begin, end, box,
/// depth)` partitions them and returns the first index of the right part, or `begin` (or `end`)
/// to make the node a leaf. Nodes are numbered depth first, children side by side. `refs` is
/// left empty: the builder knows its order.
template <class Bounds, class Split>
BvhData build_nodes(std::uint32_t n, Bounds&& bounds, Split&& split) {
    BvhData d;
    d.nodes.reserve(2 * std::size_t(n) + 1);
    d.nodes.emplace_back();
    auto recurse = [&](auto&& self, std::uint32_t node, std::uint32_t begin, std::uint32_t end, int depth) -> void {
        const Box3 box = bounds(begin, end);
        d.nodes[node].box = box;
        std::uint32_t mid = begin;
        if (end - begin > 1) mid = split(begin, end, box, depth);
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
    recurse(recurse, 0, 0, n, 0);
    d.nodes.shrink_to_fit();
    return d;
}

/// build_nodes over primitive ids (BvhData::refs), the boxes read from `info`:
/// `split(ids, begin, end, box, depth)` partitions ids[begin, end).
template <class Split>
BvhData build_topdown(const Scene& s, const PrimInfo& info, Split&& split) {
    std::vector<std::uint32_t> ids(s.size());
    for (std::uint32_t i = 0; i < s.size(); ++i) ids[i] = i;
    BvhData d = build_nodes(
        static_cast<std::uint32_t>(s.size()),
        [&](std::uint32_t begin, std::uint32_t end) {
            Box3 box;
            for (std::uint32_t i = begin; i < end; ++i) box.extend(info.bounds[ids[i]]);
            return box;
        },
        [&](std::uint32_t begin, std::uint32_t end, const Box3& box, int depth) { return split(ids, begin, end, box, depth); });
    d.refs = std::move(ids);
    return d;
}

}  // namespace rtcost::bvh
