#pragma once
/// \file io.hpp
/// Reading scenes (NFF, meshes through assimp, built-in generators) and the binary ray and hit
/// files. Every reader throws rtcost::InputError on bad input; none leaves a partial result.

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "rtcost/error.hpp"
#include "rtcost/scene.hpp"

namespace rtcost {

/// Loads a scene from `spec`: a file path (`.nff` read by rtcost's NFF reader, anything else
/// through assimp) or `builtin:NAME[:level]` (see builtin_scene). Throws InputError.
Scene load_scene(std::string_view spec);

/// Reads an NFF scene from a file; `name` is used in error messages.
Scene read_nff_file(const std::string& path);
/// Reads NFF text; `name` is used in error messages.
Scene read_nff(std::string_view text, const std::string& name);
/// Reads a mesh file through assimp (triangulated; ids in mesh order then face order).
Scene read_mesh(const std::string& path);

/// Built-in scenes: `balls` (sphereflake on a ground polygon, default level 4 = 7,382
/// primitives) and `tetra` (recursive tetrahedron, default level 6 = 4,096 triangles).
/// `level` < 0 selects the default. Throws InputError for an unknown name or a bad level.
Scene builtin_scene(std::string_view name, int level = -1);

/// Names of the built-in scenes.
std::vector<std::string> builtin_scene_names();

/// A built-in scene and the levels it takes.
struct BuiltinInfo {
    std::string name;
    int min_level = 0, max_level = 0, default_level = 0;
};
std::vector<BuiltinInfo> builtin_scenes();

/// Range of the largest component of a ray file's direction: outside it the reciprocals the
/// traversals use, or the hit distances, leave float's range.
inline constexpr float kMinDirection = 1e-12f, kMaxDirection = 1e12f;

/// One record of a ray file: 8 little-endian float32, `ox oy oz dx dy dz tmin tmax`.
/// Reads a whole ray file; throws InputError when its size is not a multiple of 32 bytes, or a
/// record has a NaN, an infinite origin or direction, a zero direction, tmin > tmax, a negative
/// tmin, an origin beyond kMaxCoordinate, or a direction outside [kMinDirection, kMaxDirection].
std::vector<Ray> read_rays(const std::string& path);
/// What is wrong with a ray record by the rules read_rays applies ("origin is not finite",
/// "tmin > tmax", ...), or empty when it is a valid ray. Rays from any source (the Python
/// module's arrays) are checked by the same rules.
std::string ray_problem(const Ray& r);
/// Writes rays atomically (to a temporary file renamed into place).
void write_rays(const std::string& path, std::span<const Ray> rays);

/// Hit file: per ray, int32 primitive id (-1 for a miss) then float32 t.
/// Writes atomically (to a temporary file renamed into place).
void write_hits(const std::string& path, std::span<const Hit> hits);
std::vector<Hit> read_hits(const std::string& path);

/// Writes `bytes` to `path` atomically: a temporary file in the same directory, renamed into
/// place once complete, so a failure never leaves a half-written output. Only a regular file (or
/// a new path) is replaced so; a device, a pipe or `-` (stdout) is written in place, a symbolic
/// link is followed to the file it names, and a directory is refused. Throws InputError.
void write_file_atomic(const std::string& path, std::string_view bytes);

/// The descriptor `-` is written to by write_file_atomic (standard output's unless a program
/// moved standard output elsewhere and kept its data descriptor, as the CLI does so that a
/// summary never mixes with data written onto `-`).
void set_standard_output_descriptor(int fd);

/// Installs handlers for SIGINT, SIGTERM, SIGHUP and SIGPIPE (those not ignored already) that
/// remove the temporary file write_file_atomic is writing, if any, then end the process as the
/// signal would have. One temporary at a time is known: the last write_file_atomic started.
void remove_output_on_signals();

}  // namespace rtcost
