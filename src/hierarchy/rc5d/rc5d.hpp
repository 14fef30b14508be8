#pragma once
// `rc5d`: Arvo and Kirk's ray classification (SIGGRAPH 1987). Rays, not points, are partitioned:
// a ray is a point of 5D space, its origin (x, y, z) and its direction (u, v) on the face of the
// direction cube of its dominant axis. Six direction cubes (dominant axis k = argmax |d_i|, ties
// to the lowest axis, and its sign s) each own a 5D hypercube: the scene box times [-1, 1]^2 with
// u = d_i1 / |d_k|, v = d_i2 / |d_k| (i1 < i2 the other two axes). A hypercube is halved at the
// midpoint of one dimension per level, cycling x, y, z, u, v, until it holds at most `max_prims`
// candidates or `max_depth` levels are reached. A hypercube's candidates are those of its parent
// that meet its beam, the set of points o + h w (o in the origin box, h >= 0, w = (s, u, v)),
// by an exact interval test against the primitive's bounding box (Rc5d::beam_meets).
//
// A query clips the ray to the scene box (one `box`); a ray that misses costs nothing more. The
// origin is moved to the box entry (kept when it starts inside or at tmin); hit.t stays in the
// caller's parameterisation. Then one path of compares: 3 `classify` for the cube (2 compares
// find the dominant axis, 1 its sign), counted with `interior(0)` for the tree's root, then one
// `classify` and one `interior(depth)` per 5D node on the path (a cube is at depth 1), then
// `leaf(depth, n)` at the beam. Its candidates are sorted by their start along the dominant
// axis (the near face of the bounding box); the search stops once the current hit (or tmax) is
// not beyond the next candidate's start, measured from the ray's own origin. `prim` counts every
// candidate tested. Query::All tests every candidate of the beam. A ray with a zero (or NaN)
// direction stops after the clip, with no hit.
//
// Robustness: the ray's 5D point is rounded, and the primitives' hits are computed in float. So
// the beam test pads the origin box and every primitive box by `pad_` (1e-5 of the scene's
// coordinate scale) and (u, v) by 1e-6, the stopping test keeps a relative margin, and the
// entry point is computed in double. Every ray of a hypercube, on its closed boundary included,
// finds every primitive it can hit in its beam's list.
//
// Lazy build (the default, as Arvo and Kirk did it): a hypercube is subdivided the first time a
// ray reaches it. Subdivision depends only on the hypercube and its parent's list, never on the
// ray that triggers it, so lazy and eager builds agree on every node a ray visits and give the
// same hits and counters, unless the memory cap `max_bytes` is reached: the cap stops
// subdivision (a node then stays a leaf with its own list), and which nodes were built before
// the cap was hit depends on the build order (eager: breadth first; lazy: ray order and thread
// timing). The six cube lists and the per-primitive tables are always built, even above the cap.
// Expansion is made thread-safe by a striped mutex per node and an atomic state published with
// release/acquire; the parent's candidate list is freed once its children exist. structure() and
// model_tree() describe what has been built so far and must not run concurrently with queries.

#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string_view>
#include <vector>

#include "../common/impl.hpp"

