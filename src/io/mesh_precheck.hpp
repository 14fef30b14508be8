#pragma once
// Checks of the mesh files that assimp reads too leniently (PLY and OFF); see mesh_precheck.cpp.
#include <string>

namespace rtcost {

/// For a .ply or .off file: throws InputError when the PLY header has no end_header, a face
/// refers to a vertex that does not exist, or the file holds fewer vertices or faces than its
/// header declares. Other files are left to assimp.
void precheck_mesh(const std::string& path);

}  // namespace rtcost
