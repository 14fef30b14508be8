#include <algorithm>
#include <charconv>
#include <chrono>
#include <fmt/format.h>
#include <stdexcept>

#include "common/model_collector.hpp"
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

/// Declines the nodes: only asks whether there is a tree.
class Asker final : public ModelSink {
public:
    bool begin(const ModelFlags&) override { return false; }
    void node(const ModelNode&, std::span<const std::uint32_t>) override {}
};

void emit_subtree(const ModelTree& t, std::uint32_t i, ModelSink& sink) {
    const ModelNode& m = t.nodes[i];
    const std::span<const std::uint32_t> prims =
        m.leaf ? std::span<const std::uint32_t>(t.prims).subspan(m.first, m.count) : std::span<const std::uint32_t>{};
    if (i < t.beams.size()) sink.beam_node(m, t.beams[i], prims);
    else sink.node(m, prims);
    if (m.leaf) return;
    for (std::uint32_t k = 0; k < m.count; ++k) emit_subtree(t, m.first + k, sink);
}

}  // namespace

bool Hierarchy::modelled() const {
    Asker a;
    return emit_model(a);
}

std::size_t Hierarchy::crossings(const Ray& ray, std::span<Crossing> out) const {
    std::size_t n = 0;
    Ray r = ray;
    // A primitive met twice (entry and exit of a sphere) costs an extra query, so allow some.
    for (std::size_t step = 0; step < 2 * out.size() && n < out.size(); ++step) {
        Hit hit;
        closest(r, hit);
        if (!hit.hit()) break;
        const auto id = static_cast<std::uint32_t>(hit.prim);
        if (std::none_of(out.begin(), out.begin() + n, [&](const Crossing& c) { return c.prim == id; }))
            out[n++] = {id, hit.t};
        if (!(hit.t > r.tmin)) break;  // no progress (cannot happen with the open interval)
        r.tmin = hit.t;
    }
    return n;
}

ModelTree Hierarchy::model_tree() const {
    ModelTree t;
    ModelCollector c(t);
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
