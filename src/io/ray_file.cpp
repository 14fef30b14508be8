// Binary ray and hit files (see docs: 8 little-endian float32 per ray; int32 id + float32 t per
// hit). The formats are fixed-size records, so no serialisation library is
// needed; the code assumes a little-endian host, which it checks at compile time.
#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <unistd.h>

#include <fmt/format.h>

#include "rtcost/io.hpp"

static_assert(std::endian::native == std::endian::little, "ray and hit files are little-endian");

namespace rtcost {
namespace {

std::string read_all(const std::string& path) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) throw InputError(path, 0, "is a directory, not a file");
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        throw InputError(path, 0, std::filesystem::exists(path) ? "cannot open file" : "no such file");
    }
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (in.bad()) throw InputError(path, 0, "read error");
    return bytes;
}

}  // namespace

std::vector<Ray> read_rays(const std::string& path) {
    std::string bytes = read_all(path);
    constexpr std::size_t kRecord = 8 * sizeof(float);
    if (bytes.empty()) throw InputError(path, 0, "empty: no rays in it");
    if (bytes.size() % kRecord != 0) {
        throw InputError(path, 0,
                         "size " + std::to_string(bytes.size()) +
                             " bytes is not a multiple of 32 (8 float32 per ray): truncated or not a ray file");
    }
    std::vector<Ray> rays(bytes.size() / kRecord);
    for (std::size_t i = 0; i < rays.size(); ++i) {
        float f[8];
        std::memcpy(f, bytes.data() + i * kRecord, kRecord);
        Ray& r = rays[i];
        r.o = {f[0], f[1], f[2]};
        r.d = {f[3], f[4], f[5]};
        r.tmin = f[6];
        r.tmax = f[7];
        if (const std::string what = ray_problem(r); !what.empty())
            throw InputError(path, 0, "ray " + std::to_string(i) + " (byte " + std::to_string(i * kRecord) + "): " + what);
    }
    return rays;
}

std::string ray_problem(const Ray& r) {
    if (!is_finite(r.o)) return "origin is not finite";
    if (!is_finite(r.d)) return "direction is not finite";
    if (r.d == Vec3{0, 0, 0}) return "direction is zero";
    if (std::isnan(r.tmin) || std::isnan(r.tmax)) return "tmin or tmax is NaN";
    if (r.tmin == kInf) return "tmin is +inf";
    if (r.tmin > r.tmax) return "tmin > tmax";
    // Traversals clip to t >= 0 (a box's widened exit shrinks a negative interval) and Embree
    // asserts on it: segments behind the origin are not traced.
    if (r.tmin < 0) return "tmin " + fmt::format("{:g}", r.tmin) + " is negative (tmin must be >= 0)";
    const float om = std::max({std::fabs(r.o.x), std::fabs(r.o.y), std::fabs(r.o.z)});
    if (om > kMaxCoordinate)
        return fmt::format("origin reaches {:g}, beyond +-{:g}, the largest coordinate rtcost traces exactly", om,
                           kMaxCoordinate);
    const float dm = std::max({std::fabs(r.d.x), std::fabs(r.d.y), std::fabs(r.d.z)});
    if (dm < kMinDirection || dm > kMaxDirection)
        return fmt::format("direction's largest component {:g} is outside [{:g}, {:g}] (reciprocals and t would leave "
                           "float's range; scale the direction)",
                           dm, kMinDirection, kMaxDirection);
    return {};
}

void write_rays(const std::string& path, std::span<const Ray> rays) {
    std::string bytes(rays.size() * 32, '\0');
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const Ray& r = rays[i];
        float f[8] = {r.o.x, r.o.y, r.o.z, r.d.x, r.d.y, r.d.z, r.tmin, r.tmax};
        std::memcpy(bytes.data() + i * 32, f, 32);
    }
    write_file_atomic(path, bytes);
}

void write_hits(const std::string& path, std::span<const Hit> hits) {
    std::string bytes(hits.size() * 8, '\0');
    for (std::size_t i = 0; i < hits.size(); ++i) {
        std::int32_t id = hits[i].prim;
        float t = hits[i].hit() ? hits[i].t : kInf;
        std::memcpy(bytes.data() + i * 8, &id, 4);
        std::memcpy(bytes.data() + i * 8 + 4, &t, 4);
    }
    write_file_atomic(path, bytes);
}

std::vector<Hit> read_hits(const std::string& path) {
    std::string bytes = read_all(path);
    if (bytes.size() % 8 != 0) {
        throw InputError(path, 0, "size " + std::to_string(bytes.size()) +
                                      " bytes is not a multiple of 8 (int32 id + float32 t per hit)");
    }
    std::vector<Hit> hits(bytes.size() / 8);
    for (std::size_t i = 0; i < hits.size(); ++i) {
        std::memcpy(&hits[i].prim, bytes.data() + i * 8, 4);
        std::memcpy(&hits[i].t, bytes.data() + i * 8 + 4, 4);
    }
    return hits;
}

}  // namespace rtcost
