// The evaluation: build each requested hierarchy, trace the test rays counted and timed, predict
// with every estimator and preset asked for, and rank. `rtcost eval` prints what this returns.
#include "rtcost/evaluate.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <map>
#include <memory>
#include <numeric>
#include <optional>
#include <stdexcept>

#include <fmt/format.h>

#include "rtcost/error.hpp"
#include "rtcost/sample.hpp"
#include "rtcost/trace.hpp"
#include "pass_times.hpp"
#include "util/rng.hpp"

namespace rtcost {

std::string fingerprint_text(std::uint64_t fingerprint) { return fmt::format("{:016x}", fingerprint); }

namespace {

/// Weighted mean of per-kind predictions (weights: the kinds' shares of the rays).
Prediction mix(const std::vector<std::pair<double, Prediction>>& parts, const UnitCosts& costs) {
    if (parts.size() == 1) return parts[0].second;
    Prediction out = parts.at(0).second;
    out.cost = CostVector{};
    out.visits_by_depth.clear();
    out.seconds = 0;
    for (const auto& [w, p] : parts) {
        add_scaled(out.cost, p.cost, w);
        if (out.visits_by_depth.size() < p.visits_by_depth.size()) out.visits_by_depth.resize(p.visits_by_depth.size());
        for (std::size_t d = 0; d < p.visits_by_depth.size(); ++d) out.visits_by_depth[d] += w * p.visits_by_depth[d];
        out.seconds += p.seconds;
    }
    out.scalar = costs.scalar(out.cost);
    return out;
}

/// Ranks 1..n by ascending value; rows whose value is not finite are not ranked (0).
template <class F>
void rank(std::vector<EvalRow>& rows, F value, int EvalRow::*out) {
    std::vector<std::size_t> idx;
    for (std::size_t i = 0; i < rows.size(); ++i) {
        if (std::isfinite(value(rows[i]))) idx.push_back(i);
        else rows[i].*out = 0;
    }
    std::stable_sort(idx.begin(), idx.end(), [&](auto x, auto y) { return value(rows[x]) < value(rows[y]); });
    for (std::size_t r = 0; r < idx.size(); ++r) rows[idx[r]].*out = static_cast<int>(r + 1);
}

std::array<std::vector<Ray>, kRayKinds> by_kind(const RaySet& s) {
    std::array<std::vector<Ray>, kRayKinds> out;
    for (std::size_t i = 0; i < s.rays.size(); ++i) out[static_cast<int>(s.kinds[i])].push_back(s.rays[i]);
    return out;
}

/// A pseudo-random half of `all` for training (thinned to `sample`), the rest for testing. Not
/// every other ray: a ray tree's order (eye, a shadow ray per light, reflection, ...) would put
/// one light's shadow rays in training and another's in test.
void split_half(RaySet& all, RaySet& train, std::size_t sample) {
    RaySet keep;
    const std::size_t half = all.rays.size() / 2;
    const double keep_share = half > sample ? static_cast<double>(sample) / half : 1.0;
    for (std::size_t i = 0; i < all.rays.size(); ++i) {
        const std::uint64_t z = mix64(i + 1);
        const bool to_train = z & 1;  // one bit picks the side, the rest thin
        if (to_train && unit_double(z) >= keep_share) continue;
        RaySet& to = to_train ? train : keep;
        to.rays.push_back(all.rays[i]);
        to.kinds.push_back(all.kinds[i]);
        if (!to_train && i < all.pixels.size()) keep.pixels.push_back(all.pixels[i]);
    }
    keep.described = all.described;
    // The test rays keep the image they came through, a pixel per ray (the geometric estimator
    // draws its eye rays through the same view).
    keep.image_width = all.image_width;
    keep.image_pixels = all.image_pixels;
    all = std::move(keep);
}

constexpr const char* kVisibilityNote =
    "P from the scene's own visibility: where eye rays through the scene camera's view (lines: rays aimed at the "
    "primitives from outside), and rays spawned where they first meet a surface as the materials and lights say, "
    "end (no ray of the distribution traced)";

bool wants(const EvalOptions& opt, Estimator e) {
    return std::find(opt.estimators.begin(), opt.estimators.end(), e) != opt.estimators.end();
}

EvalResult run(const Scene& scene, RaySet test, const RaySet& train, const RaySample* sample, const EvalOptions& opt,
               std::string split) {
    if (opt.hierarchies.empty()) throw InputError("--hierarchy", 0, "no hierarchy named");
    if (opt.estimators.empty() || opt.presets.empty()) throw InputError("--estimator", 0, "no estimator or preset");
    if (test.rays.empty())
        throw InputError("--rays", 0, "no test rays are left: the estimators need training and test rays (use more rays)");
    const bool sampled = wants(opt, Estimator::Sampled);
    const UnitCosts& costs = opt.costs;
    auto query_of = [&](int k) { return is_occlusion(static_cast<RayKind>(k)) ? opt.occlusion : opt.query; };
    const auto test_kinds = by_kind(test), train_kinds = by_kind(train);
    if (sampled)
        for (int k = 0; k < kRayKinds; ++k)
            if (!test_kinds[k].empty() && train_kinds[k].empty())
                throw InputError("--sample", 0,
                                 "no training rays of kind " + std::string(ray_kind_name(static_cast<RayKind>(k))) +
                                     ": too few rays to split (" + std::to_string(test.rays.size()) + ")");

    EvalResult res;
    res.scene = scene.name;
    res.primitives = scene.size();
    res.scene_fingerprint = scene.fingerprint();
    res.distribution = test.described;
    res.test_rays = test.rays.size();
    res.training_rays = train.rays.size();
    res.left_out = opt.left_out;
    std::array<std::vector<std::uint32_t>, kRayKinds> sample_kinds;
    if (sample) {
        res.sample_rays = sample->size();
        for (std::size_t i = 0; i < sample->size(); ++i)
            sample_kinds[static_cast<int>(sample->rays.kinds[i])].push_back(static_cast<std::uint32_t>(i));
        for (int k = 0; k < kRayKinds; ++k)
            if (!test_kinds[k].empty() && sample_kinds[k].empty())
                throw InputError("--sample", 0,
                                 "the sample has no rays of kind " + std::string(ray_kind_name(static_cast<RayKind>(k))) +
                                     ": draw a larger one");
    }
    // The geometric estimator under termination learns where searches end from the scene's own
    // visibility (draw_visibility_sample): no ray of the user's, no hierarchy's traversal.
    std::optional<RaySample> visibility;
    std::array<std::vector<std::uint32_t>, kRayKinds> visibility_kinds;
    if (wants(opt, Estimator::Geometric)) {
        std::vector<RayKind> kinds;
        for (int k = 0; k < kRayKinds; ++k)
            if (!test_kinds[k].empty() && query_of(k) != Query::All) kinds.push_back(static_cast<RayKind>(k));
        if (!kinds.empty()) {
            if (opt.on_step) opt.on_step("visibility sample");
            const auto start = std::chrono::steady_clock::now();
            auto reference = build_hierarchy(scene, "bvh-sah");
            // The camera with the image shape the distribution gives it (--size): a view framed
            // for a tall image and traced square misses more than the scene's own shape says.
            Camera view = scene.camera;
            if (test.image_width > 0 && test.image_pixels >= test.image_width) {
                view.width = static_cast<int>(test.image_width);
                view.height = static_cast<int>(test.image_pixels / test.image_width);
            }
            visibility = draw_visibility_sample(scene, kinds, kVisibilityRays, opt.sample_seed, *reference, opt.query,
                                                opt.occlusion, &view);
            for (std::size_t i = 0; i < visibility->size(); ++i)
                visibility_kinds[static_cast<int>(visibility->rays.kinds[i])].push_back(static_cast<std::uint32_t>(i));
            res.visibility_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            res.visibility_rays = visibility->size();
        }
    }
    res.split = std::move(split);
    res.query = opt.query;
    res.occlusion = opt.occlusion;
    for (int k = 0; k < kRayKinds; ++k)
        if (!test_kinds[k].empty()) res.rays_by_kind.emplace_back(ray_kind_name(static_cast<RayKind>(k)), test_kinds[k].size());
    res.estimators = opt.estimators;
    res.presets = opt.presets;
    res.calibrated = costs.calibrated;

    // interleave_timing: what the rounds of timed passes after the loop need of each row.
    struct Timed {
        std::unique_ptr<Hierarchy> h;
        RaySet subset;  // the rows' rays when not the test rays (brute force on a large scene)
        TraceOptions to;
    };
    std::vector<Timed> timed_later;
    for (const HierarchyRequest& req : opt.hierarchies) {
        if (opt.on_step) opt.on_step("build " + req.label());
        std::unique_ptr<Hierarchy> h = build_hierarchy(scene, req.name, req.params);
        EvalRow row;
        row.name = req.label();
        TraceOptions to;
        to.query = opt.query;
        to.threads = opt.threads;
        // Brute force over a large scene is measured on a subset of the rays (every k-th), so
        // that asking for it cannot take hours; the row says so.
        const RaySet* rays = &test;
        RaySet subset;
        if (req.name == "brute" && scene.size() > kBruteLimit) {
            const std::size_t keep = std::max<std::size_t>(1000, kBruteTests / scene.size());
            if (keep < test.rays.size()) {
                const std::size_t step = (test.rays.size() + keep - 1) / keep;
                for (std::size_t i = 0; i < test.rays.size(); i += step) {
                    subset.rays.push_back(test.rays[i]);
                    subset.kinds.push_back(test.kinds[i]);
                }
                subset.described = test.described;
                rays = &subset;
            }
        }
        row.measured_rays = rays->rays.size();
        auto progress = [&](const std::string& step) {
            const std::string named = step + " " + req.label();
            if (opt.on_step) opt.on_step(named);
            if (opt.on_progress) to.progress = [&, named](std::size_t done) { opt.on_progress(named, done, rays->rays.size()); };
        };
        // Counted first, so a lazily built hierarchy (rc5d) is complete when timed.
        progress("counting");
        to.count = true;
        TraceResult counted = trace_ray_set(*h, *rays, to, opt.occlusion);
        row.counted = h->counted();
        // Timed passes: repeated until they add up to opt.min_seconds (or opt.repeat of them);
        // the median is reported with the spread. Interleaved: after every row is counted.
        to.count = false;
        to.threads = opt.timing_threads;
        if (!opt.interleave_timing) {
            progress("timing");
            PassTimes times;
            while (times.more(opt)) times.add(trace_ray_set(*h, *rays, to, opt.occlusion));
            times.fill(row, rays->rays.size());
        }
        to.progress = nullptr;
        // Structure and model tree after tracing: a lazily built hierarchy (rc5d) exists only
        // where rays went, so the training rays go through it too.
        if (sampled && h->lazy())
            for (int k = 0; k < kRayKinds; ++k) trace_rays(*h, train_kinds[k]);
        if (sample && h->lazy()) trace_rays(*h, sample->rays.rays);
        row.structure = h->structure();
        row.lazy = h->lazy();
        row.modelled = h->modelled();
        if (row.modelled) {
            if (opt.on_step) opt.on_step("model " + req.label());
            // The sampled estimator's probe indexes a materialised tree; the segments one the
            // hierarchy's own traversal where it can replay the sample, else the part of the
            // tree that the sample reaches; the geometric one reads the hierarchy where it lies.
            // Materialising a tree is part of what a probed prediction costs.
            const auto tree_start = std::chrono::steady_clock::now();
            const ModelTree tree = sampled ? h->model_tree() : ModelTree{};
            const double tree_seconds =
                std::chrono::duration<double>(std::chrono::steady_clock::now() - tree_start).count();
            std::optional<SegmentsPredictor> segments;
            const std::size_t size = row.structure.interior + row.structure.leaves + row.structure.references;
            if (sample && wants(opt, Estimator::Segments)) segments.emplace(*h, scene, *sample, size);
            // Over the visibility sample. A lazy hierarchy exists only where rays went: the one
            // predicted is a fresh build grown by the sample's own rays (no ray of the user's),
            // so that the measured one stays the tree its test rays grew.
            std::optional<SegmentsPredictor> seen;
            std::unique_ptr<Hierarchy> grown;
            double grow_seconds = 0;
            if (visibility && h->lazy()) {
                const auto grow_start = std::chrono::steady_clock::now();
                grown = build_hierarchy(scene, req.name, req.params);
                trace_rays(*grown, visibility->rays.rays);
                grow_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - grow_start).count();
            }
            if (visibility) seen.emplace(grown ? *grown : *h, scene, *visibility, grown ? 0 : size);
            // (The segments predictor materialises a tree, when it needs one, within the
            // prediction that needed it, which that prediction's time holds.)
            for (Estimator est : opt.estimators) {
                for (Preset preset : opt.presets) {
                    std::vector<std::pair<double, Prediction>> parts;
                    // The geometric estimate depends on the query, not on the rays: one per query.
                    std::map<Query, Prediction> geometric;
                    for (int k = 0; k < kRayKinds; ++k) {
                        if (test_kinds[k].empty()) continue;
                        ModelOptions o;
                        o.preset = preset;
                        o.query = query_of(k);
                        const double share = static_cast<double>(test_kinds[k].size()) / test.rays.size();
                        const auto start = std::chrono::steady_clock::now();
                        if (est == Estimator::Sampled) {
                            parts.emplace_back(share, predict_sampled(tree, scene, train_kinds[k], o, costs));
                        } else if (est == Estimator::Segments) {
                            parts.emplace_back(share, segments->predict(sample_kinds[k], o, costs));
                        } else if (o.query != Query::All && !visibility_kinds[k].empty()) {
                            // (No stand-ins of a kind, e.g. every landing faces away from the
                            // lights: the Cauchy-Crofton estimate below.)
                            parts.emplace_back(share, seen->predict(visibility_kinds[k], o, costs));
                            parts.back().second.estimator = "geometric";
                            parts.back().second.note = kVisibilityNote;
                        } else {
                            auto it = geometric.find(o.query);
                            if (it == geometric.end())
                                it = geometric.emplace(o.query, predict_geometric(*h, o, costs)).first;
                            parts.emplace_back(share, it->second);
                        }
                        parts.back().second.seconds =
                            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
                    }
                    row.predictions.push_back(mix(parts, costs));
                    if (est == Estimator::Sampled) row.predictions.back().seconds += tree_seconds;
                    // (The tree the visibility sample's predictor materialises, it makes within its
                    // first call, which that part's time holds.)
                    if (est == Estimator::Geometric && seen) row.predictions.back().seconds += grow_seconds;
                }
            }
            // The segments sample's own rays traced once (real tests, not counted), after the
            // predictions (the segments replay among them): what its rays cost a trace, against
            // what replaying them cost (a few thousand rays spread over the whole distribution,
            // far less coherent than the distribution traced in its order).
            if (segments) {
                double traced = 0;
                for (int k = 0; k < kRayKinds; ++k) {
                    if (test_kinds[k].empty() || sample_kinds[k].empty()) continue;
                    std::vector<Ray> rays;
                    for (std::uint32_t i : sample_kinds[k]) rays.push_back(sample->rays.rays[i]);
                    TraceOptions t;
                    t.query = query_of(k);
                    t.threads = 1;
                    traced += trace_rays(*h, rays, t).seconds;
                }
                row.sample_trace_seconds = traced;
            }
        }
        row.measured = measured_cost(counted.counters);
        // The time model prices what the structure is as well as what it does (its box tests made
        // several at once, its size against the cache); with unit costs this is the operation count.
        row.measured_scalar = costs.scalar(row.measured, row.structure);
        for (Prediction& p : row.predictions) p.scalar = costs.scalar(p.cost, row.structure);
        const Prediction* head = row.headline();
        row.error = head && row.measured_scalar > 0 ? (head->scalar - row.measured_scalar) / row.measured_scalar : 0;
        const double n = counted.counters.rays ? static_cast<double>(counted.counters.rays) : 1;
        for (int d = 0; d < kMaxStatDepth; ++d) row.measured_visits.push_back(counted.counters.visits[d] / n);
        while (!row.measured_visits.empty() && row.measured_visits.back() == 0) row.measured_visits.pop_back();
        if (opt.interleave_timing) {
            timed_later.push_back({std::move(h), rays == &subset ? std::move(subset) : RaySet{}, to});
        } else if (opt.on_row) {
            opt.on_row(row);
        }
        res.rows.push_back(std::move(row));
    }
    if (opt.interleave_timing) {
        // Rounds of one pass per hierarchy until every one has had its share, each round in a
        // new order (seeded: the same in every run). A pass finds the caches, branch predictors
        // and TLB as the previous pass left them: with one order turned round by round, each
        // hierarchy always followed the same one, and the one after embree was timed up to 6%
        // apart from an identical copy elsewhere, the same way in every run of one command.
        if (opt.on_step) opt.on_step("timing (interleaved)");
        std::vector<PassTimes> times(timed_later.size());
        bool more = true;
        for (int round = 0; more; ++round) {
            more = false;
            for (std::size_t i : timing_order(timed_later.size(), round)) {
                if (!times[i].more(opt)) continue;
                const Timed& t = timed_later[i];
                times[i].add(trace_ray_set(*t.h, t.subset.rays.empty() ? test : t.subset, t.to, opt.occlusion));
                more = true;
            }
        }
        for (std::size_t i = 0; i < timed_later.size(); ++i) {
            const Timed& t = timed_later[i];
            times[i].fill(res.rows[i], (t.subset.rays.empty() ? test : t.subset).rays.size());
            if (opt.on_row) opt.on_row(res.rows[i]);
        }
    }
    rank(res.rows, [](const EvalRow& r) { return r.modelled ? r.headline()->scalar : kInf; }, &EvalRow::rank_predicted);
    rank(res.rows, [](const EvalRow& r) { return r.counted ? r.measured_scalar : kInf; }, &EvalRow::rank_measured);
    rank(res.rows, [](const EvalRow& r) { return r.ns_per_ray; }, &EvalRow::rank_time);
    return res;
}

}  // namespace

