#pragma once
/// \file hierarchy.hpp
/// The one interface every acceleration structure implements, its named parameters, and the
/// registry through which the CLI, the cost model and the reports find hierarchies by name.
///
/// A hierarchy lives in its own folder `src/hierarchy/<name>/`: a builder, one traversal
/// template over the counting policy (stats.hpp), and a registration. Nothing else changes when
/// a hierarchy is added. What only its author needs (HierarchyImpl, test_prim) is in the
/// library's internal `src/hierarchy/common/impl.hpp`.

#include <functional>
#include <map>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "rtcost/scene.hpp"
#include "rtcost/stats.hpp"

namespace rtcost {

/// What a query asks for.
enum class Query {
    Closest,  ///< nearest hit in (tmin, tmax)
    Any,      ///< any hit in (tmin, tmax) (occlusion); the hit reported is the first one found
    All,      ///< visit everything the segment meets, never stop early; reports the closest hit
};

/// One node of a hierarchy as the cost model sees it (see the cost-model docs): a region, an
/// optional bounding volume tested before the node is entered, an optional separating plane, the
/// operations one visit costs, and either children or the primitives of a leaf.
struct ModelNode {
    Box3 region;                 ///< R(A): the node's box (a BVH node's bounding box)
    bool has_bv = false;         ///< a box test against `bv` precedes entering the node's children
    Box3 bv;                     ///< the bounding volume tested (BVH: equals `region`)
    std::int8_t axis = -1;       ///< separating plane axis, -1 for none (BVH)
    float split = 0;             ///< separating plane position on `axis`
    std::uint32_t first = 0;     ///< first child (in ModelTree::nodes) or first primitive (in ModelTree::prims)
    std::uint32_t count = 0;     ///< number of children, or of primitives for a leaf
    bool leaf = true;
    int depth = 0;               ///< root at 0 (in model-tree levels)
    /// Operations one visit of this node performs besides primitive tests, in counter units
    /// (e.g. a kd-median node: one box and one plane; an octree's three binary levels: the
    /// first carries the visit, the other two none).
    float box = 0, plane = 0, hop = 0, classify = 0;
    bool step = true;            ///< a visit is one traversal step (N_TS)
    /// A subtree left out of a tree materialised for a ray sample (reached_model_tree): no
    /// segment of the sample meets it, so the node stands for it as an empty leaf.
    bool pruned = false;
    /// 5D ray classification: the node is a set of rays, `region` its origin box and these its
    /// directions: dominant axis `beam_axis` (-1: not a beam) and sign, u and v ranges (the other
    /// two direction components over |d[beam_axis]|, lower axis first). Children split one of
    /// the five dimensions at `split`: `beam_dim` 0..2 origin, 3 u, 4 v.
    std::int8_t beam_axis = -1;
    bool beam_negative = false;
    std::int8_t beam_dim = -1;
    float beam_u[2] = {-1, 1}, beam_v[2] = {-1, 1};
};

/// A hierarchy's family, as the model tree declares it (a label for its users: the model reads
/// what a node costs from the tree, never from the family).
enum class ModelFamily : std::uint8_t {
    Bvh,     ///< bounding volume hierarchies (and brute force, a one-leaf BVH)
    Bsp,     ///< Kaplan's BSP tree
    Octree,  ///< Glassner's octree
    Kd,      ///< kd-trees
    Grid,    ///< uniform grids
    Rc5d,    ///< Arvo and Kirk's 5D ray classification
};

/// What the seed paper's formula for a family (the `paper` preset) charges a node visit, as the
/// hierarchy declares it: every node entered (a BVH's box test), every interior visit, and, for
/// Kaplan's and Glassner's trees, the far region's entry 1_cmp + [g (1 - P_B) + (1 - g)] n_f
/// in place of `interior_box` (g the share of visits that cross the plane, P_B the near child's
/// chance to end the search).
struct PaperCharges {
    float entered_box = 0;
    float interior_box = 0, interior_plane = 0, interior_hop = 0, interior_classify = 0;
    bool far_entry = false;
};

/// The flags of a model tree: what the nodes alone do not say about the traversal.
struct ModelFlags {
    /// Every hierarchy names its family and the paper's charges: there is no default.
    ModelFlags(ModelFamily f, PaperCharges p) : family(f), paper(p) {}
    ModelFamily family;
    PaperCharges paper;
    /// Leaves are found by descending from the root for every cell (Kaplan's and Glassner's
    /// `locate` traversal): each leaf visit pays the operations of all its ancestors again.
    bool locate = false;
    /// Operations every ray pays once whatever it meets (e.g. the root box test), and those a
    /// ray that enters the root pays once more or less (a grid's first cell has no hop: -1).
    float per_ray_box = 1, per_entry_hop = 0;
    /// A ray follows exactly one root-to-leaf path (5D classification: the children of a node
    /// are disjoint sets of rays), whose leaf candidates are searched in order of their start
    /// along the dominant axis and the search stops early.
    bool one_path = false;
    /// A closest-hit query skips what lies beyond the nearest hit found so far (false: the
    /// traversal visits everything the segment meets, e.g. a BVH with `order=none`).
    bool cull = true;
    /// A ray that misses the root's region ends at the root test (false: every ray enters the
    /// root whatever it meets, as brute force's does).
    bool gated = true;
};

/// A hierarchy flattened for the model: `nodes[0]` is the root; the children of a node are
/// contiguous. Binary for space subdivisions; a BVH node may have more than two children
/// (Goldsmith and Salmon's trees are n-ary), each entered through its own box test.
struct ModelTree : ModelFlags {
    /// An empty tree (a hierarchy the model cannot see into); emit_model's flags replace these.
    ModelTree() : ModelFlags(ModelFamily::Bvh, {.entered_box = 1}) {}
    std::vector<ModelNode> nodes;
    std::vector<std::uint32_t> prims;  ///< leaf primitive references
};

/// Receives a hierarchy's model tree depth first (Hierarchy::emit_model), so that the model
/// can read a hierarchy of millions of nodes where it lies instead of copying it: `begin` once,
/// then `node` for every node in pre-order, a node with `count` children being followed by its
/// children's whole subtrees, in order.
class ModelSink {
public:
    virtual ~ModelSink() = default;
    /// The tree's flags, before its root. Returning false ends the emission there (a sink that
    /// only asks whether there is a model tree).
    virtual bool begin(const ModelFlags& flags) = 0;
    /// One node. `m.first` and `m.depth` are not read (the order says them); a leaf's
    /// primitive ids are `prims`, `m.count` of them.
    virtual void node(const ModelNode& m, std::span<const std::uint32_t> prims) = 0;
};

/// Emits a materialised model tree into `sink`, depth first (what Hierarchy::emit_model does
/// for a hierarchy).
void emit_model(const ModelTree& tree, ModelSink& sink);

/// What values a build parameter takes. One declaration serves `rtcost list` (which prints
/// it), Params (which checks every value against it before a build starts) and a search over
/// parameters (which reads the range it may search).
enum class ParamKind : std::uint8_t {
    Integer,  ///< a whole number in [lo, hi], or one of `words`
    Real,     ///< a finite number in [lo, hi], or one of `words`
    Flag,     ///< 0 or 1 (true/false, on/off, yes/no are read too)
    Choice,   ///< one of `words`
    Text,     ///< any text the builder checks itself (a file, a distribution, a resolution)
};

/// "integer", "real", "flag", "choice" or "text".
std::string_view param_kind_name(ParamKind k);

/// One named build parameter, declared by the hierarchy with its default, help text and the
/// values it takes. Make one with the named constructors.
struct ParamSpec {
    std::string name;
    std::string default_value;
    std::string help;
    ParamKind kind = ParamKind::Text;
    double lo = 0, hi = 0;           ///< Integer and Real: the closed range
    std::vector<std::string> words;  ///< Choice: the values; Integer and Real: words taken besides numbers

