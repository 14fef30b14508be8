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

[[noreturn]] void bad_param(const std::string& key, const std::string& value, const std::string& want) {
    throw InputError("--set", 0, fmt::format("{}={}: {}", key, value, want));
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

Params::Params(const std::vector<ParamSpec>& specs, const std::vector<std::string>& assignments) {
    for (const auto& s : specs) values_[s.name] = s.default_value;
    for (const auto& a : assignments) {
        auto eq = a.find('=');
        if (eq == std::string::npos || eq == 0) {
            throw InputError("--set", 0, fmt::format("'{}': expected key=value", a));
        }
        std::string key = a.substr(0, eq);
        if (!values_.contains(key)) {
            std::string known;
            for (const auto& s : specs) known += (known.empty() ? "" : ", ") + s.name;
            throw InputError("--set", 0,
                             fmt::format("unknown parameter '{}' (known: {})", key, known.empty() ? "none" : known));
        }
        values_[key] = a.substr(eq + 1);
    }
}

const std::string& Params::str(const std::string& key) const {
    auto it = values_.find(key);
    if (it == values_.end()) throw InputError("--set", 0, fmt::format("parameter '{}' is not declared", key));
    return it->second;
}

long long Params::integer(const std::string& key, long long lo, long long hi) const {
    const std::string& v = str(key);
    long long x = 0;
    auto [p, ec] = std::from_chars(v.data(), v.data() + v.size(), x);
    if (ec != std::errc() || p != v.data() + v.size()) bad_param(key, v, "expected an integer");
    if (x < lo || x > hi) bad_param(key, v, fmt::format("must be in [{}, {}]", lo, hi));
    return x;
}

double Params::real(const std::string& key, double lo, double hi) const {
    const std::string& v = str(key);
    double x = 0;
    auto [p, ec] = std::from_chars(v.data(), v.data() + v.size(), x);
    if (ec != std::errc() || p != v.data() + v.size() || !std::isfinite(x)) bad_param(key, v, "expected a number");
    if (x < lo || x > hi) bad_param(key, v, fmt::format("must be in [{}, {}]", lo, hi));
    return x;
}

bool Params::flag(const std::string& key) const {
    const std::string& v = str(key);
    if (v == "1" || v == "true" || v == "on" || v == "yes") return true;
    if (v == "0" || v == "false" || v == "off" || v == "no") return false;
    bad_param(key, v, "expected 0 or 1");
}

const std::string& Params::choice(const std::string& key, std::initializer_list<std::string_view> choices) const {
    const std::string& v = str(key);
    for (auto c : choices)
        if (c == v) return v;
    std::string list;
    for (auto c : choices) list += (list.empty() ? "" : ", ") + std::string(c);
    bad_param(key, v, "expected one of " + list);
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