namespace {
/// The segments estimator's sample (drawn from `test`, or read from opt.sample_file), left out of
/// `test`.
std::optional<RaySample> take_sample(const Scene& scene, RaySet& test, const EvalOptions& opt, double& seconds,
                                     std::string& split) {
    std::optional<RaySample> sample;
    if (wants(opt, Estimator::Segments)) {
        // The sample is left out of the test rays, which are every other ray of the distribution.
        const auto start = std::chrono::steady_clock::now();
        if (!opt.sample_file.empty()) {
            sample = read_sample(opt.sample_file);
            if (sample->scene != 0 && sample->scene != scene.fingerprint())
                throw InputError(opt.sample_file, 0,
                                 "the sample was drawn on another scene (its primitives differ from " + scene.name + "'s)" +
                                     (sample->file_version == 2
                                          ? ", or before rtcost stored an NFF polygon of three vertices as a triangle "
                                            "(a version-2 sample file): draw it again with rtcost sample"
                                          : ""));
            if (sample->distribution != test.described || sample->population != test.rays.size())
                throw InputError(opt.sample_file, 0,
                                 "the sample was drawn from '" + sample->distribution + "' (" +
                                     std::to_string(sample->population) + " rays), the test rays are '" +
                                     test.described + "' (" + std::to_string(test.rays.size()) + " rays)");
        } else {
            // By default 2% of the rays, at most 4,096, and no fewer than 256 where there are enough.
            const std::size_t pop = test.rays.size();
            const std::size_t n = opt.segments > 0 ? opt.segments
                                                   : std::min<std::size_t>(4096, std::max(pop / 50, std::min<std::size_t>(256, pop / 4)));
            if (n == 0 || n >= test.rays.size())
                throw InputError("--sample", 0, "a sample of " + std::to_string(n) + " out of " +
                                                      std::to_string(test.rays.size()) + " rays leaves no test rays");
            auto reference = build_hierarchy(scene, "bvh-sah");
            sample = draw_sample_from(scene, test, n, opt.sample_seed, *reference, opt.query, opt.occlusion);
        }
        test = rays_outside_sample(test, sample->size(), sample->seed);
        seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        split = "sample";
    }
    return sample;
}
}  // namespace