namespace rtcost::rc5d {

/// Deepest subdivision level below a direction cube accepted for `max_depth`.
inline constexpr int kMaxDepth = 60;

struct Options {
    int max_prims = 8;   ///< a hypercube with at most this many candidates is a leaf
    /// Subdivision levels below a cube (6 full cycles of x, y, z, u, v). 30 rather than 20: with
    /// 20 levels, SPD scenes under camera rays still test 40 to 2000 candidates per ray.
    int max_depth = 30;
    bool lazy = true;    ///< subdivide on the first visit (true) or all at build time
    std::uint64_t max_bytes = std::uint64_t{1} << 30;  ///< memory cap stopping subdivision (>= 1)
    /// The cap asked for where it was lowered to half the machine's memory (0: max_bytes was
    /// asked), so that the structure's limits say so if the lower cap stops the subdivision.
    std::uint64_t asked_max_bytes = 0;
};

/// A 5D hypercube: dimensions 0..2 the origin box, 3 = u, 4 = v.
struct Cell {
    float lo[5], hi[5];
    Box3 origin_box() const { return {{lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}}; }
};

enum : std::uint8_t { kPending = 0, kLeaf = 1, kInterior = 2 };

/// A hypercube. Pending: holds its candidates, to be subdivided on the first visit. Leaf: holds
/// its candidates for good. Interior: split at `split` on dimension (level % 5); kids[0] below,
/// kids[1] at or above; its own list has been freed.
struct Node {
    std::atomic<std::uint8_t> state{kPending};
    float split = 0;
    std::uint32_t count = 0;                  ///< candidates (leaf and pending)
    std::unique_ptr<std::uint32_t[]> refs;    ///< candidates, ascending start along the dominant axis
    std::unique_ptr<Node[]> kids;             ///< interior: two children
};

class Rc5d final : public HierarchyImpl<Rc5d> {
public:
    Rc5d(const Scene& s, const Options& o);

    std::string_view name() const override { return "rc5d"; }
    bool emit_model(ModelSink& sink) const override;
    bool lazy() const override { return opt_.lazy; }

    const Options& options() const { return opt_; }
    /// Memory currently held, as accounted against `max_bytes` (equals structure().bytes).
    std::uint64_t held_bytes() const { return bytes_.load(std::memory_order_relaxed); }
    /// The absolute padding of origin and primitive boxes in the beam test.
    double pad() const { return pad_; }
    /// Cube of dominant axis k and sign: 2k for +, 2k+1 for -.
    static int cube_index(int k, bool negative) { return 2 * k + (negative ? 1 : 0); }
    /// True when some ray of `cell` in cube `cube` can meet the padded box `b` (exact interval
    /// test on the beam, with the origin box padded by `pad` and (u, v) by kPadUV).
    static bool beam_meets(const Cell& cell, int cube, const Box3& b, double pad);

    template <class C, Query Q>
    bool trace(const Ray& ray, Hit& hit, C& counting) const {
        return trace_with<C, Q>(ray, hit, counting, RealPrimTest{*scene_});
    }

