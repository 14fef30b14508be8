// Mesh files as triangles: PLY and OFF through rtcost's own reader (polygon_mesh_reader.cpp
// says why), the others (OBJ, STL, glTF, ...) through assimp.

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>

#include "polygon_mesh_reader.hpp"
#include "rtcost/io.hpp"

namespace rtcost {
namespace {

Vec3 to_vec3(const aiVector3D& v) { return {v.x, v.y, v.z}; }

// Zero area: the cross product in double vanishes only for collinear or coincident vertices,
// never for a merely thin triangle (as a float cross product can, by underflow).
bool zero_area(Vec3 a, Vec3 b, Vec3 c) {
    double ux = double(b.x) - a.x, uy = double(b.y) - a.y, uz = double(b.z) - a.z;
    double vx = double(c.x) - a.x, vy = double(c.y) - a.y, vz = double(c.z) - a.z;
    return uy * vz - uz * vy == 0 && uz * vx - ux * vz == 0 && ux * vy - uy * vx == 0;
}

Material to_material(const aiMaterial* m) {
    Material out;
    aiColor3D c(1, 1, 1);
    // glTF's PBR base colour is also exposed as the diffuse colour.
    if (m && m->Get(AI_MATKEY_COLOR_DIFFUSE, c) == aiReturn_SUCCESS) {
        Vec3 col{c.r, c.g, c.b};
        if (is_finite(col)) out.color = col;
    }
    return out;
}

std::string mesh_label(const aiMesh* mesh, unsigned index) {
    if (mesh->mName.length > 0) return fmt::format("mesh {} ('{}')", index, mesh->mName.C_Str());
    return fmt::format("mesh {}", index);
}

// "face F: " for the first face using vertex `v`, for error messages.
std::string face_using(const aiMesh* mesh, unsigned v) {
    for (unsigned f = 0; f < mesh->mNumFaces; ++f)
        for (unsigned k = 0; k < mesh->mFaces[f].mNumIndices; ++k)
            if (mesh->mFaces[f].mIndices[k] == v) return fmt::format("face {}: ", f);
    return "";
}

/// The polygon's corner that a fan of triangles starts from: a reflex corner if it has one
/// (so that a quad with one reflex corner, the only way a quad can be non-convex, is split
/// inside itself), else the first. Polygons with more reflex corners are split as fans from it.
std::size_t fan_corner(const std::vector<Vec3>& v, const std::uint32_t* idx, std::size_t n) {
    if (n < 4) return 0;
    Vec3 normal{0, 0, 0};  // Newell's normal of the polygon
    for (std::size_t i = 0; i < n; ++i) {
        const Vec3 a = v[idx[i]], b = v[idx[(i + 1) % n]];
        normal = normal + Vec3{(a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y)};
    }
    for (std::size_t i = 0; i < n; ++i) {
        const Vec3 prev = v[idx[(i + n - 1) % n]], here = v[idx[i]], next = v[idx[(i + 1) % n]];
        if (dot(cross(here - prev, next - here), normal) < 0) return i;
    }
    return 0;
}

Scene scene_from_polygons(const std::string& path, const PolygonMesh& mesh) {
    Scene scene;
    scene.name = path;
    scene.materials.push_back(Material{});
    std::size_t not_triangles = 0, degenerate = 0, at = 0;
    for (const std::uint32_t n : mesh.face_sizes) {
        const std::uint32_t* idx = mesh.indices.data() + at;
        at += n;
        if (n < 3) {
            ++not_triangles;
            continue;
        }
        const std::size_t c = fan_corner(mesh.vertices, idx, n);
        for (std::size_t k = 1; k + 1 < n; ++k) {
            const Triangle t{mesh.vertices[idx[c]], mesh.vertices[idx[(c + k) % n]], mesh.vertices[idx[(c + k + 1) % n]]};
            if (zero_area(t.v0, t.v1, t.v2)) {
                ++degenerate;
                continue;
            }
            scene.add(t, 0);
        }
    }
    if (not_triangles > 0)
        scene.warnings.push_back(fmt::format("{}: {} point or line faces skipped (not triangles)", path, not_triangles));
    if (degenerate > 0)
        scene.warnings.push_back(fmt::format("{}: {} degenerate triangles skipped (zero area)", path, degenerate));
    if (scene.empty()) throw InputError(path, 0, no_primitives_message(scene.warnings));
    scene.has_camera = false;  // finalize() frames the bounds
    scene.finalize();
    return scene;
}

}  // namespace

Scene read_mesh(const std::string& path) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw InputError(path, 0, "no such file");
    if (std::filesystem::is_directory(path, ec)) throw InputError(path, 0, "is a directory");

