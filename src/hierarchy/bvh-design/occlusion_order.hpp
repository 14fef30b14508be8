#pragma once
// bvh-design's hierarchy: the BVH's nodes and traversal for closest-hit and all-hits queries,
// and for occlusion (any-hit) queries a walk that enters first, at each node, the child whose
// order the design sample prices cheaper (an order byte per node, by the sign of the ray's
// direction on the node's axis): an any-hit query needs no hit nearer than another, only one
// soon.

#include <vector>

#include "../bvh/bvh.hpp"
#include "rtcost/model.hpp"
#include "rtcost/sample.hpp"

namespace rtcost::bvh {

/// The order bytes of any binary BVH `d` over `s` (DesignedBvh's order) from `sample`'s
/// occlusion rays: at each binary node, for the rays going each way along the node's axis (the one
/// its children's centres lie furthest apart on), the child entered first is the one more of those
/// that reach it (their segments clipped where their search ends) end in, per primitive below it;
/// by all the node's rays where none going that way ends below it.
/// Byte: the axis (bits 0-1), second child first for a positive direction (bit 2), for a
/// negative one (bit 3).
std::vector<std::uint8_t> occlusion_bits(const BvhData& d, const Scene& s, const RaySample& sample);

/// Refines order bytes `bits` (occlusion_bits') on `sample`: each binary node's bit for each
/// direction sign becomes the order whose walk of the sample's occlusion rays costs least under
/// `costs`, the nodes below decided first (occlusion_priced.cpp).
void price_occlusion_bits(const BvhData& d, const Scene& s, const RaySample& sample, const UnitCosts& costs,
                          std::vector<std::uint8_t>& bits);

class DesignedBvh final : public HierarchyImpl<DesignedBvh> {
public:
    /// `order[i]`: interior node i's order byte (occlusion_bits).
    DesignedBvh(const Scene& s, BvhData data, std::vector<std::uint8_t> order)
        : HierarchyImpl(s), bvh_(s, "bvh-design", std::move(data), true), order_(std::move(order)),
          nodes_(bvh_.walk_nodes()) {
        for (std::size_t i = 0; i < nodes_.size(); ++i)
            if (!nodes_[i].leaf && nodes_[i].count == 2) nodes_[i].count = 2u | std::uint32_t{order_[i]} << kOrderShift;
    }

    std::string_view name() const override { return "bvh-design"; }
    /// The BVH's model tree with the order bytes on its nodes (ModelNode::any_order): the model
    /// orders occlusion rays as this walk does, so that its replay is the model's prediction.
    bool emit_model(ModelSink& sink) const override { return bvh_.emit_model_ordered(sink, order_); }

    template <class C, Query Q>
    bool trace(const Ray& ray, Hit& hit, C& counting) const {
        return trace_with<C, Q>(ray, hit, counting, RealPrimTest{scene()});
    }

