// `grid`: resolution formulas, the build (CSR cell references), structure statistics, the
// model tree and the registration.
#include "grid.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

#include "rtcost/error.hpp"

namespace rtcost::grid {
namespace {

[[noreturn]] void bad_res(std::string_view spec, const std::string& why) {
    throw InputError("--set", 0, fmt::format("res={}: {}", spec, why));
}

// "AxBxC" with each part an integer in [1, kMaxRes].
std::array<int, 3> parse_explicit(std::string_view spec) {
    std::array<int, 3> r{};
    std::size_t pos = 0;
    for (int a = 0; a < 3; ++a) {
        std::size_t end = a < 2 ? spec.find('x', pos) : spec.size();
        if (end == std::string_view::npos) bad_res(spec, "expected regular, woo, hetero or AxBxC");
        std::string_view part = spec.substr(pos, end - pos);
        long long v = 0;
        auto [p, ec] = std::from_chars(part.data(), part.data() + part.size(), v);
        if (part.empty() || ec != std::errc() || p != part.data() + part.size())
            bad_res(spec, "expected regular, woo, hetero or AxBxC");
        if (v < 1 || v > kMaxRes) bad_res(spec, fmt::format("each resolution must be in [1, {}]", kMaxRes));
        r[a] = static_cast<int>(v);
        pos = end + 1;
    }
    return r;
}

std::uint64_t product(const std::array<int, 3>& r) {
    return static_cast<std::uint64_t>(r[0]) * static_cast<std::uint64_t>(r[1]) * static_cast<std::uint64_t>(r[2]);
}

// Clamp to [1, kMaxRes] in double first (formulas can overflow int), then shrink uniformly
// until the cell count is within kMaxCells.
std::array<int, 3> clamp_res(const std::array<double, 3>& v) {
    std::array<int, 3> r{};
    for (int a = 0; a < 3; ++a) r[a] = static_cast<int>(std::clamp(std::isfinite(v[a]) ? v[a] : double(kMaxRes), 1.0, double(kMaxRes)));
    if (product(r) > kMaxCells) {
        const double s = std::cbrt(static_cast<double>(kMaxCells) / static_cast<double>(product(r)));
        for (int a = 0; a < 3; ++a) r[a] = std::max(1, static_cast<int>(std::floor(r[a] * s + 1e-9)));
        while (product(r) > kMaxCells) --*std::max_element(r.begin(), r.end());
    }
    return r;
}

}  // namespace

std::array<int, 3> resolution(std::string_view spec, double density, std::size_t n, const Box3& box) {
    const bool formula = spec == "regular" || spec == "woo" || spec == "hetero";
    std::array<int, 3> explicit_res{1, 1, 1};
    if (!formula) {
        explicit_res = parse_explicit(spec);
        if (product(explicit_res) > kMaxCells)
            bad_res(spec, fmt::format("{} cells exceed the limit of {}", product(explicit_res), kMaxCells));
    }
    if (box.empty() || n == 0) return {1, 1, 1};
    std::array<double, 3> ext{};
    for (int a = 0; a < 3; ++a) ext[a] = static_cast<double>(box.hi[a]) - box.lo[a];
    const double max_ext = std::max({ext[0], ext[1], ext[2]});
    if (!(max_ext > 0)) return {1, 1, 1};

    if (!formula) {
        // The user's resolution, except that a zero-extent axis has nothing to subdivide.
        for (int a = 0; a < 3; ++a)
            if (!(ext[a] > 0)) explicit_res[a] = 1;
        return explicit_res;
    }

    std::array<bool, 3> flat{};
    for (int a = 0; a < 3; ++a) flat[a] = ext[a] <= kFlat * max_ext;
    const double dn = density * static_cast<double>(n);
    std::array<double, 3> v{1, 1, 1};
    if (spec == "regular") {
        // As the issue states it: D scales the per-axis count, round(D * N^(1/3)).
        const double k = std::round(density * std::cbrt(static_cast<double>(n)));
        v = {k, k, k};
    } else if (spec == "woo") {
        // L = (D N)^(1/3); res_i = max(1, floor(size_i / max_size * L)). The 1e-9 keeps exact
        // products (a cube of 1000 primitives) from losing a cell to rounding in cbrt.
        const double l = std::cbrt(dn);
        for (int a = 0; a < 3; ++a) v[a] = std::max(1.0, std::floor(ext[a] / max_ext * l + 1e-9));
    } else {
        // Klimaszewski: cells as cubic as possible, about D N of them. A flat axis would divide
        // by zero (or blow x and y up for a nearly flat one); it gets one cell, and in the
        // formulas the extent that makes that one cell cubic: the cell size c of the lower-
        // dimensional problem, c = (product of the other extents / D N)^(1/k). With it the
        // formulas reduce exactly to the 2D (1D) ones.
        std::array<double, 3> s = ext;
        double vol = 1;
        int k = 0;
        for (int a = 0; a < 3; ++a)
            if (!flat[a]) { vol *= ext[a]; ++k; }
        const double c = std::pow(vol / dn, 1.0 / k);
        for (int a = 0; a < 3; ++a)
            if (flat[a]) s[a] = c;
        const double x = std::max(1.0, std::round(std::cbrt(dn * s[0] * s[0] / (s[1] * s[2]))));
        const double y = std::max(1.0, std::round(std::sqrt(dn * s[1] / (x * s[2]))));
        const double z = std::max(1.0, std::round(dn / (x * y)));
        v = {x, y, z};
    }
    for (int a = 0; a < 3; ++a)
        if (flat[a]) v[a] = 1;
    return clamp_res(v);
}

Grid::Grid(const Scene& s, std::array<int, 3> res, spatial::Assign assign, bool mailbox)
    : Grid(s, res, assign, mailbox, spatial::prim_bounds(s)) {}

Grid::Grid(const Scene& s, std::array<int, 3> res, spatial::Assign assign, bool mailbox, std::span<const Box3> bounds)
    : HierarchyImpl(s), box_(s.bounds()), empty_(s.empty() || s.bounds().empty()), res_(res), mailbox_(mailbox) {
    if (bounds.size() != s.size()) throw std::logic_error("grid: primitive bounds of another scene");
    if (empty_) {
        res_ = {1, 1, 1};
        box_ = Box3{{0, 0, 0}, {0, 0, 0}};
    } else {
        limit_references(bounds);
    }
    // Boundaries in double, rounded once: non-decreasing, first and last exactly the box faces.
    for (int a = 0; a < 3; ++a) {
        const int r = res_[a];
        const double lo = box_.lo[a], hi = box_.hi[a];
        planes_[a].resize(r + 1);
        for (int i = 0; i <= r; ++i) planes_[a][i] = static_cast<float>(lo + (hi - lo) * i / r);
        planes_[a][0] = box_.lo[a];
        planes_[a][r] = box_.hi[a];
        const float ext = box_.hi[a] - box_.lo[a];
        inv_cell_[a] = ext > 0 ? static_cast<float>(r) / ext : 0.0f;
    }

    // Every cell each primitive's box overlaps (closed intervals), primitives in id order. On
    // each axis: from the first cell whose upper boundary is >= the box's lo (the last cell if
    // none is) to the last whose lower boundary is <= its hi (the first if none is), found from
    // guess() by stepping along the planes (a cell or two at most) rather than by a binary search
    // over them, which was most of a grid's build (a grid-design search builds a score of grids):
    // the cells lower_bound and upper_bound find, NaN included.
    auto each_overlap = [&](auto&& f) {
        for (std::uint32_t id = 0; id < s.size(); ++id) {
            const Box3& pb = bounds[id];
            if (pb.empty()) continue;
            int lo[3], hi[3];
            for (int a = 0; a < 3; ++a) {
                const float* pl = planes_[a].data();
                const int r = res_[a];
                const float v0 = pb.lo[a], v1 = pb.hi[a];
                int i = guess(a, v0);
                while (i > 0 && !(pl[i] < v0)) --i;
                while (i < r - 1 && pl[i + 1] < v0) ++i;
                lo[a] = i;
                i = guess(a, v1);
                while (i > 0 && v1 < pl[i]) --i;
                while (i < r - 1 && !(v1 < pl[i + 1])) ++i;
                hi[a] = i;
            }
            for (int k = lo[2]; k <= hi[2]; ++k)
                for (int j = lo[1]; j <= hi[1]; ++j)
                    for (int i = lo[0]; i <= hi[0]; ++i) f(id, pb, i, j, k);
        }
    };
    const std::uint64_t cells = product(res_);
    offsets_.assign(cells + 1, 0);
    if (empty_) return;
    // Per-cell counts (offsets_[c + 1]) into CSR offsets, and room for `total` references.
    auto to_offsets = [&](std::uint64_t total) {
        if (total > std::numeric_limits<std::uint32_t>::max())
            throw InputError("--set", 0,
                             fmt::format("grid {}x{}x{} needs {} references, more than 2^32; choose a coarser resolution",
                                         res_[0], res_[1], res_[2], total));
        for (std::uint64_t c = 0; c < cells; ++c) offsets_[c + 1] += offsets_[c];
        refs_.resize(total);
        return std::vector<std::uint32_t>(offsets_.begin(), offsets_.end() - 1);  // each cell's next slot
    };
    if (assign == spatial::Assign::Bounds) {
        // The overlaps are every reference: count per cell, then fill, with no list of pairs (a
        // grid-design search builds a score of candidate grids, and the pairs' memory was most
        // of each build). Each cell's ids come out ascending.
        std::uint64_t total = 0;
        each_overlap([&](std::uint32_t, const Box3&, int i, int j, int k) {
            ++offsets_[cell_index(i, j, k) + 1];
            ++total;
        });
        std::vector<std::uint32_t> fill = to_offsets(total);
        each_overlap([&](std::uint32_t id, const Box3&, int i, int j, int k) { refs_[fill[cell_index(i, j, k)]++] = id; });
        return;
    }
    // Exact assignment: each surface test once, the references kept as (cell, id) pairs in id
    // order, then a counting sort into CSR (each cell's ids ascending).
    std::vector<std::uint64_t> pair_cell;
    std::vector<std::uint32_t> pair_id;
    each_overlap([&](std::uint32_t id, const Box3& pb, int i, int j, int k) {
        if (!spatial::overlaps(s, id, pb, cell_box(i, j, k), assign)) return;
        pair_cell.push_back(cell_index(i, j, k));
        pair_id.push_back(id);
    });
    for (std::uint64_t c : pair_cell) ++offsets_[c + 1];
    std::vector<std::uint32_t> fill = to_offsets(pair_id.size());
    for (std::size_t p = 0; p < pair_id.size(); ++p) refs_[fill[pair_cell[p]]++] = pair_id[p];
}

// Coincident primitives, or long thin ones spanning the scene, overlap nearly every cell: the
// references grow as cells x primitives (10,000 copies of a triangle: 400 MB, and every ray
// tests every copy in every cell). Two bounds, checked on the references the primitives' boxes
// imply: memory, at most kRefsPerPrim per primitive (or kMinRefBudget in all); and time, a ray
// crossing at most rx + ry + rz cells of average occupancy must not expect more than
// kTestsPerPrim times the N tests of brute force (nor kMinTests, for a handful of primitives). The resolution is reduced, all axes alike,
// until both hold; no SPD scene comes near either at the default density.
void Grid::limit_references(std::span<const Box3> bounds) {
    const Scene& s = *scene_;
    const std::uint64_t memory = std::max<std::uint64_t>(kMinRefBudget, kRefsPerPrim * s.size());
    auto budget = [&](const std::array<int, 3>& r) {
        const double tests = std::max(double(kTestsPerPrim) * double(s.size()), double(kMinTests));
        const double time = tests * double(product(r)) / double(r[0] + r[1] + r[2]);
        return std::min<double>(double(memory), time);
    };
    auto count = [&](const std::array<int, 3>& r, double limit) {
        // Per axis, once per count rather than per primitive (a division each).
        bool cut[3];
        double base[3], f[3], top[3];
        for (int a = 0; a < 3; ++a) {
            const double ext = double(box_.hi[a]) - box_.lo[a];
            cut[a] = ext > 0 && r[a] != 1;
            base[a] = box_.lo[a];
            f[a] = cut[a] ? r[a] / ext : 0;
            top[a] = r[a] - 1.0;
        }
        double total = 0;
        for (std::uint32_t id = 0; id < s.size() && total <= limit; ++id) {
            const Box3& pb = bounds[id];
            double n = 1;
            for (int a = 0; a < 3; ++a) {
                if (!cut[a]) continue;
                const double lo = std::clamp(std::floor((pb.lo[a] - base[a]) * f[a]), 0.0, top[a]);
                const double hi = std::clamp(std::floor((pb.hi[a] - base[a]) * f[a]), 0.0, top[a]);
                n *= hi - lo + 1;
            }
            total += n;
        }
        return total;
    };
    const std::array<int, 3> asked = res_;
    while (product(res_) > 1 && count(res_, budget(res_)) > budget(res_))
        for (int& r : res_) r = std::max(1, static_cast<int>(r * 0.8));
    if (res_ != asked)
        limits_.push_back(fmt::format("grid: resolution {}x{}x{} reduced to {}x{}x{}: the primitives' boxes overlap "
                                      "so many cells that a ray would test more than {} times the primitives, or the "
                                      "references exceed {} per primitive",
                                      asked[0], asked[1], asked[2], res_[0], res_[1], res_[2], kTestsPerPrim,
                                      kRefsPerPrim));
}

StructureStats Grid::compute_structure() const {
    StructureStats s;
    s.limits = limits_;
    s.interior = 1;  // the grid itself: the one node a ray enters before its first cell
    s.leaves = cell_count();
    for (std::uint64_t c = 0; c < cell_count(); ++c) s.empty_leaves += offsets_[c] == offsets_[c + 1];
    s.references = refs_.size();
    s.depth = 1;
    s.bytes = (offsets_.size() + refs_.size()) * sizeof(std::uint32_t);
    for (const auto& p : planes_) s.bytes += p.size() * sizeof(float);
    return s;
}

// The cost model's view: the balanced binary split of the cell index ranges (the longest range
// halved, the lower half getting floor(len/2) cells, ties to the lowest axis) down to single
// cells. The 3DDDA never visits these binary nodes: they only carry the regions and planes the
// probabilities are computed over, so they cost nothing (hop 0) and are no traversal step,
// except the root, which stands for the grid box and is counted like the traversal's
// interior(0). Each cell visit is a step and costs one hop; per_entry_hop = -1 because the
// first cell is reached without one.
bool Grid::emit_model(ModelSink& sink) const {
    ModelFlags f(ModelFamily::Grid, {.interior_hop = 1});  // the paper: one hop per cell
    f.per_ray_box = 1;
    f.per_entry_hop = -1;
    if (!sink.begin(f)) return true;
    struct Range {
        int lo[3], hi[3];  // cell index ranges, hi exclusive
    };
    auto region = [&](const Range& r) {
        return Box3{{planes_[0][r.lo[0]], planes_[1][r.lo[1]], planes_[2][r.lo[2]]},
                    {planes_[0][r.hi[0]], planes_[1][r.hi[1]], planes_[2][r.hi[2]]}};
    };
    auto cell_refs = [&](std::uint64_t c) {
        return std::span<const std::uint32_t>(refs_).subspan(offsets_[c], offsets_[c + 1] - offsets_[c]);
    };
    const Range all{{0, 0, 0}, {res_[0], res_[1], res_[2]}};
    if (cell_count() == 1) {
        // One cell: the grid node above it, so that the model counts the same steps and depths.
        ModelNode root;
        root.region = region(all);
        root.leaf = false;
        root.count = 1;
        root.step = true;
        sink.node(root, {});
        if (sink.skip_children()) return true;
        ModelNode leaf;
        leaf.region = root.region;
        leaf.count = offsets_[1] - offsets_[0];
        leaf.hop = 1;
        sink.node(leaf, cell_refs(0));
        return true;
    }
    auto emit = [&](auto&& self, const Range& r, bool root) -> void {
        ModelNode m;
        m.region = region(r);
        int axis = 0;
        for (int a = 1; a < 3; ++a)
            if (r.hi[a] - r.lo[a] > r.hi[axis] - r.lo[axis]) axis = a;
        const int len = r.hi[axis] - r.lo[axis];
        if (len == 1) {
            const std::uint64_t c = cell_index(r.lo[0], r.lo[1], r.lo[2]);
            m.count = offsets_[c + 1] - offsets_[c];
            m.hop = 1;
            m.step = true;
            sink.node(m, cell_refs(c));
            return;
        }
        const int mid = r.lo[axis] + len / 2;
        m.leaf = false;
        m.axis = static_cast<std::int8_t>(axis);
        m.split = planes_[axis][mid];
        m.count = 2;
        m.hop = 0;
        m.step = root;
        sink.node(m, {});
        if (sink.skip_children()) return;
        Range left = r, right = r;
        left.hi[axis] = mid;
        right.lo[axis] = mid;
        self(self, left, false);
        self(self, right, false);
    };
    emit(emit, all, true);
    return true;
}

namespace {

const Registration reg{
    {"grid",
     "Fujimoto's uniform grid, traversed by the 3DDDA of Amanatides and Woo",
     // Default hetero: of the three formulas the only one that gives about D*N cells, as cubic as
     // possible, whatever the box's shape (the common rule of Cleary-Wyvill, Havran, Wald et al.);
     // woo gives D*N only for a cube (balls: 361 cells for 7382 primitives).
     {ParamSpec::text("res", "hetero",
                      "hetero: Klimaszewski's cubic cells, about D*N of them; woo: L=(D*N)^(1/3), "
                      "res_i=floor(size_i/max_size*L); regular: round(D*N^(1/3)) on every axis; or AxBxC. Each axis "
                      "in [1, 1024], a flat axis gets 1, formula grids are scaled down to at most 2^24 cells"),
      ParamSpec::real("density", "1", 1e-3, 1e3,
                      "D in the resolution formulas (cells per primitive for woo and hetero); ignored for AxBxC"),
      spatial::kAssignParam,
      spatial::kMailboxParam},
     [](const Scene& s, const Params& p) {
         const double density = p.real("density");
         const std::array<int, 3> res = resolution(p.str("res"), density, s.size(), s.bounds());
         return std::make_unique<Grid>(s, res, spatial::parse_assign(p), p.flag("mailbox"));
     }},
    {{{}, kTestHits | kTestSampled | kTestSpdModel},
     {{"res=woo"}, kTestHits | kTestSampled},
     {{"res=regular", "assign=exact"}, kTestHits},
     {{"res=hetero", "density=8", "assign=exact", "mailbox=1"}, kTestHits},
     {{"res=13x7x9"}, kTestHits}}};

}  // namespace
}  // namespace rtcost::grid