    if (is_polygon_mesh_file(path)) return scene_from_polygons(path, read_polygon_mesh(path));
    Assimp::Importer importer;
    const aiScene* in = importer.ReadFile(path, aiProcess_ValidateDataStructure);
    if (!in) {
        std::string err = importer.GetErrorString();
        if (err.size() > 200) err = err.substr(0, 200) + "...";
        throw InputError(path, 0, err.empty() ? "cannot open file" : err);
    }
    if (in->mFlags & AI_SCENE_FLAGS_INCOMPLETE) 
        throw InputError(path, 0, "incomplete scene: no geometry, or assimp could not read all of it");
    // Non-finite vertices are checked before post-processing: joining identical vertices would
    // silently merge a NaN vertex into another one.
    for (unsigned mi = 0; mi < in->mNumMeshes; ++mi) {
        const aiMesh* mesh = in->mMeshes[mi];
        for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
            if (!is_finite(to_vec3(mesh->mVertices[v])))
                throw InputError(path, 0, fmt::format("{}: {}vertex {} is not finite", mesh_label(mesh, mi), face_using(mesh, v), v));
        }
    }
    // No aiProcess_FindDegenerates: degenerate triangles are counted and reported here instead.
    in = importer.ApplyPostProcessing(aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                      aiProcess_PreTransformVertices | aiProcess_ValidateDataStructure);
    if (!in) {
        std::string err = importer.GetErrorString();
        throw InputError(path, 0, err.empty() ? "assimp post-processing failed" : err);
    }

    Scene scene;
    scene.name = path;
    for (unsigned i = 0; i < in->mNumMaterials; ++i) scene.materials.push_back(to_material(in->mMaterials[i]));
    if (scene.materials.empty()) scene.materials.push_back(Material{});

    std::size_t not_triangles = 0, degenerate = 0;
    for (unsigned mi = 0; mi < in->mNumMeshes; ++mi) {
        const aiMesh* mesh = in->mMeshes[mi];
        std::uint32_t material = mesh->mMaterialIndex < scene.materials.size() ? mesh->mMaterialIndex : 0;
        for (unsigned fi = 0; fi < mesh->mNumFaces; ++fi) {
            const aiFace& f = mesh->mFaces[fi];
            if (f.mNumIndices != 3) {  // points and lines survive triangulation
                ++not_triangles;
                continue;
            }
            Triangle t{to_vec3(mesh->mVertices[f.mIndices[0]]), to_vec3(mesh->mVertices[f.mIndices[1]]),
                       to_vec3(mesh->mVertices[f.mIndices[2]])};
            if (!is_finite(t.v0) || !is_finite(t.v1) || !is_finite(t.v2))  // overflow in a node transform
                throw InputError(path, 0, fmt::format("{}: face {}: vertex is not finite after its node transform",
                                                      mesh_label(mesh, mi), fi));
            if (zero_area(t.v0, t.v1, t.v2)) {
                ++degenerate;
                continue;
            }
            scene.add(t, material);
        }
    }
    if (not_triangles > 0)
        scene.warnings.push_back(fmt::format("{}: {} point or line faces skipped (not triangles)", path, not_triangles));
    if (degenerate > 0)
        scene.warnings.push_back(fmt::format("{}: {} degenerate triangles skipped (zero area)", path, degenerate));
    if (scene.empty()) throw InputError(path, 0, no_primitives_message(scene.warnings));

    // Positional lights (point and spot); directional and ambient ones have no position.
    for (unsigned li = 0; li < in->mNumLights; ++li) {
        const aiLight* l = in->mLights[li];
        if (l->mType != aiLightSource_POINT && l->mType != aiLightSource_SPOT) continue;
        // aiProcess_PreTransformVertices has already moved lights into world space.
        Vec3 p = to_vec3(l->mPosition);
        aiColor3D c = l->mColorDiffuse;
        float peak = std::max({c.r, c.g, c.b});
        Vec3 col = peak > 0 ? Vec3{c.r, c.g, c.b} / peak : Vec3{1, 1, 1};  // intensities are unbounded
        if (is_finite(p) && is_finite(col)) scene.lights.push_back({p, col});
    }

    scene.has_camera = false;  // finalize() frames the bounds
    scene.finalize();
    return scene;
}

}  // namespace rtcost
