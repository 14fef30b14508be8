#pragma once
// `grid`: Fujimoto's uniform grid (ARTS) traversed by the 3DDDA of Amanatides and Woo.
//
// The grid box is the scene's bounding box. Cells hold primitive references in a compact CSR
// layout (one offset per cell plus one id array). Cell boundaries are one float array per axis
// (`planes_`), used both to build the cells (reference assignment) and to step the ray, so
// that the cells a primitive is referenced by and the cells a ray visits agree bit for bit.
//
// Counters per ray: one `box` (clip to the grid box); when the ray enters the box one
// `interior(0)` (the grid itself, depth 0); one `leaf(1, n)` per cell visited; one `hop` per
// 3DDDA step to a next cell inside the grid (so hops = cells visited - 1); one `prim` per
// primitive test (with mailbox=1 only real tests are counted).

#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "../common/spatial.hpp"
#include "../common/impl.hpp"

namespace rtcost::grid {

/// Largest resolution on one axis.
inline constexpr int kMaxRes = 1024;
/// Largest cell count (2^24 = 256^3 cells: 64 MB of offsets). Formula resolutions above it are
/// scaled down uniformly; an explicit AxBxC above it is an error.
inline constexpr std::uint64_t kMaxCells = std::uint64_t{1} << 24;
/// For the formulas, an axis shorter than this fraction of the longest is flat (one cell); an
/// explicit AxBxC keeps its resolution except on an axis of zero extent.
inline constexpr double kFlat = 1e-6;

/// Grid resolution for `spec` (regular, woo, hetero or AxBxC), density `density` (cells per
/// primitive, see the registration's help), `n` primitives, scene box `box`. Throws InputError
/// naming `res` for a bad spec.
std::array<int, 3> resolution(std::string_view spec, double density, std::size_t n, const Box3& box);

class Grid final : public HierarchyImpl<Grid> {
public:
    Grid(const Scene& s, std::array<int, 3> res, spatial::Assign assign, bool mailbox);
    /// The same grid from the primitives' bounds (spatial::prim_bounds), computed
    /// once for the several grids of a search.
    Grid(const Scene& s, std::array<int, 3> res, spatial::Assign assign, bool mailbox, std::span<const Box3> bounds);

    std::string_view name() const override { return "grid"; }
    bool emit_model(ModelSink& sink) const override;

    const std::array<int, 3>& res() const { return res_; }
    std::uint64_t cell_count() const { return offsets_.size() - 1; }
    /// Cell boundaries on `axis`: res + 1 non-decreasing values from box.lo to box.hi.
    std::span<const float> planes(int axis) const { return planes_[axis]; }
    /// Primitive ids referenced by cell (i, j, k), ascending.
    std::span<const std::uint32_t> cell(int i, int j, int k) const {
        std::uint64_t c = cell_index(i, j, k);
        return {refs_.data() + offsets_[c], refs_.data() + offsets_[c + 1]};
    }
    Box3 cell_box(int i, int j, int k) const {
        return {{planes_[0][i], planes_[1][j], planes_[2][k]}, {planes_[0][i + 1], planes_[1][j + 1], planes_[2][k + 1]}};
    }

    template <class C, Query Q>
    bool trace(const Ray& ray, Hit& hit, C& counting) const {
        return trace_with<C, Q>(ray, hit, counting, RealPrimTest{*scene_});
    }

    /// Whether Hierarchy::replay is the model tree's prediction: not with mailboxes, which the
    /// model does not know.
    bool replay_is_model() const { return !mailbox_; }

    /// The traversal with the primitive test supplied by the caller: `test(id, ray, hit,
    /// counting)` counts its test, records a hit nearer than `hit.t` and says whether it found
    /// one (design/replay.hpp).
    template <class C, Query Q, class PrimTest>
    bool trace_with(const Ray& ray, Hit& hit, C& counting, PrimTest&& test) const {
        return mailbox_ ? walk<C, Q, true>(ray, hit, counting, test) : walk<C, Q, false>(ray, hit, counting, test);
    }

protected:
    StructureStats compute_structure() const override;

private:
    /// Most references per primitive (and at least kMinRefBudget in all) before the resolution
    /// is reduced; see limit_references.
    static constexpr std::uint64_t kRefsPerPrim = 16, kMinRefBudget = std::uint64_t{1} << 20;
    /// Expected primitive tests per ray, in units of the primitive count, before the
    /// resolution is reduced; see limit_references.
    static constexpr int kTestsPerPrim = 2, kMinTests = 64;
    void limit_references(std::span<const Box3> bounds);
    std::vector<std::string> limits_;

    std::uint64_t cell_index(int i, int j, int k) const {
        return static_cast<std::uint64_t>(i) +
               static_cast<std::uint64_t>(res_[0]) * (static_cast<std::uint64_t>(j) + static_cast<std::uint64_t>(res_[1]) * k);
    }

    // Ray parameter where the ray crosses boundary `j` of `axis`; the same expression as the
    // slab test in box_entry, so the box faces give exactly the slab test's values.
    float cross(int axis, int j, const RayInv& ri) const { return (planes_[axis][j] - ri.o[axis]) * ri.inv[axis]; }

