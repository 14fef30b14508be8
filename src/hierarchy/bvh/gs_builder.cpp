// bvh-gs: Goldsmith and Salmon's incremental construction (1987). Objects are inserted one at a
// time from the root; at each node the insertion that least increases the hierarchy's
// surface-area cost is taken: add the object as a new child here, merge it with a child (into a
// leaf with room, or under a new node pairing the two), or descend into the child whose growth is
// cheapest. The trees are n-ary, as in the original.
//
// Cost, in units of area (probability of a ray meeting a box is proportional to its area):
// every child box of an interior node N is tested when N is entered (area(N) each), and every
// primitive of a leaf L when L is entered (area(L) each).
#include <fmt/format.h>
#include <stdexcept>

#include "bvh.hpp"
#include "util/rng.hpp"

namespace rtcost::bvh {
namespace {

struct GNode {
    Box3 box;
    bool leaf = true;
    std::vector<std::uint32_t> items;  // children (interior) or primitive ids (leaf)
    int height = 0;                    // levels below this node (0 for a leaf)
};

class GsTree {
public:
    GsTree(const PrimInfo& info, const GsOptions& o) : info_(info), o_(o) {}

    void insert(std::uint32_t id) {
        const Box3& b = info_.bounds[id];
        if (nodes_.empty()) {
            nodes_.push_back({b, true, {id}});
            return;
        }
        std::uint32_t n = 0;
        int depth = 0;
        if (nodes_[0].leaf) {
            if (fits(nodes_[0])) return add_to_leaf(0, id);
            // The root leaf is full: a new root pairs it with the new object.
            GNode old = std::move(nodes_[0]);
            nodes_[0] = GNode{join(old.box, b), false, {}, 1};
            nodes_[0].items = {push(std::move(old)), push({b, true, {id}})};
            return;
        }
        path_.clear();
        for (;;) {
            path_.push_back(n);
            GNode& node = nodes_[n];
            node.box.extend(b);
            enum { kAddChild, kIntoLeaf, kPair, kDescend } what = kAddChild;
            double best = kInf;
            std::uint32_t best_child = 0;
            const double ab = b.area();
            if (static_cast<int>(node.items.size()) < o_.max_children && depth + 1 <= o_.max_depth) {
                best = node.box.area() + ab;  // one more child box, and the new leaf's one test
            }
            for (std::uint32_t c : node.items) {
                const GNode& ch = nodes_[c];
                Box3 grown = join(ch.box, b);
                double g = grown.area();
                if (ch.leaf && fits(ch)) {
                    double cost = g * (ch.items.size() + 1) - ch.box.area() * ch.items.size();
                    if (cost < best) { best = cost; what = kIntoLeaf; best_child = c; }
                }
                // Pairing pushes the child's whole subtree one level down: only where its deepest
                // leaf stays within max_depth (the traversal's stack is sized by that bound).
                if (depth + 2 + ch.height <= o_.max_depth) {
                    double cost = 2 * g + ab;  // new node's two child tests, the new leaf's test
                    if (cost < best) { best = cost; what = kPair; best_child = c; }
                }
                if (!ch.leaf && depth + 1 + ch.height <= o_.max_depth) {
                    // Growth of the child's children tests, plus the least the object can cost below.
                    double cost = (g - ch.box.area()) * ch.items.size() + ab;
                    if (cost < best) { best = cost; what = kDescend; best_child = c; }
                }
            }
            if (best == kInf) {
                // At the depth limit with nowhere to go: the cheapest leaf child grows past max_prims.
                for (std::uint32_t c : node.items) {
                    if (!nodes_[c].leaf) continue;
                    double cost = join(nodes_[c].box, b).area() - nodes_[c].box.area();
                    if (cost < best) { best = cost; what = kIntoLeaf; best_child = c; }
                }
                if (best < kInf) ++overfull_;
            }
            if (best == kInf) {
                // No leaf child either: descend into the cheapest child (its subtree is within the
                // bound, since the tree is), or add one more child here when it is full of subtrees
                // already at the bound.
                for (std::uint32_t c : node.items) {
                    double cost = join(nodes_[c].box, b).area() - nodes_[c].box.area();
                    if (cost < best && depth + 1 < o_.max_depth) { best = cost; what = kDescend; best_child = c; }
                }
                // Unreachable: an interior node below max_depth - 1 has a child to descend into,
                // and one at max_depth - 1 has only leaf children.
                if (best == kInf) throw std::logic_error("bvh-gs: no insertion within max_depth");
            }
            switch (what) {
                case kAddChild: {
                    std::uint32_t leaf = push({b, true, {id}});
                    nodes_[n].items.push_back(leaf);
                    return raise(1);
                }
                case kIntoLeaf: return add_to_leaf(best_child, id);
                case kPair: {
                    // The new node takes the child's slot; the child and the new leaf go under it.
                    GNode old = std::move(nodes_[best_child]);
                    Box3 box = join(old.box, b);
                    const int h = old.height + 1;
                    std::uint32_t moved = push(std::move(old));
                    std::uint32_t leaf = push({b, true, {id}});
                    nodes_[best_child] = GNode{box, false, {moved, leaf}, h};
                    return raise(h + 1);
                }
                case kDescend:
                    n = best_child;
                    ++depth;
                    break;
            }
        }
    }

