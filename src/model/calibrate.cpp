// Fitting nanoseconds per operation kind to measured times: the model's unit-cost table.
// Non-negative least squares (Lawson and Hanson's active-set method) is written here because
// the problem has at most twelve unknowns and no Debian-packaged C++ library offers NNLS; the
// normal equations of each passive set are solved by Gaussian elimination.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include "rtcost/error.hpp"
#include "rtcost/io.hpp"
#include "rtcost/model.hpp"

namespace rtcost {
namespace {

// box, plane, hop, classify, prims, per_ray, then the time model's step, box_simd, cache, box_pair
// and polygon_edge (timed, not fitted: polygon_edge_ns).
constexpr int kOps = 4 + kPrimKinds + 1;
constexpr int kStep = kOps, kBoxSimd = kOps + 1, kCache = kOps + 2, kBoxPair = kOps + 3, kEdge = kOps + 4,
              kUnknowns = kOps + 5;

}  // namespace

/// Nanoseconds per edge of the polygons' crossing test, timed here: regular polygons of 8 and 64
/// vertices, rays that meet their plane inside them (so the test walks every edge), the slope of
/// the fastest of several passes. Timed rather than fitted because few scenes have polygons of
/// more than four vertices: fitted on quads alone, an edge cannot be told from the rest of the
/// test, and gears' 144-gons (a test of one took 228 ns here, of a quad 12) were priced as quads.
double polygon_edge_ns() {
    struct Shape {
        std::vector<Vec3> pool;
        Polygon poly;
    };
    auto regular = [](std::uint32_t n) {
        Shape s;
        for (std::uint32_t i = 0; i < n; ++i) {
            const double a = 2 * std::numbers::pi * i / n;
            s.pool.push_back({float(std::cos(a)), float(std::sin(a)), 0.0f});
        }
        s.poly.count = n;
        s.poly.normal = {0, 0, 1};
        s.poly.drop_axis = 2;
        return s;
    };
    std::vector<Ray> rays;
    for (int i = 0; i < 1024; ++i) {
        Ray r;
        // Spread inside the inscribed circle of the octagon (radius cos(pi/8) > 0.9).
        const double a = 2.399963 * i, rad = 0.85 * std::sqrt((i + 0.5) / 1024.0);
        r.o = {float(rad * std::cos(a)), float(rad * std::sin(a)), 1.0f};
        r.d = {0.01f * float(i % 7), -0.01f * float(i % 5), -1.0f};
        rays.push_back(r);
    }
    volatile int hits = 0;
    auto pass = [&](const Shape& s) {
        const auto start = std::chrono::steady_clock::now();
        int h = 0;
        for (int rep = 0; rep < 8; ++rep)
            for (const Ray& r : rays) {
                float t;
                h += intersect(s.poly, s.pool, r, t);
            }
        hits = hits + h;
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() * 1e9 /
               (8.0 * rays.size());
    };
    // The two shapes alternate, and each keeps its fastest pass: a pass slowed by another
    // process or a frequency change is not kept.
    const Shape small = regular(8), large = regular(64);
    double best_small = 1e30, best_large = 1e30;
    for (int k = 0; k < 15; ++k) {
        best_small = std::min(best_small, pass(small));
        best_large = std::min(best_large, pass(large));
    }
    return std::max(0.0, (best_large - best_small) / 56.0);
}

namespace {

std::array<double, kUnknowns> row_of(const CalibrationSample& s, const TimeTerms& terms, const UnitCosts& shape) {
    const CostVector& c = s.ops;
    std::array<double, kUnknowns> r{};
    // Box tests made several at once: a SIMD node visit's (bvh-wide), a binary node's pair.
    const int lanes = terms.simd ? s.structure.box_lanes : 1;
    r[lanes >= 4 ? kBoxSimd : lanes == 2 ? kBoxPair : 0] = c.box;
    r[1] = c.plane;
    r[2] = c.hop;
    r[3] = c.classify;
    for (int k = 0; k < kPrimKinds; ++k) r[4 + k] = c.prim[k];
    r[kOps - 1] = 1;
    if (terms.steps) r[kStep] = c.steps;
    if (terms.cache) r[kCache] = c.steps * shape.cache_doublings(s.structure.bytes);
    return r;
}

/// Least squares restricted to the columns in `passive`; others are zero in the result.
std::vector<double> solve_passive(const std::vector<std::vector<double>>& a, const std::vector<double>& b,
                                  const std::vector<int>& passive, int n) {
    const int m = static_cast<int>(passive.size());
    std::vector<std::vector<double>> g(m, std::vector<double>(m + 1, 0.0));
    for (std::size_t r = 0; r < a.size(); ++r) {
        for (int i = 0; i < m; ++i) {
            for (int j = 0; j < m; ++j) g[i][j] += a[r][passive[i]] * a[r][passive[j]];
            g[i][m] += a[r][passive[i]] * b[r];
        }
    }
    for (int c = 0; c < m; ++c) {
        int piv = c;
        for (int r = c + 1; r < m; ++r)
            if (std::fabs(g[r][c]) > std::fabs(g[piv][c])) piv = r;
        std::swap(g[c], g[piv]);
        if (std::fabs(g[c][c]) < 1e-300) continue;  // singular column: leave it at zero
        for (int r = 0; r < m; ++r) {
            if (r == c) continue;
            double f = g[r][c] / g[c][c];
            for (int k = c; k <= m; ++k) g[r][k] -= f * g[c][k];
        }
    }
    std::vector<double> x(n, 0.0);
    for (int i = 0; i < m; ++i) x[passive[i]] = std::fabs(g[i][i]) < 1e-300 ? 0.0 : g[i][m] / g[i][i];
    return x;
}

std::vector<double> nnls(const std::vector<std::vector<double>>& a, const std::vector<double>& b,
                         const std::vector<bool>& usable) {
    const int n = static_cast<int>(usable.size());
    std::vector<double> x(n, 0.0);
    std::vector<bool> in_p(n, false);
    auto gradient = [&] {
        std::vector<double> w(n, 0.0);
        for (std::size_t r = 0; r < a.size(); ++r) {
            double res = b[r];
            for (int j = 0; j < n; ++j) res -= a[r][j] * x[j];
            for (int j = 0; j < n; ++j) w[j] += a[r][j] * res;
        }
        return w;
    };
    for (int outer = 0; outer < 3 * n; ++outer) {
        std::vector<double> w = gradient();
        int best = -1;
        for (int j = 0; j < n; ++j)
            if (usable[j] && !in_p[j] && w[j] > 1e-12 && (best < 0 || w[j] > w[best])) best = j;
        if (best < 0) break;
        in_p[best] = true;
        for (int inner = 0; inner < 3 * n; ++inner) {
            std::vector<int> passive;
            for (int j = 0; j < n; ++j)
                if (in_p[j]) passive.push_back(j);
            std::vector<double> z = solve_passive(a, b, passive, n);
            bool feasible = true;
            for (int j : passive) feasible &= z[j] > 0;
            if (feasible) {
                x = z;
                break;
            }
            double alpha = 1;
            for (int j : passive)
                if (z[j] <= 0) alpha = std::min(alpha, x[j] / (x[j] - z[j]));
            for (int j = 0; j < n; ++j) x[j] += alpha * (z[j] - x[j]);
            for (int j : passive)
                if (x[j] <= 1e-12) {
                    in_p[j] = false;
                    x[j] = 0;
                }
        }
    }
    return x;
}

}  // namespace

double cache_size_bytes() {
    const long l2 = sysconf(_SC_LEVEL2_CACHE_SIZE);
    return l2 > 0 ? double(l2) : double(1 << 20);
}

Calibration calibrate(std::span<const CalibrationSample> samples, const TimeTerms& terms, double cache_bytes,
                      double edge_ns) {
    UnitCosts shape;  // carries the cache size the cache term's column is computed with
    shape.cache_bytes = cache_bytes > 0 ? cache_bytes : cache_size_bytes();
    std::vector<bool> usable(kUnknowns, false);
    std::vector<std::vector<double>> a;
    std::vector<double> b;
    // The edges' time is known before the fit: the rest of each run's time is fitted.
    const double edge = !terms.edges ? 0.0 : edge_ns >= 0 ? edge_ns : polygon_edge_ns();
    for (const CalibrationSample& s : samples) {
        if (!(s.ns_per_ray > 0) || !std::isfinite(s.ns_per_ray))
            throw InputError("calibrate", 0, "sample '" + s.label + "' has no positive time");
        auto r = row_of(s, terms, shape);
        // Relative weighting: divide each equation by the measured time.
        std::vector<double> row(kUnknowns);
        for (int j = 0; j < kUnknowns; ++j) {
            row[j] = r[j] / s.ns_per_ray;
            usable[j] = usable[j] || r[j] > 0;
        }
        a.push_back(std::move(row));
        b.push_back(1.0 - edge * s.ops.polygon_edges / s.ns_per_ray);
    }
    int fitted = static_cast<int>(std::count(usable.begin(), usable.end(), true));
    if (static_cast<int>(samples.size()) < fitted)
        throw InputError("calibrate", 0,
                         "need at least " + std::to_string(fitted) + " runs (hierarchy x scene) to fit " +
                             std::to_string(fitted) + " unit costs, have " + std::to_string(samples.size()) +
                             " (measure more scenes or hierarchies, or fit fewer terms)");
    std::vector<double> x = nnls(a, b, usable);
    // The primitive prices are then fitted again, each pulled toward the mean of the kinds the
    // runs test, as hard as the runs' own scatter: the pull's rows weigh the fit's rms relative
    // residual, so that a price moving by the whole mean costs as much as a run of typical error.
    // Runs a time model explains exactly are not pulled at all; noisy runs that fix a price poorly
    // (spheres tested only beside cones, in lattice and tree: the sum is fixed, not each) leave
    // it near the other kinds' instead of wherever the noise put it. Fitted on docs/time-model.md's
    // second half without the pull, spheres came out at 4.5 ns, and shells (all spheres) was
    // ranked with rho 0.81; a loop timing each kind is no prior (a triangle alone in a loop took
    // 36 ns, with the per-ray shear and cache misses a traversal does not pay per test).
    // A kind priced at 0 by NNLS (one the runs cannot tell from another) is pulled at least with
    // weight 0.1 however well the runs fit.
    std::vector<int> kinds;
    bool clamped = false;
    double mean = 0;
    for (int k = 0; k < kPrimKinds; ++k)
        if (usable[4 + k]) {
            kinds.push_back(4 + k);
            clamped |= !(x[4 + k] > 0);
            mean += x[4 + k];
        }
    mean /= std::max<std::size_t>(kinds.size(), 1);
    double scatter = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        double r = -b[i];
        for (int j = 0; j < kUnknowns; ++j) r += a[i][j] * x[j];
        scatter += r * r;
    }
    scatter = a.empty() ? 0.0 : std::sqrt(scatter / a.size());
    constexpr double kClampedPull = 0.1;
    const double pull = std::max(scatter, clamped ? kClampedPull : 0.0);
    if (pull > 1e-9 && kinds.size() >= 2 && mean > 0) {
        for (int k : kinds) {
            std::vector<double> row(kUnknowns, 0.0);
            for (int j : kinds) row[j] = -pull / (kinds.size() * mean);
            row[k] += pull / mean;
            a.push_back(std::move(row));
            b.push_back(0.0);
        }
        x = nnls(a, b, usable);
    }
    Calibration c;
    c.costs.box = x[0];
    c.costs.plane = x[1];
    c.costs.hop = x[2];
    c.costs.classify = x[3];
    for (int k = 0; k < kPrimKinds; ++k) c.costs.prim[k] = x[4 + k];
    c.costs.per_ray = x[kOps - 1];
    c.costs.step = x[kStep];
    c.costs.box_simd = usable[kBoxSimd] ? x[kBoxSimd] : -1;
    c.costs.box_pair = usable[kBoxPair] ? x[kBoxPair] : -1;
    // No run tests a box on its own (bvh-gs's nodes do, and the cell structures' and rc5d's clip
    // of each ray to the root box): a box test priced without knowing the structure costs what
    // the runs' box tests cost.
    if (!usable[0]) c.costs.box = usable[kBoxPair] ? x[kBoxPair] : usable[kBoxSimd] ? x[kBoxSimd] : 0.0;
    c.costs.cache = x[kCache];
    c.costs.polygon_edge = edge;
    c.costs.cache_bytes = shape.cache_bytes;
    c.costs.calibrated = true;
    c.fitted = usable;
    c.fitted[kEdge] = terms.edges;  // timed, whatever the runs tested
    double sum2 = 0;
    for (const CalibrationSample& s : samples) {
        double p = c.costs.scalar(s.ops, s.structure);
        c.predicted.push_back(p);
        double rel = (p - s.ns_per_ray) / s.ns_per_ray;
        sum2 += rel * rel;
    }
    c.rms_relative = samples.empty() ? 0.0 : std::sqrt(sum2 / samples.size());
    return c;
}

