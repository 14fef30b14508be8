// `rc5d`: the beam test, the (lazy or eager) subdivision, structure statistics, the model tree
// and the registration. The traversal is in rc5d.hpp.
#include <fmt/format.h>

#include "rc5d.hpp"

#include <algorithm>
#include <deque>
#include <numeric>

#include <unistd.h>

namespace rtcost::rc5d {
namespace {

constexpr std::uint64_t kRefBytes = sizeof(std::uint32_t);

// Narrows [hlo, hhi] to the h with h * m <= r; false when no h can satisfy it.
inline bool clip(double m, double r, double& hlo, double& hhi) {
    if (m > 0) hhi = std::min(hhi, r / m);
    else if (m < 0) hlo = std::max(hlo, r / m);
    else if (r < 0) return false;
    return true;
}

// The child of `cell` below (0) or at or above (1) `split` on dimension `dim`.
Cell child_cell(const Cell& cell, int dim, float split, int side) {
    Cell c = cell;
    if (side) c.lo[dim] = split;
    else c.hi[dim] = split;
    return c;
}

}  // namespace

bool Rc5d::beam_meets(const Cell& c, int cube, const Box3& b, double pad) {
    const int k = cube / 2;
    const bool neg = cube % 2 != 0;
    const int i1 = k == 0 ? 1 : 0, i2 = k == 2 ? 1 : 2;
    // Forward coordinate z = s p_k. Origins span [zq0, zq1], the box [zb0, zb1]; a ray from an
    // origin o reaches forward coordinate z at distance h = z - s o_k, which must be >= 0. The
    // origin's coordinates are independent, so the h at which some origin's ray can be inside
    // the box's slab on the dominant axis form [zb0 - zq1, zb1 - zq0].
    const double olo = static_cast<double>(c.lo[k]) - pad, ohi = static_cast<double>(c.hi[k]) + pad;
    const double zq0 = neg ? -ohi : olo, zq1 = neg ? -olo : ohi;
    const double zb0 = neg ? -static_cast<double>(b.hi[k]) : b.lo[k];
    const double zb1 = neg ? -static_cast<double>(b.lo[k]) : b.hi[k];
    double hlo = std::max(0.0, zb0 - zq1), hhi = zb1 - zq0;
    for (int j = 0; j < 2; ++j) {
        const int i = j == 0 ? i1 : i2;
        const double w0 = c.lo[3 + j] - kPadUV, w1 = c.hi[3 + j] + kPadUV;
        const double a = static_cast<double>(c.lo[i]) - pad, e = static_cast<double>(c.hi[i]) + pad;
        // At distance h the beam's cross-section on axis i is [a + h w0, e + h w1] (h >= 0); the
        // same h must reach the box on both lateral axes and the dominant one.
        if (!clip(w0, b.hi[i] - a, hlo, hhi)) return false;
        if (!clip(-w1, e - b.lo[i], hlo, hhi)) return false;
    }
    return hlo <= hhi;
}

Rc5d::Rc5d(const Scene& s, const Options& o)
    : HierarchyImpl(s), box_(s.bounds()), empty_(s.empty() || s.bounds().empty()), opt_(o) {
    if (empty_) box_ = Box3{{0, 0, 0}, {0, 0, 0}};
    // Padding in the units of the scene's coordinates: it must cover float rounding of points
    // inside the box (relative to the coordinates' magnitude) and of the box's extent.
    double scale = 0;
    for (int a = 0; a < 3; ++a)
        scale = std::max({scale, std::fabs(static_cast<double>(box_.lo[a])), std::fabs(static_cast<double>(box_.hi[a])),
                          static_cast<double>(box_.hi[a]) - box_.lo[a]});
    pad_ = kPadRel * (scale > 0 ? scale : 1.0);
    for (int d = 0; d < 3; ++d) {
        root_.lo[d] = box_.lo[d];
        root_.hi[d] = box_.hi[d];
    }
    root_.lo[3] = root_.lo[4] = -1;
    root_.hi[3] = root_.hi[4] = 1;

    const auto n = static_cast<std::uint32_t>(s.size());
    const float fpad = static_cast<float>(pad_);
    pbox_.resize(n);
    for (std::uint32_t id = 0; id < n; ++id) {
        Box3 b = s.prim_bounds(id);
        if (!b.empty()) b = Box3{b.lo - Vec3{fpad, fpad, fpad}, b.hi + Vec3{fpad, fpad, fpad}};
        pbox_[id] = b;
    }
    for (int cube = 0; cube < 6; ++cube) {
        const int k = cube / 2;
        const bool neg = cube % 2 != 0;
        near_[cube].resize(n);
        for (std::uint32_t id = 0; id < n; ++id) near_[cube][id] = neg ? -pbox_[id].hi[k] : pbox_[id].lo[k];
    }
    std::uint64_t bytes = pbox_.size() * sizeof(Box3) + 6 * n * sizeof(float) + 6 * sizeof(Node);

    for (int cube = 0; cube < 6; ++cube) {
        std::vector<std::uint32_t> ids;
        if (!empty_)
            for (std::uint32_t id = 0; id < n; ++id)
                if (!pbox_[id].empty() && beam_meets(root_, cube, pbox_[id], pad_)) ids.push_back(id);
        // Ascending start along the dominant direction; ties by id, so the order is fixed.
        const std::vector<float>& key = near_[cube];
        std::sort(ids.begin(), ids.end(),
                  [&](std::uint32_t x, std::uint32_t y) { return key[x] < key[y] || (key[x] == key[y] && x < y); });
        bytes += ids.size() * kRefBytes;
        init_node(cubes_[cube], std::move(ids), 0);
    }
    bytes_.store(bytes, std::memory_order_relaxed);
    if (!opt_.lazy) build_eager();
}

void Rc5d::init_node(Node& n, std::vector<std::uint32_t>&& ids, int level) const {
    n.count = static_cast<std::uint32_t>(ids.size());
    if (n.count > 0) {
        n.refs = std::make_unique_for_overwrite<std::uint32_t[]>(n.count);
        std::copy(ids.begin(), ids.end(), n.refs.get());
    }
    const bool split = n.count > static_cast<std::uint32_t>(opt_.max_prims) && level < opt_.max_depth;
    n.state.store(split ? kPending : kLeaf, std::memory_order_relaxed);
}

bool Rc5d::subdivide(Node& n, const Cell& cell, int level, int cube) const {
    const int dim = level % 5;
    const float split = 0.5f * (cell.lo[dim] + cell.hi[dim]);
    const Cell lo = child_cell(cell, dim, split, 0), hi = child_cell(cell, dim, split, 1);
    // Children keep the parent's order (a filter), so their lists stay sorted.
    std::vector<std::uint32_t> a, b;
    for (std::uint32_t i = 0; i < n.count; ++i) {
        const std::uint32_t id = n.refs[i];
        if (beam_meets(lo, cube, pbox_[id], pad_)) a.push_back(id);
        if (beam_meets(hi, cube, pbox_[id], pad_)) b.push_back(id);
    }
    // Reserve the children's memory against the cap (atomically: lazy expansions run in parallel).
    const std::uint64_t need = 2 * sizeof(Node) + (a.size() + b.size()) * kRefBytes;
    std::uint64_t cur = bytes_.load(std::memory_order_relaxed);
    do {
        if (cur + need > opt_.max_bytes) {
            capped_.store(true, std::memory_order_relaxed);
            return false;
        }
    } while (!bytes_.compare_exchange_weak(cur, cur + need, std::memory_order_relaxed));
    auto kids = std::make_unique<Node[]>(2);
    init_node(kids[0], std::move(a), level + 1);
    init_node(kids[1], std::move(b), level + 1);
    n.split = split;
    n.kids = std::move(kids);
    // An interior node's list is never read again.
    bytes_.fetch_sub(n.count * kRefBytes, std::memory_order_relaxed);
    n.refs.reset();
    return true;
}

std::uint8_t Rc5d::expand(Node& n, const Cell& cell, int level, int cube) const {
    std::lock_guard lock(locks_[(reinterpret_cast<std::uintptr_t>(&n) / sizeof(Node)) % locks_.size()]);
    std::uint8_t st = n.state.load(std::memory_order_relaxed);
    if (st != kPending) return st;  // another ray expanded it meanwhile
    st = subdivide(n, cell, level, cube) ? kInterior : kLeaf;
    n.state.store(st, std::memory_order_release);
    return st;
}

// Breadth first, so that a memory cap truncates every cube at about the same depth.
void Rc5d::build_eager() {
    struct Item {
        Node* n;
        Cell cell;
        int level, cube;
    };
    std::deque<Item> queue;
    for (int cube = 0; cube < 6; ++cube)
        if (cubes_[cube].state.load(std::memory_order_relaxed) == kPending) queue.push_back({&cubes_[cube], root_, 0, cube});
    while (!queue.empty()) {
        const Item it = queue.front();
        queue.pop_front();
        if (!subdivide(*it.n, it.cell, it.level, it.cube)) {
            it.n->state.store(kLeaf, std::memory_order_relaxed);
            continue;
        }
        it.n->state.store(kInterior, std::memory_order_relaxed);
        const int dim = it.level % 5;
        for (int side = 0; side < 2; ++side) {
            Node* kid = &it.n->kids[side];
            if (kid->state.load(std::memory_order_relaxed) == kPending)
                queue.push_back({kid, child_cell(it.cell, dim, it.n->split, side), it.level + 1, it.cube});
        }
    }
}

StructureStats Rc5d::compute_structure() const {
    StructureStats s;
    if (capped_.load(std::memory_order_relaxed))
        s.limits.push_back(fmt::format("rc5d: subdivision stopped at the memory cap max_bytes={}{}; beams below it hold "
                                       "more candidates than max_prims",
                                       opt_.max_bytes,
                                       opt_.asked_max_bytes ? fmt::format(" (half this machine's memory; {} was asked)",
                                                                          opt_.asked_max_bytes)
                                                            : ""));
    s.interior = 1;  // the cube selection: the root every classified ray passes
    std::uint64_t nodes = 0;
    std::vector<std::pair<const Node*, int>> stack;
    for (const Node& c : cubes_) stack.emplace_back(&c, 1);
    while (!stack.empty()) {
        auto [n, depth] = stack.back();
        stack.pop_back();
        ++nodes;
        if (n->state.load(std::memory_order_acquire) == kInterior) {
            ++s.interior;
            stack.emplace_back(&n->kids[0], depth + 1);
            stack.emplace_back(&n->kids[1], depth + 1);
            continue;
        }
        // Leaves and pending beams (not yet reached by a ray) alike: the structure built so far.
        ++s.leaves;
        s.empty_leaves += n->count == 0;
        s.references += n->count;
        s.depth = std::max(s.depth, depth);
    }
    s.bytes = pbox_.size() * sizeof(Box3) + 6 * pbox_.size() * sizeof(float) + nodes * sizeof(Node) +
              s.references * kRefBytes;
    return s;
}

// Root: the cube selection (3 classify), six children, the direction cubes. Every 5D interior
// node costs one classify per visit and has two children; leaves are the beams with their
// candidate lists in search order. A 5D node's region is not a 3D box: `region` is its origin
// box (a u or v split leaves it unchanged), and `axis` is -1 throughout because no split is a
// plane that a ray crosses: a ray goes to exactly one child. The split dimension of a node at
// model depth d >= 1 is (d - 1) % 5 (x, y, z, u, v). Pending beams appear as leaves.
bool Rc5d::emit_model(ModelSink& sink) const {
    ModelFlags f(ModelFamily::Rc5d, {.interior_classify = 1});  // the paper: one classification per level
    f.per_ray_box = 1;
    f.per_entry_hop = 0;
    f.one_path = true;
    f.search_pad = static_cast<float>(pad_);
    f.stop_margin = kStopMargin;
    if (!sink.begin(f)) return true;
    ModelNode root;
    root.region = box_;
    root.leaf = false;
    root.count = 6;
    root.classify = 3;
    sink.beam_node(root, ModelBeam{}, {});
    if (sink.skip_children()) return true;  // no ray of the sink's reaches the scene box
    // `m` arrives with the beam's origin box, `b` with its directions; the node decides leaf or
    // split.
    auto emit = [&](auto&& self, const Node& n, const Cell& cell, int level, ModelNode m, const ModelBeam& b) -> void {
        if (n.state.load(std::memory_order_acquire) != kInterior) {
            m.count = n.count;
            sink.beam_node(m, b, std::span<const std::uint32_t>(n.refs.get(), n.count));
            return;
        }
        const int dim = level % 5;
        m.leaf = false;
        m.classify = 1;
        m.count = 2;
        m.beam_dim = static_cast<std::int8_t>(dim);
        m.split = n.split;
        sink.beam_node(m, b, {});
        if (sink.skip_children()) return;  // a reached tree (reached_tree.cpp) left it out
        for (int side = 0; side < 2; ++side) {
            const Cell c = child_cell(cell, dim, n.split, side);
            ModelNode k;
            k.region = c.origin_box();
            ModelBeam kb = b;
            kb.u[0] = c.lo[3];
            kb.u[1] = c.hi[3];
            kb.v[0] = c.lo[4];
            kb.v[1] = c.hi[4];
            self(self, n.kids[side], c, level + 1, k, kb);
        }
    };
    for (int c = 0; c < 6; ++c) {
        ModelNode m;
        m.region = root_.origin_box();
        ModelBeam b;
        b.axis = static_cast<std::int8_t>(c / 2);
        b.negative = c % 2 == 1;
        emit(emit, cubes_[c], root_, 0, m, b);
    }
    return true;
}

namespace {

const Registration reg{
    {"rc5d",
     "Arvo and Kirk's 5D ray classification: beams over ray origin (x, y, z) and direction (u, v)",
     {ParamSpec::integer("max_prims", "8", 0, 1 << 30, "a beam with at most this many candidates is not subdivided"),
      ParamSpec::integer("max_depth", "30", 0, kMaxDepth,
                         "subdivision levels below each of the six direction cubes, cycling x, y, z, u, v (0: one "
                         "beam per cube)"),
      ParamSpec::choice("build", "lazy", {"lazy", "eager"},
                        "lazy: a beam is subdivided when the first ray reaches it (Arvo and Kirk); eager: everything "
                        "at build time"),
      ParamSpec::integer("max_bytes", "1073741824", 1, 1LL << 36,
                         "memory cap in bytes: subdivision stops where the structure would exceed it (a bound always "
                         "holds, as eager builds grow exponentially; at most half the machine's memory); with a cap "
                         "that is reached, lazy and eager trees can differ")},
     [](const Scene& s, const Params& p) {
         Options o;
         o.max_prims = static_cast<int>(p.integer("max_prims"));
         o.max_depth = static_cast<int>(p.integer("max_depth"));
         o.lazy = p.is("build", "lazy");
         o.max_bytes = static_cast<std::uint64_t>(p.integer("max_bytes"));
         // A cap beyond the machine's memory bounds nothing: the build would end out of memory
         // before reaching it. Half the physical memory at most.
         const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGESIZE);
         if (pages > 0 && page > 0) {
             const std::uint64_t half = static_cast<std::uint64_t>(pages) * static_cast<std::uint64_t>(page) / 2;
             if (o.max_bytes > half) o.asked_max_bytes = o.max_bytes, o.max_bytes = half;
         }
         return std::make_unique<Rc5d>(s, o);
     }},
    {{{}, kTestHits},
     {{"max_prims=2", "max_depth=45"}, kTestHits},
     {{"build=eager", "max_depth=10"}, kTestHits | kTestSampled},
     {{"build=eager", "max_depth=8"}, kTestSpdModel},
     {{"build=eager", "max_depth=12"}, kTestModelTree}}};

}  // namespace
}  // namespace rtcost::rc5d
