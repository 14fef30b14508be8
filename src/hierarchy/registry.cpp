#include <algorithm>
#include <charconv>
#include <chrono>
#include <fmt/format.h>
#include <stdexcept>

#include "rtcost/error.hpp"
#include "rtcost/hierarchy.hpp"

namespace rtcost {
namespace {

// Function-local static: registrations run during static initialisation of other translation
// units, in unspecified order, so the table must be created on first use.
std::vector<HierarchyInfo>& registry() {
    static std::vector<HierarchyInfo> table;
    return table;
}

}  // namespace

namespace {

/// Materialises an emitted tree: a node's children get contiguous slots when the node arrives,
/// and are filled as their subtrees follow.
class Collector final : public ModelSink {
public:
    explicit Collector(ModelTree& t) : t_(t) {}
    bool begin(const ModelFlags& f) override {
        static_cast<ModelFlags&>(t_) = f;
        return true;
    }
    void node(const ModelNode& m, std::span<const std::uint32_t> prims) override {
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
        ModelNode& n = t_.nodes[at];
        n = m;
        n.depth = depth;
        if (m.leaf) {
            n.first = static_cast<std::uint32_t>(t_.prims.size());
            t_.prims.insert(t_.prims.end(), prims.begin(), prims.end());
        } else {
            n.first = static_cast<std::uint32_t>(t_.nodes.size());
            if (m.count > 0) open_.push_back({n.first, n.first + m.count, depth + 1});
            t_.nodes.resize(t_.nodes.size() + m.count);  // invalidates `n`
        }
    }

private:
    struct Slots {
        std::uint32_t next, end;
        int depth;
    };
    ModelTree& t_;
    std::vector<Slots> open_;
};

/// Declines the nodes: only asks whether there is a tree.
class Asker final : public ModelSink {
public:
    bool begin(const ModelFlags&) override { return false; }
    void node(const ModelNode&, std::span<const std::uint32_t>) override {}
};

void emit_subtree(const ModelTree& t, std::uint32_t i, ModelSink& sink) {
    const ModelNode& m = t.nodes[i];
    if (m.leaf) {
        sink.node(m, std::span<const std::uint32_t>(t.prims).subspan(m.first, m.count));
        return;
    }
    sink.node(m, {});
    for (std::uint32_t k = 0; k < m.count; ++k) emit_subtree(t, m.first + k, sink);
}

}  // namespace

bool Hierarchy::modelled() const {
    Asker a;
    return emit_model(a);
}

ModelTree Hierarchy::model_tree() const {
    ModelTree t;
    Collector c(t);
    emit_model(c);
    return t;
}

void emit_model(const ModelTree& t, ModelSink& sink) {
    if (!sink.begin(t) || t.nodes.empty()) return;
    emit_subtree(t, 0, sink);
}

Registration::Registration(HierarchyInfo info, std::vector<TestVariant> tests) {
    info.tests = std::move(tests);
    registry().push_back(std::move(info));
}

std::vector<const HierarchyInfo*> hierarchies() {
    std::vector<const HierarchyInfo*> out;
    for (const auto& h : registry()) out.push_back(&h);
    std::sort(out.begin(), out.end(), [](auto* a, auto* b) { return a->name < b->name; });
    return out;
}

const HierarchyInfo* find_hierarchy(std::string_view name) {
    for (const auto& h : registry())
        if (h.name == name) return &h;
    return nullptr;
}

std::unique_ptr<Hierarchy> build_hierarchy(const Scene& scene, std::string_view name,
                                           const std::vector<std::string>& assignments) {
    const HierarchyInfo* info = find_hierarchy(name);
    if (!info) {
        std::string known;
        for (auto* h : hierarchies()) known += (known.empty() ? "" : ", ") + h->name;
        throw InputError("--hierarchy", 0, fmt::format("unknown hierarchy '{}' (known: {})", name, known));
    }
    Params params(info->params, assignments);
    auto start = std::chrono::steady_clock::now();
    auto h = info->build(scene, params);
    h->build_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return h;
}

}  // namespace rtcost
