// `bsp`: how a node splits its cell, and the registration (the rest is common/cell_tree.hpp's).
#include "bsp.hpp"

namespace rtcost::bsp {

int Bsp::split(const Box3& cell, int depth, const std::vector<std::uint32_t>& refs, const subdiv::Assigner& as,
               Box3* kids, std::vector<std::uint8_t>& mask, std::array<std::size_t, 8>& counts) const {
    // At the top of each block of three levels (X, Y, Z: the block ends in the cell's octants,
    // the very cells an octree node makes), the growth guard: the references straddle so much
    // that the block would hardly separate them.
    if (depth % 3 == 0 && options().growth < 9) {
        Box3 oct[8];
        const Vec3 c = subdiv::centre(cell);
        for (int k = 0; k < 8; ++k) oct[k] = subdiv::octant(cell, c, k);
        std::vector<std::uint8_t> omask;
        std::array<std::size_t, 8> ocounts;
        as.masks(refs, oct, 8, omask, ocounts);
        if (subdiv::hardly_separates(ocounts, refs.size(), options().growth)) return 0;
    }
    const int a = depth % 3;
    const float s = subdiv::mid(cell.lo[a], cell.hi[a]);
    kids[0] = subdiv::half(cell, a, s, 0);
    kids[1] = subdiv::half(cell, a, s, 1);
    as.masks(refs, kids, 2, mask, counts);
    return 2;
}

void Bsp::make_interior(Node& n, const Box3& cell, int depth, std::uint32_t first) const {
    const int a = depth % 3;
    n.axis = static_cast<std::uint32_t>(a);
    n.split = subdiv::mid(cell.lo[a], cell.hi[a]);
    n.index = first;
    n.count = 0;
}

namespace {

const Registration reg{
    {"bsp",
     "Kaplan's BSP tree: binary, spatial mid-plane, axes X, Y, Z in turn",
     subdiv::param_specs(20, kMaxDepth, 2),
     [](const Scene& s, const Params& p) {
         Options o = subdiv::read_options(p);
         o.name = "bsp";
         return std::make_unique<Bsp>(s, o);
     }},
    {{{}, kTestHits | kTestSampled | kTestSpdModel | kTestSubdivision},
     {{"traversal=recursive", "assign=exact", "mailbox=1"}, kTestHits | kTestSubdivision},
     {{"traversal=recursive"}, kTestSampled | kTestSubdivision},
     {{"assign=exact", "mailbox=1"}, kTestSubdivision},
     {{"max_depth=0"}, kTestSubdivision},
     {{"max_depth=0", "traversal=recursive"}, kTestSubdivision},
     {{"max_prims=1", "max_depth=30", "growth=7"}, kTestSubdivision}}};

}  // namespace
}  // namespace rtcost::bsp