void write_costs(const std::string& path, const Calibration& c, std::span<const CalibrationSample> samples) {
    nlohmann::json prim = nlohmann::json::object();
    for (int k = 0; k < kPrimKinds; ++k) prim[std::string(prim_kind_name(static_cast<PrimKind>(k)))] = c.costs.prim[k];
    nlohmann::json fits = nlohmann::json::array();
    for (std::size_t i = 0; i < samples.size(); ++i)
        fits.push_back({{"run", samples[i].label},
                        {"measured_ns_per_ray", samples[i].ns_per_ray},
                        {"fitted_ns_per_ray", c.predicted[i]}});
    nlohmann::json j = {{"unit", "ns"},       {"box", c.costs.box},           {"plane", c.costs.plane},
                        {"hop", c.costs.hop}, {"classify", c.costs.classify}, {"prim", prim},
                        {"per_ray", c.costs.per_ray}, {"step", c.costs.step},
                        {"box_simd", c.costs.box_simd >= 0 ? nlohmann::json(c.costs.box_simd) : nlohmann::json(nullptr)},
                        {"box_pair", c.costs.box_pair >= 0 ? nlohmann::json(c.costs.box_pair) : nlohmann::json(nullptr)},
                        {"cache", c.costs.cache}, {"cache_bytes", c.costs.cache_bytes},
                        {"polygon_edge", c.costs.polygon_edge},
                        {"rms_relative_residual", c.rms_relative},
                        {"runs", fits}};
    write_file_atomic(path, j.dump(2) + "\n");
}

}  // namespace rtcost
