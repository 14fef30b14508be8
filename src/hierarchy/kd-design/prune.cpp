// Bottom-up pruning of a kd-tree by the cost model (prune.hpp).
#include "prune.hpp"

#include <algorithm>
#include <iterator>
#include <stdexcept>

namespace rtcost::kd {
namespace {

class Pruner {
public:
    Pruner(const KdData& t, const designing::CellRays& cells) : t_(t), cells_(cells), leaf_(t.nodes.size(), 0) {}

    KdData run() {
        KdData out;
        out.root = t_.root;
        if (t_.nodes.empty()) return out;
        if (!t_.boxes.empty()) throw std::logic_error("kd::prune: a tree with node boxes (kd-median's)");
        const std::vector<std::uint32_t> rays = cells_.meeting(nullptr, t_.root);
        std::vector<std::uint32_t> refs;
        judge(0, t_.root, rays, refs);
        out.nodes.resize(1);
        emit(0, 0, out);
        return out;
    }

private:
    // The model's cost of the subtree at `node` per segment reaching it (its own step left out:
    // paid either way), the cheaper of its split and a leaf; `refs` gets its references, sorted
    // and each once.
    double judge(std::uint32_t node, const Box3& cell, const std::vector<std::uint32_t>& rays,
                 std::vector<std::uint32_t>& refs) {
        const Node& n = t_.nodes[node];
        if (n.leaf()) {
            refs.assign(t_.refs.begin() + n.index, t_.refs.begin() + n.index + n.count);
            std::sort(refs.begin(), refs.end());
            refs.erase(std::unique(refs.begin(), refs.end()), refs.end());
            return tests(refs);
        }
        double split = cells_.k_trav();
        std::vector<std::uint32_t> sides[2];
        for (int i = 0; i < 2; ++i) {
            const Box3 half = spatial::half(cell, static_cast<int>(n.axis), n.split, i);
            const std::vector<std::uint32_t> met = cells_.meeting(&rays, half);
            const double below = judge(n.index + i, half, met, sides[i]);
            split += cells_.probability(cell, half, rays.size(), met.size()) * (cells_.k_step() + below);
        }
        refs.clear();
        std::set_union(sides[0].begin(), sides[0].end(), sides[1].begin(), sides[1].end(), std::back_inserter(refs));
        const double leaf = tests(refs);
        if (leaf <= split) {
            leaf_[node] = 1;
            return leaf;
        }
        return split;
    }

    double tests(const std::vector<std::uint32_t>& refs) const {
        double c = 0;
        for (std::uint32_t id : refs) c += cells_.test_cost(id);
        return c;
    }

    // Copies the subtree at `src` to out.nodes[dst], a judged leaf as one leaf.
    void emit(std::uint32_t src, std::uint32_t dst, KdData& out) {
        const Node& n = t_.nodes[src];
        if (n.leaf() || leaf_[src]) {
            std::vector<std::uint32_t> refs;
            gather(src, refs);
            if (!n.leaf()) {
                std::sort(refs.begin(), refs.end());
                refs.erase(std::unique(refs.begin(), refs.end()), refs.end());
            }
            Node leaf;
            leaf.index = static_cast<std::uint32_t>(out.refs.size());
            leaf.count = static_cast<std::uint32_t>(refs.size());
            out.refs.insert(out.refs.end(), refs.begin(), refs.end());
            out.nodes[dst] = leaf;
            return;
        }
        const auto first = static_cast<std::uint32_t>(out.nodes.size());
        out.nodes.resize(first + 2);
        Node interior = n;
        interior.index = first;
        out.nodes[dst] = interior;
        emit(n.index, first, out);
        emit(n.index + 1, first + 1, out);
    }

    void gather(std::uint32_t node, std::vector<std::uint32_t>& refs) const {
        const Node& n = t_.nodes[node];
        if (n.leaf()) {
            refs.insert(refs.end(), t_.refs.begin() + n.index, t_.refs.begin() + n.index + n.count);
            return;
        }
        gather(n.index, refs);
        gather(n.index + 1, refs);
    }

    const KdData& t_;
    const designing::CellRays& cells_;
    std::vector<std::uint8_t> leaf_;  // per node of t_: judged cheaper as a leaf
};

}  // namespace

KdData prune(const KdData& tree, const designing::CellRays& cells) { return Pruner(tree, cells).run(); }

}  // namespace rtcost::kd