EvalResult evaluate(const Scene& scene, const RaySpec& spec, const EvalOptions& opt) {
    RaySet test = make_rays(scene, spec);
    const std::size_t whole = test.rays.size();
    RaySet train;
    double sample_seconds = 0;
    std::string split = "none";
    std::optional<RaySample> sample = take_sample(scene, test, opt, sample_seconds, split);
    if (wants(opt, Estimator::Sampled)) {
        if (const RayDistributionInfo* d = find_ray_distribution(spec.name); d && d->seeded_draws) {
            // A fresh draw of the same distribution with another seed.
            RaySpec t = spec;
            t.seed = spec.seed + 7919;
            t.count = opt.sample;
            train = make_rays(scene, t);
            split = split == "none" ? "fresh draw" : split + " and fresh draw";
        } else {
            split_half(test, train, opt.sample);
            split = split == "none" ? "pseudo-random half" : split + " and pseudo-random half";
        }
    }
    EvalResult r = run(scene, std::move(test), train, sample ? &*sample : nullptr, opt, split);
    r.sample_seconds = sample_seconds;
    if (sample) r.sample_file = opt.sample_file;
    r.distribution_rays = whole;
    return r;
}

EvalResult evaluate(const Scene& scene, RaySet rays, const EvalOptions& opt) {
    const std::size_t whole = rays.rays.size();
    RaySet train;
    double sample_seconds = 0;
    std::string split = "none";
    std::optional<RaySample> sample = take_sample(scene, rays, opt, sample_seconds, split);
    if (wants(opt, Estimator::Sampled)) {
        split_half(rays, train, opt.sample);
        split = split == "none" ? "pseudo-random half" : split + " and pseudo-random half";
    }
    EvalResult r = run(scene, std::move(rays), train, sample ? &*sample : nullptr, opt, split);
    r.sample_seconds = sample_seconds;
    if (sample) r.sample_file = opt.sample_file;
    r.distribution_rays = whole;
    return r;
}

}  // namespace rtcost
