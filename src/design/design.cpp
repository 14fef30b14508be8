// `rtcost design`: each family's designed hierarchy beside its yardstick, both evaluated on the
// rays of the distribution outside the design sample, single thread; tables and JSON.
#include <fmt/format.h>

#include "rtcost/design.hpp"
#include "rtcost/error.hpp"
#include "rtcost/evaluate.hpp"

namespace rtcost {
namespace {

struct Family {
    const char* family;
    const char* designed;
    const char* yardstick;  // "name[:key=value]"
    const char* extra = nullptr;  // a designed parameter beyond the shared ones
};

// The yardsticks the issue names: the SAH builders, the default octree and BSP, the hetero grid.
constexpr Family kFamilies[] = {
    {"grid", "grid-design", "grid:res=hetero"},  {"bvh", "bvh-design", "bvh-sah", "occlusion=sample"}, {"kd", "kd-design", "kd-sah"},
    {"octree", "octree-design", "octree"},       {"bsp", "bsp-design", "bsp"},
};

// The size is always passed: the sample must be drawn from the very rays the evaluation splits.
std::vector<std::string> design_set(const DesignOptions& opt, const Scene& scene) {
    std::vector<std::string> set{"rays=" + opt.rays.name, "sample=" + std::to_string(opt.sample),
                                 "seed=" + std::to_string(opt.seed)};
    // Without --size, the size the distribution itself takes: spd's 512x512, else the scene's.
    set.push_back("size=" + (!opt.rays.size.empty() ? opt.rays.size
                             : opt.rays.name == "spd"
                                 ? std::string("512x512")
                                 : fmt::format("{}x{}", scene.camera.width, scene.camera.height)));
    if (!opt.costs_file.empty()) set.push_back("costs=" + opt.costs_file);
    return set;
}

}  // namespace

std::vector<std::string> design_families() {
    std::vector<std::string> out;
    for (const Family& f : kFamilies)
        if (find_hierarchy(f.designed)) out.push_back(f.family);
    return out;
}

DesignResult design(const Scene& scene, const DesignOptions& opt) {
    std::vector<std::string> families = opt.families.empty() ? design_families() : opt.families;
    const std::vector<std::string> known = design_families();
    for (const auto& f : families)
        if (std::find(known.begin(), known.end(), f) == known.end()) {
            std::string list;
            for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
            throw InputError("--family", 0, fmt::format("unknown family '{}' (known: {})", f, list));
        }
    if (opt.sample == 0) throw InputError("--sample", 0, "a design sample needs at least one ray");
    DesignResult res;
    res.scene = scene.name;
    // The table reports operations unless a costs file is given; the designs minimise the
    // named costs (typical ns per operation by default).
    res.calibrated = !opt.costs_file.empty() && !UnitCosts::built_in(opt.costs_file);
    res.designed_for = opt.costs_file.empty() ? "each family's default" : opt.costs_file;
    UnitCosts costs;
    if (res.calibrated) costs = UnitCosts::read(opt.costs_file);
    // The size of the sample each design draws (draw_design_input: draw_sample), the same for all.
    const RaySet all = make_rays(scene, opt.rays);
    const std::size_t segments = sample_size(all, draw_sample_count(all, opt.sample), opt.seed);
    for (const auto& fam : families) {
        const Family* f = nullptr;
        for (const Family& k : kFamilies)
            if (fam == k.family) f = &k;
        const HierarchyRequest yardstick = parse_hierarchy_list(f->yardstick, scene.size()).front();
        HierarchyRequest designed{f->designed, design_set(opt, scene)};
        // The BVH's occlusion order too (its model tree carries the order: ModelNode::any_order).
        if (f->extra) designed.params.push_back(f->extra);
        EvalOptions eo;
        eo.hierarchies = {designed, yardstick, {"embree", {}}};  // Embree: the speed peer, same rays and run
        eo.estimators = {Estimator::Segments};
        eo.costs = costs;
        eo.threads = 1;
        // The gain is a ratio of two timings: taken in alternating passes, not one after the other.
        eo.interleave_timing = true;
        eo.sample_seed = opt.seed;
        eo.on_step = opt.on_step;
        // The evaluation draws the designed hierarchy's sample again (draw_sample's) and leaves
        // it out, so the test rays are the ones the design never saw.
        eo.segments = segments;
        const EvalResult r = evaluate(scene, opt.rays, eo);
        res.distribution = r.distribution;
        res.sample = r.sample_rays;
        res.test_rays = r.test_rays;
        const EvalRow& d = r.rows[0];
        const EvalRow& y = r.rows[1];
        DesignRow row;
        row.family = f->family;
        row.designed = d.name;
        row.yardstick = y.name;
        row.structure = fmt::format("{} leaves, depth {}, {} references", d.structure.leaves, d.structure.depth,
                                    d.structure.references);
        row.designed_build = d.structure.seconds;
        row.yardstick_build = y.structure.seconds;
        row.designed_predicted = d.headline() ? d.headline()->scalar : 0;
        row.yardstick_predicted = y.headline() ? y.headline()->scalar : 0;
        row.designed_measured = d.measured_scalar;
        row.yardstick_measured = y.measured_scalar;
        row.designed_ns = d.ns_per_ray;
        row.yardstick_ns = y.ns_per_ray;
        row.embree_ns = r.rows[2].ns_per_ray;
        // The control: the same three built and evaluated again, the yardstick first; its time
        // there against its time here is how far apart two evaluations time one structure. Not
        // a second yardstick beside the first: passes over the same rays teach the branch
        // predictor, so twins timed in turn speed each other up (tree diffuse: the yardstick
        // 110 ns beside the designed one, 102 ns beside its twin).
        if (opt.control) {
            EvalOptions again = eo;
            again.hierarchies = {yardstick, designed, {"embree", {}}};
            row.control_ns = evaluate(scene, opt.rays, again).rows[0].ns_per_ray;
        }
        row.gain = row.yardstick_ns > 0 ? 1 - row.designed_ns / row.yardstick_ns : 0;
        res.rows.push_back(row);
    }
    return res;
}

namespace {
// 1 - control ns / yardstick ns: how far apart two evaluations timed the yardstick.
double control_gain(const DesignRow& x) { return x.yardstick_ns > 0 ? 1 - x.control_ns / x.yardstick_ns : 0; }
}  // namespace

nlohmann::json to_json(const DesignResult& r) {
    nlohmann::json rows = nlohmann::json::array();
    for (const DesignRow& x : r.rows) {
        const auto colon = x.designed.find(':');
        nlohmann::json set = nlohmann::json::array();
        for (std::size_t at = colon; at != std::string::npos;) {
            const auto next = x.designed.find(':', at + 1);
            set.push_back(x.designed.substr(at + 1, next == std::string::npos ? std::string::npos : next - at - 1));
            at = next;
        }
        rows.push_back({{"family", x.family},
                        {"designed", x.designed.substr(0, colon)},
                        {"set", set},
                        {"yardstick", x.yardstick},
                        {"structure", x.structure},
                        {"build_seconds", {{"designed", x.designed_build}, {"yardstick", x.yardstick_build}}},
                        {"predicted", {{"designed", x.designed_predicted}, {"yardstick", x.yardstick_predicted}}},
                        {"measured", {{"designed", x.designed_measured}, {"yardstick", x.yardstick_measured}}},
                        {"ns_per_ray", {{"designed", x.designed_ns}, {"yardstick", x.yardstick_ns}, {"embree", x.embree_ns}}},
                        {"gain", x.gain}});
        if (x.control_ns > 0) {
            rows.back()["ns_per_ray"]["control"] = x.control_ns;
            rows.back()["control_gain"] = control_gain(x);
        }
    }
    return {{"scene", r.scene},     {"distribution", r.distribution}, {"sample", r.sample},
            {"test_rays", r.test_rays}, {"units", r.calibrated ? "ns" : "operations"}, {"designed_for", r.designed_for},
            {"results", rows}};
}

std::string design_table(const DesignResult& r) {
    const std::string aim = r.designed_for == "each family's default"
                                ? "each family's default: typical ns per operation (kd; bvh: a BVH's own), operations with polygon edges (grid, octree, bsp)"
                            : r.designed_for == "typical" ? "typical ns per operation (built in)"
                            : r.designed_for == "typical-bvh" ? "a BVH's typical ns per operation (built in)"
                            : r.designed_for == "unit"  ? "operations (unit costs)"
                            : r.designed_for == "ops"   ? "operations, polygon edges at a share of a test"
                                                        : "ns per operation of " + r.designed_for;
    std::string s = fmt::format("scene      {}\nrays       {}: design sample {}, test rays {} (disjoint)\ncosts      {}\n"
                                "designed   to minimise {}\n\n",
                                r.scene, r.distribution, r.sample, r.test_rays,
                                r.calibrated ? "calibrated ns per ray" : "operations per ray (unit costs)", aim);
    s += fmt::format("{:<7} {:<26} {:>9} {:>11} {:>11} {:>10} {:>7}\n", "family", "hierarchy", "build s", "predicted",
                     "measured", "ns/ray", "gain");
    for (const DesignRow& x : r.rows) {
        const std::string dn = x.designed.substr(0, x.designed.find(':'));
        s += fmt::format("{:<7} {:<26} {:>9.3f} {:>11.2f} {:>11.2f} {:>10.1f} {:>+6.1f}%\n", x.family, dn, x.designed_build,
                         x.designed_predicted, x.designed_measured, x.designed_ns, 100 * x.gain);
        s += fmt::format("{:<7} {:<26} {:>9.3f} {:>11.2f} {:>11.2f} {:>10.1f}\n", "", x.yardstick, x.yardstick_build,
                         x.yardstick_predicted, x.yardstick_measured, x.yardstick_ns);
        if (x.control_ns > 0)
            s += fmt::format("{:<7} {:<26} {:>9} {:>11} {:>11} {:>10.1f} {:>+6.1f}%\n", "", "control: " + x.yardstick, "", "",
                             "", x.control_ns, 100 * control_gain(x));
    }
    if (!r.rows.empty()) s += fmt::format("{:<7} {:<26} {:>9} {:>11} {:>11} {:>10.1f}\n", "", "embree", "", "", "", r.rows.back().embree_ns);
    s += "\ngain: 1 - designed / yardstick measured single-thread ns per ray (0.2: 20% fewer ns)\n";
    if (!r.rows.empty() && r.rows.front().control_ns > 0)
        s += "control: the yardstick in a second evaluation of the three; its gain is this run's noise\n";
    return s;
}

}  // namespace rtcost