    /// The traversal with the primitive test supplied by the caller: RealPrimTest in a trace,
    /// CrossingCollector for Hierarchy::crossings, KnownTest for Hierarchy::replay.
    template <class C, Query Q, class PrimTest>
    bool trace_with(const Ray& ray, Hit& hit, C& counting, PrimTest test) const {
        counting.box();
        if (empty_) return false;
        const RayInv ri(ray);
        if (box_entry(box_, ri.o, ri.inv, ray.tmin, ray.tmax) == kInf) return false;
        const int k = max_axis(ray.d);
        const float dk = ray.d[k];
        const float adk = std::fabs(dk);
        if (!(adk > 0)) return false;  // no direction (or NaN): nothing to classify
        // Cube selection: two compares find the dominant axis, one its sign.
        counting.classify();
        counting.classify();
        counting.classify();
        counting.interior(0);
        const bool neg = dk < 0;
        const int cube = cube_index(k, neg);
        float x[5];
        entry_point(ray, x);
        const int i1 = k == 0 ? 1 : 0, i2 = k == 2 ? 1 : 2;
        x[3] = ray.d[i1] / adk;  // |u|, |v| <= 1 exactly: division is correctly rounded
        x[4] = ray.d[i2] / adk;

        Node* n = &cubes_[cube];
        Cell cell = root_;
        int level = 0;
        for (;;) {
            std::uint8_t st = n->state.load(std::memory_order_acquire);
            if (st == kPending) [[unlikely]]
                st = expand(*n, cell, level, cube);
            if (st == kLeaf) break;
            counting.classify();
            counting.interior(level + 1);
            const int dim = level % 5;
            const float split = n->split;
            const bool high = x[dim] >= split;
            if (high) cell.lo[dim] = split;
            else cell.hi[dim] = split;
            n = &n->kids[high ? 1 : 0];
            ++level;
        }
        const std::uint32_t count = n->count;
        const std::uint32_t* refs = n->refs.get();
        counting.leaf(level + 1, count);

        bool found = false;
        if constexpr (Q == Query::All) {
            for (std::uint32_t i = 0; i < count; ++i)
                if (test(refs[i], ray, hit, counting)) found = true;
            return found;
        } else {
            // Candidate i can only be hit at a dominant coordinate (forward, s * p_k) at or beyond
            // near[i]; the current hit lies at s * o_k + t |d_k|. Stop once the next start is
            // beyond the hit (or the segment's end), with a relative margin for float hits.
            const float* near = near_[cube].data();
            const double so = neg ? -static_cast<double>(ray.o[k]) : static_cast<double>(ray.o[k]);
            auto stop_at = [&](float t) {
                if (!(t < kInf)) return static_cast<double>(kInf);
                const double dist = static_cast<double>(t) * adk;
                return so + dist + kStopMargin * (std::fabs(so) + std::fabs(dist));
            };
            double stop = stop_at(hit.t < ray.tmax ? hit.t : ray.tmax);
            for (std::uint32_t i = 0; i < count; ++i) {
                const std::uint32_t id = refs[i];
                if (static_cast<double>(near[id]) > stop) break;
                if (test(id, ray, hit, counting)) {
                    found = true;
                    if constexpr (Q == Query::Any) return true;
                    stop = stop_at(hit.t < ray.tmax ? hit.t : ray.tmax);
                }
            }
            return found;
        }
    }

protected:
    StructureStats compute_structure() const override;

private:
    static constexpr double kPadRel = 1e-5;       ///< box padding, relative to the coordinate scale
    static constexpr double kStopMargin = 1e-5;   ///< relative margin of the stopping test
    static constexpr double kPadUV = 1e-6;        ///< (u, v) padding (their rounding is < 6e-8)

    // The origin used for classification: the ray's point at max(tmin, box entry), computed in
    // double and clamped to the scene box.
    void entry_point(const Ray& ray, float x[3]) const {
        double t0 = ray.tmin;
        for (int a = 0; a < 3; ++a) {
            if (ray.d[a] == 0) continue;
            const double bound = ray.d[a] > 0 ? box_.lo[a] : box_.hi[a];
            const double t = (bound - static_cast<double>(ray.o[a])) / static_cast<double>(ray.d[a]);
            if (t > t0) t0 = t;
        }
        for (int a = 0; a < 3; ++a) {
            double p = static_cast<double>(ray.o[a]);
            if (ray.d[a] != 0) p += t0 * static_cast<double>(ray.d[a]);
            p = p < box_.lo[a] ? box_.lo[a] : (p > box_.hi[a] ? box_.hi[a] : p);
            x[a] = static_cast<float>(p);
        }
    }

    /// Subdivides a pending node (under its stripe lock) and returns its new state.
    std::uint8_t expand(Node& n, const Cell& cell, int level, int cube) const;
    /// Splits `n` into two children; false (nothing changed) when the memory cap forbids it.
    bool subdivide(Node& n, const Cell& cell, int level, int cube) const;
    /// Gives `n` its candidates and its initial state at `level`.
    void init_node(Node& n, std::vector<std::uint32_t>&& ids, int level) const;
    void build_eager();

    Box3 box_;
    bool empty_ = false;
    Options opt_;
    double pad_ = 0;
    Cell root_{};
    std::vector<Box3> pbox_;                     ///< padded primitive bounds
    std::array<std::vector<float>, 6> near_;     ///< per cube: forward start of each padded box
    mutable std::array<Node, 6> cubes_;
    mutable std::array<std::mutex, 64> locks_;
    mutable std::atomic<std::uint64_t> bytes_{0};
    mutable std::atomic<bool> capped_{false};  ///< the cap refused a subdivision
};

}  // namespace rtcost::rc5d
