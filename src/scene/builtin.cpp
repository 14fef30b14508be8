// Built-in procedural scenes after Eric Haines' Standard Procedural Databases, so that the
// standard benchmarks are available without the SPD files: `balls` (sphereflake) and `tetra`
// (recursive tetrahedron). At their default levels they reproduce balls.nff and tetra.nff:
// same primitives in the same order, same camera, lights and materials.

#include <array>
#include <cmath>
#include <numbers>
#include <string>

#include <fmt/format.h>

#include "rtcost/io.hpp"

namespace rtcost {
namespace {

constexpr Vec3 kSpdBackground{0.078f, 0.361f, 0.753f};

// Double-precision vector for the generators: the recursion compounds rounding, and the SPD
// programs work in double too.
struct D3 {
    double x, y, z;
    D3 operator+(D3 o) const { return {x + o.x, y + o.y, z + o.z}; }
    D3 operator*(double s) const { return {x * s, y * s, z * s}; }
    Vec3 f() const { return {float(x), float(y), float(z)}; }
};
double ddot(D3 a, D3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
D3 dcross(D3 a, D3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }

// --- balls -----------------------------------------------------------------------------------

// Child directions in a frame whose +z points away from the parent: three trios, each one ball
// high up (elevation ~54.7 deg) and two on the equator, the trios 120 deg apart.
std::array<D3, 9> sphereflake_directions() {
    const double pi = std::numbers::pi;
    const double top_z = std::sqrt(2.0 / 3.0), top_r = std::sqrt(1.0 / 3.0);
    std::array<D3, 9> dirs{};
    for (int trio = 0; trio < 3; ++trio) {
        double base = trio * 2.0 * pi / 3.0;
        auto at = [&](double deg, double r, double z) {
            double a = base + deg * pi / 180.0;
            return D3{r * std::cos(a), r * std::sin(a), z};
        };
        dirs[3 * trio + 0] = at(45, top_r, top_z);
        dirs[3 * trio + 1] = at(15, 1, 0);
        dirs[3 * trio + 2] = at(75, 1, 0);
    }
    return dirs;
}

// Applies the smallest rotation taking +z to the unit vector `d` (Rodrigues about z x d).
D3 rotate_z_to(D3 d, D3 v) {
    double c = d.z;
    if (c > 1 - 1e-9) return v;
    // Straight down the axis is undefined; a half turn about y is what the SPD generator does.
    if (c < -1 + 1e-9) return {-v.x, v.y, -v.z};
    D3 w{-d.y, d.x, 0};                              // z x d, length sin(angle)
    return v * c + dcross(w, v) + w * (ddot(w, v) / (1 + c));
}

struct Sphereflake {
    Scene& scene;
    std::uint32_t material;
    std::array<D3, 9> dirs = sphereflake_directions();

    // Depth first, parent before children: the order of the SPD file.
    void grow(D3 center, D3 dir, double radius, int depth) {
        scene.add(Sphere{center.f(), float(radius)}, material);
        if (depth == 0) return;
        const double child_r = radius / 3;
        for (const D3& local : dirs) {
            D3 d = rotate_z_to(dir, local);
            grow(center + d * (radius + child_r), d, child_r, depth - 1);
        }
    }
};

Scene make_balls(int level) {
    Scene s;
    s.background = kSpdBackground;
    s.has_camera = true;
    s.camera.from = {2.1f, 1.3f, 1.7f};
    s.camera.at = {0, 0, 0};
    s.camera.up = {0, 0, 1};
    s.camera.angle = 45;
    s.camera.hither = 0.01f;
    s.camera.width = s.camera.height = 512;
    s.lights = {{{4, 3, 2}, {1, 1, 1}}, {{1, -4, 4}, {1, 1, 1}}, {{-3, 1, 5}, {1, 1, 1}}};
    s.materials.push_back({{1, 0.75f, 0.33f}, 0.8f, 0, 100000, 0, 1});  // ground
    s.materials.push_back({{1, 0.9f, 0.7f}, 0.5f, 0.5f, 3.0827f, 0, 1});  // balls

    const Vec3 ground[4] = {{12, 12, -0.5f}, {-12, 12, -0.5f}, {-12, -12, -0.5f}, {12, -12, -0.5f}};
    s.add_polygon(ground, 0);
    s.spheres.reserve(s.spheres.size() + (static_cast<std::size_t>(std::pow(9.0, level + 1)) - 1) / 8);
    Sphereflake{s, 1}.grow({0, 0, 0}, {0, 0, 1}, 0.5, level);
    return s;
}

// --- tetra -----------------------------------------------------------------------------------

// Corners of the root tetrahedron (inscribed in the cube [-1,1]^3), in the SPD order.
constexpr std::array<std::array<double, 3>, 4> kCorners{{{-1, -1, 1}, {-1, 1, -1}, {1, -1, -1}, {1, 1, 1}}};

// Four half-size tetrahedra in the corners, recursively; the leaves are output as four
// triangles each, counter-clockwise seen from outside.
void sierpinski(Scene& s, D3 center, double half, int depth) {
    if (depth > 1) {
        for (const auto& c : kCorners)
            sierpinski(s, center + D3{c[0], c[1], c[2]} * (half / 2), half / 2, depth - 1);
        return;
    }
    Vec3 v[4];
    for (int i = 0; i < 4; ++i) v[i] = (center + D3{kCorners[i][0], kCorners[i][1], kCorners[i][2]} * half).f();
    s.add(Triangle{v[0], v[1], v[2]}, 0);
    s.add(Triangle{v[3], v[2], v[1]}, 0);
    s.add(Triangle{v[2], v[3], v[0]}, 0);
    s.add(Triangle{v[1], v[0], v[3]}, 0);
}

Scene make_tetra(int level) {
    Scene s;
    s.background = kSpdBackground;
    s.has_camera = true;
    s.camera.from = {1.02285f, -3.17715f, -2.17451f};
    s.camera.at = {-0.004103f, -0.004103f, 0.216539f};
    s.camera.up = {-0.816497f, -0.816497f, 0.816497f};
    s.camera.angle = 45;
    s.camera.hither = 1;
    s.camera.width = s.camera.height = 512;
    s.lights = {{{2, -18, -5}, {1, 1, 1}}};
    s.materials.push_back({{1, 0.2f, 0.2f}, 1, 0, 100000, 0, 0});
    s.triangles.reserve(std::size_t{1} << (2 * level));
    s.prims.reserve(std::size_t{1} << (2 * level));
    sierpinski(s, {0, 0, 0}, 1.0, level);
    return s;
}

struct Builtin {
    const char* name;
    int min_level, default_level, max_level;
    Scene (*make)(int);
};

// Levels follow the SPD size factor: balls level L has sum 9^i (i = 0..L) spheres, tetra
// level L has 4^(L-1) tetrahedra, i.e. 4^L triangles.
constexpr Builtin kBuiltins[] = {
    {"balls", 0, 4, 6, make_balls},
    {"tetra", 1, 6, 9, make_tetra},
};

}  // namespace

std::vector<std::string> builtin_scene_names() {
    std::vector<std::string> names;
    for (const Builtin& b : kBuiltins) names.emplace_back(b.name);
    return names;
}

std::vector<BuiltinInfo> builtin_scenes() {
    std::vector<BuiltinInfo> out;
    for (const Builtin& b : kBuiltins) out.push_back({b.name, b.min_level, b.max_level, b.default_level});
    return out;
}

Scene builtin_scene(std::string_view name, int level) {
    for (const Builtin& b : kBuiltins) {
        if (name != b.name) continue;
        if (level < 0) level = b.default_level;
        if (level < b.min_level || level > b.max_level)
            throw InputError(fmt::format("builtin:{}", name), 0,
                             fmt::format("level must be {}..{} (got {})", b.min_level, b.max_level, level));
        Scene s = b.make(level);
        s.name = fmt::format("builtin:{}:{}", name, level);
        s.finalize();
        return s;
    }
    std::string known;
    for (const Builtin& b : kBuiltins) known += (known.empty() ? "" : ", ") + std::string(b.name);
    throw InputError(fmt::format("builtin:{}", name), 0,
                     fmt::format("unknown built-in scene '{}' (known: {})", name, known));
}

}  // namespace rtcost