    /// Breadth-first layout: children contiguous, every child after its parent.
    BvhData flatten() const {
        BvhData d;
        if (nodes_.empty()) {
            d.nodes.push_back(Node{});
            return d;
        }
        d.nodes.reserve(nodes_.size());
        std::vector<std::uint32_t> order{0};
        d.nodes.push_back(Node{});
        for (std::size_t i = 0; i < order.size(); ++i) {
            const GNode& g = nodes_[order[i]];
            Node& out = d.nodes[i];
            out.box = g.box;
            out.leaf = g.leaf;
            out.count = static_cast<std::uint32_t>(g.items.size());
            if (!g.leaf) {
                out.index = static_cast<std::uint32_t>(d.nodes.size());
                for (std::uint32_t c : g.items) {
                    order.push_back(c);
                    d.nodes.push_back(Node{});
                }
            }
        }
        // Leaves' references depth first, as every BVH builder lays them out, so that each
        // subtree holds one contiguous run of them (ModelSink::leaf_order).
        auto place = [&](auto&& self, std::uint32_t i) -> void {
            Node& out = d.nodes[i];
            if (out.leaf) {
                const GNode& g = nodes_[order[i]];
                out.index = static_cast<std::uint32_t>(d.refs.size());
                d.refs.insert(d.refs.end(), g.items.begin(), g.items.end());
                return;
            }
            for (std::uint32_t k = 0; k < out.count; ++k) self(self, out.index + k);
        };
        place(place, 0);
        return d;
    }

private:
    // The nodes on the insertion path (root first) are at least `h` above the changed level.
    void raise(int h) {
        for (std::size_t i = path_.size(); i-- > 0; ++h) {
            if (nodes_[path_[i]].height >= h) break;
            nodes_[path_[i]].height = h;
        }
    }
    bool fits(const GNode& leaf) const { return static_cast<int>(leaf.items.size()) < o_.max_prims; }
    void add_to_leaf(std::uint32_t leaf, std::uint32_t id) {
        nodes_[leaf].items.push_back(id);
        nodes_[leaf].box.extend(info_.bounds[id]);
    }
    std::uint32_t push(GNode n) {
        nodes_.push_back(std::move(n));
        return static_cast<std::uint32_t>(nodes_.size() - 1);
    }

public:
    /// Insertions that the depth bound pushed into a leaf already holding max_prims.
    std::size_t overfull() const { return overfull_; }

private:
    const PrimInfo& info_;
    const GsOptions& o_;
    std::size_t overfull_ = 0;
    std::vector<GNode> nodes_;
    std::vector<std::uint32_t> path_;
};

}  // namespace

BvhData build_gs(const Scene& s, const GsOptions& o) {
    PrimInfo info(s);
    std::vector<std::uint32_t> order(s.size());
    for (std::uint32_t i = 0; i < s.size(); ++i) order[i] = i;
    if (o.seed != 0) {
        Rng rng(o.seed);
        shuffle(order, rng);
    }
    GsTree tree(info, o);
    for (std::uint32_t id : order) tree.insert(id);
    BvhData d = tree.flatten();
    if (tree.overfull() > 0)
        d.limits.push_back(fmt::format("bvh-gs: max_depth {} reached: {} of {} primitives went into leaves already "
                                       "holding max_prims ({}); {}",
                                       o.max_depth, tree.overfull(), s.size(), o.max_prims,
                                       o.seed == 0 ? "the file's order degenerates here, shuffle it with --set seed=1"
                                                   : "raise max_prims or max_depth"));
    return d;
}

}  // namespace rtcost::bvh
