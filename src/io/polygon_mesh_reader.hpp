#pragma once
// rtcost's own readers of PLY and OFF, the two simple polygon formats (see the .cpp for why).
#include <cstdint>
#include <string>
#include <vector>

#include "rtcost/math.hpp"

namespace rtcost {

/// Vertices and polygons (each a list of vertex indices, all in range) of a PLY or OFF file.
struct PolygonMesh {
    std::vector<Vec3> vertices;
    std::vector<std::uint32_t> indices;     ///< the faces' vertex indices, one face after another
    std::vector<std::uint32_t> face_sizes;  ///< the number of indices of each face
};

/// True for the files rtcost reads itself: the extensions .ply and .off, in any case.
bool is_polygon_mesh_file(const std::string& path);

/// Reads a .ply (ASCII or binary) or .off (text) file. Throws InputError, with the line where
/// it knows it, on anything malformed: a header that is not PLY's or OFF's, a count the file
/// does not hold, a face referring to a vertex that does not exist, a vertex that is not finite.
PolygonMesh read_polygon_mesh(const std::string& path);

}  // namespace rtcost
