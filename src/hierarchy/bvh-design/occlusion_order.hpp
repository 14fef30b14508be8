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
        : HierarchyImpl(s), bvh_(s, "bvh-design", std::move(data), true), order_(std::move(order)) {}

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
        st.bytes += order_.size();
        return st;
    }

private:
    // Counted as the BVH's walk counts: one box for the root, per interior visit interior(depth)
    // and one box per child, per leaf visit leaf(depth, n) and its primitive tests.
    template <class C, class PrimTest>
    bool occlusion(const Ray& ray, Hit& hit, C& counting, PrimTest test) const {
        const BvhData& d = bvh_.data();
        const Node* nodes = d.nodes.data();
        const RayInv ri(ray);
        counting.box();
        if (box_entry(nodes[0].box, ri, ray.tmin, ray.tmax) == kInf) return false;
        // The leaves' tests of bvh-sah's walk: triangle copies in leaf order, one shear per ray.
        const RayShear shear = bvh_.shear_of(ray);
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
                if (bvh_.template test_leaf_of<C, Query::Any>(n, ray, shear, hit, counting, found, test)) return true;
            } else {
                counting.interior(e.depth);
                Entry next[kMaxFanout];
                int nn = 0;
                for (std::uint32_t k = 0; k < n.count; ++k) {
                    counting.box();
                    if (box_entry(nodes[n.index + k].box, ri, ray.tmin, ray.tmax) != kInf)
                        next[nn++] = {n.index + k, e.depth + 1};
                }
                if (nn == 2) {
                    // The byte decoded as any_order_first_child_first does (model_tree.hpp),
                    // spelled out here: the traversal's code stays the one timed in docs/design.md.
                    const std::uint8_t b = order_[e.node];
                    if ((b >> (2 + ri.neg[b & 3])) & 1) std::swap(next[0], next[1]);
                }
                if (nn > 0) {
                    // The first is entered next, the others wait, last to first.
                    for (int i = nn - 1; i > 0; --i) stack[sp++] = next[i];
                    if (nn > 1) bvh_.prefetch_node(next[1].node);
                    e = next[0];
                    continue;
                }
            }
            if (sp == 0) return false;
            e = stack[--sp];
        }
    }

    Bvh bvh_;
    std::vector<std::uint8_t> order_;
};

}  // namespace rtcost::bvh