    static ParamSpec integer(std::string name, std::string def, long long lo, long long hi, std::string help,
                             std::vector<std::string> words = {});
    static ParamSpec real(std::string name, std::string def, double lo, double hi, std::string help,
                          std::vector<std::string> words = {});
    static ParamSpec flag(std::string name, std::string def, std::string help);
    static ParamSpec choice(std::string name, std::string def, std::vector<std::string> words, std::string help);
    static ParamSpec text(std::string name, std::string def, std::string help);
    /// The values it takes, for people: "integer in [1, 64]", "one of near, none", "0 or 1".
    std::string domain() const;
    /// Empty when `value` is one it takes, else what is wrong with it ("must be in [1, 64]").
    std::string problem(const std::string& value) const;
};

/// Validated parameter values of one build (`--set key=value`): every value, given or
/// default, is checked against its declaration when the Params are made (InputError naming
/// the parameter), so the accessors read a declared, valid value.
class Params {
public:
    Params() = default;
    /// Checks every `key=value` against `specs` (unknown keys are an error) and fills defaults.
    Params(const std::vector<ParamSpec>& specs, const std::vector<std::string>& assignments);

    const std::string& str(const std::string& key) const;
    /// An Integer parameter's number (InputError if it holds one of its words instead).
    long long integer(const std::string& key) const;
    /// A Real parameter's number (InputError if it holds one of its words instead).
    double real(const std::string& key) const;
    bool flag(const std::string& key) const;
    /// Whether the value is `word` (e.g. max_depth=auto).
    bool is(const std::string& key, std::string_view word) const { return str(key) == word; }
    const std::map<std::string, std::string>& values() const { return values_; }
    /// The declaration of `key` (InputError if it has none).
    const ParamSpec& spec(const std::string& key) const;

private:
    std::map<std::string, std::string> values_;
    std::map<std::string, ParamSpec> specs_;
};

/// An acceleration structure over a scene. Thread-safe for concurrent queries.
class Hierarchy {
public:
    virtual ~Hierarchy() = default;

