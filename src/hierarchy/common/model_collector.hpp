#pragma once
// Materialising an emitted model tree (Hierarchy::model_tree, and the segments estimator's
// reached tree): library-internal.
#include <cstdint>
#include <span>
#include <stdexcept>
#include <vector>

#include "rtcost/hierarchy.hpp"

namespace rtcost {

/// Materialises a tree emitted depth first (ModelSink): a node's children get contiguous slots
/// when the node arrives, and are filled as their subtrees follow. A derived collector may drop
/// a node's subtree (keep() false): the node then stands for it as a pruned empty leaf
/// (ModelNode::pruned), and the subtree's nodes are read and dropped as they arrive.
class ModelCollector : public ModelSink {
public:
    explicit ModelCollector(ModelTree& t) : t_(t) {}

    bool begin(const ModelFlags& f) override {
        static_cast<ModelFlags&>(t_) = f;
        return true;
    }

    void node(const ModelNode& m, std::span<const std::uint32_t> prims) final { place(m, prims); }

    /// The last node's subtree is dropped: the emitter may leave it out (then it is not waited for).
    bool skip_children() final {
        if (pending_ == 0) return false;
        skip_ -= pending_;
        pending_ = 0;
        return true;
    }

    void beam_node(const ModelNode& m, const ModelBeam& beam, std::span<const std::uint32_t> prims) final {
        const std::uint32_t at = place(m, prims);
        if (at == kDropped) return;
        if (t_.beams.size() < t_.nodes.size()) t_.beams.resize(t_.nodes.size());
        t_.beams[at] = beam;
    }

protected:
    /// Whether the node arriving at `depth` (root 0) keeps its subtree; asked in pre-order.
    virtual bool keep(const ModelNode&, int) { return true; }

    ModelTree& t_;

private:
    static constexpr std::uint32_t kDropped = ~0u;

    // Stores `m` in its slot and returns the slot (kDropped inside a dropped subtree).
    std::uint32_t place(const ModelNode& m, std::span<const std::uint32_t> prims) {
        pending_ = 0;
        if (skip_ > 0) {  // inside a dropped subtree
            --skip_;
            if (!m.leaf) skip_ += pending_ = m.count;
            return kDropped;
        }
        std::uint32_t at = 0;
        int depth = 0;
        if (!t_.nodes.empty()) {
            if (open_.empty()) throw std::logic_error("model tree: a node after the tree was complete");
            Slots& s = open_.back();
            at = s.next++;
            depth = s.depth;
            if (s.next == s.end) open_.pop_back();
        } else {
            t_.nodes.emplace_back();
        }
        const bool kept = keep(m, depth);
        ModelNode& n = t_.nodes[at];
        n = m;
        n.depth = depth;
        n.first = static_cast<std::uint32_t>(t_.prims.size());
        if (!kept) {
            n.leaf = true;
            n.pruned = true;
            n.count = 0;
            if (!m.leaf) skip_ += pending_ = m.count;
        } else if (m.leaf) {
            t_.prims.insert(t_.prims.end(), prims.begin(), prims.end());
        } else {
            n.first = static_cast<std::uint32_t>(t_.nodes.size());
            if (m.count > 0) open_.push_back({n.first, n.first + m.count, depth + 1});
            t_.nodes.resize(t_.nodes.size() + m.count);  // invalidates `n`
        }
        return at;
    }

    struct Slots {
        std::uint32_t next, end;
        int depth;
    };
    std::vector<Slots> open_;
    std::uint64_t skip_ = 0;     // nodes of dropped subtrees still to arrive
    std::uint64_t pending_ = 0;  // children of the last node, when it was dropped (skip_children)
};

}  // namespace rtcost
