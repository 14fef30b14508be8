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

#include "rtcost/model_tree.hpp"
#include "rtcost/scene.hpp"
#include "rtcost/stats.hpp"

namespace rtcost {

struct RaySample;  // sample.hpp

/// What a query asks for.
enum class Query {
    Closest,  ///< nearest hit in (tmin, tmax)
    Any,      ///< any hit in (tmin, tmax) (occlusion); the hit reported is the first one found
    All,      ///< visit everything the segment meets, never stop early; reports the closest hit
};

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

/// One primitive a ray meets in (tmin, tmax): its id and the nearest parameter there.
struct Crossing {
    std::uint32_t prim = 0;
    float t = 0;
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

    /// The first primitives `ray` meets in (tmin, tmax), nearest first, each once at its nearest
    /// parameter there (a closed surface met again on its way out counts once): at most
    /// `out.size()` of them, written to `out`; returns how many. How a ray sample learns how its
    /// rays end (sample.hpp). A hierarchy whose traversal takes its primitive test finds them
    /// in one traversal and keeps every primitive met at the same parameter as another; the
    /// others restart a closest-hit query at each crossing found, which keeps one of such ties.
    virtual std::size_t crossings(const Ray& ray, std::span<Crossing> out) const;

    /// Adds to `counters` the operations of the sample rays `rays` (indices into `sample`), each
    /// traced with `query` by this hierarchy's own traversal, every primitive test answered from
    /// the ray's known crossings instead of intersecting. That is the segments estimator's
    /// prediction (Preset::Exact) without materialising a model tree: how SegmentsPredictor
    /// predicts where it can. Returns false, counting nothing, where the hierarchy has no such
    /// replay or its replay is not its model tree's prediction (mailboxes, an order for
    /// occlusion rays the model does not know).
    virtual bool replay(const RaySample& sample, std::span<const std::uint32_t> rays, Query query,
                        RayCounters& counters) const {
        (void)sample, (void)rays, (void)query, (void)counters;
        return false;
    }

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