    /// Registered name, e.g. "bvh-sah".
    virtual std::string_view name() const = 0;

    /// Closest hit of `ray`; `hit.prim` is -1 on a miss. `hit.ng` is not filled (see
    /// Scene::complete_hit). The counting overload adds this ray's operations to `counters`.
    virtual void closest(const Ray& ray, Hit& hit) const = 0;
    virtual void closest(const Ray& ray, Hit& hit, RayCounters& counters) const = 0;
    /// Any-hit (occlusion) query: true when some primitive is hit in (tmin, tmax); `hit` then
    /// holds the first hit found (not necessarily the closest).
    virtual bool any(const Ray& ray, Hit& hit) const = 0;
    virtual bool any(const Ray& ray, Hit& hit, RayCounters& counters) const = 0;
    /// All-hits query (the cost model's no-termination case): every node and primitive the
    /// segment meets is visited; `hit` receives the closest hit.
    virtual void all(const Ray& ray, Hit& hit) const = 0;
    virtual void all(const Ray& ray, Hit& hit, RayCounters& counters) const = 0;

    /// Structural statistics (N_IN, N_V, N_EV, N_OIV, depth, bytes, build seconds).
    StructureStats structure() const {
        StructureStats s = compute_structure();
        s.seconds = build_seconds_;
        return s;
    }

    const Scene& scene() const { return *scene_; }

    /// Emits the structure as the cost model's tree into `sink`, depth first, reading the
    /// hierarchy's own nodes: no copy of them is made. Emits nothing and returns false for
    /// hierarchies the model cannot see into (embree).
    virtual bool emit_model(ModelSink& sink) const {
        (void)sink;
        return false;
    }
    /// Whether emit_model has a tree to emit.
    bool modelled() const;
    /// The model tree, materialised (the sampled estimator, tests and reports index it). Empty
    /// for hierarchies the model cannot see into.
    ModelTree model_tree() const;

