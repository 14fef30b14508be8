// `brute`: tests every primitive for every ray. The reference every other hierarchy is checked
// against; it has no structure, so its structural statistics describe one leaf holding all.
#include "../common/impl.hpp"

namespace rtcost {
namespace {

class Brute final : public HierarchyImpl<Brute> {
public:
    explicit Brute(const Scene& s) : HierarchyImpl(s) {}
    std::string_view name() const override { return "brute"; }

    template <class C, Query Q>
    bool trace(const Ray& ray, Hit& hit, C& counting) const {
        const auto n = static_cast<std::uint32_t>(scene_->size());
        counting.leaf(0, n);
        bool found = false;
        for (std::uint32_t id = 0; id < n; ++id) {
            if (test_prim(*scene_, id, ray, hit, counting)) {
                found = true;
                if constexpr (Q == Query::Any) return true;
            }
        }
        return found;
    }

    /// One leaf holding every primitive, entered with no box test.
    bool emit_model(ModelSink& sink) const override {
        ModelFlags f(ModelFamily::Bvh, {.entered_box = 1});  // the paper: a box test per node entered
        f.per_ray_box = 0;
        f.gated = false;  // a ray that misses the scene's box still tests every primitive
        if (!sink.begin(f)) return true;
        std::vector<std::uint32_t> ids(scene_->size());
        for (std::uint32_t id = 0; id < ids.size(); ++id) ids[id] = id;
        ModelNode leaf;
        leaf.region = scene_->bounds();
        leaf.count = static_cast<std::uint32_t>(ids.size());
        sink.node(leaf, ids);
        return true;
    }

protected:
    StructureStats compute_structure() const override {
        StructureStats s;
        s.leaves = 1;
        s.empty_leaves = scene_->empty() ? 1 : 0;
        s.references = scene_->size();
        s.bytes = 0;
        return s;
    }
};

const Registration reg{{"brute", "every primitive tested for every ray (the reference)", {},
                        [](const Scene& s, const Params&) { return std::make_unique<Brute>(s); }, kBruteInAll}};

}  // namespace
}  // namespace rtcost