    // Cell index on `axis` from a position, clamped to the grid (a first guess, refined by the
    // caller against the planes). NaN and infinities clamp too.
    int guess(int axis, float pos) const {
        float f = (pos - box_.lo[axis]) * inv_cell_[axis];
        if (!(f >= 0)) return 0;
        if (f >= static_cast<float>(res_[axis])) return res_[axis] - 1;
        return static_cast<int>(f);
    }

    template <class C, Query Q, bool kMailbox, class PrimTest>
    bool walk(const Ray& ray, Hit& hit, C& counting, PrimTest& test) const {
        counting.box();
        if (empty_) return false;
        const RayInv ri(ray);
        const float t0 = box_entry(box_, ri.o, ri.inv, ray.tmin, ray.tmax);
        if (t0 == kInf) return false;
        counting.interior(0);  // the grid itself, entered

        // Start cell from the entry parameter, in t rather than in space: on each axis the cell
        // whose crossing interval holds t0, computed with the very crossings the 3DDDA uses below,
        // so rounding can neither skip the first cell nor disagree with the stepping. On a tie
        // (t0 exactly on a boundary) the cell being entered is taken.
        int idx[3], step[3];
        float tnext[3];
        for (int a = 0; a < 3; ++a) {
            const int r = res_[a];
            // A component whose reciprocal overflows (|d| below about 3e-39, a denormal) is taken
            // as parallel to the axis, as the slab test (box_entry) and so every box-based
            // hierarchy takes it; stepping it would give NaN crossings (0 * inf) that misorder
            // the exits and skip cells.
            const bool moves = std::isfinite(ri.inv[a]);
            if (moves && ray.d[a] > 0) {
                int i = guess(a, ri.o[a] + t0 * ri.d[a]);
                while (i < r - 1 && cross(a, i + 1, ri) <= t0) ++i;
                while (i > 0 && cross(a, i, ri) > t0) --i;
                idx[a] = i;
                step[a] = 1;
                tnext[a] = cross(a, i + 1, ri);
            } else if (moves && ray.d[a] < 0) {
                int i = guess(a, ri.o[a] + t0 * ri.d[a]);
                while (i > 0 && cross(a, i, ri) <= t0) --i;
                while (i < r - 1 && cross(a, i + 1, ri) > t0) ++i;
                idx[a] = i;
                step[a] = -1;
                tnext[a] = cross(a, i, ri);
            } else {
                // Never crosses a plane of this axis: the cell holding the origin (on a plane
                // either neighbour holds every primitive touching that plane: closed intervals).
                const float* pl = planes_[a].data();
                int i = guess(a, ri.o[a]);
                while (i < r - 1 && pl[i + 1] <= ri.o[a]) ++i;
                while (i > 0 && pl[i] > ri.o[a]) --i;
                idx[a] = i;
                step[a] = 0;
                tnext[a] = kInf;
            }
        }

        spatial::Mailbox* mb = nullptr;
        if constexpr (kMailbox) mb = &spatial::Mailbox::begin_ray(this, scene_->size());
        const std::int64_t stride[3] = {1, res_[0], static_cast<std::int64_t>(res_[0]) * res_[1]};
        std::int64_t c = static_cast<std::int64_t>(cell_index(idx[0], idx[1], idx[2]));
        bool found = false;
        for (;;) {
            const std::uint32_t b = offsets_[c], e = offsets_[c + 1];
            counting.leaf(1, e - b);
            for (std::uint32_t k = b; k < e; ++k) {
                const std::uint32_t id = refs_[k];
                if constexpr (kMailbox) {
                    if (!mb->first_visit(id)) continue;
                }
                if (test(id, ray, hit, counting)) {
                    found = true;
                    if constexpr (Q == Query::Any) return true;
                }
            }
            // Exit through the nearest boundary; ties go to the lowest axis (a corner is passed
            // one axis at a time, visiting a cell that the ray touches in a point).
            const int a = tnext[0] <= tnext[1] ? (tnext[0] <= tnext[2] ? 0 : 2) : (tnext[1] <= tnext[2] ? 1 : 2);
            const float t_exit = tnext[a];
            // A hit up to and including the exit lies in this cell (closed): nothing later is nearer.
            if constexpr (Q != Query::All) {
                if (hit.t <= t_exit) return found;
            }
            if (t_exit >= ray.tmax) return found;  // the segment ends in this cell
            idx[a] += step[a];
            if (idx[a] < 0 || idx[a] >= res_[a]) return found;  // left the grid
            counting.hop();
            c += step[a] * stride[a];
            tnext[a] = cross(a, step[a] > 0 ? idx[a] + 1 : idx[a], ri);
        }
    }

    Box3 box_;
    bool empty_ = false;
    std::array<int, 3> res_{1, 1, 1};
    std::array<std::vector<float>, 3> planes_;
    Vec3 inv_cell_;                       ///< res / extent per axis, 0 on a flat axis
    std::vector<std::uint32_t> offsets_;  ///< cell c holds refs_[offsets_[c] .. offsets_[c+1])
    std::vector<std::uint32_t> refs_;
    bool mailbox_;
};

}  // namespace rtcost::grid