    /// True when the structure grows as rays arrive (Arvo and Kirk's lazy classification):
    /// structure() and model_tree() then describe only what the rays so far have built.
    virtual bool lazy() const { return false; }

    /// False for hierarchies whose traversal cannot count its operations (embree): they are
    /// timed, never counted or modelled.
    virtual bool counted() const { return true; }

protected:
    explicit Hierarchy(const Scene& scene) : scene_(&scene) {}
    /// Everything of StructureStats but `seconds`, which build_hierarchy measures.
    virtual StructureStats compute_structure() const = 0;
    const Scene* scene_;

private:
    friend std::unique_ptr<Hierarchy> build_hierarchy(const Scene&, std::string_view,
                                                      const std::vector<std::string>&);
    double build_seconds_ = 0;
};

/// What the test suites build a test variant of a hierarchy for, a bit each. The suites that
/// check every hierarchy iterate the registry and pick the variants by these bits, so a new
/// hierarchy declares its tests in its own registration.
enum TestUse : unsigned {
    /// Closest hits equal brute force's, any-hit agrees, counting changes nothing
    /// (tests/test_hierarchies.cpp).
    kTestHits = 1u << 0,
    /// On its own training rays the sampled estimator reproduces the counters, for every query
    /// (tests/test_model.cpp): the model tree must be complete before tracing (no lazy build).
    kTestSampled = 1u << 1,
    /// The geometric estimator is exact for lines on every SPD scene (tests/test_model.cpp; slow,
    /// so one variant per hierarchy).
    kTestSpdModel = 1u << 2,
    /// The parameters of the tests that read the whole model tree (emitted and materialised);
    /// without such a variant they build the defaults.
    kTestModelTree = 1u << 3,
    /// Kaplan's BSP and Glassner's octree's own hit checks (tests/test_bsp_octree.cpp).
    kTestSubdivision = 1u << 4,
};

/// A parameter set the test suites build a hierarchy with.
struct TestVariant {
    std::vector<std::string> set;  ///< `--set` assignments
    unsigned uses = 0;             ///< TestUse bits: which suites build it
};

/// A registered hierarchy: its name, a one-line description, its parameters and its builder.
struct HierarchyInfo {
    std::string name;
    std::string description;
    std::vector<ParamSpec> params;
    std::function<std::unique_ptr<Hierarchy>(const Scene&, const Params&)> build;
    /// `-H all` takes it over at most this many primitives: beyond, its build or trace is too
    /// slow for a first look, and `eval` says it was left out (naming it still builds it).
    std::size_t all_up_to = std::numeric_limits<std::size_t>::max();
    /// The variants the test suites check, declared by the hierarchy's registration.
    std::vector<TestVariant> tests = {};
};

/// Brute force tests every primitive for every ray: `-H all` takes it on small scenes only.
inline constexpr std::size_t kBruteInAll = 5000;
/// Where the builders that grow faster than N log N (or trace like brute force) leave `-H all`.
inline constexpr std::size_t kLargeScene = 250000;

/// All registered hierarchies, sorted by name.
std::vector<const HierarchyInfo*> hierarchies();
/// The hierarchy called `name`, or nullptr.
const HierarchyInfo* find_hierarchy(std::string_view name);

/// Builds `name` over `scene` with `--set` assignments; fills `structure().seconds`. Throws
/// InputError for an unknown name or bad parameters. The scene must outlive the result.
std::unique_ptr<Hierarchy> build_hierarchy(const Scene& scene, std::string_view name,
                                           const std::vector<std::string>& assignments = {});

/// Registers a hierarchy at static-initialisation time; used once in each hierarchy's folder:
///   static const rtcost::Registration reg{{"bvh-sah", "...", {...}, builder}, {{{}, kTestHits}}};
/// `tests` become `info.tests`.
struct Registration {
    explicit Registration(HierarchyInfo info, std::vector<TestVariant> tests = {});
};

}  // namespace rtcost
