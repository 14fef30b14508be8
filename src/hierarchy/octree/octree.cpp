// `octree`: how a node splits its cell, and the registration (the rest is common/cell_tree.hpp's).
#include "octree.hpp"

namespace rtcost::octree {

int Octree::split(const Box3& cell, int, const std::vector<std::uint32_t>& refs, const subdiv::Assigner& as,
                  Box3* kids, std::vector<std::uint8_t>& mask, std::array<std::size_t, 8>& counts) const {
    const Vec3 c = subdiv::centre(cell);
    for (int k = 0; k < 8; ++k) kids[k] = subdiv::octant(cell, c, k);
    as.masks(refs, kids, 8, mask, counts);
    return subdiv::hardly_separates(counts, refs.size(), options().growth) ? 0 : 8;
}

void Octree::make_interior(Node& n, const Box3& cell, int, std::uint32_t first) const {
    n.is_leaf = 0;
    n.center = subdiv::centre(cell);
    n.index = first;
    n.count = 0;
}

namespace {

const Registration reg{
    {"octree",
     "Glassner's octree: eight children at the centre",
     subdiv::param_specs(8, kMaxDepth, 1),
     [](const Scene& s, const Params& p) {
         Options o = subdiv::read_options(p);
         o.name = "octree";
         return std::make_unique<Octree>(s, o);
     }},
    {{{}, kTestHits | kTestSampled | kTestSpdModel | kTestSubdivision},
     {{"traversal=recursive", "max_prims=4"}, kTestHits},
     {{"traversal=recursive", "max_prims=2"}, kTestSampled},
     {{"traversal=recursive"}, kTestSubdivision},
     {{"assign=exact", "mailbox=1"}, kTestSubdivision},
     {{"traversal=recursive", "max_prims=4", "mailbox=1"}, kTestSubdivision},
     {{"max_depth=0"}, kTestSubdivision},
     {{"max_depth=0", "traversal=recursive"}, kTestSubdivision},
     {{"max_depth=10", "max_prims=2"}, kTestSubdivision}}};

}  // namespace
}  // namespace rtcost::octree