    /// The traversal with the caller's primitive test (design/replay.hpp prices it on a sample).
    template <class C, Query Q, class PrimTest>
    bool trace_with(const Ray& ray, Hit& hit, C& counting, PrimTest test) const {
        if constexpr (Q == Query::Any) return occlusion(ray, hit, counting, test);
        else return bvh_.template trace_with<C, Q>(ray, hit, counting, test);
    }

protected:
    StructureStats compute_structure() const override {
        StructureStats st = bvh_.structure();
        st.bytes += order_.size() + nodes_.size() * sizeof(Node);
        return st;
    }

private:
    // Counted as the BVH's walk counts: one box for the root, per interior visit interior(depth)
    // and one box per child, per leaf visit leaf(depth, n) and its primitive tests.
    template <class C, class PrimTest>
    bool occlusion(const Ray& ray, Hit& hit, C& counting, PrimTest test) const {
        const Node* nodes = nodes_.data();
        const RayInv ri(ray);
        const PairRay pair_ray(ri);
        // The direction's signs in one register, for decoding the nodes' orders.
        const std::uint32_t neg_bits = static_cast<std::uint32_t>(ri.neg[0] | ri.neg[1] << 1 | ri.neg[2] << 2);
        counting.box();
        if (box_entry(nodes[0].box, ri, ray.tmin, ray.tmax) == kInf) return false;
        // The leaves' tests of bvh-sah's walk: triangle copies in leaf order, one shear per ray,
        // made at the first leaf.
        RayShear shear;
        bool sheared = false;
        bool found = false;
        struct Entry {
            std::uint32_t node;
            int depth;
        };
        Entry stack[kMaxDepth * (kMaxFanout - 1) + 2];
        int sp = 0;
        Entry e{0, 0};
        for (;;) {
            const Node& n = nodes[e.node];
            if (n.leaf) {
                counting.leaf(e.depth, n.count);
                if (!sheared) shear = bvh_.shear_of(ray), sheared = true;
                if (bvh_.template test_leaf_of<C, Query::Any>(n, ray, shear, hit, counting, found, test)) return true;
            } else {
                counting.interior(e.depth);
                if ((n.count & ((1u << kOrderShift) - 1)) == 2) {
                    // A binary node: the child its order enters first is visited next, the other
                    // waits on the stack, as in the BVH's own walk. Both boxes are tested before
                    // the order is decoded, so that neither test waits for it.
                    counting.box();
                    counting.box();
                    float ta, tb;
                    pair_entry(nodes[n.index].box, nodes[n.index + 1].box, pair_ray, ray.tmin, ray.tmax, ta, tb);
                    // The byte decoded as any_order_first_child_first does (model_tree.hpp),
                    // from the packed count and the signs held in neg_bits (the walk timed in
                    // docs/design.md on 2026-12-06).
                    const std::uint32_t b = n.count >> kOrderShift;
                    const std::uint32_t second = (b >> (2 + ((neg_bits >> (b & 3)) & 1))) & 1;
                    std::uint32_t first_child = n.index, other = n.index + 1;
                    float tf = ta, to = tb;
                    if (second) std::swap(first_child, other), std::swap(tf, to);
                    if (tf != kInf) {
                        if (to != kInf) {
                            stack[sp++] = {other, e.depth + 1};
                            prefetch(nodes[other]);
                        }
                        e = {first_child, e.depth + 1};
                        continue;
                    }
                    if (to != kInf) {
                        e = {other, e.depth + 1};
                        continue;
                    }
                } else {
                    Entry next[kMaxFanout];
                    int nn = 0;
                    for (std::uint32_t k = 0; k < n.count; ++k) {
                        counting.box();
                        if (box_entry(nodes[n.index + k].box, ri, ray.tmin, ray.tmax) != kInf)
                            next[nn++] = {n.index + k, e.depth + 1};
                    }
                    if (nn > 0) {
                        // The first is entered next, the others wait, last to first.
                        for (int i = nn - 1; i > 0; --i) stack[sp++] = next[i];
                        if (nn > 1) prefetch(nodes[next[1].node]);
                        e = next[0];
                        continue;
                    }
                }
            }
            if (sp == 0) return false;
            e = stack[--sp];
        }
    }

    /// What a visit of `n` reads first, fetched ahead: its children, or its leaf's primitives.
    void prefetch(const Node& n) const {
        if (n.leaf) bvh_.prefetch_prims(n.index);
        else __builtin_prefetch(nodes_.data() + n.index);
    }

    /// Where a binary interior node's order byte sits in its `count` in nodes_.
    static constexpr int kOrderShift = 8;

    Bvh bvh_;
    std::vector<std::uint8_t> order_;
    /// bvh_'s walk nodes, each binary interior node's order byte in its `count` from bit kOrderShift:
    /// the walk reads the order with the node. (Read from order_, a load apart whose result the
    /// next step waited for, the walk took 8-10% longer per ray on the same operations, and its
    /// gain over bvh-sah's walk on shadow rays was 1-14 points smaller: lattice 13.8% against 28.3%,
    /// rings 21.1% against 27.4%.)
    NodeArray nodes_;
};

}  // namespace rtcost::bvh
